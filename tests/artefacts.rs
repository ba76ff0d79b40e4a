//! Recovery under depth-camera artefacts: the can, the cereal box and the bowl, seen from their
//! views of `tests/recovery.rs` with Kinect noise, each rendered with one artefact of the
//! synthetic renderer on: mixed (flying) pixels at depth discontinuities, holes on the object, a
//! 640 x 480 frame in 0.1 mm units (an Xtion), a bottle standing in front of the object. The
//! search (default settings, mask and table given) must find the object's class within the
//! tolerances of `tests/recovery.rs`, whose helpers this file copies.
//!
//! Cases the engine does not recover as it is are ignored with the measured figures
//! (`cargo test --release --test artefacts -- --ignored` runs them, and
//! [`pass_rates_over_noise_seeds`] measures every case over 40 seeds).

use sfs_testkit::synth::{
    Artefacts, BUILTIN_INTRINSICS, Noise, Part, ReadyObject, Shape, SynthScene, View,
    XTION_DEPTH_SCALE, XTION_INTRINSICS, object, occluder_in_front, render, transform_symmetry,
};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{
    Axis, CompletedPoint, Config, Engine, Intrinsics, Plane, Report, Scene, Status, Symmetry,
};

/// Largest angle (degrees) between a found plane normal or axis direction and the truth: as in
/// `tests/recovery.rs` (the hill climber's finest step turns an element by about 1°).
const ANGLE_TOL_DEG: f32 = 3.0;
/// Largest distance (metres), at the object's centre, between a found element and the truth: as
/// in `tests/recovery.rs`.
const DIST_TOL: f32 = 0.01;

/// Work units per poll (any slicing gives the same result).
const BUDGET: u32 = 20_000;
/// Completed points the output can hold (visible + generated).
const OUTPUT: usize = 20_000;
/// Seed of the noise and of the artefacts (the first seed of `tests/recovery.rs`).
const SEED: u32 = 7;

/// Probability that a pixel on a depth discontinuity reads a mixed depth: half of them, between
/// a structured-light camera (the Kinect drops or interpolates its edges: some mixed pixels) and
/// a time-of-flight one (nearly every edge pixel mixed). Of the object's pixels, this mixes
/// about 3 % of the can's, 1 % of the box's and 4 % of the bowl's (its rim over its inside).
const FLYING: f32 = 0.5;
/// Holes on the object, each a disc of `HOLE_RADIUS_PX` (49 pixels): 8 of them clear 11-13 % of
/// the can's 2450 pixels (0.5 m away, 320 x 240), 7-8 % of the bowl's and 3-4 % of the box's.
const HOLES: u32 = 8;

/// One artefact of the renderer, on top of the Kinect noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Artefact {
    /// None: the scene of `tests/recovery.rs`.
    None,
    /// [`FLYING`] of the discontinuity pixels mixed.
    FlyingPixels,
    /// [`HOLES`] holes of the default radius.
    Holes,
    /// The Xtion's 640 x 480 frame in 0.1 mm units.
    Xtion,
    /// [`bottle`] in front of the object.
    Bottle,
}

const ARTEFACTS: [Artefact; 5] = [
    Artefact::None,
    Artefact::FlyingPixels,
    Artefact::Holes,
    Artefact::Xtion,
    Artefact::Bottle,
];

fn view(distance: f32, elevation_deg: f32, azimuth_deg: f32, roll_deg: f32) -> View {
    View {
        distance,
        elevation_deg,
        azimuth_deg,
        roll_deg,
    }
}

/// The view of `tests/recovery.rs` for each object (the first of the can's and the box's).
fn view_of(name: &str) -> View {
    match name {
        "bowl" => view(0.5, 30.0, 150.0, 0.0),
        _ => view(0.5, 45.0, 60.0, 0.0),
    }
}

