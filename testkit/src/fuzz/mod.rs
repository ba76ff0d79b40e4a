//! The fuzz targets' harnesses (`fuzz/fuzz_targets/`), also replayed on stable by `cargo test`
//! over the saved inputs in `fuzz/regressions/<target>/`.
//!
//! - [`engine`]: arbitrary scenes fed to the Rust API, the budget contract checked per poll.
//! - `c_api` (feature `capi`): arbitrary call sequences through the C API, each documented
//!   status checked.

pub mod bytes;
#[cfg(feature = "capi")]
pub mod c_api;
pub mod engine;

use std::path::Path;

/// Runs `harness` on every file of `fuzz/regressions/<target>` (sorted by name) and on a few
/// fixed inputs (empty, all zero, all ones); returns how many saved files it replayed.
pub fn replay(target: &str, harness: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz/regressions")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .collect();
    files.sort();
    for file in &files {
        let data = std::fs::read(file).unwrap();
        println!("{}", file.display());
        harness(&data);
    }
    for data in [&[][..], &[0; 64], &[0xFF; 64], &[7; 300], &[2; 300]] {
        harness(data);
    }
    files.len()
}
