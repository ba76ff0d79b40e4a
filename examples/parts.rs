//! How often the part search (`DomainConfig::parts`) finds each part of the test kit's objects
//! made of parts: the cases `tests/domains.rs` asserts on one noise draw
//! (`sfs_testkit::parts::CASES`), each view searched under [`DRAWS`] draws of the Kinect noise
//! model. A part is found when a domain covers it with its own symmetry
//! (`sfs_testkit::parts`: 80 % of its points, under 10 % of the domain elsewhere, within 3° and
//! 10 mm).
//!
//! ```text
//! cargo run --release --example parts [-- --why]
//! ```
//! Prints a Markdown table, one row per check: the draws it holds on, and whether it holds on
//! the tests' draw (`TEST_SEED`). `--why` also writes to standard error, for each check that
//! fails on a draw, how it fails (no domain covers the part and how the domains split among
//! the parts, or how far the axis found is from the part's).

use sfs_testkit::parts::{CASES, TEST_SEED};

/// Noise draws per view (seeds 1 to 12, the tests' among them): enough to tell a part found on
/// most draws from one found on a few.
const DRAWS: u32 = 12;

fn main() {
    let why = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--why") => true,
        Some(other) => {
            eprintln!("unknown argument {other:?}; usage: parts [--why]");
            std::process::exit(2);
        }
    };
    println!(
        "| object | view (elevation, azimuth) | part | found on draws (of {DRAWS}) | on the tests' draw |"
    );
    println!("|---|---|---|---|---|");
    let (mut found, mut checks) = (0, 0);
    for case in &CASES {
        for (index, &(elevation, azimuth, view_checks)) in case.views.iter().enumerate() {
            let mut held = vec![0u32; view_checks.len()];
            let mut on_test = vec![false; view_checks.len()];
            for seed in 1..=DRAWS {
                for (i, (check, result)) in case.run(index, seed).into_iter().enumerate() {
                    if let (true, Err(how)) = (why, &result) {
                        let (object, label) = (case.object, check.label());
                        eprintln!("{object} ({elevation}, {azimuth}) {label}, draw {seed}: {how}");
                    }
                    held[i] += result.is_ok() as u32;
                    if seed == TEST_SEED {
                        on_test[i] = result.is_ok();
                    }
                }
            }
            for (i, check) in view_checks.iter().enumerate() {
                println!(
                    "| {} | ({elevation}, {azimuth}) | {} | {} | {} |",
                    case.object,
                    check.label(),
                    held[i],
                    if on_test[i] { "yes" } else { "no" }
                );
                (found, checks) = (found + held[i], checks + DRAWS);
            }
        }
    }
    println!(
        "| **all** | | | {found} of {checks} ({} %) | |",
        (found * 100 + checks / 2) / checks
    );
}
