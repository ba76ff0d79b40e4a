//! The command-line tool of `SCENES.md`: find an object's symmetries in one depth image and
//! predict its hidden back side.
//!
//! ```text
//! cargo run --release --example complete -- [SCENE.json] [--out RESULT.json] [--ply COMPLETED.ply]
//!     [--png PICTURE.png] [--budget WORK_UNITS_PER_POLL] [--types TYPE,TYPE,...] [--parts]
//! ```
//! Without `SCENE.json` it runs on the library's built-in synthetic scene. Exit code 0 when the
//! search ran (whether or not it found a symmetry), 1 with a message for unusable input.

use std::path::PathBuf;
use std::process::ExitCode;

use sfs_testkit::scene::LoadedScene;
use sfs_testkit::search::{self, Outcome};
use sfs_testkit::{Result, picture, ply, result::ResultJson};
use shape_from_symmetry::{Config, Found, Symmetry, SymmetryType, TypeSet};

const USAGE: &str =
    "usage: complete [SCENE.json] [--out RESULT.json] [--ply COMPLETED.ply] [--png PICTURE.png]
                [--budget WORK_UNITS_PER_POLL] [--types TYPE,TYPE,...] [--parts]
  SCENE.json  a scene in the format of SCENES.md (default: the built-in synthetic scene)
  --out       write the result JSON
  --ply       write the visible and generated points (ASCII PLY)
  --png       write a picture of the completed object seen from behind
  --budget    work units per poll (default 50000; the result does not depend on it)
  --types     restrict the search to these types: plane_reflection, line_reflection,
              point_reflection, axial, spherical, dual_plane, triple_plane, axial_plane
  --parts     also search part symmetries (domains): an axial part of an object whose whole
              has only mirror planes or nothing, then the rest; PLY and PNG colour the
              visible points by domain";

/// The parsed command line.
#[derive(Debug)]
struct Args {
    scene: Option<PathBuf>,
    out: Option<PathBuf>,
    ply: Option<PathBuf>,
    png: Option<PathBuf>,
    budget: u32,
    types: TypeSet,
    parts: bool,
}

fn main() -> ExitCode {
    sfs_testkit::run_cli(USAGE, parse_args, |args| complete(args).map(|()| true))
}

fn complete(args: &Args) -> Result<()> {
    let scene = match &args.scene {
        Some(path) => LoadedScene::load(path)?,
        None => LoadedScene::builtin()?,
    };
    let mut config = Config {
        types: args.types,
        ..Config::DEFAULT
    };
    config.domains.parts = args.parts;
    let outcome =
        search::run(&scene, config, args.budget).map_err(|e| format!("{}: {e}", scene.name))?;
    print_summary(&scene, &outcome, args.budget);
    let domains = outcome.report.symmetries.len();
    if let Some(path) = &args.out {
        sfs_testkit::write_json(path, &ResultJson::new(&outcome))?;
    }
    if let Some(path) = &args.ply {
        ply::write(path, &outcome.points, domains)?;
    }
    if let Some(path) = &args.png {
        picture::back_view(&outcome.points, domains, scene.up()).write_png(path)?;
    }
    Ok(())
}

fn parse_args(args: Vec<String>) -> Result<Args> {
    let mut parsed = Args {
        scene: None,
        out: None,
        ply: None,
        png: None,
        budget: search::DEFAULT_BUDGET,
        types: TypeSet::ALL,
        parts: false,
    };
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next()
                .ok_or_else(|| format!("{arg} needs a value\n{USAGE}"))
        };
        match arg.as_str() {
            "--out" => parsed.out = Some(value()?.into()),
            "--ply" => parsed.ply = Some(value()?.into()),
            "--png" => parsed.png = Some(value()?.into()),
            "--budget" => parsed.budget = search::parse_budget(&value()?)?,
            "--types" => parsed.types = parse_types(&value()?)?,
            "--parts" => parsed.parts = true,
            flag if flag.starts_with('-') => return Err(format!("unknown option {flag}\n{USAGE}")),
            _ if parsed.scene.is_some() => {
                return Err(format!("more than one scene given: {arg}\n{USAGE}"));
            }
            _ => parsed.scene = Some(arg.into()),
        }
    }
    Ok(parsed)
}

