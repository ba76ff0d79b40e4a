//! `cargo +nightly-2026-05-20 fuzz run engine`: the Rust API on arbitrary scenes (see
//! `sfs_testkit::fuzz::engine`).
#![no_main]

use sfs_testkit::fuzz::engine;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    engine::run(data);
    // SFS_FUZZ_REPORT_MAX=1: print each new maximum of work units (to measure the bound).
    if std::env::var_os("SFS_FUZZ_REPORT_MAX").is_some() {
        use std::sync::atomic::{AtomicU64, Ordering};
        static PRINTED: AtomicU64 = AtomicU64::new(0);
        let max = engine::MAX_SEEN.load(Ordering::Relaxed);
        if max > PRINTED.fetch_max(max, Ordering::Relaxed) {
            eprintln!("SFS max work units: {max}");
        }
    }
});
