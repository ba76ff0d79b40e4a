//! The command-line tool of `SCENES.md`: find an object's symmetries in one depth image and
//! predict its hidden back side.
//!
//! ```text
//! cargo run --release --example complete -- [SCENE.json] [--out RESULT.json] [--ply COMPLETED.ply]
//!     [--png PICTURE.png] [--budget WORK_UNITS_PER_POLL] [--types TYPE,TYPE,...] [--parts]
//!     [--target U,V | --roi X,Y,W,H] [--one-object]
//! cargo run --release --example complete -- --depth DEPTH.png --depth-scale METRES_PER_UNIT
//!     (--intrinsics FX,FY,CX,CY | --camera-info CAMERA_INFO.yaml) [--mask MASK.png]
//!     [--table NX,NY,NZ,D] [--out ...and the other options above]
//! ```
//! Without `SCENE.json` it runs on the library's built-in synthetic scene. Instead of a scene
//! file it also takes raw sensor input: the depth PNG with its scale and intrinsics (numbers, or
//! a ROS `sensor_msgs/CameraInfo` YAML file), and optionally the mask and the table plane, each
//! as the scene file would give it (`sfs_testkit::raw`). Without a mask, `--target` or `--roi`
//! names the object among the candidate regions the engine segments. Exit code 0 when the search ran
//! (whether or not it found a symmetry), 1 with a message for unusable input.

use std::path::PathBuf;
use std::process::ExitCode;

use sfs_testkit::raw::{self, Camera, Pinhole, RawInput};
use sfs_testkit::scene::LoadedScene;
use sfs_testkit::search::{self, Outcome};
use sfs_testkit::{Result, picture, ply, result::ResultJson};
use shape_from_symmetry::{
    Config, Error, Found, Plane, Segmentation, Symmetry, SymmetryType, Target, TypeSet,
};

const USAGE: &str =
    "usage: complete [SCENE.json] [--out RESULT.json] [--ply COMPLETED.ply] [--png PICTURE.png]
                [--budget WORK_UNITS_PER_POLL] [--types TYPE,TYPE,...] [--parts]
                [--target U,V | --roi X,Y,W,H] [--one-object]
       complete --depth DEPTH.png --depth-scale METRES_PER_UNIT
                (--intrinsics FX,FY,CX,CY | --camera-info CAMERA_INFO.yaml)
                [--mask MASK.png] [--table NX,NY,NZ,D] [--out ... and the options above]
  SCENE.json     a scene in the format of SCENES.md (default: the built-in synthetic scene)
  --depth        instead of a scene file, raw input: a 16-bit grayscale depth PNG, 0 = no
                 reading; its size is the image size
  --depth-scale  metres per depth unit (0.001 for millimetres)
  --intrinsics   pinhole intrinsics in pixels: focal lengths, principal point
  --camera-info  the intrinsics from a ROS sensor_msgs/CameraInfo YAML file (width, height,
                 K or k; or a calibration file's image_width, image_height, camera_matrix)
  --mask         an 8-bit PNG of the depth image's size, nonzero = object (default: the
                 tool segments the object)
  --table        the support plane n · X + d = 0 (camera frame, metres), n a unit normal
                 pointing away from the table (default: the tool fits it)
  --out          write the result JSON
  --ply          write the visible and generated points (ASCII PLY)
  --png          write a picture: the camera's view and the completed object from behind,
                 seen and predicted points apart, the symmetry drawn
  --budget       work units per poll (default 50000; the result does not depend on it)
  --types        restrict the search to these types: plane_reflection, line_reflection,
                 point_reflection, axial, spherical, dual_plane, triple_plane, axial_plane
  --parts        also search part symmetries (domains): an axial part of an object whose
                 whole has only mirror planes or nothing, then the rest; PLY and PNG colour
                 the visible points by domain
  --target       without a mask: the object is the candidate region holding pixel (U, V)
                 (column, row; default: the candidate of plausible size at the optical
                 axis, or else nearest it); ignored when there is a mask
  --roi          without a mask: the object is the candidate region with the most of its
                 pixels in the region X,Y,W,H (first column and row, width, height);
                 --target and --roi exclude each other
  --one-object   without a mask: nothing touches the object, so a part that meets its body
                 at a concave crease or a neck (a handle, a bottle's neck) stays with it (default:
                 regions are parted there, where touching objects meet;
                 PrepareConfig::with_one_object)";

