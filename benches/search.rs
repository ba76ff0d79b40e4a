//! Host benchmark of the whole search (preparation, type and parameter search, completion) on
//! the built-in scene and on every development scene in `scenes/dev`: `whole_search`
//! with the default configuration, `parts_search` with part symmetries searched
//! (`DomainConfig::parts`), which shows what the domain search adds.
//!
//! `cargo bench --bench search`; one thread, the default engine (`DefaultEngine`), one poll with an
//! unlimited budget (slicing changes nothing but the poll count). The "items" divan reports are
//! work units, so items/s is the engine's throughput.

use std::path::Path;

use divan::{Bencher, counter::ItemsCount};
use shape_from_symmetry::{CompletedPoint, Config, DefaultEngine, Status};

use sfs_testkit::scene::{LoadedScene, scene_files, scene_name};

fn main() {
    divan::main();
}

const DEV: &str = "scenes/dev";

/// The built-in scene, then the development scenes that are present.
fn scenes() -> Vec<String> {
    let mut names = vec!["builtin".to_string()];
    if let Ok(files) = scene_files(Path::new(DEV)) {
        names.extend(files.iter().map(|f| scene_name(f)));
    }
    names
}

fn load(name: &str) -> LoadedScene {
    sfs_testkit::scene::load_named(Path::new(DEV), name).expect("scene loads")
}

/// Runs one whole search with a fresh engine (on the stack: 92 KiB); returns its work units.
fn search(scene: &LoadedScene, config: Config, out: &mut [CompletedPoint]) -> u64 {
    let mut engine = DefaultEngine::new(config);
    engine.start(scene.scene(), out).expect("valid scene");
    while engine.poll(u32::MAX) != Ok(Status::Done) {}
    engine.report().work_units
}

fn bench_search(bencher: Bencher, name: &str, config: Config) {
    let scene = load(name);
    let mut out = vec![CompletedPoint::ZERO; 1 << 15];
    let work = search(&scene, config, &mut out);
    bencher
        .counter(ItemsCount::new(work))
        .bench_local(|| search(&scene, config, &mut out));
}

#[divan::bench(args = scenes(), sample_count = 10, sample_size = 1)]
fn whole_search(bencher: Bencher, name: &str) {
    bench_search(bencher, name, Config::DEFAULT);
}

#[divan::bench(args = scenes(), sample_count = 10, sample_size = 1)]
fn parts_search(bencher: Bencher, name: &str) {
    let mut config = Config::DEFAULT;
    config.domains.parts = true;
    bench_search(bencher, name, config);
}
