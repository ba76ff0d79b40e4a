//! The result digest of the built-in scene and of every scene in the folders given: the check
//! that a restructuring changed no bit of any result.
//!
//! ```text
//! cargo run --release --example digests -- [FOLDER ...] [--parts]
//! ```
//! One line per scene: `NAME digest work_units`, the digest of the firmware example (every bit
//! of the report and the completed points), polled at `RECOMMENDED_BUDGET`.

use std::path::PathBuf;

use sfs_testkit::scene::{LoadedScene, scene_files};
use shape_from_symmetry::{CompletedPoint, Config, DefaultEngine, RECOMMENDED_BUDGET, Status};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parts = args.iter().any(|a| a == "--parts");
    let mut scenes = vec![LoadedScene::builtin().expect("built-in scene")];
    for dir in args.iter().filter(|a| !a.starts_with("--")) {
        for path in scene_files(&PathBuf::from(dir)).expect("scene folder") {
            scenes.push(LoadedScene::load(&path).expect("scene"));
        }
    }
    for scene in &scenes {
        let mut config = Config::DEFAULT;
        config.domains.parts = parts;
        let (digest, units) = std::thread::scope(|s| {
            std::thread::Builder::new()
                .stack_size(64 << 20)
                .spawn_scoped(s, || {
                    let mut output = vec![CompletedPoint::ZERO; 3 * 1024];
                    let mut engine = Box::new(DefaultEngine::new(config));
                    engine.start(scene.scene(), &mut output).expect("start");
                    while engine.poll(RECOMMENDED_BUDGET).expect("poll") == Status::Working {}
                    let report = engine.report();
                    (
                        sfs_testkit::harness::digest(report, engine.points()),
                        report.work_units,
                    )
                })
                .unwrap()
                .join()
                .unwrap()
        });
        println!("{} 0x{digest:016x} {units}", scene.name);
    }
}
