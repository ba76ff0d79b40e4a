//! The budgeted engine: one explicit state machine that prepares the scene, searches it and
//! writes the completion, doing at most `budget` work units per [`Engine::poll`].
//!
//! Stages: `Preparing` (`prepare`) → `Searching` (the middle loop of `search::domains`, each
//! hypothesis it asks for scored a bounded number of points at a time by `score::Evaluation`) →
//! `Completing` (`complete`) → `Done`. The engine only dispatches: each stage owns its state and
//! advances through the protocol of `work` (a [`Meter`] per poll, `Poll<Output>` back), its
//! output handed to the next stage as a value; the scene travels with the stage that reads it.
//!
//! **Cost.** A poll does at most its budget of work units and at least one (`work` states what
//! a unit buys in each stage). Bookkeeping between stages is O(1), except starting the search
//! (O(`POINTS`)).
//!
//! **Determinism.** Every loop keeps its position in its stage; floating-point sums are
//! accumulated in one fixed order; nothing depends on where a poll ends. The result is
//! bit-identical however the work is sliced (tested with random slicings).
//!
//! **Memory.** Everything lives inline: [`Engine::MEMORY_BYTES`] is the whole footprint of a
//! configuration, known at compile time; the caller lends the scene and the output storage.

use crate::Plane;
use crate::complete::{CompletedPoint, Completion, Pixels};
use crate::component::Scratch;
use crate::config::Config;
use crate::depth::DepthGrid;
use crate::math::{Vec3, sqrt};
use crate::prepare::{Points, Preparation, Prepared, Segmentation, Storage};
use crate::refine::{PlaneContext, Refinement};
use crate::score::{Evaluation, Evidence, Explanation, ImageCost, Level, View, Visit, Watch};
use crate::search::Frame;
use crate::search::domains::{Context, DomainSearch};
use crate::symmetry::Symmetry;
use crate::voxel::VoxelMap;
use crate::work::{Meter, Poll};
use crate::{Error, Scene};

/// A poll budget for a 1 kHz control loop on a 168 MHz Cortex-M4F: measured under QEMU on the
/// built-in scene, no poll at this budget executes more than 100 000 instructions
/// (`ci/firmware.sh` enforces it; the measured figures are in `docs/figures.md`).
pub const RECOMMENDED_BUDGET: u32 = 120;

/// Most symmetries (domains) one search reports.
pub const MAX_SYMMETRIES: usize = 8;
impl Default for Report {
    fn default() -> Self {
        Self::new()
    }
}

impl Report {
    /// An empty report: nothing found, nothing done.
    pub const fn new() -> Self {
        Self {
            symmetries: heapless::Vec::new(),
            runner_up: None,
            points_visible: 0,
            points_generated: 0,
            points_dropped: 0,
            object_pixels: 0,
            segmentation: None,
            support: None,
            sampled_points: 0,
            work_units: 0,
            polls: 0,
        }
    }
}

/// One symmetry found, with the part of the object it explains.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Found {
    /// The symmetry, in the camera frame.
    pub symmetry: Symmetry,
    /// The measurement model's score (lower is better; accepted below
    /// [`crate::ModelConfig::accept`]): the mean cost of its transformed points, for a composite
    /// the mean of its elements' means when each passes, else its least confirmed element's.
    pub score: f32,
    /// `1 - score / accept`, within 0..=1: the share of the acceptance margin the symmetry's
    /// images leave on average (0: at the threshold or above it; 1: every image on a seen
    /// point). How often a symmetry of a given confidence is true is measured in
    /// `docs/figures.md`.
    pub confidence: f32,
    /// Visible (sampled) points this symmetry explains.
    pub domain_points: u32,
}

impl Found {
    /// `symmetry` with its `score` against the acceptance threshold `accept`, explaining
    /// `domain_points` points.
    pub(crate) fn new(symmetry: Symmetry, score: f32, domain_points: u32, accept: f32) -> Self {
        Self {
            symmetry,
            score,
            // An infinite score (too few informative points) is no confidence.
            confidence: ((accept - score) / accept).clamp(0.0, 1.0),
            domain_points,
        }
    }
}

