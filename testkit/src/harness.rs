//! The search both builds run, and the digest of its result.
//!
//! Host and target call the same [`run`] on the same scene with the same budget; only the clock
//! differs (SysTick instruction counts on the target, nanoseconds on the host). The digest covers
//! every bit of the result, so equal digests mean bit-identical results.

use core::fmt::{self, Write};

use shape_from_symmetry::{CompletedPoint, Engine, Error, Report, Scene, Stage, Status, Symmetry};

/// Work units per poll, as a control loop would grant them: the library's recommendation.
pub const POLL_BUDGET: u32 = shape_from_symmetry::RECOMMENDED_BUDGET;

/// A hard stop for a search that never finishes (a bug): far more polls than any search takes.
pub const MAX_POLLS: u32 = 10_000_000;

/// What one search left behind, with its cost in the caller's clock units.
#[derive(Debug)]
pub struct Outcome {
    pub digest: u64,
    pub polls: u32,
    /// Clock units from before `start` to after the last poll.
    pub total: u64,
    /// Clock units of `start` (input checks).
    pub start: u64,
    /// The most clock units one poll took, which poll (0-based) it was, and the work units it
    /// reported.
    pub max_poll: u64,
    pub max_poll_index: u32,
    pub max_poll_units: u64,
    /// The most work units one poll reported.
    pub most_units: u64,
    /// Cost by the stage each poll began in: preparing, searching, completing.
    pub stages: [StageCost; 3],
}

/// The cost of the polls that began in one stage.
#[derive(Clone, Copy, Debug, Default)]
pub struct StageCost {
    pub polls: u32,
    pub units: u64,
    /// Clock units.
    pub clock: u64,
    /// The most clock units one of these polls took.
    pub max_poll: u64,
}

/// The names of [`Outcome::stages`].
pub const STAGE_NAMES: [&str; 3] = ["preparing", "searching", "completing"];

fn stage_index(stage: Stage) -> usize {
    match stage {
        Stage::Searching => 1,
        Stage::Completing | Stage::Done => 2,
        _ => 0,
    }
}

/// Why the search did not finish.
#[derive(Debug)]
pub enum RunError {
    Start(Error),
    Poll {
        poll: u32,
        error: Error,
    },
    NoEnd {
        polls: u32,
    },
    /// A poll did more work units than its budget (the engine's contract: at most `budget`).
    OverBudget {
        poll: u32,
        units: u64,
    },
    /// A poll that left more work did no work unit (the contract: at least one).
    NoProgress {
        poll: u32,
    },
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Start(e) => write!(f, "start failed: {e}"),
            RunError::Poll { poll, error } => write!(f, "poll {poll} failed: {error}"),
            RunError::NoEnd { polls } => write!(f, "no result after {polls} polls"),
            RunError::OverBudget { poll, units } => {
                write!(
                    f,
                    "poll {poll} did {units} work units, over its budget of {POLL_BUDGET}"
                )
            }
            RunError::NoProgress { poll } => write!(f, "poll {poll} did no work and is not done"),
        }
    }
}

/// Start `engine` on `scene`, poll it with [`POLL_BUDGET`] until it is done, and digest the
/// result. `clock` is read before `start` and after `start` and every poll (nothing else runs
/// between two readings but the engine). Checks the poll contract on the way: every poll does
/// at most the budget, and a poll that is not the last does at least one unit.
pub fn run<'a, const P: usize, const V: usize, const C: usize>(
    engine: &mut Engine<'a, P, V, C>,
    scene: Scene<'a>,
    output: &'a mut [CompletedPoint],
    mut clock: impl FnMut() -> u64,
) -> Result<Outcome, RunError> {
    let t0 = clock();
    engine.start(scene, output).map_err(RunError::Start)?;
    let t1 = clock();
    let (mut polls, mut last, mut units_before) = (0u32, t1, engine.report().work_units);
    let (mut max_poll, mut max_poll_index, mut max_poll_units, mut most_units) =
        (0u64, 0u32, 0u64, 0u64);
    let mut stages = [StageCost::default(); 3];
    loop {
        if polls == MAX_POLLS {
            return Err(RunError::NoEnd { polls });
        }
        let stage = &mut stages[stage_index(engine.stage())];
        let status = engine
            .poll(POLL_BUDGET)
            .map_err(|error| RunError::Poll { poll: polls, error })?;
        let now = clock();
        let units_now = engine.report().work_units;
        let units = units_now.wrapping_sub(units_before);
        if units > POLL_BUDGET as u64 {
            return Err(RunError::OverBudget { poll: polls, units });
        }
        if units == 0 && status == Status::Working {
            return Err(RunError::NoProgress { poll: polls });
        }
        if now - last > max_poll {
            (max_poll, max_poll_index, max_poll_units) = (now - last, polls, units);
        }
        most_units = most_units.max(units);
        stage.polls += 1;
        stage.units += units;
        stage.clock += now - last;
        stage.max_poll = stage.max_poll.max(now - last);
        (last, units_before) = (now, units_now);
        polls += 1;
        if status == Status::Done {
            break;
        }
    }
    Ok(Outcome {
        digest: digest(engine.report(), engine.points()),
        polls,
        total: last - t0,
        start: t1 - t0,
        max_poll,
        max_poll_index,
        max_poll_units,
        most_units,
        stages,
    })
}