/// Clutter: a bottle (an upright cylinder 5 cm across and 16 cm tall, taller than each object
/// but the box) standing 10 cm from the object's centre toward the camera, 3 cm to the right.
/// From these views it hides 28 % of the can's pixels, 19 % of the box's and 43 % of the bowl's
/// (the wide bowl is nearer to it, and the bottle cuts across its opening).
fn bottle(object: &ReadyObject, view: &View) -> Part {
    occluder_in_front(
        object,
        view,
        Shape::Cylinder {
            radius: 0.025,
            half_height: 0.08,
        },
        0.1,
        0.03,
    )
}

/// What one search left behind.
struct Outcome {
    report: Report,
    /// The documented symmetry in the camera frame.
    truth: Option<Symmetry>,
    /// The engine's score of `truth` (lower is better).
    truth_score: Option<f32>,
    /// The object's centre (bounding box), camera frame.
    center: Vec3,
    /// Object pixels (the mask's), and those with a reading.
    object_pixels: u32,
    valid_object_pixels: u32,
}

/// Render `name` from its view with Kinect noise and `artefact` (both drawn from `seed`) and
/// search it, mask and table given.
fn run(name: &str, artefact: Artefact, seed: u32) -> Outcome {
    run_with(name, artefact, seed, Config::DEFAULT)
}

