//! The budgeted engine: an explicit state machine that prepares the scene, searches symmetry
//! types and parameters, and writes the completion, a bounded amount of work per `poll`.
//! (SKELETON: the stages are being written; the public API below is final.)

use crate::complete::CompletedPoint;
use crate::symmetry::{Sampling, Symmetry, TypeSet};
use crate::{Error, Scene};

/// Most symmetries (domains) one search reports.
pub const MAX_SYMMETRIES: usize = 8;

/// Search settings. `Config::DEFAULT` is what the figures in the README were measured with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// The symmetry types the caller wants (the search still visits the weaker types on the way).
    pub types: TypeSet,
    pub sampling: Sampling,
}

impl Config {
    pub const DEFAULT: Config = Config { types: TypeSet::ALL, sampling: Sampling { axial_steps: 7 } };

    /// Check that every value is in range.
    pub fn validate(&self) -> Result<(), Error> {
        if self.types.is_empty() || !(2..=7).contains(&self.sampling.axial_steps) {
            return Err(Error::InvalidConfig);
        }
        Ok(())
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
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Strongest first. Empty: no symmetry.
    pub symmetries: heapless::Vec<Found, MAX_SYMMETRIES>,
    /// Visible points written to the output.
    pub points_visible: u32,
    /// Generated points written to the output.
    pub points_generated: u32,
    /// The output storage (or the deduplication table) was full: some points were not written.
    pub truncated: bool,
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

/// The engine, with all its storage inline: `POINTS` sampled object points, `VOXELS` hash slots
/// (a power of two), `CELLS` compact depth cells.
#[derive(Debug)]
pub struct Engine<'a, const POINTS: usize = 1024, const VOXELS: usize = 4096, const CELLS: usize = 8192> {
    config: Config,
    scene: Option<Scene<'a>>,
    output: &'a mut [CompletedPoint],
    report: Report,
    stage: Stage,
}

impl<'a, const POINTS: usize, const VOXELS: usize, const CELLS: usize> Engine<'a, POINTS, VOXELS, CELLS> {
    /// Bytes of memory this configuration occupies (all of it; nothing is allocated later).
    pub const MEMORY_BYTES: usize = core::mem::size_of::<Self>();

    /// A new idle engine (`const`: it can live in a `static`).
    pub const fn new(config: Config) -> Self {
        Self { config, scene: None, output: &mut [], report: Report { symmetries: heapless::Vec::new(), points_visible: 0, points_generated: 0, truncated: false, work_units: 0, polls: 0 }, stage: Stage::Idle }
    }

    /// Begin a search of `scene`, writing the completed points into `output`. Checks the input
    /// (O(1)); any earlier search is discarded.
    pub fn start(&mut self, scene: Scene<'a>, output: &'a mut [CompletedPoint]) -> Result<(), Error> {
        self.config.validate()?;
        scene.validate()?;
        self.scene = Some(scene);
        self.output = output;
        self.report = Report::default();
        self.stage = Stage::Preparing;
        Ok(())
    }

    /// Do at most `budget` work units (at least one). See the crate docs for what a unit costs.
    pub fn poll(&mut self, budget: u32) -> Result<Status, Error> {
        let _ = budget;
        match self.stage {
            Stage::Idle => Err(Error::NotStarted),
            Stage::Failed(e) => Err(e),
            _ => {
                self.stage = Stage::Done;
                Ok(Status::Done)
            }
        }
    }

    /// The result so far (final once `poll` returned `Done`).
    pub fn report(&self) -> &Report {
        &self.report
    }

    /// The completed points written so far.
    pub fn points(&self) -> &[CompletedPoint] {
        let n = (self.report.points_visible + self.report.points_generated) as usize;
        &self.output[..n.min(self.output.len())]
    }

    pub fn stage(&self) -> Stage {
        self.stage
    }

    pub fn config(&self) -> &Config {
        &self.config
    }
}
