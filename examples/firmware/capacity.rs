//! The engine's capacity and output buffer, the same in both builds (Cortex-M4F under QEMU, and
//! host): capacity can change results.

use shape_from_symmetry::{CompletedPoint, Engine};

/// Engine capacity, the same in both builds (capacity can change results): sampled object
/// points, voxel hash slots, compact depth cells. These are the library's defaults; the
/// firmware's memory.x (192 KiB RAM, at least 16 KiB of it stack) decides whether they fit.
#[cfg(not(feature = "firmware-dense"))]
mod sizes {
    pub const POINTS: usize = 1024;
    pub const VOXELS: usize = 8192;
    pub const CELLS: usize = 8192;

    /// Completed points the output buffer holds: every visible point plus twice as many
    /// generated ones, what 192 KiB of RAM leave beside the engine and the stack (a can's axial +
    /// plane predicts more; `points_dropped` in the output tells when the output or the table is
    /// full). No room for the completion's dense pass.
    pub const OUTPUT_POINTS: usize = 3 * POINTS;
}

/// With `--features firmware-dense`: a quarter of the default capacity, and an output with room
/// for the completion's dense pass on the built-in scene (each written point's lattice cell of
/// four pixels), so that CI measures that pass on the Cortex-M4F (`ci/firmware.sh`).
#[cfg(feature = "firmware-dense")]
mod sizes {
    pub const POINTS: usize = 256;
    pub const VOXELS: usize = 2048;
    pub const CELLS: usize = 2048;
    pub const OUTPUT_POINTS: usize = 24 * POINTS;
}

pub use sizes::{CELLS, OUTPUT_POINTS, POINTS, VOXELS};

/// The engine both builds run.
pub type SearchEngine<'a> = Engine<'a, POINTS, VOXELS, CELLS>;

/// Bytes of the output buffer.
pub const OUTPUT_BYTES: usize = OUTPUT_POINTS * core::mem::size_of::<CompletedPoint>();
