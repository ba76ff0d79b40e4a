//! `cargo +nightly-2026-05-20 fuzz run c_api`: the C API under arbitrary call sequences (see
//! `sfs_testkit::fuzz::c_api`).
#![no_main]

use sfs_testkit::fuzz::c_api;

libfuzzer_sys::fuzz_target!(|data: &[u8]| c_api::run(data));