/// The parsed command line.
#[derive(Clone, Debug)]
struct Args {
    input: Input,
    out: Option<PathBuf>,
    ply: Option<PathBuf>,
    png: Option<PathBuf>,
    budget: u32,
    types: TypeSet,
    parts: bool,
    /// `--one-object`: `PrepareConfig::with_one_object`.
    one_object: bool,
    /// `--target` or `--roi`.
    target: Option<Target>,
}

fn main() -> ExitCode {
    sfs_testkit::run_cli(USAGE, parse_args, |args| complete(args).map(|()| true))
}

/// What the search runs on.
#[derive(Clone, Debug, PartialEq)]
enum Input {
    Builtin,
    Scene(PathBuf),
    Raw(RawInput),
}

/// The options of raw input, as given.
#[derive(Debug, Default)]
struct RawOptions {
    depth: Option<PathBuf>,
    depth_scale: Option<f32>,
    intrinsics: Option<Pinhole>,
    camera_info: Option<PathBuf>,
    mask: Option<PathBuf>,
    table: Option<Plane>,
}

/// The raw-input options, in the order of `RawOptions`' fields.
const RAW_OPTIONS: [&str; 6] = [
    "--depth",
    "--depth-scale",
    "--intrinsics",
    "--camera-info",
    "--mask",
    "--table",
];

/// Where the demo (the built-in scene, no output named) writes its result, PLY and picture.
const DEMO_FOLDER: &str = "target/demo";

fn complete(args: &Args) -> Result<()> {
    let demo = matches!(args.input, Input::Builtin)
        && args.out.is_none()
        && args.ply.is_none()
        && args.png.is_none();
    let args = &if demo {
        with_demo_files(args)?
    } else {
        args.clone()
    };
    let scene = match &args.input {
        Input::Builtin => LoadedScene::builtin()?,
        Input::Scene(path) => LoadedScene::load(path)?,
        Input::Raw(raw) => LoadedScene::from_raw(raw)?,
    };
    let mut config = Config {
        types: args.types,
        ..Config::DEFAULT
    };
    config.domains.parts = args.parts;
    config.prepare = config.prepare.with_one_object(args.one_object);
    let outcome = search::run(&scene, args.target, config, args.budget, None)
        .map_err(|e| search_error(&scene, args.target, e))?;
    print_summary(&scene, args.target, &outcome, args.budget);
    let domains = outcome.report.symmetries.len();
    if let Some(path) = &args.out {
        sfs_testkit::write_json(path, &ResultJson::new(&outcome))?;
    }
    if let Some(path) = &args.ply {
        ply::write(path, &outcome.points, domains)?;
    }
    if let Some(path) = &args.png {
        let report = &outcome.report;
        picture::render(&scene.name, report, &outcome.points, scene.up()).write_png(path)?;
    }
    if demo {
        println!(
            "wrote {DEMO_FOLDER}/builtin.json, .ply and .png (the result, the completed points, a picture)"
        );
    }
    Ok(())
}

/// The message for a search that failed: the scene's name, the target option for the target's
/// errors, the library's words.
fn search_error(scene: &LoadedScene, target: Option<Target>, error: Error) -> String {
    let name = &scene.name;
    let k = &scene.intrinsics;
    match (target.as_ref().map(raw::target_option), error) {
        (Some(option), Error::TargetOutsideImage) => format!(
            "{name}: {option}: {error}; the image is {}x{} pixels",
            k.width, k.height
        ),
        (Some(option), Error::TargetOnNoObject) => format!("{name}: {option}: {error}"),
        _ => format!("{name}: {error}"),
    }
}

/// `args` with the demo's three output files in [`DEMO_FOLDER`] (created).
fn with_demo_files(args: &Args) -> Result<Args> {
    let folder = PathBuf::from(DEMO_FOLDER);
    std::fs::create_dir_all(&folder).map_err(|e| format!("cannot create {DEMO_FOLDER}: {e}"))?;
    let file = |ext: &str| Some(folder.join(format!("builtin.{ext}")));
    Ok(Args {
        out: file("json"),
        ply: file("ply"),
        png: file("png"),
        ..args.clone()
    })
}

