//! Recovery on the synthetic objects of the test kit (`sfs_testkit::synth`): shapes the
//! development scenes do not hold (boxes, cones, plates, parts joined into a mug, a hammer, a
//! figure, objects lying on their side), each seen from twelve views with two draws of the
//! Kinect noise model, searched with the default configuration but the renderer's sensor
//! (`synth::SENSOR`: no lateral noise), mask and table given. With `--lateral-jitter` the
//! renders also carry the Kinect's lateral noise (`Artefacts::lateral`, `KINECT_LATERAL_PX`)
//! and the search models it (`SensorConfig::lateral_noise`); `--model-lateral on|off` overrides
//! the model either way. With `--shadow` the renders also lack the readings the Kinect's
//! projector cannot light (`Artefacts::projector_baseline`, `KINECT_BASELINE`). With
//! `--correlated-noise` their axial noise is correlated between neighbouring pixels as a real
//! Xtion's (`Artefacts::xtion_correlated`). With `--glossy-tops` the faces of the objects that
//! face up read nothing (`Artefacts::unread_up_deg`, `GLOSSY_TOP_DEG`: a metal lid, a glossy
//! top). With `--registered` they are rendered through the
//! real frames' camera (`REAL_FRAME_INTRINSICS`, 640 x 480, f = 1067 px, 0.1 mm units): an Xtion's
//! depth registered to its colour camera, each pixel the reading of its nearest depth sensor
//! pixel (`Artefacts::sensor_focal_ratio`). With `--no-input` the search is given neither the
//! mask nor the table (it fits the support and segments the object itself); `--one-object`
//! also tells it that nothing touches the object (`PrepareConfig::with_one_object`).
//! `--distance M` moves the camera (default 0.5 m); `--noise-scale S` multiplies the rendered
//! axial noise (`Noise::axial_scale`) and the search's sensor model
//! (`SensorConfig::noise_floor`, `noise_growth`) alike: a noisier camera, configured as such.
//! It is the check that a change helps objects, ranges and sensors beyond the ten scanned
//! objects' scenes.
//!
//! ```text
//! cargo run --release --example synthetic [-- --lateral-jitter] [--model-lateral on|off]
//!     [--shadow] [--correlated-noise] [--glossy-tops] [--registered] [--no-input [--one-object]]
//!     [--distance M] [--noise-scale S] [--why | --why-all] [--explain NAME]
//! ```
//! Prints a Markdown table, one row per object: how often the strongest symmetry is **valid**
//! (every map of it takes the engine's sampled points, moved onto the true surface, onto the
//! object's true surface: mean distance at most 4 mm, 90th percentile at most 8 mm and 99th at most
//! 12 mm for the worst map, distances capped at 50 mm, the thresholds of `evaluate`
//! (`sfs_testkit::metrics::VALID_MEAN`, `VALID_P90`, `VALID_P99`); on an asymmetric object, none
//! found or a near-symmetry within those bounds), of the object's **exact** class (on an asymmetric
//! object, none found), or **missed** (none found on a symmetric object). `--why` also writes to
//! standard error a line for each scene whose strongest symmetry is not valid: the view and noise
//! seed, what was found (or missed), the worst map's mean and 90th and 99th percentiles, and each
//! element against the nearest true one (angle, offset, and the offset's component toward the
//! camera: positive where the hidden back is predicted too near). `--why-all` writes that line for
//! every scene, the valid ones too (marked `valid`): the precision of the elements of symmetries
//! that pass, e.g. whether the axes of an object lean towards the camera. `--explain NAME` writes
//! to standard error, for every scene of the object `NAME`, what was found and the true symmetry
//! scored over every point (`Engine::explain`): its score and each element's images, mean cost,
//! decided images and strays (and of those, the ones beyond the observed crop, taken for seen free
//! space whatever the camera read there), and whether its strays fail it: why the model accepts or
//! rejects the truth.
//!
//! Views: 0.5 m from the object (a wrist camera's reach, the distance of `tests/recovery.rs`);
//! elevations 30°, 45° and 60° (a head camera looks down on a table at about 30-45°, a wrist
//! camera at 45-60°); azimuths 0°, 60°, 150° and 260° around the object (the tests' views:
//! along a mirror plane of most objects, and three between); noise seeds 7 and 8 (the tests').

