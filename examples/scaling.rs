//! How the cost of one search grows with the object's size in the image and with the engine's
//! capacity.
//!
//! ```text
//! cargo run --release --example scaling -- [--repeat N] [--objects can,cereal_box]
//!     [--out-md F] [--out-json F]
//! ```
//! For each object and each target count of object pixels (1 000 to 50 000) it renders a
//! synthetic scene (`sfs_testkit::scaling`: a 640 x 480 camera, the object's distance chosen to give
//! that many pixels), then searches it with three engine capacities, charging time and work units
//! to the stages. One thread; each search runs `--repeat` times (default 5) and the fastest run
//! is reported (the work units and the result are the same every run). Prints a Markdown table.

use std::path::PathBuf;
use std::process::ExitCode;

use serde::Serialize;
use sfs_testkit::scaling::{self, SizedScene};
use sfs_testkit::stages::{self, StageCost, Staged};
use sfs_testkit::synth::{self, ReadyObject};
use sfs_testkit::{Context, Result};
use shape_from_symmetry::{Config, Engine, Error};

const USAGE: &str =
    "usage: scaling [--repeat N] [--objects NAME,NAME,...] [--out-md F] [--out-json F]
  --objects  synth objects to render (default can,cereal_box)";

/// An engine configuration to compare.
struct Capacity {
    name: &'static str,
    memory_bytes: usize,
    run: fn(&sfs_testkit::scene::LoadedScene, Config) -> std::result::Result<Staged, Error>,
}

const CAPACITIES: [Capacity; 3] = [
    Capacity {
        name: "Engine<512, 2048, 4096>",
        memory_bytes: Engine::<512, 2048, 4096>::MEMORY_BYTES,
        run: stages::run_staged::<512, 2048, 4096>,
    },
    Capacity {
        name: "DefaultEngine",
        memory_bytes: Engine::<1024, 8192, 8192>::MEMORY_BYTES,
        run: stages::run_staged::<1024, 8192, 8192>,
    },
    Capacity {
        name: "Engine<2048, 8192, 16384>",
        memory_bytes: Engine::<2048, 8192, 16384>::MEMORY_BYTES,
        run: stages::run_staged::<2048, 8192, 16384>,
    },
];

struct Args {
    repeat: usize,
    objects: Vec<&'static ReadyObject>,
    out_md: Option<PathBuf>,
    out_json: Option<PathBuf>,
}

/// One search: an object at one size, one capacity.
#[derive(Serialize)]
struct Row {
    object: &'static str,
    engine: &'static str,
    memory_bytes: usize,
    target_pixels: u32,
    distance_m: f32,
    /// Object pixels with a reading, as the engine segmented them, and the points it sampled.
    object_pixels: u32,
    sampled_points: u32,
    found: &'static str,
    points_generated: u32,
    points_dropped: u32,
    preparing: StageCost,
    searching: StageCost,
    completing: StageCost,
    total: StageCost,
    ns_per_work_unit: f64,
}

#[derive(Serialize)]
struct Scaling {
    format: &'static str,
    width: u16,
    height: u16,
    focal_px: f32,
    repeat: usize,
    rows: Vec<Row>,
}

fn main() -> ExitCode {
    sfs_testkit::run_cli(USAGE, parse_args, |args| scale(args).map(|()| true))
}

fn parse_args(args: Vec<String>) -> Result<Args> {
    let mut parsed = Args {
        repeat: 5,
        objects: vec![object("can")?, object("cereal_box")?],
        out_md: None,
        out_json: None,
    };
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next()
                .ok_or_else(|| format!("{arg} needs a value\n{USAGE}"))
        };
        match arg.as_str() {
            "--repeat" => {
                let text = value()?;
                parsed.repeat = text
                    .parse()
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| format!("--repeat {text}: expected a positive number"))?;
            }
            "--objects" => {
                parsed.objects = value()?.split(',').map(object).collect::<Result<_>>()?;
            }
            "--out-md" => parsed.out_md = Some(value()?.into()),
            "--out-json" => parsed.out_json = Some(value()?.into()),
            _ => return Err(format!("unknown argument {arg}\n{USAGE}")),
        }
    }
    Ok(parsed)
}

