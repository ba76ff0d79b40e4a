//! The budgeted engine: one explicit state machine that prepares the scene, walks the symmetry
//! search and writes the completion, doing at most `budget` work units per [`Engine::poll`].
//!
//! Stages: `Preparing` ([`crate::prepare`]) → `Searching` ([`crate::search`], each hypothesis
//! scored a bounded number of points at a time by [`crate::score::Evaluation`]) → `Completing`
//! ([`crate::complete`]) → `Done`.
//!
//! **Work unit.** One transformed point scored (one 3x3 transform, up to eight hash probes, and a
//! projection with a division and a depth lookup unless the match already beats occlusion), and,
//! at about the same cost (the weights are in [`crate::prepare`]): 8 pixels of a preparation pass,
//! 4 sampling-lattice points, 16 RANSAC residuals, 4 neighbours of a segmentation block, a point
//! hashed at one voxel level, one completion test (plus one unit per
//! [`crate::complete::PROBES_PER_UNIT`] hash slots its lookups read beyond the first eight), one
//! step of the search's bookkeeping. Measured on a Cortex-M4F (README, "On the target"): 455 to
//! 542 instructions per unit on average in every stage, and at most 91 280 in a poll of
//! [`RECOMMENDED_BUDGET`] units.
//!
//! **Determinism.** Every loop keeps its position in the engine; floating-point sums are
//! accumulated in one fixed order; nothing depends on where a poll ends. The result is
//! bit-identical however the work is sliced (tested with random slicings).
//!
//! **Memory.** Everything lives inline: [`Engine::MEMORY_BYTES`] is the whole footprint of a
//! configuration, known at compile time; the caller lends the scene and the output storage.

use crate::complete::{CompletedPoint, Completion};
use crate::depth::DepthGrid;
use crate::math::Vec3;
use crate::prepare::{Points, Preparation, PrepareConfig, Progress, Segmentation, Storage};
use crate::score::{Evaluation, Evidence, ModelConfig, View};
use crate::search::domains::{DomainConfig, Grown, Growth, frame_of};
use crate::search::{Candidate, Frame, Request, SearchConfig, TypeSearch};
use crate::symmetry::{Sampling, Symmetry, TypeSet};
use crate::voxel::VoxelMap;
use crate::{Error, Scene};

/// A poll budget for a 1 kHz control loop on a 168 MHz Cortex-M4F: measured under QEMU on the
/// built-in scene, no poll at this budget executes more than 91 280 instructions, under the
/// 100 000 that `ci/firmware.sh` enforces (README, "On the target").
pub const RECOMMENDED_BUDGET: u32 = 140;

/// Most symmetries (domains) one search reports.
pub const MAX_SYMMETRIES: usize = 8;
/// Owner of a point no symmetry claims (yet).
pub const UNCLAIMED: u8 = u8::MAX;
/// Owner of a point searched in a domain that held no symmetry.
pub const EXHAUSTED: u8 = u8::MAX - 1;

/// What a domain growth is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Growing {
    /// A node of the type search failed: the part of the domain its proposal explains.
    Narrowing,
    /// A domain's symmetry is found: the part of the domain it explains becomes its domain.
    Claiming,
    /// The largest connected part of the unclaimed points, searched next.
    Leftover,
    /// A part was carved out of a domain: the part of the rest of it the domain's own symmetry
    /// does not contradict stays that symmetry's.
    Rest,
}

/// The middle loop's position between type searches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Middle {
    /// A type search (or nothing) is running.
    Idle,
    Growing(Growing),
    /// Collecting the unclaimed points into the domain list, from this point on.
    Gathering {
        next: usize,
    },
}

/// Search settings. [`Config::DEFAULT`] is what the README's figures were measured with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// The symmetry types wanted (the search still visits the weaker types on the way).
    pub types: TypeSet,
    pub sampling: Sampling,
    pub prepare: PrepareConfig,
    pub model: ModelConfig,
    pub search: SearchConfig,
    pub domains: DomainConfig,
}

