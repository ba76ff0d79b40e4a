//! The engine's capacity and output buffer, the same in both builds (Cortex-M4F under QEMU, and
//! host): capacity can change results.

use shape_from_symmetry::{CompletedPoint, Engine};

/// Engine capacity, the same in both builds (capacity can change results): sampled object
/// points, voxel hash slots, compact depth cells. These are the library's defaults; the
/// firmware's memory.x (192 KiB RAM, at least 16 KiB of it stack) decides whether they fit.
pub const POINTS: usize = 1024;
pub const VOXELS: usize = 8192;
pub const CELLS: usize = 8192;

/// Completed points the output buffer holds: every visible point plus twice as many generated
/// ones, what 192 KiB of RAM leave beside the engine and the stack (a can's axial + plane
/// predicts more; `points_dropped` in the output tells when the output or the table is full).
pub const OUTPUT_POINTS: usize = 3 * POINTS;

/// The engine both builds run.
pub type SearchEngine<'a> = Engine<'a, POINTS, VOXELS, CELLS>;

/// Bytes of the output buffer.
pub const OUTPUT_BYTES: usize = OUTPUT_POINTS * core::mem::size_of::<CompletedPoint>();
