//! How often the part search (`DomainConfig::parts`) finds each part of the test kit's objects
//! made of parts: the cases `tests/domains.rs` asserts (`sfs_testkit::parts::CASES`), each view
//! searched under `DRAWS` draws of the Kinect noise model. A part is found when a domain covers
//! it with its own symmetry (`sfs_testkit::parts`: 80 % of its points, under 10 % of the domain
//! elsewhere, within 3° and 10 mm).
//!
//! ```text
//! cargo run --release --example parts [-- --lateral-jitter] [--why]
//! ```
//! Prints a Markdown table, one row per check: the draws it holds on, and what it claims (found
//! or a known gap, and the fewest draws the tests accept: `parts::Claim`). `--lateral-jitter`
//! renders the views with the Kinect's lateral noise too, and searches them with the default
//! sensor model, which models it (`parts::Camera::Lateral`); the claims are those the tests
//! assert without it. `--why` also writes to standard error, for each check that fails on a
//! draw, how it fails (no domain covers the part and how the domains split among the parts,
//! or how far the axis found is from the part's).

use sfs_testkit::parts::{CASES, Camera, DRAWS};

const USAGE: &str = "usage: parts [--lateral-jitter] [--why]";

fn main() {
    let (mut why, mut camera) = (false, Camera::Axial);
    for arg in std::env::args().skip(1) {
        match arg.as_str() {
            "--why" => why = true,
            "--lateral-jitter" => camera = Camera::Lateral,
            other => {
                eprintln!("unknown argument {other:?}; {USAGE}");
                std::process::exit(2);
            }
        }
    }
    println!(
        "| object | view (elevation, azimuth) | part | found on draws (of {DRAWS}) | claim (least) |"
    );
    println!("|---|---|---|---|---|");
    let (mut found, mut checks) = (0, 0);
    for case in &CASES {
        for (index, &(elevation, azimuth, view_checks)) in case.views.iter().enumerate() {
            let held = case.held(index, camera, |seed, check, how| {
                if why {
                    let (object, label) = (case.object, check.label());
                    eprintln!("{object} ({elevation}, {azimuth}) {label}, draw {seed}: {how}");
                }
            });
            for (&(check, claim), held) in view_checks.iter().zip(held) {
                println!(
                    "| {} | ({elevation}, {azimuth}) | {} | {held} | {} ({}) |",
                    case.object,
                    check.label(),
                    claim.name(),
                    claim.least()
                );
                (found, checks) = (found + held, checks + DRAWS);
            }
        }
    }
    println!(
        "| **all** | | | {found} of {checks} ({} %) | |",
        (found * 100 + checks / 2) / checks
    );
}