impl Config {
    pub const DEFAULT: Config = Config {
        types: TypeSet::ALL,
        sampling: Sampling { axial_steps: 7 },
        prepare: PrepareConfig::DEFAULT,
        model: ModelConfig::DEFAULT,
        search: SearchConfig::DEFAULT,
        domains: DomainConfig::DEFAULT,
    };

    /// Check that every value is in range.
    pub fn validate(&self) -> Result<(), Error> {
        let m = &self.model;
        let g = &self.search.grid;
        let positive = |x: f32| x.is_finite() && x > 0.0;
        let ok = !self.types.is_empty()
            && (2..=7).contains(&self.sampling.axial_steps)
            && [
                m.cost_occluded,
                m.cost_stray,
                m.sigma_min,
                m.free_per_match,
                m.accept,
            ]
            .into_iter()
            .all(positive)
            && m.sigma_per_spacing.is_finite()
            && m.self_radius.is_finite()
            && (0.0..=1.0).contains(&m.min_informative)
            && g.plane_normals >= 1
            && g.line_directions >= 1
            && g.angle_steps >= 1
            && (2..=64).contains(&g.offset_steps)
            && (2..=64).contains(&g.lattice_steps)
            && self.search.candidates >= 1
            && self.search.grid_transformed >= 1
            && self.search.climb_transformed >= 1
            && self.search.polish_transformed >= 1
            && self.search.finest_step > 0.0
            && self.search.finest_step <= 1.0
            && positive(self.prepare.plane_tolerance)
            && self.prepare.min_height.is_finite()
            && self.prepare.max_height > self.prepare.min_height
            && (0.0..=1.0).contains(&self.domains.min_share)
            && (0.0..=1.0).contains(&self.domains.max_share)
            && (0.0..=1.0).contains(&self.domains.min_leftover)
            && self.domains.max_rim >= 0.0;
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidConfig)
        }
    }

    /// This configuration restricted to `types`.
    pub const fn with_types(self, types: TypeSet) -> Self {
        Self { types, ..self }
    }
}

impl Default for Report {
    fn default() -> Self {
        Self::new()
    }
}

impl Report {
    pub const fn new() -> Self {
        Self {
            symmetries: heapless::Vec::new(),
            points_visible: 0,
            points_generated: 0,
            points_dropped: 0,
            object_pixels: 0,
            sampled_points: 0,
            work_units: 0,
            polls: 0,
        }
    }
}

impl Default for Config {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// One symmetry found, with the part of the object it explains.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Found {
    pub symmetry: Symmetry,
    /// The measurement model's mean cost over the transformed points (lower is better).
    pub score: f32,
    /// Visible (sampled) points this symmetry explains.
    pub domain_points: u32,
}

/// What the search has found so far, and what it cost.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Strongest first. Empty: no symmetry.
    pub symmetries: heapless::Vec<Found, MAX_SYMMETRIES>,
    /// Visible points written to the output.
    pub points_visible: u32,
    /// Generated points written to the output.
    pub points_generated: u32,
    /// Points left out because the output (or the deduplication table) was full; non-zero means
    /// the output is incomplete. Once the table is full, every transformed point not yet tested
    /// is counted without being tested (an upper bound on the points lost).
    pub points_dropped: u32,
    /// Object pixels with a reading, and the sampled points searched.
    pub object_pixels: u32,
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
    Idle,
    Preparing,
    Searching,
    Completing,
    Done,
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

/// The engine at its default capacities (1024 points, 4096 voxel slots, 8192 depth cells), the
/// configuration the README's figures were measured with. (Default const parameters do not apply
/// in expression position: write `DefaultEngine::new(..)`, not `Engine::new(..)`.)
pub type DefaultEngine<'a> = Engine<'a, 1024, 4096, 8192>;

/// The engine, all its storage inline: `POINTS` sampled object points (at most 65 535),
/// `VOXELS` hash slots (a power of two, at least 16), `CELLS` compact depth cells (at most
/// 65 535). See the crate docs for sizing.
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
    const VOXELS: usize = 4096,
    const CELLS: usize = 8192,