/// What the search has found so far, and what it cost.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Strongest first. Empty: no symmetry.
    pub symmetries: heapless::Vec<Found, MAX_SYMMETRIES>,
    /// The whole object's runner-up, once the search is over: the best-scoring other
    /// hypothesis its search met that the first symmetry does not entail (an alternative
    /// reading, accepted or not: its `confidence` is 0 when not; with no symmetry, the nearest
    /// miss). `domain_points`: the object's sampled points.
    pub runner_up: Option<Found>,
    /// Visible points written to the output (object pixels: one per sampling cell, or all of
    /// them when the output has room for the completion's dense pass, `complete::Completion`).
    pub points_visible: u32,
    /// Generated points written to the output.
    pub points_generated: u32,
    /// Points left out because the output (or the deduplication table) was full; non-zero means
    /// the output is incomplete. Once the table is full, every transformed point not yet tested
    /// is counted without being tested (an upper bound on the points lost).
    pub points_dropped: u32,
    /// Object pixels with a reading.
    pub object_pixels: u32,
    /// How the object was chosen, when the engine segmented it (no mask given); set once the
    /// preparation is over.
    pub segmentation: Option<Segmentation>,
    /// The support plane, given or fitted (normal toward the camera); `None` until the
    /// preparation is over, or when neither a table was given nor one fitted (a mask given).
    pub support: Option<Plane>,
    /// Sampled object points searched.
    pub sampled_points: u32,
    /// Work units done so far.
    pub work_units: u64,
    /// Polls so far.
    pub polls: u32,
}

/// Where the engine is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stage {
    /// No input yet (after `new` or `set_config`).
    Idle,
    /// From the depth image to the sampled object points.
    Preparing,
    /// The symmetry search.
    Searching,
    /// Writing the visible and predicted points.
    Completing,
    /// Finished: the report is final.
    Done,
    /// The input's content ended the search (every later poll returns this error).
    Failed(Error),
}

/// What one poll left behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// More work remains: poll again.
    Working,
    /// The search and the completion are finished; [`Engine::report`] is final.
    Done,
}

/// The engine at its default capacities (1024 points, 8192 voxel slots, 8192 depth cells), the
/// configuration `docs/figures.md` was measured with. (Default const parameters do not apply
/// in expression position: write `DefaultEngine::new(..)`, not `Engine::new(..)`.)
pub type DefaultEngine<'a> = Engine<'a, 1024, 8192, 8192>;

