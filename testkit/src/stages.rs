//! One search with its cost split by stage (preparation, search, completion), at any engine
//! capacity: the scaling example and the stage benchmarks use it.
//!
//! The engine is polled with a small budget and each poll's time and work units are charged to
//! the stage it began in, so a poll that crosses into the next stage charges at most
//! `budget - 1` of that stage's units to the previous one.

use std::time::Instant;

use shape_from_symmetry::symmetry::MAX_MAPS;
use shape_from_symmetry::{CompletedPoint, Config, Engine, Error, Report, Stage, Status};

use super::scene::LoadedScene;

/// Work units per poll of a staged run: small enough that stage boundaries are sharp (a few
/// hundred of the hundreds of thousands of units a search does), large enough that the clock
/// costs nothing.
pub const STAGED_BUDGET: u32 = 256;

/// Time and work of one stage.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct StageCost {
    pub work_units: u64,
    pub wall_ms: f64,
}

impl StageCost {
    fn add(&mut self, units: u64, ms: f64) {
        self.work_units += units;
        self.wall_ms += ms;
    }
}

/// A finished search and what each stage cost.
#[derive(Clone, Debug)]
pub struct Staged {
    pub report: Report,
    pub preparing: StageCost,
    pub searching: StageCost,
    pub completing: StageCost,
}

impl Staged {
    pub fn total(&self) -> StageCost {
        let stages = [self.preparing, self.searching, self.completing];
        StageCost {
            work_units: stages.iter().map(|s| s.work_units).sum(),
            wall_ms: stages.iter().map(|s| s.wall_ms).sum(),
        }
    }
}

/// Output points an engine of `POINTS` needs: every sampled point and its image under every
/// map of the richest symmetry.
pub const fn output_points(points: usize) -> usize {
    points * (1 + MAX_MAPS)
}

/// Search `scene` with an `Engine<POINTS, VOXELS, CELLS>` (boxed: the largest is 170 KiB),
/// [`STAGED_BUDGET`] units per poll, charging each poll to its stage.
pub fn run_staged<const POINTS: usize, const VOXELS: usize, const CELLS: usize>(
    scene: &LoadedScene,
    config: Config,
) -> Result<Staged, Error> {
    let mut output = vec![CompletedPoint::ZERO; output_points(POINTS)];
    let mut engine = Box::new(Engine::<POINTS, VOXELS, CELLS>::new(config));
    let mut staged = Staged {
        report: Report::new(),
        preparing: StageCost::default(),
        searching: StageCost::default(),
        completing: StageCost::default(),
    };
    let clock = Instant::now();
    engine.start(scene.scene(), &mut output)?;
    staged.preparing.add(0, clock.elapsed().as_secs_f64() * 1e3);
    loop {
        let (stage, units) = (engine.stage(), engine.report().work_units);
        let clock = Instant::now();
        let status = engine.poll(STAGED_BUDGET)?;
        let ms = clock.elapsed().as_secs_f64() * 1e3;
        let units = engine.report().work_units - units;
        match stage {
            Stage::Preparing => staged.preparing.add(units, ms),
            Stage::Searching => staged.searching.add(units, ms),
            _ => staged.completing.add(units, ms),
        }
        if status == Status::Done {
            break;
        }
    }
    staged.report = engine.report().clone();
    Ok(staged)
}

#[cfg(test)]
mod tests {
    // The benchmarks include this module without a test harness, which drops the tests.
    #![allow(unused_imports)]
    use super::*;

    #[test]
    fn stages_add_up_to_the_whole_search() {
        let scene = LoadedScene::builtin().unwrap();
        let staged = run_staged::<256, 1024, 2048>(&scene, Config::DEFAULT).unwrap();
        let total = staged.total();
        assert_eq!(total.work_units, staged.report.work_units);
        for stage in [staged.preparing, staged.searching, staged.completing] {
            assert!(stage.work_units > 0 && stage.wall_ms > 0.0, "{stage:?}");
        }
        assert!(staged.report.sampled_points <= 256);
    }
}