> {
    stage: Stage,
    preparation: Preparation,
    evaluation: Evaluation,
    completion: Completion,
    /// An evaluation was started and its score not yet handed to the search.
    awaiting_score: bool,
    /// The symmetry whose points the completion writes next.
    completing: u8,
    sigma_fine: f32,
    /// Where the middle loop is.
    middle: Middle,
    domain_len: usize,
    /// Length of the domain a narrowing started from (the narrower domain is its prefix).
    wider_len: usize,
    /// Length of the domain the walk ended in (claimed if the claiming growth finds nothing).
    searched_len: usize,
    /// Index in `found` of the whole object's symmetry: the first domain's, or the one the
    /// rest of the first domain kept when a part was carved out of it. Points of no domain are
    /// completed through it.
    whole: u8,
    /// The first domain's symmetry was accepted on the whole object and no part was carved out
    /// of it: the points it contradicts are searched only for symmetries that share a mirror
    /// plane with it.
    leftovers_keep_whole: bool,
    config: Config,
    scene: Option<Scene<'a>>,
    output: &'a mut [CompletedPoint],
    search: TypeSearch,
    /// The symmetries of the finished domains.
    found: heapless::Vec<Found, MAX_SYMMETRIES>,
    report: Report,
    points: Points<POINTS>,
    /// Indices of the points of the domain being searched.
    domain: [u16; POINTS],
    /// Index (in `found`) of the symmetry whose domain holds each point; [`UNCLAIMED`], or
    /// [`EXHAUSTED`] for points searched in a domain that held no symmetry.
    owners: [u8; POINTS],
    grid: DepthGrid<CELLS>,
    segmentation: Segmentation<CELLS>,
    voxels: VoxelMap<VOXELS>,
    growth: Growth<POINTS>,
}