/// FNV-1a, 64 bits.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(pub u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv1a {
    pub const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    pub const PRIME: u64 = 0x0000_0100_0000_01b3;

    pub fn new() -> Self {
        Self(Self::OFFSET)
    }

    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(Self::PRIME);
        }
    }

    pub fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }

    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    pub fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    pub fn f32s(&mut self, vs: &[f32]) {
        for &v in vs {
            self.f32(v);
        }
    }
}

/// The geometry of a symmetry as floats, in a fixed order: planes as `normal, offset`, axes as
/// `direction, point`, centres as `x, y, z`; composites element by element, axis first.
fn hash_symmetry(h: &mut Fnv1a, s: &Symmetry) {
    let plane = |h: &mut Fnv1a, p: &shape_from_symmetry::Plane| {
        h.f32s(&p.normal);
        h.f32(p.offset);
    };
    let axis = |h: &mut Fnv1a, a: &shape_from_symmetry::Axis| {
        h.f32s(&a.direction);
        h.f32s(&a.point);
    };
    match s {
        Symmetry::PlaneReflection(p) => plane(h, p),
        Symmetry::LineReflection(a) | Symmetry::Axial(a) => axis(h, a),
        Symmetry::PointReflection(c) | Symmetry::Spherical(c) => h.f32s(c),
        Symmetry::DualPlane(ps) => ps.iter().for_each(|p| plane(h, p)),
        Symmetry::TriplePlane(ps) => ps.iter().for_each(|p| plane(h, p)),
        Symmetry::AxialPlane(a, p) => {
            axis(h, a);
            plane(h, p);
        }
    }
}

/// The digest of a result: each found symmetry (type, score bits, domain points, geometry bits),
/// then each completed point (position bits, plausibility bits, provenance, symmetry index),
/// then the counts (symmetries, visible, generated, dropped, object pixels, sampled points, work
/// units, polls). All integers little-endian, floats as their IEEE-754 bits.
pub fn digest(report: &Report, points: &[CompletedPoint]) -> u64 {
    let mut h = Fnv1a::new();
    for found in &report.symmetries {
        h.u8(found.symmetry.kind() as u8);
        h.f32(found.score);
        h.u32(found.domain_points);
        hash_symmetry(&mut h, &found.symmetry);
    }
    for p in points {
        h.f32s(&p.position);
        h.f32(p.plausibility);
        h.u8(p.provenance as u8);
        h.u8(p.symmetry);
    }
    h.u32(report.symmetries.len() as u32);
    h.u32(report.points_visible);
    h.u32(report.points_generated);
    h.u32(report.points_dropped);
    h.u32(report.object_pixels);
    h.u32(report.sampled_points);
    h.u64(report.work_units);
    h.u32(report.polls);
    h.0
}

/// The lines both builds print identically (CI compares the `digest:` line). (The firmware's
/// defmt build logs the same lines through defmt instead.)
pub fn describe(w: &mut impl Write, report: &Report, outcome: &Outcome) -> fmt::Result {
    writeln!(
        w,
        "object: {} pixels with depth, {} points sampled",
        report.object_pixels, report.sampled_points
    )?;
    writeln!(w, "symmetries: {}", report.symmetries.len())?;
    for (i, found) in report.symmetries.iter().enumerate() {
        writeln!(
            w,
            "  #{i} {} score {:.4} domain {} points",
            found.symmetry.kind().name(),
            found.score,
            found.domain_points
        )?;
    }
    writeln!(
        w,
        "points: {} visible, {} generated, {} dropped (output or dedup table full)",
        report.points_visible, report.points_generated, report.points_dropped
    )?;
    writeln!(
        w,
        "work units: {}, polls: {} at budget {}, most units in a poll: {}",
        report.work_units, outcome.polls, POLL_BUDGET, outcome.most_units
    )?;
    writeln!(w, "digest: 0x{:016x}", outcome.digest)
}

#[cfg(test)]
mod tests {
    use super::Fnv1a;

    #[test]
    fn fnv1a_reference_values() {
        let mut h = Fnv1a::new();
        assert_eq!(h.0, 0xcbf2_9ce4_8422_2325);
        h.bytes(b"a");
        assert_eq!(h.0, 0xaf63_dc4c_8601_ec8c);
        let mut h = Fnv1a::new();
        h.bytes(b"foobar");
        assert_eq!(h.0, 0x8594_4171_f739_67e8);
    }
}
