//! The memory figures of `docs/figures.md`: `Engine::MEMORY_BYTES` of three capacities, as a
//! Markdown table. `bash ci/figures.sh` runs it with the other measurements and writes the file.
//!
//! ```text
//! cargo run --release --example figures
//! ```

use shape_from_symmetry::Engine;

/// One row: the capacities and the bytes they occupy.
fn row<const P: usize, const V: usize, const C: usize>(name: &str) {
    let bytes = Engine::<'_, P, V, C>::MEMORY_BYTES;
    println!("| {name} | {P} | {V} | {C} | {bytes} |");
}

fn main() {
    println!("| configuration | points | voxel slots | depth cells | `Engine::MEMORY_BYTES` |");
    println!("|---|---|---|---|---|");
    row::<512, 2048, 4096>("`Engine<'_, 512, 2048, 4096>`");
    row::<1024, 8192, 8192>("`DefaultEngine` = `Engine<'_, 1024, 8192, 8192>`");
    row::<2048, 8192, 16384>("`Engine<'_, 2048, 8192, 16384>`");
}