impl<'a, const POINTS: usize, const VOXELS: usize, const CELLS: usize>
    Engine<'a, POINTS, VOXELS, CELLS>
{
    /// Bytes of memory this configuration occupies (all of it; nothing is allocated later).
    pub const MEMORY_BYTES: usize = core::mem::size_of::<Self>();
    const CHECK: () = assert!(
        POINTS >= 32 && POINTS <= u16::MAX as usize && CELLS >= 64 && CELLS <= u16::MAX as usize,
        "POINTS must be in 32..=65535 and CELLS in 64..=65535"
    );

    /// A new idle engine (`const`: it can live in a `static`).
    pub const fn new(config: Config) -> Self {
        let () = Self::CHECK;
        Self {
            config,
            scene: None,
            output: &mut [],
            points: Points::new(),
            domain: [0; POINTS],
            domain_len: 0,
            owners: [UNCLAIMED; POINTS],
            found: heapless::Vec::new(),
            growth: Growth::new(config.domains),
            wider_len: 0,
            searched_len: 0,
            whole: 0,
            leftovers_keep_whole: false,
            middle: Middle::Idle,
            grid: DepthGrid::new(),
            segmentation: Segmentation::new(),
            voxels: VoxelMap::new(),
            preparation: Preparation::new(config.prepare),
            search: TypeSearch::new(config.search),
            evaluation: Evaluation::new(),
            awaiting_score: false,
            completing: 0,
            sigma_fine: 0.0,
            completion: Completion::new(),
            report: Report::new(),
            stage: Stage::Idle,
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
        self.scene = Some(scene);
        self.output = output;
        self.stage = Stage::Preparing;
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
        match self.stage {
            Stage::Idle => return Err(Error::NotStarted),
            Stage::Failed(e) => return Err(e),
            Stage::Done => return Ok(Status::Done),
            _ => {}
        }
        self.report.polls = self.report.polls.saturating_add(1);
        let mut used = 0;
        while used < budget && self.stage != Stage::Done {
            let step = match self.stage {
                Stage::Preparing => self.prepare(budget - used),
                Stage::Searching => Ok(self.search_step(budget - used)),
                Stage::Completing => Ok(self.complete(budget - used, output)),
                _ => Ok(budget - used),
            };
            match step {
                Ok(units) => used += units,
                Err(e) => {
                    self.stage = Stage::Failed(e);
                    self.report.work_units += used as u64;
                    return Err(e);
                }
            }
        }
        self.report.work_units += used as u64;
        Ok(if self.stage == Stage::Done {
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

    /// The completed points written so far.
    pub fn points(&self) -> &[CompletedPoint] {
        let n = (self.report.points_visible + self.report.points_generated) as usize;
        &self.output[..n.min(self.output.len())]
    }

    /// The measurement model's score of any `symmetry` over all the object's points at the finest
    /// resolution (lower is better; accepted below `config.model.accept`), once preparation is
    /// over (`None` before). Synchronous: it costs one work unit per transformed point, about
    /// `POINTS × maps` (the budget does not apply).
    pub fn score(&self, symmetry: &Symmetry) -> Option<f32> {
        if matches!(
            self.stage,
            Stage::Idle | Stage::Preparing | Stage::Failed(_)
        ) {
            return None;
        }
        let scene = self.scene.as_ref()?;
        let evidence = Evidence {
            view: View::new(scene, &self.grid, self.preparation.table),
            voxels: &self.voxels,
            points: self.points.positions(),
        };
        let mut evaluation = Evaluation::new();
        let level = self.config.model.level(self.sigma_fine, &self.voxels);
        evaluation.begin(
            symmetry,
            self.config.sampling,
            level,
            self.points.len,
            u32::MAX,
        );
        while evaluation.is_running() {
            evaluation.advance(&evidence, |j| j, u32::MAX);
        }
        Some(evaluation.score(&self.config.model))
    }

    /// The sampled object points (camera frame), once preparation is over.
    pub fn object_points(&self) -> &[Vec3] {
        self.points.positions()
    }

    pub fn stage(&self) -> Stage {
        self.stage
    }

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
        self.scene = None;
        self.output = &mut [];
        self.stage = Stage::Idle;
        Ok(())
    }

    /// Forget the run in progress: its preparation, search, report and any evaluation still
    /// running (which indexes the old domain, so must not survive into a new input's).
    fn discard_run(&mut self) {
        self.preparation = Preparation::new(self.config.prepare);
        self.search = TypeSearch::new(self.config.search);
        (self.evaluation, self.awaiting_score) = (Evaluation::new(), false);
        self.middle = Middle::Idle;
        self.report = Report::new();
    }

    fn prepare(&mut self, budget: u32) -> Result<u32, Error> {
        let Some(scene) = self.scene else {
            return Err(Error::NotStarted);
        };
        let mut storage = Storage {
            points: &mut self.points,
            grid: &mut self.grid,
            segmentation: &mut self.segmentation,
            voxels: &mut self.voxels,
        };
        match self.preparation.step(&scene, &mut storage, budget)? {
            Progress::Working(units) => Ok(units),
            Progress::Finished(units) => {
                self.begin_search();
                Ok(units)
            }
        }
    }

    /// The whole object is the first domain; start the type search on it.
    fn begin_search(&mut self) {
        let stats = self.preparation.stats;
        self.report.object_pixels = stats.object_pixels;
        self.report.sampled_points = self.points.len as u32;
        self.owners = [UNCLAIMED; POINTS];
        self.found.clear();
        (self.whole, self.leftovers_keep_whole) = (0, false);
        self.domain_len = self.points.len;
        for (i, slot) in self.domain[..self.domain_len].iter_mut().enumerate() {
            *slot = i as u16;
        }
        self.sigma_fine = self.config.model.sigma_fine(stats.spacing);
        let frame = Frame {
            center: Vec3::from_array(stats.centroid),
            radius: stats.radius.max(1e-3),
        };
        self.begin_domain(frame);
        self.stage = Stage::Searching;
    }

    /// Start the type search on the domain (the first `domain_len` points of the list).
    fn begin_domain(&mut self, frame: Frame) {
        self.wider_len = self.domain_len;
        let object = self.found.first().filter(|_| self.leftovers_keep_whole);
        self.search.begin(
            self.config.types,
            self.config.domains.parts,
            frame,
            self.sigma_fine,
            self.config.model.accept,
            object.map(|f| f.symmetry),
        );
    }

    /// One step of the search: score the hypothesis at hand, grow a domain, or take one step of
    /// the type search (one unit).
    fn search_step(&mut self, budget: u32) -> u32 {
        let Some(scene) = self.scene else {
            return budget;
        };
        let evidence = Evidence {
            view: View::new(&scene, &self.grid, self.preparation.table),
            voxels: &self.voxels,
            points: self.points.positions(),
        };
        if self.evaluation.is_running() {
            let domain = &self.domain[..self.domain_len];
            return self
                .evaluation
                .advance(&evidence, |j| domain[j] as usize, budget);
        }
        match self.middle {
            Middle::Growing(growing) => {
                let domain = &mut self.domain[..self.domain_len];
                let used = self.growth.advance(&evidence, &self.points, domain, budget);
                if let Some(grown) = self.growth.result() {
                    self.middle = Middle::Idle;
                    self.grown(growing, grown);
                }
                return used;
            }
            Middle::Gathering { next } => return self.gather(next, budget),
            Middle::Idle => {}
        }
        let last = core::mem::take(&mut self.awaiting_score)
            .then(|| self.evaluation.score(&self.config.model));
        match self.search.next(last) {
            Request::Evaluate {
                symmetry,
                sigma,
                transformed,
            } => {
                let level = self.config.model.level(sigma, &self.voxels);
                self.evaluation.begin(
                    &symmetry,
                    self.config.sampling,
                    level,
                    self.domain_len,
                    transformed,
                );
                self.awaiting_score = true;
            }
            Request::Narrow { proposal } => self.grow(&proposal, Growing::Narrowing),
            Request::Widen => self.domain_len = self.wider_len,
            Request::Done => self.finish_domain(),
        }
        self.publish_best();
        1
    }

    /// Grow, in the domain, the part `symmetry` explains, at the finest match σ. A narrowing
    /// keeps the points the proposal does not contradict (their images cost on average at most
    /// an unconfirmed, occluded point): the part the climb refines the symmetry on must keep the
    /// points seen from one side only (near a silhouette most images fall behind the object), or
    /// the climb tilts the axis towards the points it can confirm. A claim by a symmetry
    /// accepted on the whole domain keeps the same points: the walk judged it there, and its
    /// points the symmetry does not contradict (noisy silhouettes, most of them) are its own; left
    /// over, they would be searched as a further domain and completed through what a sliver
    /// happens to fit. A symmetry found on a narrowed part claims only the points it explains (at
    /// most the acceptance threshold): the rest of the domain is why it was narrowed. That rest
    /// goes back to the symmetry the whole domain got, which was judged on it too: it keeps the
    /// points it does not contradict.
    fn grow(&mut self, symmetry: &Symmetry, growing: Growing) {
        let model = &self.config.model;
        let level = model.level(self.sigma_fine, &self.voxels);
        let threshold = match growing {
            Growing::Narrowing | Growing::Rest => model.cost_occluded,
            Growing::Claiming if !self.search.found_on_part() => model.cost_occluded,
            Growing::Claiming | Growing::Leftover => model.accept,
        };
        let stride = self.preparation.stats.stride;
        self.growth
            .begin_proposal(symmetry, self.config.sampling, level, threshold, stride);
        self.middle = Middle::Growing(growing);
    }

    /// A growth is over: hand a narrower domain to the type search, claim a symmetry's domain,
    /// or search the leftover part.
    fn grown(&mut self, growing: Growing, grown: Grown) {
        match (growing, grown) {
            (Growing::Narrowing, Grown::Domain(len)) => {
                self.wider_len = self.domain_len;
                self.domain_len = len;
                let frame = frame_of(self.points.positions(), &self.domain[..len]);
                self.search.narrowed(Some(frame));
            }
            (Growing::Narrowing, Grown::Nothing | Grown::Nearly) => self.search.narrowed(None),
            (Growing::Claiming, grown) => {
                let len = match grown {
                    Grown::Domain(len) => len,
                    Grown::Nothing | Grown::Nearly => self.searched_len,
                };
                self.claim(len);
            }
            (Growing::Rest, Grown::Domain(len)) => self.claim_rest(len),
            (Growing::Rest, Grown::Nearly) => self.claim_rest(self.domain_len),
            (Growing::Rest, Grown::Nothing) => self.next_domain(),
            (Growing::Leftover, Grown::Domain(len)) => {
                self.domain_len = len;
                if self.leftover_is_large() {
                    let frame = frame_of(self.points.positions(), &self.domain[..len]);
                    self.begin_domain(frame);
                } else {
                    self.begin_completion();
                }
            }
            (Growing::Leftover, Grown::Nothing | Grown::Nearly) => self.begin_completion(),
        }
    }

    fn leftover_is_large(&self) -> bool {
        let least = (self.config.domains.min_leftover * self.points.len as f32) as usize;
        self.domain_len >= least.max(crate::prepare::MIN_POINTS as usize)
    }

    /// The type search of a domain is over. A symmetry found claims the part of the domain it
    /// explains (grown from the domain, at the acceptance threshold; all of it when no part
    /// qualifies); without one, the domain's points are exhausted.
    fn finish_domain(&mut self) {
        match self.search.best().copied() {
            Some(best) if !self.found.is_full() && self.config.domains.parts => {
                // Claim from the whole domain the walk started in: the refined symmetry may
                // explain more than the part it was found on.
                self.searched_len = self.domain_len;
                self.domain_len = self.wider_len;
                self.grow(&best.symmetry, Growing::Claiming);
            }
            Some(_) if !self.found.is_full() => self.claim(self.domain_len),
            _ => {
                for &i in &self.domain[..self.domain_len] {
                    self.owners[i as usize] = EXHAUSTED;
                }
                self.next_domain();
            }
        }
    }

    /// The first `len` points of the domain go to the domain's symmetry. When it was found on
    /// a part carved out of the domain, the rest of the domain is offered to the symmetry the
    /// domain got before it was carved; otherwise, the next domain.
    fn claim(&mut self, len: usize) {
        if let Some(best) = self.search.best().copied() {
            if self.found.is_empty() {
                self.leftovers_keep_whole = !self.search.found_on_part();
            }
            self.push_found(best, len);
        }
        match self.search.carved_from() {
            Some(wider) if !self.found.is_full() => {
                // The rest: the domain's points after the part's, moved to the front.
                let end = self.domain_len;
                self.domain.copy_within(len..end, 0);
                self.domain_len = end - len;
                self.grow(&wider.symmetry, Growing::Rest);
            }
            _ => self.next_domain(),
        }
    }

    /// The rest of a domain a part was carved out of: its first `len` points go to the symmetry
    /// the domain got before it was carved. That symmetry was accepted on all of the domain;
    /// the points of it the part's symmetry does not explain need no new hypothesis where it does
    /// not contradict them (the paper's mug: the handle keeps the mug's mirror plane). Without
    /// this, the rest was searched as a new domain: the mustard bottle's dev scene wrist_1,
    /// whose cap passes as an axial part, had the rest of its body searched alone, and it
    /// passed as a triple plane whose third plane is normal to the bottle's axis, a symmetry of
    /// that band of the body but not of the bottle.
    fn claim_rest(&mut self, len: usize) {
        if let Some(wider) = self.search.carved_from() {
            if self.found.len() == 1 {
                // Only the part of the first domain is found: the rest keeps the whole object's.
                self.whole = 1;
            }
            self.push_found(wider, len);
        }
        self.next_domain();
    }

    /// Record `symmetry` as found, with the first `len` points of the domain.
    fn push_found(&mut self, symmetry: Candidate, len: usize) {
        let found = Found {
            symmetry: symmetry.symmetry,
            score: symmetry.score,
            domain_points: len as u32,
        };
        if self.found.push(found).is_ok() {
            let owner = (self.found.len() - 1) as u8;
            for &i in &self.domain[..len] {
                self.owners[i as usize] = owner;
            }
        }
    }

    /// With parts searched, gather the unclaimed points to find the next domain among them;
    /// otherwise the whole object was the only domain: complete.
    fn next_domain(&mut self) {
        if self.config.domains.parts {
            self.middle = Middle::Gathering { next: 0 };
        } else {
            self.begin_completion();
        }
    }

    /// Collect the unclaimed points into the domain list, 16 a unit; then find their largest
    /// connected part (the next domain), or complete.
    fn gather(&mut self, next: usize, budget: u32) -> u32 {
        if next == 0 {
            self.domain_len = 0;
        }
        let end = (next + 16 * budget.max(1) as usize).min(self.points.len);
        for i in next..end {
            if self.owners[i] == UNCLAIMED {
                self.domain[self.domain_len] = i as u16;
                self.domain_len += 1;
            }
        }
        let used = (end - next).div_ceil(16).max(1) as u32;
        if end < self.points.len {
            self.middle = Middle::Gathering { next: end };
        } else if self.leftover_is_large() && !self.found.is_full() {
            self.growth.begin_component(self.preparation.stats.stride);
            self.middle = Middle::Growing(Growing::Leftover);
        } else {
            self.middle = Middle::Idle;
            self.begin_completion();
        }
        self.publish_best();
        used
    }

    /// Expose the symmetries found so far (the finished domains' and the current best) in the
    /// report, strongest first.
    fn publish_best(&mut self) {
        self.report.symmetries.clone_from(&self.found);
        let searching = matches!(
            self.middle,
            Middle::Idle | Middle::Growing(Growing::Narrowing | Growing::Claiming)
        );
        if self.stage == Stage::Searching && searching {
            if let Some(best) = self.search.best() {
                let found = Found {
                    symmetry: best.symmetry,
                    score: best.score,
                    domain_points: self.domain_len as u32,
                };
                let _ = self.report.symmetries.push(found);
            }
        }
    }

    /// Order the symmetries strongest first (the points they explain, then type), relabel the
    /// points, and start writing the completion.
    fn begin_completion(&mut self) {
        self.stage = Stage::Completing;
        let found = &mut self.found;
        let mut order: heapless::Vec<u8, MAX_SYMMETRIES> = (0..found.len() as u8).collect();
        let key = |f: &Found| {
            (
                core::cmp::Reverse(f.domain_points),
                core::cmp::Reverse(f.symmetry.kind().strength()),
            )
        };
        order.sort_unstable_by_key(|&k| key(&found[k as usize]));
        let mut rank = [UNCLAIMED; MAX_SYMMETRIES];
        for (new, &old) in order.iter().enumerate() {
            rank[old as usize] = new as u8;
        }
        for owner in self.owners.iter_mut() {
            *owner = rank.get(*owner as usize).copied().unwrap_or(UNCLAIMED);
        }
        let sorted: heapless::Vec<Found, MAX_SYMMETRIES> =
            order.iter().map(|&k| found[k as usize]).collect();
        *found = sorted;
        self.publish_best();
        let tolerance = self.sigma_fine * self.config.model.free_per_match;
        // A point no domain claimed is completed as a search without parts would complete it:
        // through the whole object's symmetry (when the whole object's walk finds nothing, no
        // domain is searched after it and `rank[0]` is UNCLAIMED).
        self.completion
            .begin(tolerance, self.sigma_fine, rank[self.whole as usize]);
        self.completing = 0;
    }

    fn complete(&mut self, budget: u32, output: &mut [CompletedPoint]) -> u32 {
        let Some(scene) = self.scene else {
            return budget;
        };
        if self.completion.is_between() {
            let Some(f) = self.found.get(self.completing as usize) else {
                self.stage = Stage::Done;
                return 1;
            };
            let accept = self.config.model.accept;
            let plausibility = ((accept - f.score) / accept).clamp(0.0, 1.0);
            self.completion.begin_symmetry(
                self.completing,
                &f.symmetry,
                self.config.sampling,
                plausibility,
            );
            self.completing += 1;
            return 1;
        }
        let view = View::new(&scene, &self.grid, self.preparation.table);
        let used = self.completion.advance(
            &view,
            &mut self.voxels,
            self.points.positions(),
            &self.owners[..self.points.len],
            output,
            budget,
        );
        let written = self.completion.written;
        (
            self.report.points_visible,
            self.report.points_generated,
            self.report.points_dropped,
        ) = (written.visible, written.generated, written.dropped);
        used
    }
}
