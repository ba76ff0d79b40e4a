//! Replays the saved fuzz inputs (`fuzz/regressions/<target>/`: crash inputs, if a fuzz run ever
//! finds one, and a few corpus seeds that reach deep into the search) through the same harnesses
//! the fuzz targets run (`fuzz/harness/`), so `cargo test` keeps them passing on stable without
//! cargo-fuzz. The C API's replays need `--features ffi` (ci/harden.sh runs them).

use std::path::Path;

#[path = "../fuzz/harness/bytes.rs"]
mod bytes;
#[cfg(feature = "ffi")]
#[path = "../fuzz/harness/c_api.rs"]
mod c_api;
#[path = "../fuzz/harness/engine.rs"]
mod engine;

/// Runs `harness` on every file of `fuzz/regressions/<target>`; returns how many.
fn replay(target: &str, harness: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/regressions")
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
    files.len()
}

#[test]
fn engine_inputs_replay() {
    assert!(replay("engine", engine::run) > 0);
    // The empty input and a few fixed ones.
    for data in [&[][..], &[0; 64], &[0xFF; 64], &[7; 300]] {
        engine::run(data);
    }
}

#[cfg(feature = "ffi")]
#[test]
fn c_api_inputs_replay() {
    assert!(replay("c_api", c_api::run) > 0);
    for data in [&[][..], &[0; 64], &[0xFF; 64], &[2; 300]] {
        c_api::run(data);
    }
}
