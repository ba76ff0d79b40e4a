//! Host benchmarks of the engine's stages, of each symmetry type's search, and of how the cost
//! grows with the object's size in the image and with the engine's capacity.
//!
//! `cargo bench --bench stages` (one thread; `cargo bench --bench stages -- preparation` runs one
//! group). Groups:
//! * `preparation`: `start` and polls until the engine leaves `Preparing` (support plane,
//!   segmentation, sampling, depth grid, voxel hash). Items: the preparation's work units.
//! * `score_hypothesis`: `Engine::score` of one hypothesis (the strongest symmetry found, else a
//!   plane through the object) after the search, over the whole domain at the finest σ. Items:
//!   transformed points (domain points x scored maps), so items/s is the scoring throughput.
//! * `type_search`: the whole search restricted to one type with `Config::with_types`, on a
//!   synthetic object that has that symmetry (`synth::OBJECTS`, the built-in view and noise);
//!   `whole_search_synthetic`: the same objects with every type, for comparison. Items: work units.
//! * `completion`: polls from stage `Completing` to `Done`. Items: the completion's work units.
//! * `scaling`: the whole search of the synthetic can at about 1k, 3k, 10k, 30k and 50k object
//!   pixels (a 640 x 480 camera, `sfs_testkit::scaling`) with three engine capacities. Items: work units.
//!
//! Scenes: the built-in one and, when `scenes/dev` is present, two development scenes
//! (a can seen from near, 4 193 object pixels; a cracker box, 27 024).

use std::path::Path;

use divan::{Bencher, counter::ItemsCount};
use sfs_testkit::synth::{self, Noise};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{
    CompletedPoint, Config, DefaultEngine, Engine, Plane, Stage, Status, Symmetry, SymmetryType,
    TypeSet,
};

use sfs_testkit::scaling;
use sfs_testkit::scene::LoadedScene;
use sfs_testkit::stages::{self, output_points};

fn main() {
    divan::main();
}

const DEV: &str = "scenes/dev";
const DEV_SCENES: [&str; 2] = [
    "ycb_005_tomato_soup_can_wrist_0",
    "ycb_003_cracker_box_wrist_0",
];
/// Work units per poll while driving the engine to a stage boundary.
const STEP: u32 = 16;
const OUTPUT: usize = output_points(1024);

/// The built-in scene, then the development scenes that are present.
fn scenes() -> Vec<&'static str> {
    let mut names = vec!["builtin"];
    if Path::new(DEV).is_dir() {
        names.extend(DEV_SCENES);
    }
    names
}

fn load(name: &str) -> LoadedScene {
    sfs_testkit::scene::load_named(Path::new(DEV), name).expect("scene loads")
}

/// A fresh default engine started on `scene`, polled `STEP` units at a time until it reaches
/// `stage` (or is done).
fn engine_at<'a>(
    scene: &'a LoadedScene,
    out: &'a mut [CompletedPoint],
    stage: Stage,
) -> Box<DefaultEngine<'a>> {
    let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
    engine.start(scene.scene(), out).expect("valid scene");
    while engine.stage() != stage && engine.poll(STEP) == Ok(Status::Working) {}
    engine
}

#[divan::bench(args = scenes(), sample_count = 20, sample_size = 1)]
fn preparation(bencher: Bencher, name: &str) {
    let scene = load(name);
    let staged = stages::run_staged::<1024, 8192, 8192>(&scene, Config::DEFAULT).expect("search");
    let mut out = vec![CompletedPoint::ZERO; OUTPUT];
    bencher
        .counter(ItemsCount::new(staged.preparing.work_units))
        .bench_local(|| {
            let mut engine = DefaultEngine::new(Config::DEFAULT);
            engine.start(scene.scene(), &mut out).expect("valid scene");
            while engine.stage() == Stage::Preparing {
                engine.poll(STEP).expect("preparation");
            }
            engine.report().work_units
        });
}

#[divan::bench(args = scenes(), sample_count = 20, sample_size = 5)]
fn score_hypothesis(bencher: Bencher, name: &str) {
    let scene = load(name);
    let mut out = vec![CompletedPoint::ZERO; OUTPUT];
    let engine = engine_at(&scene, &mut out, Stage::Done);
    let report = engine.report();
    let symmetry = report.symmetries.first().map_or_else(
        || {
            let points = engine.object_points();
            let centroid = points.iter().copied().sum::<Vec3>() / points.len().max(1) as f32;
            Symmetry::PlaneReflection(Plane::new(Vec3::X, centroid.x).expect("unit normal"))
        },
        |f| f.symmetry,
    );
    let maps = symmetry.maps(engine.config().sampling).scored() as u64;
    let transformed = report.sampled_points as u64 * maps;
    bencher
        .counter(ItemsCount::new(transformed))
        .bench_local(|| engine.score(divan::black_box(&symmetry)));
}

/// The type names, for the per-type search.
fn types() -> Vec<&'static str> {
    SymmetryType::ALL.iter().map(|t| t.name()).collect()
}

/// A synthetic object whose strongest symmetry is `kind`, from the built-in view.
fn object_with(kind: SymmetryType) -> LoadedScene {
    let object = synth::OBJECTS
        .iter()
        .find(|o| o.class() == Some(kind))
        .expect("every type has a ready-made object");
    render(object)
}