use sfs_testkit::metrics::{VALID_MEAN, VALID_P90, VALID_P99, axis_offset, toward_camera};
use sfs_testkit::synth::{
    Artefacts, BUILTIN_INTRINSICS, KINECT_BASELINE, KINECT_LATERAL_PX, LYING_OBJECTS, Noise,
    OBJECTS, PART_OBJECTS, REAL_FRAME_INTRINSICS, ReadyObject, SENSOR, SynthScene, View,
    XTION_DEPTH_SCALE, XTION_INTRINSICS, render, signed_distance, transform_symmetry,
};
use shape_from_symmetry::math::{Isometry, Vec3};
use shape_from_symmetry::{
    Axis, CompletedPoint, Config, Engine, Found, SensorConfig, Status, Symmetry,
};

const ELEVATIONS_DEG: [f32; 3] = [30.0, 45.0, 60.0];
const AZIMUTHS_DEG: [f32; 4] = [0.0, 60.0, 150.0, 260.0];
const SEEDS: [u32; 2] = [7, 8];
/// Metres from the camera to the object's centre.
const DISTANCE: f32 = 0.5;
/// With `--glossy-tops`, the faces within this angle of up read nothing (degrees): a lid or a
/// box's top resting level, with room for the few degrees a scanned lid is domed or a box
/// bulges; not a can's wall (90°) nor the test kit's cone's side.
const GLOSSY_TOP_DEG: f32 = 20.0;
/// Distances are capped here (metres), so one far image does not dominate the mean.
const CAP: f32 = 0.05;

/// What one object's scenes gave.
#[derive(Default)]
struct Tally {
    scenes: u32,
    valid: u32,
    exact: u32,
    missed: u32,
    failed: u32,
}

/// How far the maps of `found` take `points` (camera frame), moved onto the true surface of
/// `object` (placed by `to_camera`), from that surface: the largest mean and the largest 90th
/// and 99th percentiles over the maps, metres. The symmetry is valid when all three are within
/// the bounds.
fn misses(found: &Symmetry, points: &[Vec3], object: &ReadyObject, to_camera: &Isometry) -> Miss {
    let maps = found.maps(Config::DEFAULT.sampling).maps;
    maps.iter().fold(Miss::default(), |worst, (map, _)| {
        let mut distances: Vec<f32> = points
            .iter()
            .map(|&p| {
                let q = map.apply(onto_surface(object, to_camera, p));
                signed_distance(object.parts, to_object(to_camera, q))
                    .abs()
                    .min(CAP)
            })
            .collect();
        distances.sort_by(f32::total_cmp);
        let mean = distances.iter().sum::<f32>() / distances.len().max(1) as f32;
        let percentile =
            |p: usize| (distances.get(distances.len() * p / 100).copied()).unwrap_or(0.0);
        Miss {
            mean: worst.mean.max(mean),
            p90: worst.p90.max(percentile(90)),
            p99: worst.p99.max(percentile(99)),
        }
    })
}

/// The worst map's distances from the true surface (see [`misses`]), metres.
#[derive(Clone, Copy, Debug, Default)]
struct Miss {
    mean: f32,
    p90: f32,
    p99: f32,
}

impl Miss {
    /// Within `evaluate`'s bounds.
    fn valid(&self) -> bool {
        self.mean <= VALID_MEAN && self.p90 <= VALID_P90 && self.p99 <= VALID_P99
    }
}

/// Each element of `found` against the nearest element of `truth` (object frame, placed by
/// `to_camera`), as `--why` prints it: a plane's angle (degrees) and its offset (mm) at the
/// foot of the object's origin on the true plane, an axis' angle and its offset from the true
/// axis at that axis' point, a centre's offset; each offset also as its component toward the
/// camera (positive: the found element lies nearer the camera, the object's hidden back
/// predicted too near).
fn element_errors(found: &Symmetry, truth: &Symmetry, to_camera: &Isometry) -> String {
    let origin = to_camera.translation;
    let mut out = Vec::new();
    let truth_planes: Vec<(Vec3, Vec3)> = (truth.planes().iter())
        .map(|p| {
            let n = to_camera.linear * p.n();
            (n, to_camera.apply(p.n() * p.offset))
        })
        .collect();
    for plane in found.planes() {
        let n = plane.n();
        let nearest =
            (truth_planes.iter()).max_by(|a, b| a.0.dot(n).abs().total_cmp(&b.0.dot(n).abs()));
        let Some(&(tn, on)) = nearest else { continue };
        let foot = origin - tn * tn.dot(origin - on);
        // The found plane lies this far from the true one's foot, along its own normal.
        let moved = -plane.signed_distance(foot) * n;
        let angle = n.dot(tn).abs().min(1.0).acos().to_degrees();
        let toward = moved.dot(toward_camera(foot, None));
        out.push(format!(
            "plane {angle:.1} deg, {:.1} mm ({:+.1} mm toward)",
            moved.length() * 1e3,
            toward * 1e3
        ));
    }
    if let (Some(a), Some(t)) = (found.axis(), truth.axis()) {
        let at = to_camera.apply(t.p());
        let true_axis = Axis::new(to_camera.linear * t.d(), at, at);
        let (off, toward) = axis_offset(a, &true_axis, at);
        let angle = a.d().dot(true_axis.d()).abs().min(1.0).acos().to_degrees();
        out.push(format!(
            "axis {angle:.1} deg, {:.1} mm ({:+.1} mm toward)",
            off.length() * 1e3,
            toward * 1e3
        ));
    }
    if let (Some(c), Some(t)) = (found.center(), truth.center()) {
        let at = to_camera.apply(Vec3::from_array(t));
        let off = Vec3::from_array(c) - at;
        let toward = off.dot(toward_camera(at, None));
        out.push(format!(
            "centre {:.1} mm ({:+.1} mm toward)",
            off.length() * 1e3,
            toward * 1e3
        ));
    }
    out.join("; ")
}

