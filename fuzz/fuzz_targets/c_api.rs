//! `cargo +nightly-2026-05-20 fuzz run c_api`: the C API under arbitrary call sequences (see
//! `fuzz/harness/c_api.rs`).
#![no_main]

#[path = "../harness/bytes.rs"]
mod bytes;
#[path = "../harness/c_api.rs"]
mod c_api;

libfuzzer_sys::fuzz_target!(|data: &[u8]| c_api::run(data));
