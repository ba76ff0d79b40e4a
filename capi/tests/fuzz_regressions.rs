//! Replays the saved fuzz inputs of the `c_api` target (`fuzz/regressions/c_api/`) through the
//! harness the fuzz target runs (`sfs_testkit::fuzz::c_api`), so `cargo test` keeps them passing
//! on stable without cargo-fuzz.

use sfs_testkit::fuzz::{c_api, replay};

#[test]
fn c_api_inputs_replay() {
    assert!(replay("c_api", c_api::run) > 0);
}