/// `p` (camera frame) moved onto the true surface of `object` along the distance field's
/// gradient: the sampled point without its reading's noise, so that the test measures the
/// symmetry, not the sensor (at 1 m the Kinect's σ alone is half the 4 mm mean allowed).
fn onto_surface(object: &ReadyObject, to_camera: &Isometry, p: Vec3) -> Vec3 {
    /// Step of the central differences, metres: well under the parts' sizes (centimetres).
    const H: f32 = 2e-4;
    let d = |q: Vec3| signed_distance(object.parts, q);
    let mut q = to_object(to_camera, p);
    // Two Newton steps: one lands on a plane or sphere exactly, the second corrects a curve.
    for _ in 0..2 {
        let g = Vec3::new(
            d(q + Vec3::X * H) - d(q - Vec3::X * H),
            d(q + Vec3::Y * H) - d(q - Vec3::Y * H),
            d(q + Vec3::Z * H) - d(q - Vec3::Z * H),
        ) / (2.0 * H);
        if g.length_squared() > 1e-6 {
            q -= g * (d(q) / g.length_squared());
        }
    }
    to_camera.apply(q)
}

/// `p` (camera frame) in the object's frame, placed by `to_camera`.
fn to_object(to_camera: &Isometry, p: Vec3) -> Vec3 {
    to_camera.linear.transpose() * (p - to_camera.translation)
}

/// How the scenes are rendered and searched.
#[derive(Clone, Copy)]
struct Setup {
    /// Render with the Kinect's lateral noise.
    jitter: bool,
    /// Render the projector's shadow.
    shadow: bool,
    /// Render the axial noise correlated between neighbouring pixels, as an Xtion's.
    correlated: bool,
    /// Render through the real frames' camera: an Xtion's depth registered to its colour camera.
    registered: bool,
    /// Render the faces that face up without readings (glossy tops).
    glossy: bool,
    /// Give the search neither the mask nor the table: it segments the object itself.
    no_input: bool,
    /// Tell the search that nothing touches the object (`PrepareConfig::with_one_object`).
    one_object: bool,
    /// The sensor the search assumes.
    sensor: SensorConfig,
    /// The rendered noise's axial σ per the Kinect's.
    noise_scale: f32,
    /// Metres from the camera to the object's centre.
    distance: f32,
    /// Print each scene whose strongest symmetry is not valid, and why, to standard error.
    why: bool,
    /// ... and the valid ones too.
    why_all: bool,
    /// The object whose true symmetry is explained in every scene (`--explain NAME`).
    explain: Option<&'static str>,
}