fn object(name: &str) -> Result<&'static ReadyObject> {
    synth::object(name.trim()).ok_or_else(|| {
        let names: Vec<&str> = synth::OBJECTS.iter().map(|o| o.name).collect();
        format!("unknown object {name:?}; one of {}", names.join(", "))
    })
}

fn scale(args: &Args) -> Result<()> {
    let mut rows = Vec::new();
    for object in &args.objects {
        for target in scaling::TARGETS {
            let sized = scaling::scene_with_pixels(object, target)?;
            eprintln!(
                "{}: {} pixels at {:.3} m",
                object.name, sized.pixels, sized.distance
            );
            for capacity in &CAPACITIES {
                rows.push(measure(object, target, &sized, capacity, args.repeat)?);
            }
        }
    }
    let scaling = Scaling {
        format: "shape-from-symmetry/scaling-1",
        width: scaling::INTRINSICS.width,
        height: scaling::INTRINSICS.height,
        focal_px: scaling::INTRINSICS.fx,
        repeat: args.repeat,
        rows,
    };
    let markdown = markdown(&scaling);
    print!("{markdown}");
    if let Some(path) = &args.out_md {
        std::fs::write(path, &markdown).context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.out_json {
        sfs_testkit::write_json(path, &scaling)?;
    }
    Ok(())
}

/// The fastest of `repeat` searches of one scene with one capacity.
fn measure(
    object: &ReadyObject,
    target: u32,
    sized: &SizedScene,
    capacity: &Capacity,
    repeat: usize,
) -> Result<Row> {
    let mut best: Option<Staged> = None;
    for _ in 0..repeat {
        let staged = (capacity.run)(&sized.scene, Config::DEFAULT)
            .map_err(|e| format!("{} with {}: {e}", sized.scene.name, capacity.name))?;
        if best
            .as_ref()
            .is_none_or(|b| staged.total().wall_ms < b.total().wall_ms)
        {
            best = Some(staged);
        }
    }
    let staged = best.ok_or("no run")?;
    let report = &staged.report;
    let total = staged.total();
    eprintln!(
        "  {:<26} {:>6} sampled, {:>9} units, {:>7.1} ms",
        capacity.name, report.sampled_points, total.work_units, total.wall_ms
    );
    Ok(Row {
        object: object.name,
        engine: capacity.name,
        memory_bytes: capacity.memory_bytes,
        target_pixels: target,
        distance_m: sized.distance,
        object_pixels: report.object_pixels,
        sampled_points: report.sampled_points,
        found: report
            .symmetries
            .first()
            .map_or("none", |f| f.symmetry.kind().name()),
        points_generated: report.points_generated,
        points_dropped: report.points_dropped,
        preparing: staged.preparing,
        searching: staged.searching,
        completing: staged.completing,
        total,
        ns_per_work_unit: total.wall_ms * 1e6 / total.work_units.max(1) as f64,
    })
}

fn markdown(s: &Scaling) -> String {
    let mut md = format!(
        "# Cost against object size and engine capacity\n\n\
         Synthetic objects on the table (Kinect noise), {}x{} camera, f = {} px, the distance chosen \
         for the object pixel count; fastest of {} runs, one thread. Work units and time are split \
         by stage: preparation / search / completion.\n\n\
         | object | engine (memory) | object px | distance m | sampled points | found | work units prep / search / completion | work units total | ms prep / search / completion | ms total | ns per unit |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        s.width, s.height, s.focal_px, s.repeat
    );
    for r in &s.rows {
        md += &format!(
            "| {} | {} ({} KiB) | {} | {:.2} | {} | {} | {} / {} / {} | {} | {:.1} / {:.1} / {:.1} | {:.1} | {:.0} |\n",
            r.object,
            r.engine,
            r.memory_bytes / 1024,
            r.object_pixels,
            r.distance_m,
            r.sampled_points,
            r.found,
            r.preparing.work_units,
            r.searching.work_units,
            r.completing.work_units,
            r.total.work_units,
            r.preparing.wall_ms,
            r.searching.wall_ms,
            r.completing.wall_ms,
            r.total.wall_ms,
            r.ns_per_work_unit
        );
    }
    md + "\n"
}