/// `plane_reflection,axial` as a set of types.
fn parse_types(text: &str) -> Result<TypeSet> {
    let types = text.split(',').map(|name| {
        SymmetryType::from_name(name.trim())
            .ok_or_else(|| format!("--types: unknown type {name:?}\n{USAGE}"))
    });
    Ok(TypeSet::of(&types.collect::<Result<Vec<_>>>()?))
}

fn print_summary(scene: &LoadedScene, outcome: &Outcome, budget: u32) {
    let report = &outcome.report;
    let k = &scene.intrinsics;
    let given = |has: bool, what: &str| {
        if has {
            format!("{what} given")
        } else {
            format!("no {what}")
        }
    };
    println!(
        "scene {}: {}x{} depth, {}, {}",
        scene.name,
        k.width,
        k.height,
        given(scene.mask.is_some(), "mask"),
        given(scene.table.is_some(), "table plane")
    );
    match report.symmetries.len() {
        0 => println!("no symmetry found"),
        n => println!(
            "{n} symmetr{} found, strongest first:",
            if n == 1 { "y" } else { "ies" }
        ),
    }
    for (i, found) in report.symmetries.iter().enumerate() {
        print_symmetry(i, found);
    }
    let dropped = match report.points_dropped {
        0 => String::new(),
        n => format!(" ({n} dropped: the output or the deduplication table was full)"),
    };
    println!(
        "points: {} visible, {} generated{dropped}; searched {} sampled of {} object pixels",
        report.points_visible, report.points_generated, report.sampled_points, report.object_pixels
    );
    println!(
        "work: {} polls, {} work units, {:.1} ms (budget {budget} units per poll, engine {} KiB)",
        report.polls,
        report.work_units,
        outcome.wall_ms,
        search::HostEngine::MEMORY_BYTES / 1024
    );
}

fn print_symmetry(index: usize, found: &Found) {
    let s: &Symmetry = &found.symmetry;
    println!(
        "  {}. {:<16} score {:.3}, {} domain points",
        index + 1,
        s.kind().name(),
        found.score,
        found.domain_points
    );
    let v = |a: [f32; 3]| format!("[{:+.3}, {:+.3}, {:+.3}]", a[0], a[1], a[2]);
    for plane in s.planes() {
        println!(
            "       plane  normal {}  offset {:+.4} m",
            v(plane.normal),
            plane.offset
        );
    }
    if let Some(axis) = s.axis() {
        println!(
            "       axis   direction {}  through {} m",
            v(axis.direction),
            v(axis.point)
        );
    }
    if let Some(center) = s.center() {
        println!("       centre {} m", v(center));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(line: &str) -> Result<Args> {
        parse_args(line.split_whitespace().map(String::from).collect())
    }

    #[test]
    fn parses_every_option() {
        let args = parse(
            "s.json --out r.json --ply c.ply --png p.png --budget 7 --types axial,plane_reflection --parts",
        )
        .unwrap();
        assert_eq!(args.scene, Some(PathBuf::from("s.json")));
        assert_eq!(
            (args.out.unwrap(), args.ply.unwrap(), args.png.unwrap()),
            ("r.json".into(), "c.ply".into(), "p.png".into())
        );
        assert_eq!((args.budget, args.parts), (7, true));
        assert_eq!(
            args.types,
            TypeSet::of(&[SymmetryType::Axial, SymmetryType::PlaneReflection])
        );
    }

    #[test]
    fn defaults_to_the_builtin_scene_and_every_type() {
        let args = parse("").unwrap();
        assert_eq!(
            (args.scene, args.budget, args.types, args.parts),
            (None, search::DEFAULT_BUDGET, TypeSet::ALL, false)
        );
    }

    #[test]
    fn rejects_bad_arguments_with_a_reason() {
        let error = |line: &str| parse(line).unwrap_err();
        assert!(error("--types axial,cube").starts_with("--types: unknown type \"cube\""));
        assert!(error("--budget 0").starts_with("--budget 0: expected a positive"));
        assert!(error("--out").starts_with("--out needs a value"));
        assert!(error("--verbose").starts_with("unknown option --verbose"));
        assert!(error("a.json b.json").starts_with("more than one scene given: b.json"));
    }
}