/// Search `object` from `view` with noise `seed` and count the outcome into `tally`.
fn run(object: &ReadyObject, view: View, seed: u32, setup: Setup, tally: &mut Tally) {
    let (k, ratio, scale) = if setup.registered {
        let ratio = XTION_INTRINSICS.fx / REAL_FRAME_INTRINSICS.fx;
        (REAL_FRAME_INTRINSICS, ratio, XTION_DEPTH_SCALE)
    } else {
        (BUILTIN_INTRINSICS, 1.0, 0.001)
    };
    let lateral_px = if setup.jitter { KINECT_LATERAL_PX } else { 0.0 };
    let baseline = if setup.shadow { KINECT_BASELINE } else { 0.0 };
    // Drawn on the depth sensor's pixels: with registration, the Xtion's own.
    let sensor = if setup.registered {
        XTION_INTRINSICS
    } else {
        k
    };
    let correlation = if setup.correlated {
        Artefacts::xtion_correlated(&sensor).noise_correlation_px
    } else {
        0.0
    };
    let scene = SynthScene {
        artefacts: Artefacts {
            projector_baseline: baseline,
            noise_correlation_px: correlation,
            sensor_focal_ratio: ratio,
            unread_up_deg: if setup.glossy { GLOSSY_TOP_DEG } else { 0.0 },
            ..Artefacts::lateral(seed, lateral_px)
        },
        depth_scale: scale,
        ..object.scene(
            view,
            Noise {
                axial_scale: setup.noise_scale,
                ..Noise::kinect(seed)
            },
        )
    };
    let (mut depth, mut mask) = (vec![0u16; k.pixel_count()], vec![0u8; k.pixel_count()]);
    let Ok(rendered) = render(&scene, &k, &mut depth, &mut mask) else {
        tally.failed += 1;
        return;
    };
    let mut input = scene.input(k, (&depth, &mask), &rendered);
    if setup.no_input {
        (input.mask, input.table) = (None, None);
    }
    let mut out = vec![CompletedPoint::ZERO; 4096];
    let mut config = Config {
        sensor: setup.sensor,
        ..Config::DEFAULT
    };
    config.prepare = config.prepare.with_one_object(setup.one_object);
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
    let searched = engine.start(input, &mut out).and_then(|()| {
        loop {
            if engine.poll(50_000)? == Status::Done {
                return Ok(());
            }
        }
    });
    if searched.is_err() {
        tally.failed += 1;
        return;
    }
    tally.scenes += 1;
    let strongest = engine.report().symmetries.first().copied();
    let scene = || {
        let View {
            elevation_deg,
            azimuth_deg,
            ..
        } = view;
        format!(
            "{} (elevation {elevation_deg}, azimuth {azimuth_deg}, seed {seed})",
            object.name
        )
    };
    if setup.explain == Some(object.name) {
        let to_camera = &rendered.object_to_camera;
        explain_truth(&engine, object, to_camera, strongest, &scene());
    }
    match (strongest, object.symmetry) {
        (None, None) => (tally.valid, tally.exact) = (tally.valid + 1, tally.exact + 1),
        (None, Some(_)) => {
            tally.missed += 1;
            if setup.why {
                eprintln!("{}: missed", scene());
            }
        }
        (Some(found), truth) => {
            let to_camera = &rendered.object_to_camera;
            let miss = misses(&found.symmetry, engine.object_points(), object, to_camera);
            tally.valid += miss.valid() as u32;
            tally.exact += truth.is_some_and(|t| t.kind() == found.symmetry.kind()) as u32;
            if setup.why && (setup.why_all || !miss.valid()) {
                let errors = truth
                    .map(|t| element_errors(&found.symmetry, &t, to_camera))
                    .filter(|e| !e.is_empty())
                    .map_or(String::new(), |e| format!("; {e}"));
                let valid = if miss.valid() { " valid" } else { "" };
                eprintln!(
                    "{}: {}{valid} (score {:.3}), worst map {:.1} / {:.1} / {:.1} mm \
                     (mean / p90 / p99){errors}",
                    scene(),
                    found.symmetry.kind().name(),
                    found.score,
                    miss.mean * 1e3,
                    miss.p90 * 1e3,
                    miss.p99 * 1e3,
                );
            }
        }
    }
}

/// `--explain`'s line for `scene`, a view of `object`, to standard error: what the search found,
/// and the true symmetry scored over every point of the object (`Engine::explain`): its score
/// and each element's informative images, mean cost, images that confirm or contradict it,
/// strays among those, and whether its strays fail it.
fn explain_truth(
    engine: &Engine<'_>,
    object: &ReadyObject,
    to_camera: &Isometry,
    found: Option<Found>,
    scene: &str,
) {
    let found = found.map_or("none", |f| f.symmetry.kind().name());
    let Some(truth) = object.symmetry else {
        eprintln!("{scene}: found {found}; no true symmetry");
        return;
    };
    // Per element, the strays beyond the observed crop (`ImageCost::reading`).
    let mut beyond = [0u32; 3];
    let symmetry = transform_symmetry(&truth, to_camera);
    let explained = engine.explain(&symmetry, |image| {
        let stray = image.stray_beyond_crop();
        if let Some(n) = beyond.get_mut(image.element as usize).filter(|_| stray) {
            *n += 1;
        }
    });
    let Some(explained) = explained else {
        eprintln!("{scene}: found {found}; not prepared");
        return;
    };
    let elements: Vec<String> = (explained.elements.iter())
        .enumerate()
        .map(|(k, e)| {
            format!(
                "element {k}: {} images, mean {:.3}, {} decided, {} strays ({} beyond the crop){}",
                e.images,
                e.mean,
                e.decided,
                e.strays,
                beyond.get(k).copied().unwrap_or_default(),
                if e.contradicted { ", contradicted" } else { "" }
            )
        })
        .collect();
    eprintln!(
        "{scene}: found {found}; true {} over every point: score {:.3}; {}",
        truth.kind().name(),
        explained.score,
        elements.join("; ")
    );
}