fn render(object: &synth::ReadyObject) -> LoadedScene {
    let k = synth::BUILTIN_INTRINSICS;
    let (mut depth, mut mask) = (vec![0; k.pixel_count()], vec![0; k.pixel_count()]);
    let scene = object.scene(synth::BUILTIN_VIEW, Noise::kinect(1));
    let rendered = synth::render(&scene, &k, &mut depth, &mut mask).expect("renders");
    LoadedScene {
        name: object.name.into(),
        depth,
        depth_scale: scene.depth_scale,
        intrinsics: k,
        table: Some(rendered.table),
        mask: Some(mask),
    }
}

/// One whole search with a fresh default engine; its work units.
fn search(scene: &LoadedScene, config: Config, out: &mut [CompletedPoint]) -> u64 {
    let mut engine = DefaultEngine::new(config);
    engine.start(scene.scene(), out).expect("valid scene");
    while engine.poll(u32::MAX) != Ok(Status::Done) {}
    engine.report().work_units
}

#[divan::bench(args = types(), sample_count = 10, sample_size = 1)]
fn type_search(bencher: Bencher, name: &str) {
    let kind = SymmetryType::from_name(name).expect("a type name");
    let scene = object_with(kind);
    let config = Config::DEFAULT.with_types(TypeSet::of(&[kind]));
    let mut out = vec![CompletedPoint::ZERO; OUTPUT];
    let work = search(&scene, config, &mut out);
    bencher
        .counter(ItemsCount::new(work))
        .bench_local(|| search(&scene, config, &mut out));
}

/// The objects of `type_search`, by their type, searched for every type.
#[divan::bench(args = types(), sample_count = 10, sample_size = 1)]
fn whole_search_synthetic(bencher: Bencher, name: &str) {
    let scene = object_with(SymmetryType::from_name(name).expect("a type name"));
    let mut out = vec![CompletedPoint::ZERO; OUTPUT];
    let work = search(&scene, Config::DEFAULT, &mut out);
    bencher
        .counter(ItemsCount::new(work))
        .bench_local(|| search(&scene, Config::DEFAULT, &mut out));
}

#[divan::bench(args = scenes(), sample_count = 10, sample_size = 1)]
fn completion(bencher: Bencher, name: &str) {
    let scene = load(name);
    let staged = stages::run_staged::<1024, 8192, 8192>(&scene, Config::DEFAULT).expect("search");
    bencher
        .counter(ItemsCount::new(staged.completing.work_units))
        .with_inputs(|| {
            // Each input is an engine that has searched and is about to complete: it needs an
            // output of its own for as long as it lives, so each one leaks one (about 400 KiB
            // per sample; the benchmark process is short).
            let out = Box::leak(vec![CompletedPoint::ZERO; OUTPUT].into_boxed_slice());
            engine_at(&scene, out, Stage::Completing)
        })
        .bench_local_values(|mut engine| {
            while engine.poll(u32::MAX) != Ok(Status::Done) {}
            engine // dropped outside the timing
        });
}

/// An engine capacity for the scaling group.
trait Capacity {
    fn search(scene: &LoadedScene, out: &mut [CompletedPoint]) -> u64;
}

fn search_with<const P: usize, const V: usize, const C: usize>(
    scene: &LoadedScene,
    out: &mut [CompletedPoint],
) -> u64 {
    let mut engine = Box::new(Engine::<P, V, C>::new(Config::DEFAULT));
    engine.start(scene.scene(), out).expect("valid scene");
    while engine.poll(u32::MAX) != Ok(Status::Done) {}
    engine.report().work_units
}

/// `Engine<'_, 512, 2048, 4096>`.
struct Small512;
/// `DefaultEngine`: `Engine<'_, 1024, 8192, 8192>`.
struct Default1024;
/// `Engine<'_, 2048, 8192, 16384>`.
struct Large2048;

impl Capacity for Small512 {
    fn search(scene: &LoadedScene, out: &mut [CompletedPoint]) -> u64 {
        search_with::<512, 2048, 4096>(scene, out)
    }
}
impl Capacity for Default1024 {
    fn search(scene: &LoadedScene, out: &mut [CompletedPoint]) -> u64 {
        search_with::<1024, 8192, 8192>(scene, out)
    }
}
impl Capacity for Large2048 {
    fn search(scene: &LoadedScene, out: &mut [CompletedPoint]) -> u64 {
        search_with::<2048, 8192, 16384>(scene, out)
    }
}

#[divan::bench(types = [Small512, Default1024, Large2048], args = scaling::TARGETS, sample_count = 5, sample_size = 1)]
fn scaling<C: Capacity>(bencher: Bencher, target_pixels: u32) {
    let can = synth::object("can").expect("the can");
    let sized = scaling::scene_with_pixels(can, target_pixels).expect("renders");
    let mut out = vec![CompletedPoint::ZERO; output_points(2048)];
    let work = C::search(&sized.scene, &mut out);
    bencher
        .counter(ItemsCount::new(work))
        .bench_local(|| C::search(&sized.scene, &mut out));
}