fn parse_args(args: Vec<String>) -> Result<Args> {
    let (mut scene, mut raw) = (None, RawOptions::default());
    let mut parsed = Args {
        input: Input::Builtin,
        out: None,
        ply: None,
        png: None,
        budget: search::DEFAULT_BUDGET,
        types: TypeSet::ALL,
        parts: false,
        one_object: false,
        target: None,
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
            "--one-object" => parsed.one_object = true,
            "--target" => set_target(&mut parsed.target, raw::parse_target(&value()?)?)?,
            "--roi" => set_target(&mut parsed.target, raw::parse_roi(&value()?)?)?,
            flag if RAW_OPTIONS.contains(&flag) => raw.set(flag, value()?)?,
            flag if flag.starts_with('-') => return Err(format!("unknown option {flag}\n{USAGE}")),
            _ if scene.is_some() => {
                return Err(format!("more than one scene given: {arg}\n{USAGE}"));
            }
            _ => scene = Some(arg.into()),
        }
    }
    parsed.input = raw.input(scene)?;
    Ok(parsed)
}

impl RawOptions {
    /// Record `flag`'s value; each at most once.
    fn set(&mut self, flag: &str, value: String) -> Result<()> {
        match flag {
            "--depth" => once(&mut self.depth, flag, value.into()),
            "--depth-scale" => once(&mut self.depth_scale, flag, raw::parse_depth_scale(&value)?),
            "--intrinsics" => once(&mut self.intrinsics, flag, raw::parse_intrinsics(&value)?),
            "--camera-info" => once(&mut self.camera_info, flag, value.into()),
            "--mask" => once(&mut self.mask, flag, value.into()),
            "--table" => once(&mut self.table, flag, raw::parse_table(&value)?),
            _ => Err(format!("unknown option {flag}\n{USAGE}")),
        }
    }

    /// The first raw-input option given, if any.
    fn first_given(&self) -> Option<&'static str> {
        let given = [
            self.depth.is_some(),
            self.depth_scale.is_some(),
            self.intrinsics.is_some(),
            self.camera_info.is_some(),
            self.mask.is_some(),
            self.table.is_some(),
        ];
        RAW_OPTIONS
            .into_iter()
            .zip(given)
            .find_map(|(flag, g)| g.then_some(flag))
    }

    /// The input these options and the scene argument name, if they fit together.
    fn input(self, scene: Option<PathBuf>) -> Result<Input> {
        let Some(flag) = self.first_given() else {
            return Ok(scene.map_or(Input::Builtin, Input::Scene));
        };
        if let Some(scene) = scene {
            let scene = scene.display();
            return Err(format!(
                "{scene} and {flag} exclude each other: give a scene file or raw input\n{USAGE}"
            ));
        }
        let depth = self
            .depth
            .ok_or_else(|| format!("{flag} needs --depth\n{USAGE}"))?;
        let depth_scale = self
            .depth_scale
            .ok_or_else(|| format!("--depth needs --depth-scale\n{USAGE}"))?;
        let camera = match (self.intrinsics, self.camera_info) {
            (Some(pinhole), None) => Camera::Pinhole(pinhole),
            (None, Some(path)) => Camera::Info(path),
            (Some(_), Some(_)) => {
                return Err(format!(
                    "--intrinsics and --camera-info exclude each other: give one\n{USAGE}"
                ));
            }
            (None, None) => {
                return Err(format!(
                    "--depth needs --intrinsics or --camera-info\n{USAGE}"
                ));
            }
        };
        Ok(Input::Raw(RawInput {
            depth,
            depth_scale,
            camera,
            mask: self.mask,
            table: self.table,
        }))
    }
}

/// Fill `slot` with `value`, unless `flag` was given before.
fn once<T>(slot: &mut Option<T>, flag: &str, value: T) -> Result<()> {
    match slot.replace(value) {
        None => Ok(()),
        Some(_) => Err(format!("{flag} given twice\n{USAGE}")),
    }
}

/// Record the target of `--target` or `--roi`: one of them, once.
fn set_target(slot: &mut Option<Target>, target: Target) -> Result<()> {
    let flag = |t: &Target| match t {
        Target::Pixel { .. } => "--target",
        Target::Region(_) => "--roi",
    };
    match slot.replace(target) {
        None => Ok(()),
        Some(before) if flag(&before) == flag(&target) => {
            Err(format!("{} given twice\n{USAGE}", flag(&target)))
        }
        Some(_) => Err(format!(
            "--target and --roi exclude each other: name the object by a pixel or by a region\n{USAGE}"
        )),
    }
}

/// `plane_reflection,axial` as a set of types.
fn parse_types(text: &str) -> Result<TypeSet> {
    let types = text.split(',').map(|name| {
        SymmetryType::from_name(name.trim())
            .ok_or_else(|| format!("--types: unknown type {name:?}\n{USAGE}"))
    });
    Ok(TypeSet::of(&types.collect::<Result<Vec<_>>>()?))
}