/// The finite positive number after `flag` in `args`, or `default` without the flag; exits
/// with a message on anything else.
fn number(args: &[String], flag: &str, default: f32) -> f32 {
    let Some(i) = args.iter().position(|a| a == flag) else {
        return default;
    };
    match args.get(i + 1).map(|s| s.parse::<f32>()) {
        Some(Ok(x)) if x.is_finite() && x > 0.0 => x,
        _ => {
            eprintln!("{flag} takes a positive number");
            std::process::exit(2);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let jitter = args.iter().any(|a| a == "--lateral-jitter");
    let shadow = args.iter().any(|a| a == "--shadow");
    let correlated = args.iter().any(|a| a == "--correlated-noise");
    let registered = args.iter().any(|a| a == "--registered");
    let glossy = args.iter().any(|a| a == "--glossy-tops");
    let no_input = args.iter().any(|a| a == "--no-input");
    let one_object = args.iter().any(|a| a == "--one-object");
    let why_all = args.iter().any(|a| a == "--why-all");
    let why = why_all || args.iter().any(|a| a == "--why");
    let model = args
        .iter()
        .position(|a| a == "--model-lateral")
        .and_then(|i| args.get(i + 1));
    let lateral_noise = match model.map(String::as_str) {
        Some("on") => true,
        Some("off") => false,
        Some(other) => {
            eprintln!("--model-lateral takes on or off, not {other}");
            std::process::exit(2);
        }
        None => jitter,
    };
    let objects = || OBJECTS.iter().chain(&LYING_OBJECTS).chain(&PART_OBJECTS);
    let explain = args.iter().position(|a| a == "--explain").map(|i| {
        let name = args.get(i + 1).map_or("", String::as_str);
        match objects().find(|o| o.name == name) {
            Some(object) => object.name,
            None => {
                let names: Vec<&str> = objects().map(|o| o.name).collect();
                eprintln!("--explain takes an object: {}", names.join(", "));
                std::process::exit(2);
            }
        }
    });
    let noise_scale = number(&args, "--noise-scale", 1.0);
    let distance = number(&args, "--distance", DISTANCE);
    let setup = Setup {
        jitter,
        shadow,
        correlated,
        registered,
        glossy,
        no_input,
        one_object,
        sensor: SensorConfig {
            lateral_noise,
            noise_floor: SENSOR.noise_floor * noise_scale,
            noise_growth: SENSOR.noise_growth * noise_scale,
            ..SENSOR
        },
        noise_scale,
        distance,
        why,
        why_all,
        explain,
    };
    println!("| object | class | scenes | valid | exact class | missed | failed |");
    println!("|---|---|---|---|---|---|---|");
    let mut all = Tally::default();
    for object in objects() {
        let mut tally = Tally::default();
        for elevation_deg in ELEVATIONS_DEG {
            for azimuth_deg in AZIMUTHS_DEG {
                for seed in SEEDS {
                    let view = View {
                        distance: setup.distance,
                        elevation_deg,
                        azimuth_deg,
                        roll_deg: 0.0,
                    };
                    run(object, view, seed, setup, &mut tally);
                }
            }
        }
        let class = object.symmetry.map_or("none", |s| s.kind().name());
        let Tally {
            scenes,
            valid,
            exact,
            missed,
            failed,
        } = tally;
        println!(
            "| {} | {class} | {scenes} | {valid} | {exact} | {missed} | {failed} |",
            object.name
        );
        all.scenes += scenes;
        all.valid += valid;
        all.exact += exact;
        all.missed += missed;
        all.failed += failed;
    }
    let share = |n: u32| 100.0 * n as f32 / all.scenes.max(1) as f32;
    println!(
        "| **all** | | {} | {} ({:.0} %) | {} ({:.0} %) | {} | {} |",
        all.scenes,
        all.valid,
        share(all.valid),
        all.exact,
        share(all.exact),
        all.missed,
        all.failed
    );
}
