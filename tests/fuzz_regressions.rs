//! Replays the saved fuzz inputs of the `engine` target (`fuzz/regressions/engine/`: crash
//! inputs, if a fuzz run ever finds one, and a few corpus seeds that reach deep into the search)
//! through the harness the fuzz target runs (`sfs_testkit::fuzz::engine`), so `cargo test`
//! keeps them passing on stable without cargo-fuzz. The C API's are replayed by
//! `capi/tests/fuzz_regressions.rs`.

use sfs_testkit::fuzz::{engine, replay};

#[test]
fn engine_inputs_replay() {
    assert!(replay("engine", engine::run) > 0);
}