fn print_summary(scene: &LoadedScene, target: Option<Target>, outcome: &Outcome, budget: u32) {
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
    if let (Some(t), Some(_)) = (target, &scene.mask) {
        println!(
            "{} ignored: the mask names the object",
            raw::target_option(&t)
        );
    }
    if let Some(s) = &report.segmentation {
        println!("{}", segmentation_line(s));
    }
    match report.symmetries.len() {
        0 => println!("no symmetry found"),
        n => println!(
            "{n} symmetr{} found, strongest first:",
            if n == 1 { "y" } else { "ies" }
        ),
    }
    for (i, found) in report.symmetries.iter().enumerate() {
        print_symmetry(&format!("{}.", i + 1), found);
    }
    if let Some(runner_up) = &report.runner_up {
        println!("runner-up (another reading of the whole object):");
        print_symmetry("-", runner_up);
    }
    let written = (report.points_visible + report.points_generated) as usize;
    let dropped = match report.points_dropped {
        0 => String::new(),
        n if written >= search::OUTPUT_POINTS => format!(
            " ({n} dropped: the output was full; hold more than {} points)",
            search::OUTPUT_POINTS
        ),
        n => format!(
            " ({n} dropped: the voxel table was full; raise the engine's VOXELS, now {})",
            search::VOXELS
        ),
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

/// How the engine chose the object: candidates, the chosen one, its pixel box.
fn segmentation_line(s: &Segmentation) -> String {
    let n = s.candidates;
    let chosen = match s.chosen {
        Some(i) => format!("chose candidate {i} (from 0)"),
        None => "chose the target's region, of implausible size".into(),
    };
    let b = &s.object_box;
    format!(
        "segmented: {n} candidate{} of plausible size, {chosen}; object box {}x{} pixels at ({}, {})",
        if n == 1 { "" } else { "s" },
        b.width,
        b.height,
        b.u0,
        b.v0
    )
}

fn print_symmetry(label: &str, found: &Found) {
    let s: &Symmetry = &found.symmetry;
    println!(
        "  {label:<3} {:<16} confidence {:.2} (score {:.3}, lower is better), {} domain points",
        s.kind().name(),
        found.confidence,
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
    use shape_from_symmetry::Rect;

    fn parse(line: &str) -> Result<Args> {
        parse_args(line.split_whitespace().map(String::from).collect())
    }

    #[test]
    fn parses_every_option() {
        let args = parse(
            "s.json --out r.json --ply c.ply --png p.png --budget 7 --types axial,plane_reflection --parts \
             --target 12,34 --one-object",
        )
        .unwrap();
        assert_eq!(args.input, Input::Scene("s.json".into()));
        assert_eq!(
            (args.out.unwrap(), args.ply.unwrap(), args.png.unwrap()),
            ("r.json".into(), "c.ply".into(), "p.png".into())
        );
        assert_eq!((args.budget, args.parts, args.one_object), (7, true, true));
        assert_eq!(
            args.types,
            TypeSet::of(&[SymmetryType::Axial, SymmetryType::PlaneReflection])
        );
        assert_eq!(args.target, Some(Target::Pixel { u: 12, v: 34 }));
        let roi = Rect {
            u0: 1,
            v0: 2,
            width: 30,
            height: 40,
        };
        let args = parse("--roi 1,2,30,40 --depth d.png --depth-scale 0.001 --intrinsics 1,1,0,0");
        assert_eq!(args.unwrap().target, Some(Target::Region(roi)));
    }

    #[test]
    fn defaults_to_the_builtin_scene_and_every_type() {
        let args = parse("").unwrap();
        assert_eq!(
            (args.input, args.budget, args.types, args.parts, args.target),
            (
                Input::Builtin,
                search::DEFAULT_BUDGET,
                TypeSet::ALL,
                false,
                None
            )
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

    #[test]
    fn rejects_bad_targets_with_a_reason() {
        let error = |line: &str| parse(line).unwrap_err();
        let both =
            "--target and --roi exclude each other: name the object by a pixel or by a region";
        assert!(error("--target 1,2 --roi 0,0,5,5").starts_with(both));
        assert!(error("--roi 0,0,5,5 s.json --target 1,2").starts_with(both));
        assert!(error("--target 1,2 --target 3,4").starts_with("--target given twice"));
        assert!(error("--roi 0,0,5,5 --roi 0,0,5,5").starts_with("--roi given twice"));
        assert!(error("--target").starts_with("--target needs a value"));
        assert!(error("--target 1").starts_with(
            "--target 1: expected 2 comma-separated whole numbers, got 1 (expected U,V"
        ));
        assert!(error("--target 1,-2").contains("\"-2\" is not a whole number from 0 to 65535"));
        assert!(error("--roi 0,0,5").starts_with("--roi 0,0,5: expected 4 comma-separated"));
        assert!(error("--roi 0,0,5,0").contains("the region is 5x0, it must be at least 1x1"));
        assert!(error("--roi 0,0,5,70000").contains("\"70000\" is not a whole number"));
    }

    #[test]
    fn parses_raw_input() {
        let args = parse(
            "--depth d.png --depth-scale 0.001 --intrinsics 285,285,159.5,119.5 --mask m.png \
             --table 0,-1,0,0.25 --out r.json",
        )
        .unwrap();
        let expected = RawInput {
            depth: "d.png".into(),
            depth_scale: 0.001,
            camera: Camera::Pinhole(Pinhole::new(285.0, 285.0, 159.5, 119.5).unwrap()),
            mask: Some("m.png".into()),
            table: Plane::new(shape_from_symmetry::math::Vec3::NEG_Y, -0.25),
        };
        assert_eq!(args.input, Input::Raw(expected));
        assert_eq!(args.out, Some("r.json".into()));
        let args = parse("--camera-info c.yaml --depth-scale 0.001 --depth d.png").unwrap();
        let Input::Raw(raw) = args.input else {
            panic!("raw input expected, got {:?}", args.input)
        };
        assert_eq!(
            (raw.camera, raw.mask, raw.table),
            (Camera::Info("c.yaml".into()), None, None)
        );
    }

    #[test]
    fn rejects_raw_input_that_does_not_fit_together() {
        let error = |line: &str| parse(line).unwrap_err();
        let raw = "--depth d.png --depth-scale 0.001";
        let k = "--intrinsics 285,285,159.5,119.5";
        assert!(
            error(&format!("s.json {raw} {k}")).starts_with(
                "s.json and --depth exclude each other: give a scene file or raw input"
            )
        );
        assert!(error("--mask m.png s.json").starts_with("s.json and --mask exclude each other"));
        assert!(
            error(&format!("--depth-scale 0.001 {k}")).starts_with("--depth-scale needs --depth")
        );
        assert!(error(&format!("--depth d.png {k}")).starts_with("--depth needs --depth-scale"));
        assert!(error(raw).starts_with("--depth needs --intrinsics or --camera-info"));
        assert!(
            error(&format!("{raw} {k} --camera-info c.yaml"))
                .starts_with("--intrinsics and --camera-info exclude each other")
        );
        assert!(error(&format!("{raw} {k} --depth e.png")).starts_with("--depth given twice"));
    }

    #[test]
    fn rejects_bad_raw_values_naming_the_option() {
        let error = |line: &str| parse(line).unwrap_err();
        assert!(
            error("--intrinsics 285,285,159.5").starts_with(
                "--intrinsics 285,285,159.5: expected 4 comma-separated numbers, got 3"
            )
        );
        assert!(error("--intrinsics 285,x,1,1").contains("\"x\" is not a finite number"));
        assert!(error("--intrinsics 0,285,1,1").contains("focal length fx = 0 must be positive"));
        assert!(error("--depth-scale NaN").starts_with("--depth-scale NaN: expected metres"));
        assert!(error("--depth-scale -1").starts_with("--depth-scale -1: expected metres"));
        assert!(error("--table 0,-2,0,0.25").contains("it must be a unit vector"));
        assert!(error("--camera-info").starts_with("--camera-info needs a value"));
    }

    /// The folder of the development scenes, the repository's `scenes/dev`; `None` in a
    /// checkout without it (the published crate).
    fn development_scenes() -> Option<PathBuf> {
        let dev = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dev");
        dev.is_dir().then_some(dev)
    }

    /// The result file of the command line `args` (plus `--out`), less its wall-clock time.
    fn result_of(args: &[&str], tag: &str) -> serde_json::Value {
        let out =
            std::env::temp_dir().join(format!("sfs-complete-{tag}-{}.json", std::process::id()));
        let mut words: Vec<String> = args.iter().map(|&a| a.into()).collect();
        words.extend(["--out".into(), out.display().to_string()]);
        complete(&parse_args(words).unwrap()).unwrap();
        let text = std::fs::read_to_string(&out).unwrap();
        std::fs::remove_file(&out).unwrap();
        let mut result: serde_json::Value = serde_json::from_str(&text).unwrap();
        result["work"]["wall_ms"] = serde_json::Value::Null;
        result
    }

    /// `values` as the file writes them, comma-separated.
    fn joined<'a>(values: impl IntoIterator<Item = &'a serde_json::Value>) -> String {
        let texts: Vec<String> = values.into_iter().map(|v| v.to_string()).collect();
        texts.join(",")
    }

    /// The built-in scene (no mask: segmented): its result names the candidates, the chosen one
    /// and the object's box; a target pixel on the object or a region around it chooses the same
    /// object (the same result), one off it or outside the image fails, naming the option.
    #[test]
    fn a_target_names_the_segmented_object() {
        let plain = result_of(&[], "plain");
        let segmentation = &plain["segmentation"];
        assert_eq!(
            (&segmentation["candidates"], &segmentation["chosen"]),
            (&1.into(), &0.into())
        );
        let b: Vec<u64> = (0..4)
            .map(|i| segmentation["object_box"][i].as_u64().unwrap())
            .collect();
        assert!(b[2] > 10 && b[3] > 10, "the can's box: {b:?}");
        let centre = format!("{},{}", b[0] + b[2] / 2, b[1] + b[3] / 2);
        assert_eq!(result_of(&["--target", &centre], "pixel"), plain);
        let around = format!("{},{},{},{}", b[0] - 5, b[1] - 5, b[2] + 10, b[3] + 10);
        // The same result, but for the work of each one's own pass (with the region, the
        // candidate regions wholly within it join the object; without, those that hang from it).
        let mut roi = result_of(&["--roi", &around], "roi");
        let units = |r: &serde_json::Value| r["work"]["work_units"].as_u64().unwrap();
        assert_ne!(units(&roi), units(&plain));
        roi["work"]["work_units"] = plain["work"]["work_units"].clone();
        assert_eq!(roi, plain);
        // Never written: the search fails first.
        let out = std::env::temp_dir().join(format!("sfs-unused-{}.json", std::process::id()));
        let error = |line: &str| {
            let line = format!("{line} --out {}", out.display());
            complete(&parse(&line).unwrap()).unwrap_err()
        };
        assert_eq!(
            error("--target 0,0"),
            "builtin: --target 0,0: no object candidate at the target pixel or in its region"
        );
        assert_eq!(
            error("--roi 300,0,21,5"),
            "builtin: --roi 300,0,21,5: the target pixel or region is not inside the image \
             (or the region is empty); the image is 320x240 pixels"
        );
    }

    /// A scene file's depth, mask, depth scale, intrinsics and table plane given as raw input
    /// (the numbers as the file writes them) give exactly the scene file's result, with
    /// `--intrinsics` and with the committed camera info file of the same camera.
    #[test]
    fn raw_input_gives_the_scene_files_result() {
        let Some(dev) = development_scenes() else {
            println!("skipped: no development scenes (scenes/dev)");
            return;
        };
        let path = |suffix: &str| {
            let name = format!("ycb_025_mug_wrist_0{suffix}");
            dev.join(name).display().to_string()
        };
        let (json, depth, mask) = (path(".json"), path(".depth.png"), path(".mask.png"));
        let file: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let k = &file["intrinsics"];
        let intrinsics = joined([&k["fx"], &k["fy"], &k["cx"], &k["cy"]]);
        let table = joined(file["table_plane"].as_array().unwrap());
        let scale = file["depth_scale"].to_string();
        let raw = [
            "--depth",
            &depth,
            "--mask",
            &mask,
            "--depth-scale",
            &scale,
            "--table",
            &table,
        ];
        let info = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/testkit/data/camera_info_320x240.yaml"
        );
        let expected = result_of(&[&json], "json");
        assert_eq!(expected["status"], "symmetric");
        assert_eq!(
            expected.get("segmentation"),
            None,
            "a mask: no segmentation"
        );
        let numbers = [&raw[..], &["--intrinsics", &intrinsics]].concat();
        assert_eq!(result_of(&numbers, "numbers"), expected);
        let camera_info = [&raw[..], &["--camera-info", info]].concat();
        assert_eq!(result_of(&camera_info, "info"), expected);
    }
}