/// [`run`] with `config`.
fn run_with(name: &str, artefact: Artefact, seed: u32, config: Config) -> Outcome {
    let object = object(name).expect("a ready-made object");
    let view = view_of(name);
    let base = object.scene(view, Noise::kinect(seed));
    let clutter = [bottle(object, &view)];
    let (scene, k) = match artefact {
        Artefact::None => (base, BUILTIN_INTRINSICS),
        Artefact::FlyingPixels => (
            SynthScene {
                artefacts: Artefacts::flying(seed, FLYING),
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
        Artefact::Holes => (
            SynthScene {
                artefacts: Artefacts::holes(seed, HOLES),
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
        Artefact::Xtion => (
            SynthScene {
                depth_scale: XTION_DEPTH_SCALE,
                ..base
            },
            XTION_INTRINSICS,
        ),
        Artefact::Bottle => (
            SynthScene {
                occluders: &clutter,
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
    };
    search(object, &scene, k, config)
}

/// Render `scene` (of `object`) with camera `k` and search it, mask and table given.
fn search(object: &ReadyObject, scene: &SynthScene, k: Intrinsics, config: Config) -> Outcome {
    let mut depth = vec![0u16; k.pixel_count()];
    let mut mask = vec![0u8; k.pixel_count()];
    let rendered = render(scene, &k, &mut depth, &mut mask).expect("renders");
    let truth = object
        .symmetry
        .map(|s| transform_symmetry(&s, &rendered.object_to_camera));
    let center = rendered
        .object_to_camera
        .apply(Vec3::from_array(object.center()));

    let mut output = vec![CompletedPoint::ZERO; OUTPUT];
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
    let input = Scene {
        table: Some(rendered.table),
        mask: Some(&mask[..]),
        ..Scene::new(&depth, scene.depth_scale, k)
    };
    engine.start(input, &mut output).expect("starts");
    while engine.poll(BUDGET).expect("polls") != Status::Done {}
    let report = engine.report().clone();
    let truth_score = truth.and_then(|t| engine.score(&t));
    drop(engine);
    Outcome {
        report,
        truth,
        truth_score,
        center,
        object_pixels: rendered.object_pixels,
        valid_object_pixels: rendered.valid_object_pixels,
    }
}

fn angle_deg(cos: f32) -> f32 {
    cos.abs().min(1.0).acos().to_degrees()
}

/// Angle (degrees) and distance at `center` between plane `p` and the nearest true plane.
fn plane_error(p: &Plane, truth: &Symmetry, center: Vec3) -> (f32, f32) {
    let mut best = (f32::INFINITY, f32::INFINITY);
    for q in truth.planes() {
        let cos = p.n().dot(q.n());
        let dist = (p.signed_distance(center) - cos.signum() * q.signed_distance(center)).abs();
        if angle_deg(cos) < best.0 {
            best = (angle_deg(cos), dist);
        }
    }
    // Every plane containing a continuous axis is a mirror plane.
    if let Symmetry::Axial(a) | Symmetry::AxialPlane(a, _) = truth {
        let tilt = 90.0 - angle_deg(p.n().dot(a.d()));
        let foot = nearest_on_axis(a, center);
        if tilt < best.0 {
            best = (tilt, p.signed_distance(foot).abs());
        }
    }
    best
}

fn nearest_on_axis(a: &Axis, q: Vec3) -> Vec3 {
    a.p() + a.d() * a.d().dot(q - a.p())
}

/// Angle (degrees) between the axes, and the distance from the point of `found` nearest `center`
/// to the true axis.
fn axis_error(found: &Axis, truth: &Axis, center: Vec3) -> (f32, f32) {
    let at = nearest_on_axis(found, center);
    (
        angle_deg(found.d().dot(truth.d())),
        truth.distance_squared(at).sqrt(),
    )
}

/// The largest angle and distance errors of the strongest symmetry found, or why it is not
/// recovered: its type is not the object's class, or an error exceeds the tolerances.
fn evaluate(name: &str, out: &Outcome) -> Result<(f32, f32), String> {
    let truth = out.truth.expect("these objects are symmetric");
    let Some(found) = out.report.symmetries.first() else {
        return Err(format!(
            "{name}: found nothing; the truth scores {:?}",
            out.truth_score
        ));
    };
    if found.symmetry.kind() != truth.kind() {
        return Err(format!(
            "{name}: found {} {:?} (score {}); the truth scores {:?}",
            found.symmetry.kind().name(),
            found.symmetry,
            found.score,
            out.truth_score
        ));
    }
    let (mut angle, mut dist) = (0.0f32, 0.0f32);
    for p in found.symmetry.planes() {
        let (a, d) = plane_error(p, &truth, out.center);
        (angle, dist) = (angle.max(a), dist.max(d));
    }
    if let (Some(f), Some(t)) = (found.symmetry.axis(), truth.axis()) {
        let (a, d) = axis_error(f, t, out.center);
        (angle, dist) = (angle.max(a), dist.max(d));
    }
    if let (Some(f), Some(t)) = (found.symmetry.center(), truth.center()) {
        dist = dist.max((Vec3::from_array(f) - Vec3::from_array(t)).length());
    }
    println!(
        "{name}: {} score {:.3} (truth {:.3}), angle error {angle:.2}°, distance error {:.1} mm \
         ({} of {} object pixels with a reading)",
        found.symmetry.kind().name(),
        found.score,
        out.truth_score.unwrap_or(f32::NAN),
        dist * 1000.0,
        out.valid_object_pixels,
        out.object_pixels,
    );
    if angle > ANGLE_TOL_DEG {
        return Err(format!(
            "{name}: angle error {angle}° > {ANGLE_TOL_DEG}°: {:?} vs {truth:?}",
            found.symmetry
        ));
    }
    if dist > DIST_TOL {
        return Err(format!(
            "{name}: distance error {dist} m > {DIST_TOL} m: {:?} vs {truth:?}",
            found.symmetry
        ));
    }
    Ok((angle, dist))
}

/// Search `name` with `artefact` (seed [`SEED`]) and check the result.
fn recovers(name: &str, artefact: Artefact) {
    let out = run(name, artefact, SEED);
    if let Err(why) = evaluate(&format!("{name} with {artefact:?}"), &out) {
        panic!("{why}");
    }
}

// ------------------------------------------------------------------------------------------------
// Flying pixels
// ------------------------------------------------------------------------------------------------

#[test]
fn flying_pixels_can() {
    recovers("can", Artefact::FlyingPixels);
}

#[test]
#[ignore = "engine: with half the discontinuity pixels mixed, the box's third plane is not \
            preferred: a dual plane is reported (score 0.763; the true triple plane scores \
            0.832). Recovered for 13 of 40 noise seeds (18 of 20 with 10 % mixed, 9 of 20 with \
            25 %, 2 of 20 with all); 40 of 40 with PrepareConfig::drop_edge_pixels"]
fn flying_pixels_cereal_box() {
    recovers("cereal_box", Artefact::FlyingPixels);
}

#[test]
#[ignore = "engine: with half the discontinuity pixels mixed, the bowl's axis scores 1.067 \
            (accepted below 0.85): a dual plane is reported (score 0.772). Recovered for 13 of \
            40 noise seeds (20 of 20 with 10 % mixed, 16 of 20 with 25 %, 0 of 20 with all); 39 \
            of 40 with PrepareConfig::drop_edge_pixels"]
fn flying_pixels_bowl() {
    recovers("bowl", Artefact::FlyingPixels);
}

/// With `PrepareConfig::drop_edge_pixels`, the pixels next to a depth jump, the mixed ones among
/// them, are not sampled: the box and the bowl are recovered (over 40 noise seeds, 40 and 39).
#[test]
fn flying_pixels_with_edge_pixels_dropped() {
    let mut config = Config::DEFAULT;
    config.prepare.drop_edge_pixels = true;
    for name in ["can", "cereal_box", "bowl"] {
        let out = run_with(name, Artefact::FlyingPixels, SEED, config);
        if let Err(why) = evaluate(&format!("{name} with flying pixels, edges dropped"), &out) {
            panic!("{why}");
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Holes
// ------------------------------------------------------------------------------------------------

#[test]
fn holes_can() {
    recovers("can", Artefact::Holes);
}

#[test]
fn holes_cereal_box() {
    recovers("cereal_box", Artefact::Holes);
}

#[test]
fn holes_bowl() {
    recovers("bowl", Artefact::Holes);
}

// ------------------------------------------------------------------------------------------------
// A 640 x 480 frame in 0.1 mm units
// ------------------------------------------------------------------------------------------------

#[test]
fn xtion_frame_can() {
    recovers("can", Artefact::Xtion);
}

#[test]
fn xtion_frame_cereal_box() {
    recovers("cereal_box", Artefact::Xtion);
}

#[test]
fn xtion_frame_bowl() {
    recovers("bowl", Artefact::Xtion);
}

// ------------------------------------------------------------------------------------------------
// Clutter in front of the object
// ------------------------------------------------------------------------------------------------

#[test]
fn bottle_in_front_of_the_can() {
    recovers("can", Artefact::Bottle);
}

#[test]
fn bottle_in_front_of_the_cereal_box() {
    recovers("cereal_box", Artefact::Bottle);
}

#[test]
#[ignore = "engine: with the bottle hiding 43 % of the bowl and cutting across its opening, the \
            bowl's axis scores 0.985 (accepted below 0.85): a dual plane is reported (score \
            0.720). Recovered for 4 of 40 noise seeds; a 12 cm bottle at the same place hides \
            35 % and lets 40 of 40 through"]
fn bottle_in_front_of_the_bowl() {
    recovers("bowl", Artefact::Bottle);
}

/// How often each case is recovered over 40 noise (and artefact) seeds; prints a table, asserts
/// nothing (the figures in the ignore reasons and comments above come from it).
#[test]
#[ignore = "measurement: 600 searches, about 15 s in release"]
fn pass_rates_over_noise_seeds() {
    const SEEDS: u32 = 40;
    let mut dropping = Config::DEFAULT;
    dropping.prepare.drop_edge_pixels = true;
    for name in ["can", "cereal_box", "bowl"] {
        for (artefact, config) in ARTEFACTS
            .iter()
            .map(|&a| (a, Config::DEFAULT))
            .chain([(Artefact::FlyingPixels, dropping)])
        {
            let mut failures = Vec::new();
            for seed in SEED..SEED + SEEDS {
                let label = format!("{name} with {artefact:?}, seed {seed}");
                if let Err(why) = evaluate(&label, &run_with(name, artefact, seed, config)) {
                    failures.push(why);
                }
            }
            for why in &failures {
                println!("  {why}");
            }
            let edges = if config.prepare.drop_edge_pixels {
                ", edge pixels dropped"
            } else {
                ""
            };
            println!(
                "RATE {name} with {artefact:?}{edges}: {} of {SEEDS} recovered",
                SEEDS - failures.len() as u32
            );
        }
    }
}