/// Where the engine is, with the scene and what preparation found, for the stages that read
/// them.
#[derive(Clone, Copy, Debug)]
enum Run<'a> {
    Idle,
    Preparing(Scene<'a>),
    Searching(Scene<'a>, Prepared),
    Refining(Scene<'a>, Prepared),
    Completing(Scene<'a>, Prepared),
    /// The scene stays for [`Engine::score`].
    Done(Scene<'a>, Prepared),
    Failed(Error),
}

/// The engine, all its storage inline: `POINTS` sampled object points (32 to 65 535),
/// `VOXELS` hash slots (a power of two, at least 16), `CELLS` compact depth cells (64 to
/// 65 535, at least `POINTS`: the domain growth borrows the segmentation's flags and queue).
/// See the crate docs for sizing.
///
/// The fields are laid out in the order written (`repr(C)`): the stages' small state first, the
/// large tables last. A Cortex-M4 float load reaches at most 1020 bytes past its base register:
/// with the per-point state of preparation, scoring or completion further in, every float field
/// those loops read costs an extra address instruction (measured on the M4F when a 3 KiB table
/// landed in front of them: 2 to 15 % more instructions per unit).
#[derive(Debug)]
#[repr(C)]
pub struct Engine<
    'a,
    const POINTS: usize = 1024,
    const VOXELS: usize = 8192,
    const CELLS: usize = 8192,
> {
    preparation: Preparation,
    evaluation: Evaluation,
    completion: Completion,
    /// An evaluation was started and its score not yet handed to the search.
    awaiting_score: bool,
    refinement: Refinement,
    /// Where the engine is (after the stages' own state: see above).
    run: Run<'a>,
    config: Config,
    output: &'a mut [CompletedPoint],
    report: Report,
    /// The middle loop (and through it the outer and inner loops): its small state first,
    /// then the domain list, the owners and the growth's per-point state.
    domains: DomainSearch<POINTS>,
    points: Points<POINTS>,
    grid: DepthGrid<CELLS>,
    /// The component searches' flags and queue: the segmentation's while preparing, the domain
    /// growth's afterwards.
    scratch: Scratch<CELLS>,
    voxels: VoxelMap<VOXELS>,
}

/// The preparation `config` asks for: the outline sampled when `prepare.outline` asks and no
/// parts are searched ([`crate::PrepareConfig::outline`]).
const fn preparation(config: &Config) -> Preparation {
    let outline = config.prepare.outline && !config.domains.parts;
    Preparation::new(config.prepare, config.sensor, outline)
}

impl<'a, const POINTS: usize, const VOXELS: usize, const CELLS: usize>
    Engine<'a, POINTS, VOXELS, CELLS>
{
    /// Bytes of memory this configuration occupies (all of it; nothing is allocated later).
    pub const MEMORY_BYTES: usize = core::mem::size_of::<Self>();
    const CHECK: () = assert!(
        POINTS >= 32
            && POINTS <= u16::MAX as usize
            && CELLS >= 64
            && CELLS <= u16::MAX as usize
            && CELLS >= POINTS,
        "POINTS must be in 32..=65535, CELLS in 64..=65535 and CELLS at least POINTS"
    );

    /// A new idle engine (`const`: it can live in a `static`).
    pub const fn new(config: Config) -> Self {
        let () = Self::CHECK;
        Self {
            run: Run::Idle,
            preparation: preparation(&config),
            evaluation: Evaluation::new(),
            completion: Completion::new(),
            awaiting_score: false,
            refinement: Refinement::new(),
            config,
            output: &mut [],
            report: Report::new(),
            domains: DomainSearch::new(&config),
            points: Points::new(),
            grid: DepthGrid::new(),
            scratch: Scratch::new(),
            voxels: VoxelMap::new(),
        }
    }

    /// Begin a search of `scene`, writing the completed points into `output`. Checks the input
    /// in O(1) (sizes, intrinsics, scale, table plane, configuration); content errors (no valid
    /// depth, no object) come from `poll`. Any earlier search is discarded.
    pub fn start(
        &mut self,
        scene: Scene<'a>,
        output: &'a mut [CompletedPoint],
    ) -> Result<(), Error> {
        self.config.validate()?;
        scene.validate()?;
        self.discard_run();
        self.preparation.begin(&scene);
        self.output = output;
        self.run = Run::Preparing(scene);
        Ok(())
    }

    /// Do at most `budget` work units (a budget of 0 counts as 1, so every poll makes progress).
    pub fn poll(&mut self, budget: u32) -> Result<Status, Error> {
        let output = core::mem::take(&mut self.output);
        let status = self.poll_into(budget, output);
        self.output = output;
        status
    }

    /// [`Engine::poll`] for a caller that lends its output buffer one poll at a time instead of
    /// for the whole search (the C API, whose caller reads the buffer between polls): this poll
    /// writes completed points into `output`, not into the buffer given to [`Engine::start`]
    /// (pass an empty one there). Pass the same buffer every poll: points are appended at the
    /// count written so far, and what does not fit is counted in `points_dropped`. Same bits as
    /// `poll`. [`Engine::points`] reads only the buffer given to `start`.
    pub fn poll_into(
        &mut self,
        budget: u32,
        output: &mut [CompletedPoint],
    ) -> Result<Status, Error> {
        let budget = budget.max(1);
        match self.run {
            Run::Idle => return Err(Error::NotStarted),
            Run::Failed(e) => return Err(e),
            Run::Done(..) => return Ok(Status::Done),
            _ => {}
        }
        self.report.polls = self.report.polls.saturating_add(1);
        let mut meter = Meter::new(budget);
        while meter.has_left() {
            let run = self.run;
            let step = match &run {
                Run::Preparing(scene) => self.prepare(scene, &mut meter),
                Run::Searching(scene, prepared) => {
                    self.search_step(scene, prepared, &mut meter);
                    Ok(())
                }
                Run::Refining(scene, prepared) => {
                    self.refine(scene, prepared, &mut meter);
                    Ok(())
                }
                Run::Completing(scene, prepared) => {
                    self.complete(scene, prepared, &mut meter, output);
                    Ok(())
                }
                _ => break,
            };
            if let Err(e) = step {
                self.run = Run::Failed(e);
                self.report.work_units += (budget - meter.left()) as u64;
                return Err(e);
            }
        }
        self.report.work_units += (budget - meter.left()) as u64;
        Ok(if matches!(self.run, Run::Done(..)) {
            Status::Done
        } else {
            Status::Working
        })
    }

    /// The result so far: the best symmetry found up to now during the search, final once
    /// `poll` returned `Done`.
    pub fn report(&self) -> &Report {
        &self.report
    }

    /// The completed points written so far. When the output has room for the completion's
    /// dense pass, the count starts again from zero as it begins (its points replace the sampled
    /// ones); final once `poll` returned `Done`.
    pub fn points(&self) -> &[CompletedPoint] {
        let n = (self.report.points_visible + self.report.points_generated) as usize;
        &self.output[..n.min(self.output.len())]
    }

    /// The measurement model's score of any `symmetry` over all the object's points at the finest
    /// resolution (lower is better; accepted below `config.model.accept`), once preparation is
    /// over (`None` before). Synchronous: it costs one work unit per transformed point, about
    /// `POINTS × maps` (the budget does not apply).
    pub fn score(&self, symmetry: &Symmetry) -> Option<f32> {
        self.explained(symmetry, |_, _| ()).map(|e| e.score)
    }

    /// [`Engine::score`], and how it came about: each element's evidence (its mean cost, the
    /// images that confirm or contradict it, whether its strays fail it), and each transformed
    /// point handed to `visit` with its cost and likeliest cause, in scoring order. For finding
    /// out why a symmetry is rejected or preferred; `None` before preparation is over.
    /// Synchronous, as [`Engine::score`], plus one call of `visit` per transformed point.
    pub fn explain(
        &self,
        symmetry: &Symmetry,
        visit: impl FnMut(&ImageCost),
    ) -> Option<Explanation> {
        self.explained(symmetry, |level, view| Visit { level, view, visit })
    }

    /// [`Engine::explain`], each transformed point handed to the watch `watch` makes from the
    /// evaluation's level and view.
    fn explained<'s, W: Watch>(
        &'s self,
        symmetry: &Symmetry,
        watch: impl FnOnce(Level, View<'s, CELLS>) -> W,
    ) -> Option<Explanation> {
        let (Run::Searching(scene, prepared)
        | Run::Refining(scene, prepared)
        | Run::Completing(scene, prepared)
        | Run::Done(scene, prepared)) = &self.run
        else {
            return None;
        };
        let evidence = Evidence {
            view: View::new(
                scene,
                &self.grid,
                self.scratch.spare(POINTS),
                prepared.table,
                &prepared.stats,
                &self.config,
            ),
            voxels: &self.voxels,
            points: self.points.positions(),
        };
        let marks = self.scratch.marks(POINTS);
        let mut evaluation = Evaluation::new();
        let level =
            (self.domains).level(&self.config.model, self.domains.sigma_fine(), &self.voxels);
        evaluation.begin(
            symmetry,
            self.config.sampling,
            level,
            self.points.len,
            u32::MAX,
        );
        let mut watch = watch(level, evidence.view);
        let mut meter = Meter::new(u32::MAX);
        let point = |j: usize| crate::prepare::with_mark(marks, j);
        loop {
            let poll = evaluation.advance_watched(&evidence, point, &mut meter, &mut watch);
            if poll.is_ready() {
                return Some(evaluation.explain(&self.config.model));
            }
        }
    }

    /// The sampled object points (camera frame), once preparation is over.
    pub fn object_points(&self) -> &[Vec3] {
        self.points.positions()
    }

    /// Where the engine is.
    pub fn stage(&self) -> Stage {
        match self.run {
            Run::Idle => Stage::Idle,
            Run::Preparing(_) => Stage::Preparing,
            Run::Searching(..) | Run::Refining(..) => Stage::Searching,
            Run::Completing(..) => Stage::Completing,
            Run::Done(..) => Stage::Done,
            Run::Failed(e) => Stage::Failed(e),
        }
    }

    /// The configuration in force.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Replace the configuration (checked as in [`Config::validate`]; on error nothing changes).
    /// Any search in progress is discarded with its input: the engine is idle, as after
    /// [`Engine::new`] with `config`. Unlike building a new engine, this needs no second
    /// `MEMORY_BYTES` of stack or memory, so an engine in a `static` can be reconfigured.
    pub fn set_config(&mut self, config: Config) -> Result<(), Error> {
        config.validate()?;
        self.config = config;
        self.discard_run();
        self.output = &mut [];
        self.run = Run::Idle;
        Ok(())
    }

    /// Forget the run in progress: its preparation, search, report and any evaluation still
    /// running (which indexes the old domain, so must not survive into a new input's).
    fn discard_run(&mut self) {
        self.preparation = preparation(&self.config);
        self.domains.reset(&self.config);
        (self.evaluation, self.awaiting_score) = (Evaluation::new(), false);
        self.report = Report::new();
    }

    fn prepare(&mut self, scene: &Scene<'a>, meter: &mut Meter) -> Result<(), Error> {
        let mut storage = Storage {
            points: &mut self.points,
            grid: &mut self.grid,
            scratch: &mut self.scratch,
            voxels: &mut self.voxels,
        };
        if let Poll::Ready(prepared) = self.preparation.advance(scene, &mut storage, meter)? {
            self.begin_search(*scene, prepared);
        }
        Ok(())
    }

    /// The whole object is the first domain; start the search on it.
    fn begin_search(&mut self, scene: Scene<'a>, prepared: Prepared) {
        let stats = prepared.stats;
        self.report.object_pixels = stats.object_pixels;
        self.report.segmentation = prepared.segmentation;
        self.report.support = prepared.table;
        self.report.sampled_points = self.points.len as u32;
        let frame = Frame {
            center: Vec3::from_array(stats.centroid),
            radius: stats.radius.max(1e-3),
        };
        let model = &self.config.model;
        let sigma_fine = model.sigma_fine(stats.spacing);
        let excess2 = model.excess2(self.config.sensor.sigma(stats.centroid[2]));
        let gap = stats.surface_gap(&self.config.sensor);
        self.domains.begin(
            &self.config,
            self.points.len,
            frame,
            (sigma_fine, gap),
            excess2,
            prepared.table.filter(|_| self.config.model.resting),
        );
        self.run = Run::Searching(scene, prepared);
    }

    /// Search, spending what is left on `meter`: score the hypothesis at hand, or one step of
    /// the middle loop (which asks for the next hypothesis, grows a domain or gathers the next
    /// one); once the search is finished, begin the completion.
    fn search_step(&mut self, scene: &Scene<'a>, prepared: &Prepared, meter: &mut Meter) {
        let (lent, around, marks) = self.scratch.split(POINTS);
        let (grid, config) = (&self.grid, &self.config);
        let view = View::new(scene, grid, around, prepared.table, &prepared.stats, config);
        let evidence = Evidence::new(view, &self.voxels, self.points.positions());
        let mut last = None;
        if self.awaiting_score {
            let domain = self.domains.domain();
            let point = |j: usize| crate::prepare::with_mark(marks, domain[j] as usize);
            match self.evaluation.advance(&evidence, point, meter) {
                // The score is handed over by the next unit of the middle loop (in the next
                // poll when this one is spent: the finished evaluation gives it again).
                Poll::Ready(()) if meter.has_left() => {
                    last = Some(self.evaluation.scored(&self.config.model))
                }
                _ => return,
            }
            self.awaiting_score = false;
        }
        let cx = Context {
            evidence: &evidence,
            points: &self.points,
            config: &self.config,
            stride: prepared.stats.stride,
        };
        let published = &mut self.report.symmetries;
        let hypothesis = self.domains.step(&cx, last, meter, published, lent);
        if let Some(h) = hypothesis {
            let level = (self.domains).level(&self.config.model, h.sigma, &self.voxels);
            self.evaluation.begin(
                &h.symmetry,
                self.config.sampling,
                level,
                self.domains.domain().len(),
                h.transformed,
            );
            if h.tally {
                self.evaluation.tally_strays();
            }
            if h.every_mirror {
                self.evaluation.halves_about_every_mirror();
            }
            self.awaiting_score = true;
        }
        if self.domains.is_finished() {
            self.refinement.begin(self.config.search.refine_rounds);
            self.run = Run::Refining(*scene, *prepared);
        }
    }

    /// Refine the symmetries found, spending what is left on `meter`; then begin the
    /// completion.
    fn refine(&mut self, scene: &Scene<'a>, prepared: &Prepared, meter: &mut Meter) {
        let (lent, around, mixed) = self.scratch.split(POINTS);
        let (grid, config) = (&self.grid, &self.config);
        let view = View::new(scene, grid, around, prepared.table, &prepared.stats, config);
        let evidence = Evidence::new(view, &self.voxels, self.points.positions());
        let sigma_fine = self.domains.sigma_fine();
        let level = (self.domains).level(&self.config.model, sigma_fine, &self.voxels);
        let (owners, found) = self.domains.owners_and_found_mut();
        let settings = (&self.config.model, self.config.sampling, &level);
        let context = PlaneContext {
            pixels: self.points.pixels(),
            stride: prepared.stats.stride,
            radius: prepared.stats.radius,
            mixed,
        };
        let done = self.refinement.advance(
            &evidence,
            context,
            &owners[..self.points.len],
            found,
            lent.queue,
            &mut self.evaluation,
            settings,
            meter,
        );
        if done.is_ready() {
            self.report.symmetries = self.domains.found().iter().copied().collect();
            self.report.runner_up = self.domains.runner_up();
            // Generated points may lie in front of the observed depth by the free-space term's
            // σ and the reading's excess noise (`ModelConfig::excess2`).
            let free = sigma_fine * self.config.model.free_per_match;
            let tolerance = sqrt(free * free + self.domains.excess2());
            self.completion
                .begin(tolerance, sigma_fine, self.domains.whole());
            self.run = Run::Completing(*scene, *prepared);
        }
    }

    /// Write the visible points, then each symmetry's generated points, spending what is left
    /// on `meter`.
    fn complete(
        &mut self,
        scene: &Scene<'a>,
        prepared: &Prepared,
        meter: &mut Meter,
        output: &mut [CompletedPoint],
    ) {
        let around = self.scratch.spare(POINTS);
        let view = View::new(
            scene,
            &self.grid,
            around,
            prepared.table,
            &prepared.stats,
            &self.config,
        );
        let pixels = Pixels {
            scene,
            preparation: &self.preparation,
            pixels: self.points.pixels(),
            stats: &prepared.stats,
        };
        let done = self.completion.advance(
            &view,
            &pixels,
            &mut self.voxels,
            self.points.positions(),
            &self.domains.owners()[..self.points.len],
            self.domains.found(),
            self.config.sampling,
            output,
            meter,
        );
        let written = self.completion.written();
        (
            self.report.points_visible,
            self.report.points_generated,
            self.report.points_dropped,
        ) = (written.visible, written.generated, written.dropped);
        if done.is_ready() {
            self.run = Run::Done(*scene, *prepared);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::Cause;
    use crate::score::plate::{self, K, PIXELS, SCALE};
    use crate::symmetry::{SymmetryType, TypeSet};

    /// Room for the square plate's 400 points (7/8 of 512 is the sampling's target: stride 1),
    /// its crop of 28 x 28 depth cells and its voxels.
    type Small<'a> = Engine<'a, 512, 2048, 1024>;
    type Plate = plate::Plate<512, 2048>;
    const OUT: usize = 1024;

    /// Plane reflections only: one node of Table 1, a search short enough for a unit test.
    fn planes() -> Config {
        Config::DEFAULT.with_types(TypeSet::of(&[SymmetryType::PlaneReflection]))
    }

    /// Poll with `budgets` in turn until done, checking every poll's cost; the stages seen after
    /// each poll, without repeats.
    fn run(engine: &mut Small<'_>, budgets: &[u32]) -> heapless::Vec<Stage, 8> {
        let mut stages: heapless::Vec<Stage, 8> = heapless::Vec::new();
        // A bound far above the polls a search of the plate takes (units / mean budget).
        for &budget in budgets.iter().cycle().take(1_000_000) {
            let (before, polls) = (engine.report().work_units, engine.report().polls);
            let status = engine.poll(budget).unwrap();
            let spent = engine.report().work_units - before;
            // A budget of 0 counts as 1: every poll makes progress, none overspends.
            assert!(
                (1..=budget.max(1) as u64).contains(&spent),
                "{spent} of {budget}"
            );
            assert_eq!(engine.report().polls, polls + 1);
            if stages.last() != Some(&engine.stage()) {
                stages.push(engine.stage()).unwrap();
            }
            if status == Status::Done {
                return stages;
            }
        }
        panic!("the search ends");
    }

    /// `plate` searched to the end with [`planes`], and the mirror plane it found.
    fn searched<'a>(plate: &'a Plate, out: &'a mut [CompletedPoint; OUT]) -> (Small<'a>, Symmetry) {
        let mut engine = Small::new(planes());
        engine.start(plate.scene(), out).unwrap();
        run(&mut engine, &[RECOMMENDED_BUDGET]);
        let found = engine.report().symmetries[0].symmetry;
        (engine, found)
    }

    /// Mirror plane `symmetry` moved `by` metres along its normal.
    fn moved(symmetry: Symmetry, by: f32) -> Symmetry {
        match symmetry {
            Symmetry::PlaneReflection(p) => Symmetry::PlaneReflection(Plane {
                offset: p.offset + by,
                ..p
            }),
            other => panic!("a plane, not {other:?}"),
        }
    }

    #[test]
    fn a_poll_before_start_is_an_error() {
        let mut engine = Small::new(planes());
        assert_eq!(engine.stage(), Stage::Idle);
        assert_eq!(engine.poll(100), Err(Error::NotStarted));
        assert_eq!(
            *engine.report(),
            Report::new(),
            "nothing done, nothing counted"
        );
        // An input refused by `start` leaves the engine idle.
        let short = [plate::PLATE_MM; PIXELS - 1];
        let mut out = [CompletedPoint::ZERO; OUT];
        let refused = engine.start(Scene::new(&short, SCALE, K), &mut out);
        let mismatch = Error::DepthSizeMismatch {
            expected: PIXELS as u32,
            actual: PIXELS as u32 - 1,
        };
        assert_eq!(refused, Err(mismatch));
        assert_eq!(engine.poll(100), Err(Error::NotStarted));
    }

    #[test]
    fn polls_walk_the_stages_in_order_within_their_budgets() {
        let plate = Plate::square();
        let mut out = [CompletedPoint::ZERO; OUT];
        let mut engine = Small::new(planes());
        engine.start(plate.scene(), &mut out).unwrap();
        assert_eq!(engine.stage(), Stage::Preparing);
        // Budgets of every size, down to none (counted as one).
        let stages = run(&mut engine, &[0, 1, 7, RECOMMENDED_BUDGET]);
        use Stage::*;
        assert_eq!(stages, [Preparing, Searching, Completing, Done]);
        let report = engine.report();
        // The 20 x 20 plate pixels, all sampled (stride 1), all written as visible points.
        assert_eq!(report.sampled_points, 400);
        // A square plate has mirror planes; without parts the whole object is the one domain.
        assert_eq!(report.symmetries.len(), 1);
        assert!(report.symmetries[0].score < Config::DEFAULT.model.accept);
        assert_eq!(report.points_visible, 400);
        let written = report.points_visible + report.points_generated;
        assert_eq!(engine.points().len(), written as usize);
    }

    #[test]
    fn an_explained_score_adds_up_to_the_score() {
        let (plate, mut out) = (Plate::square(), [CompletedPoint::ZERO; OUT]);
        let (engine, found) = searched(&plate, &mut out);
        // The found plane, and one 0.2 m off it (the plate is 0.17 m wide): the shifted
        // plane's images land 0.4 m beside the plate.
        let off = moved(found, 0.2);
        for symmetry in [found, off] {
            let (mut sum, mut images, mut causes) = (0.0f64, 0u32, [0u32; 7]);
            let explained = engine
                .explain(&symmetry, |image| {
                    causes[image.cause as usize] += 1;
                    if !matches!(
                        image.cause,
                        Cause::SelfMap | Cause::Obstructed | Cause::Mixed
                    ) {
                        (sum, images) = (sum + image.cost as f64, images + 1);
                    }
                })
                .unwrap();
            // The same evaluation as `score`: the same bits.
            assert_eq!(Some(explained.score), engine.score(&symmetry));
            let [element] = explained.elements[..] else {
                panic!("one element: {explained:?}");
            };
            assert_eq!(element.images, images);
            assert!((element.mean as f64 - sum / images as f64).abs() < 1e-4);
            let left_out = causes[Cause::SelfMap as usize]
                + causes[Cause::Obstructed as usize]
                + causes[Cause::Mixed as usize];
            assert_eq!(left_out, explained.uninformative);
            let decided = causes[Cause::Confirmed as usize] + causes[Cause::Stray as usize];
            assert_eq!(
                (element.decided, element.strays),
                (decided, causes[Cause::Stray as usize])
            );
        }
        // The shifted plane's images are not confirmed: the found one's mostly are.
        let confirmed = |s: &Symmetry| {
            let mut n = 0;
            engine.explain(s, |i| n += (i.cause == Cause::Confirmed) as u32);
            n
        };
        assert!(confirmed(&found) > 4 * confirmed(&off).max(1));
    }

    #[test]
    fn an_explained_image_carries_the_reading_it_was_judged_against() {
        let (plate, mut out) = (Plate::square(), [CompletedPoint::ZERO; OUT]);
        let (engine, found) = searched(&plate, &mut out);
        let near = |r: Option<f32>, depth: f32| r.is_some_and(|r| (r - depth).abs() < 1e-6);
        // The found plane's confirmed images land on the plate, 0.5 m away.
        let mut confirmed = 0;
        engine.explain(&found, |i| {
            if i.cause == Cause::Confirmed {
                assert!(near(i.reading, 0.5), "{i:?}");
                confirmed += 1;
            }
        });
        assert!(confirmed > 0);
        // 5 cm off, the images land up to 10 cm beside the plate (12 pixels): on the wall
        // 0.8 m away within the crop's margin of 4 pixels, in free space (next to the plate's
        // edge, the lateral alternative makes them less than strays), or beyond the crop,
        // where the reading is taken to be infinitely far: strays.
        let off = moved(found, 0.05);
        let (mut wall, mut beyond) = (0, 0);
        engine.explain(&off, |i| {
            if near(i.reading, 0.8) {
                assert!(matches!(i.cause, Cause::FreeSpace | Cause::Stray), "{i:?}");
                wall += 1;
            } else if i.reading == Some(f32::INFINITY) {
                assert!(i.stray_beyond_crop(), "{i:?}");
                beyond += 1;
            }
        });
        assert!(
            wall > 0 && beyond > 0,
            "{wall} on the wall, {beyond} beyond the crop"
        );
    }

    #[test]
    fn dropping_edge_pixels_leaves_the_plates_rim_out() {
        let plate = Plate::square();
        let mut out = [CompletedPoint::ZERO; OUT];
        let mut config = planes();
        config.prepare.drop_edge_pixels = true;
        let mut engine = Small::new(config);
        engine.start(plate.scene(), &mut out).unwrap();
        run(&mut engine, &[RECOMMENDED_BUDGET]);
        // The plate's outer ring borders the wall 0.3 m behind: a depth jump.
        assert_eq!(engine.report().sampled_points, 18 * 18);
        assert!(engine.report().symmetries[0].score < Config::DEFAULT.model.accept);
    }

    #[test]
    fn after_done_a_poll_returns_done_at_no_cost() {
        let plate = Plate::square();
        let mut out = [CompletedPoint::ZERO; OUT];
        let mut engine = Small::new(planes());
        engine.start(plate.scene(), &mut out).unwrap();
        run(&mut engine, &[RECOMMENDED_BUDGET]);
        let (report, points) = (engine.report().clone(), copied(engine.points()));
        for budget in [0, 1, u32::MAX] {
            assert_eq!(engine.poll(budget), Ok(Status::Done));
        }
        assert_eq!(engine.stage(), Stage::Done);
        assert_eq!(*engine.report(), report, "no unit, no poll counted");
        assert_eq!(copied(engine.points()), points);
    }

    #[test]
    fn a_failing_input_keeps_its_error() {
        // No reading at all: no support plane to fit, nothing to segment.
        let blank = [0u16; PIXELS];
        let mut engine = Small::new(planes());
        engine.start(Scene::new(&blank, SCALE, K), &mut []).unwrap();
        let error = loop {
            match engine.poll(7) {
                Ok(Status::Working) => {}
                Ok(Status::Done) => panic!("a blank image has no object"),
                Err(e) => break e,
            }
        };
        assert_eq!(error, Error::NoValidDepth);
        assert_eq!(engine.stage(), Stage::Failed(error));
        let report = engine.report().clone();
        for budget in [0, 1, u32::MAX] {
            assert_eq!(engine.poll(budget), Err(error));
        }
        assert_eq!(*engine.report(), report, "no unit, no poll counted");
        // A 3 x 3 mask: 9 points at stride 1, too few to search.
        let plate = Plate::new(|u, v| (u < 3 && v < 3).then_some(plate::PLATE_MM));
        engine.start(plate.scene(), &mut []).unwrap();
        let needed = crate::prepare::MIN_POINTS;
        let few = Error::TooFewPoints { found: 9, needed };
        assert_eq!(engine.poll(u32::MAX), Err(few));
        assert_eq!(engine.poll(1), Err(few));
        assert_eq!(engine.stage(), Stage::Failed(few));
    }

    #[test]
    fn a_bad_configuration_changes_nothing_and_a_good_one_discards_the_run() {
        let plate = Plate::square();
        // Any slicing, the same for both runs.
        let budgets = [97];
        let (mut out, mut out_again) = ([CompletedPoint::ZERO; OUT], [CompletedPoint::ZERO; OUT]);
        let mut engine = Small::new(planes());
        engine.start(plate.scene(), &mut out).unwrap();
        run(&mut engine, &budgets);
        let (report, points) = (engine.report().clone(), copied(engine.points()));
        // The same run, offered a bad configuration in the middle of its search.
        let mut again = Small::new(planes());
        again.start(plate.scene(), &mut out_again).unwrap();
        while again.stage() != Stage::Searching {
            again.poll(budgets[0]).unwrap();
        }
        let mut bad = planes();
        bad.model.accept = f32::NAN;
        let field = "model.accept";
        assert_eq!(again.set_config(bad), Err(Error::InvalidConfig { field }));
        assert_eq!(again.stage(), Stage::Searching);
        assert_eq!(*again.config(), planes());
        run(&mut again, &budgets);
        assert_eq!(*again.report(), report);
        assert_eq!(copied(again.points()), points);
        // A good one: the run and its report are gone.
        assert_eq!(again.set_config(Config::DEFAULT), Ok(()));
        assert_eq!(again.stage(), Stage::Idle);
        assert_eq!(*again.report(), Report::new());
        assert_eq!(again.poll(100), Err(Error::NotStarted));
    }

    /// The completed points, copied.
    fn copied(points: &[CompletedPoint]) -> heapless::Vec<CompletedPoint, OUT> {
        heapless::Vec::from_slice(points).unwrap()
    }
}
