//! Running one search: the engine polled under a work budget until it is done, timed.

use std::time::Instant;

use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::symmetry::MAX_MAPS;
use shape_from_symmetry::{
    CompletedPoint, Config, Engine, Error, Provenance, Report, Status, Symmetry, Target,
};

use super::scene::LoadedScene;

/// The engine the host tools run: the library's default capacities.
pub type HostEngine<'a> = Engine<'a, POINTS, VOXELS, 8192>;
/// The host engine's voxel slots (the deduplication table of the completion): the library's
/// default.
pub const VOXELS: usize = 8192;
const POINTS: usize = 1024;

/// Room for every sampled point and its image under every map of the richest symmetry.
pub const OUTPUT_POINTS: usize = POINTS * (1 + MAX_MAPS);

/// Work units per poll when the caller names no budget.
pub const DEFAULT_BUDGET: u32 = 50_000;

/// A `--budget` value: a positive whole number of work units per poll.
pub fn parse_budget(text: &str) -> super::Result<u32> {
    let budget = text.parse().ok().filter(|&b| b > 0);
    budget.ok_or_else(|| format!("--budget {text}: expected a positive whole number"))
}

/// The search runs on its own thread with this much stack, so that a large engine never
/// overflows the caller's (or a worker thread's) stack.
const SEARCH_STACK_BYTES: usize = 64 << 20;

/// What one search found, with the completed points and the time it took.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub report: Report,
    pub points: Vec<CompletedPoint>,
    /// Wall-clock time of `start` and every `poll`, milliseconds.
    pub wall_ms: f64,
    /// The measurement model's score of the symmetry [`run`] was asked to score
    /// ([`Engine::score`]: over the object's sampled points at the finest σ), once the search was
    /// done; `None` when it was asked for none.
    pub scored: Option<f32>,
    /// The model's score of the strongest symmetry found over every point ([`Engine::score`]),
    /// once the search was done: the search accepts a symmetry on scores taken on a subset of
    /// the points (the least of a climb's), this is the same test without that sampling.
    pub strongest_scored: Option<f32>,
}

impl Outcome {
    /// Positions of the completed points: all of them, or those of one provenance.
    pub fn positions(&self, only: Option<Provenance>) -> Vec<Vec3> {
        let selected = |p: &&CompletedPoint| only.is_none_or(|o| p.provenance == o);
        self.points
            .iter()
            .filter(selected)
            .map(|p| Vec3::from_array(p.position))
            .collect()
    }
}

/// Search `scene` for the object `target` names (`None`: the engine's choice; ignored when the
/// scene has a mask) with `config`, `budget` work units per poll, until the engine is done; then
/// score `also` (a symmetry to compare with what was found, such as the true one), untimed.
pub fn run(
    scene: &LoadedScene,
    target: Option<Target>,
    config: Config,
    budget: u32,
    also: Option<Symmetry>,
) -> Result<Outcome, Error> {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .name(format!("search {}", scene.name))
            .stack_size(SEARCH_STACK_BYTES)
            .spawn_scoped(s, || run_here(scene, target, config, budget, also))
            .expect("cannot start the search thread")
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

fn run_here(
    scene: &LoadedScene,
    target: Option<Target>,
    config: Config,
    budget: u32,
    also: Option<Symmetry>,
) -> Result<Outcome, Error> {
    let mut output = vec![CompletedPoint::ZERO; OUTPUT_POINTS];
    let mut engine = Box::new(HostEngine::new(config));
    let clock = Instant::now();
    let library_scene = shape_from_symmetry::Scene {
        target,
        ..scene.scene()
    };
    engine.start(library_scene, &mut output)?;
    while engine.poll(budget)? == Status::Working {}
    let wall_ms = clock.elapsed().as_secs_f64() * 1e3;
    Ok(Outcome {
        report: engine.report().clone(),
        points: engine.points().to_vec(),
        wall_ms,
        scored: also.and_then(|symmetry| engine.score(&symmetry)),
        strongest_scored: (engine.report().symmetries.first())
            .and_then(|found| engine.score(&found.symmetry)),
    })
}
