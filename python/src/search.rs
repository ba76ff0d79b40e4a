//! One search, without Python: the engine polled until it is done, on a thread of its own.

use shape_from_symmetry::symmetry::MAX_MAPS;
use shape_from_symmetry::{
    CompletedPoint, Config, DefaultEngine, Engine, Error, Intrinsics, Plane, Report, Scene, Status,
    Target,
};

/// The point capacity of an engine type, read from its const parameter.
trait Capacity {
    const POINTS: usize;
}

impl<const POINTS: usize, const VOXELS: usize, const CELLS: usize> Capacity
    for Engine<'_, POINTS, VOXELS, CELLS>
{
    const POINTS: usize = POINTS;
}

/// Room for every sampled point and its image under every map of the richest symmetry: nothing
/// is dropped for want of output (the command-line tool's capacity). The engine is the library's
/// `DefaultEngine`, as the command-line tool's, so that both give the same result.
const OUTPUT_POINTS: usize = <DefaultEngine<'static> as Capacity>::POINTS * (1 + MAX_MAPS);

/// The search thread's stack. The engine lives on it (`DefaultEngine::MEMORY_BYTES`, about
/// 114 KiB; docs/figures.md) with the search's own frames (a few KiB: the peak is measured on the
/// Cortex-M4F, docs/figures.md). An unoptimised build may hold temporary copies of the engine
/// too; 16 MiB leaves room for dozens. Only the pages touched are committed.
const SEARCH_STACK_BYTES: usize = 16 << 20;
/// Fails the build should the engine outgrow that margin (room for 64 engines).
const _: () = assert!(SEARCH_STACK_BYTES >= 64 * DefaultEngine::MEMORY_BYTES);

/// Everything a search reads, owned, so that no Python object is touched during it.
#[derive(Debug)]
pub struct Input {
    /// Row-major, `intrinsics.width * intrinsics.height` values; `0` = no reading.
    pub depth: Vec<u16>,
    /// Row-major, nonzero = object pixel.
    pub mask: Option<Vec<u8>>,
    pub depth_scale: f32,
    pub intrinsics: Intrinsics,
    pub table: Option<Plane>,
    pub config: Config,
    /// Work units per poll.
    pub budget: u32,
    /// The object's pixel or region when the engine segments it.
    pub target: Option<Target>,
}

impl Input {
    /// The library's view of this input.
    fn scene(&self) -> Scene<'_> {
        Scene {
            depth: &self.depth,
            depth_scale: self.depth_scale,
            intrinsics: self.intrinsics,
            table: self.table,
            mask: self.mask.as_deref(),
            target: self.target,
        }
    }
}

/// What a search found and the completed points.
#[derive(Debug)]
pub struct Output {
    pub report: Report,
    pub points: Vec<CompletedPoint>,
}

/// Why a search gave no output.
#[derive(Debug)]
pub enum Failure {
    /// The library rejected the input.
    Rejected(Error),
    /// The search thread could not start, or panicked (a bug: the library does not panic).
    Thread(String),
}

/// Search `input` on a thread with a large stack, polling until the engine is done.
pub fn run(input: &Input) -> Result<Output, Failure> {
    std::thread::scope(|scope| {
        let search = std::thread::Builder::new()
            .name("shape-from-symmetry".into())
            .stack_size(SEARCH_STACK_BYTES)
            .spawn_scoped(scope, || run_here(input))
            .map_err(|e| Failure::Thread(format!("cannot start the search thread: {e}")))?;
        let result = search
            .join()
            .map_err(|_| Failure::Thread("the search thread panicked".into()))?;
        result.map_err(Failure::Rejected)
    })
}

fn run_here(input: &Input) -> Result<Output, Error> {
    let mut output = vec![CompletedPoint::ZERO; OUTPUT_POINTS];
    let mut engine = DefaultEngine::new(input.config);
    engine.start(input.scene(), &mut output)?;
    while engine.poll(input.budget)? == Status::Working {}
    Ok(Output {
        report: engine.report().clone(),
        points: engine.points().to_vec(),
    })
}
