//! Recovery under depth-camera artefacts: the can, the cereal box and the bowl, seen from their
//! views of `tests/recovery.rs` with Kinect noise, each rendered with one artefact of the
//! synthetic renderer on: mixed (flying) pixels at depth discontinuities, holes on the object, a
//! 640 x 480 frame in 0.1 mm units (an Xtion), a bottle standing in front of the object, the
//! Kinect's lateral noise, the shadow of its projector; and mixed pixels with the lateral noise
//! together. The search (default settings, the sensor as rendered, mask and table given) must
//! find the object's class within the tolerances of `tests/recovery.rs` (`tests/common/mod.rs`).
//!
//! Cases the engine does not recover as it is are ignored with the measured figures
//! (`cargo test --release --test artefacts -- --ignored` runs them, and
//! [`pass_rates_over_noise_seeds`] measures every case over 40 seeds).

mod common;

use common::{ANGLE_TOL_DEG, DIST_TOL, Outcome, check, judge, plane_error, view};
use sfs_testkit::synth::{
    Artefacts, BUILTIN_INTRINSICS, KINECT_BASELINE, KINECT_LATERAL_PX, Noise, Part, ReadyObject,
    Shape, SynthScene, View, XTION_DEPTH_SCALE, XTION_INTRINSICS, object, occluder_in_front,
};
use shape_from_symmetry::Config;

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
    /// The Kinect's lateral noise, [`KINECT_LATERAL_PX`].
    Lateral,
    /// The shadow of the Kinect's projector, [`KINECT_BASELINE`] right of the camera.
    Shadow,
    /// [`FLYING`] of the discontinuity pixels mixed and the Kinect's lateral noise: the
    /// default sensor, which models the lateral noise, under mixed pixels.
    FlyingPixelsLateral,
}

const ARTEFACTS: [Artefact; 8] = [
    Artefact::None,
    Artefact::FlyingPixels,
    Artefact::Holes,
    Artefact::Xtion,
    Artefact::Bottle,
    Artefact::Lateral,
    Artefact::Shadow,
    Artefact::FlyingPixelsLateral,
];

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
        Artefact::Lateral => (
            SynthScene {
                artefacts: Artefacts::lateral(seed, KINECT_LATERAL_PX),
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
        Artefact::Shadow => (
            SynthScene {
                artefacts: Artefacts::shadow(KINECT_BASELINE),
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
        Artefact::FlyingPixelsLateral => (
            SynthScene {
                artefacts: Artefacts {
                    flying_pixels: FLYING,
                    ..Artefacts::lateral(seed, KINECT_LATERAL_PX)
                },
                ..base
            },
            BUILTIN_INTRINSICS,
        ),
    };
    common::search(object, &scene, k, true, config)
}

/// Search `name` with `artefact` (seed [`SEED`]) and check the result.
fn recovers(name: &str, artefact: Artefact) {
    check(
        &format!("{name} with {artefact:?}"),
        &run(name, artefact, SEED),
    );
}

// ------------------------------------------------------------------------------------------------
// Flying pixels
// ------------------------------------------------------------------------------------------------

#[test]
fn flying_pixels_can() {
    recovers("can", Artefact::FlyingPixels);
}

/// With half the discontinuity pixels mixed: recovered for 40 of 40 noise seeds, as with
/// `PrepareConfig::drop_edge_pixels` (`pass_rates_over_noise_seeds`).
#[test]
fn flying_pixels_cereal_box() {
    recovers("cereal_box", Artefact::FlyingPixels);
}

#[test]
#[ignore = "engine: with half the discontinuity pixels mixed, the bowl's axis scores 0.985 \
            on this seed (accepted below 0.85): a dual plane is reported (score 0.705). \
            Recovered for 36 of 40 noise seeds; 39 of 40 with PrepareConfig::drop_edge_pixels, \
            40 of 40 with PrepareConfig::trim_past_outline"]
fn flying_pixels_bowl() {
    recovers("bowl", Artefact::FlyingPixels);
}

/// With `PrepareConfig::drop_edge_pixels`, the pixels next to a depth jump, the mixed ones among
/// them, are not sampled: the can, the box and the bowl are recovered (over 40 noise seeds, 39,
/// 40 and 39).
#[test]
fn flying_pixels_with_edge_pixels_dropped() {
    let mut config = Config::DEFAULT;
    config.prepare.drop_edge_pixels = true;
    for name in ["can", "cereal_box", "bowl"] {
        let out = run_with(name, Artefact::FlyingPixels, SEED, config);
        check(&format!("{name} with flying pixels, edges dropped"), &out);
    }
}

/// With `PrepareConfig::trim_past_outline`, the masked pixels at the outline that read what lies
/// past it (the mixed ones blended toward the background among them) are left out: with half
/// the discontinuity pixels mixed, the can, the box and the bowl are recovered for 40, 40 and 40
/// of 40 noise seeds; under lateral noise too, the box and the bowl for 40 and 40 (the can for
/// 29).
#[test]
fn flying_pixels_with_the_outline_trimmed() {
    let mut config = Config::DEFAULT;
    config.prepare.trim_past_outline = true;
    let (mixed, lateral) = (Artefact::FlyingPixels, Artefact::FlyingPixelsLateral);
    for (name, artefact) in [
        ("can", mixed),
        ("cereal_box", mixed),
        ("bowl", mixed),
        ("cereal_box", lateral),
        ("bowl", lateral),
    ] {
        let out = run_with(name, artefact, SEED, config);
        check(&format!("{name} with {artefact:?}, outline trimmed"), &out);
    }
}

/// Mixed pixels under the Kinect's lateral noise too, searched with the default sensor (which
/// models the lateral noise): the box is recovered for 37 of 40 noise seeds, the bowl for 33.
#[test]
fn flying_pixels_with_lateral_noise_cereal_box() {
    recovers("cereal_box", Artefact::FlyingPixelsLateral);
}

#[test]
#[ignore = "engine: under mixed pixels and lateral noise the can's axis + plane is rejected \
            (the truth scores 0.85, its rotations failing) and a plane is reported (score \
            0.477). Recovered for 24 of 40 noise seeds, 29 with \
            PrepareConfig::trim_past_outline; 39 of 40 with \
            PrepareConfig::drop_edge_pixels and no lateral noise"]
fn flying_pixels_with_lateral_noise_can() {
    recovers("can", Artefact::FlyingPixelsLateral);
}

#[test]
fn flying_pixels_with_lateral_noise_bowl() {
    recovers("bowl", Artefact::FlyingPixelsLateral);
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

/// The bottle hides 43 % of the bowl and cuts across its opening; the images the bowl's
/// rotations send behind it are obstructed, not occluded (`score`): recovered for 40 of 40 noise
/// seeds (`pass_rates_over_noise_seeds`).
#[test]
fn bottle_in_front_of_the_bowl() {
    recovers("bowl", Artefact::Bottle);
}

// ------------------------------------------------------------------------------------------------
// Lateral noise
// ------------------------------------------------------------------------------------------------

#[test]
fn lateral_noise_can() {
    recovers("can", Artefact::Lateral);
}

#[test]
fn lateral_noise_cereal_box() {
    recovers("cereal_box", Artefact::Lateral);
}

#[test]
fn lateral_noise_bowl() {
    recovers("bowl", Artefact::Lateral);
}

/// The figure's limbs are 1.7-2 cm across, a few pixels at 0.5 m: under the lateral noise many
/// of their masked pixels read the table 10-30 cm behind. Those readings must not set the
/// object's radius (`ObjectStats::radius`), which scales the search's grid and steps: taken at
/// the farthest of them, it was three times the figure's and the climbs missed its mirror
/// plane through the camera on seed 7. The strongest symmetry found, from both seeds, is a mirror
/// plane of the figure (a plane or both: the second, front to back, maps the seen front onto
/// the unseen back and is confirmed by nothing).
#[test]
fn lateral_noise_thin_limbs() {
    let figure = object("figure").expect("a ready-made object");
    for seed in [SEED, SEED + 1] {
        let scene = SynthScene {
            artefacts: Artefacts::lateral(seed, KINECT_LATERAL_PX),
            ..figure.scene(view(0.5, 30.0, 0.0, 0.0), Noise::kinect(seed))
        };
        let out = common::search(figure, &scene, BUILTIN_INTRINSICS, true, Config::DEFAULT);
        let truth = out.truth.expect("the figure is symmetric");
        let found = (out.report.symmetries.first()).unwrap_or_else(|| {
            panic!(
                "seed {seed}: nothing found; the truth scores {:?}",
                out.truth_score
            )
        });
        assert!(
            !found.symmetry.planes().is_empty(),
            "seed {seed}: {found:?}"
        );
        for plane in found.symmetry.planes() {
            let (angle, distance) = plane_error(plane, &truth, out.center);
            assert!(
                angle <= ANGLE_TOL_DEG && distance <= DIST_TOL,
                "seed {seed}: {plane:?} is {angle:.1}° and {:.1} mm off the figure's",
                distance * 1e3
            );
        }
    }
}

// ------------------------------------------------------------------------------------------------
// The projector's shadow
// ------------------------------------------------------------------------------------------------

#[test]
fn projector_shadow_can() {
    recovers("can", Artefact::Shadow);
}

#[test]
fn projector_shadow_cereal_box() {
    recovers("cereal_box", Artefact::Shadow);
}

#[test]
fn projector_shadow_bowl() {
    recovers("bowl", Artefact::Shadow);
}

/// How often each case is recovered over 40 noise (and artefact) seeds; prints a table, asserts
/// nothing (the figures in the ignore reasons and comments above come from it).
#[test]
#[ignore = "measurement: 1320 searches, about two minutes in release"]
fn pass_rates_over_noise_seeds() {
    const SEEDS: u32 = 40;
    let mut dropping = Config::DEFAULT;
    dropping.prepare.drop_edge_pixels = true;
    let mut trimming = Config::DEFAULT;
    trimming.prepare.trim_past_outline = true;
    for name in ["can", "cereal_box", "bowl"] {
        for (artefact, config) in ARTEFACTS
            .iter()
            .map(|&a| (a, Config::DEFAULT))
            .chain([(Artefact::FlyingPixels, dropping)])
            .chain([Artefact::FlyingPixels, Artefact::FlyingPixelsLateral].map(|a| (a, trimming)))
        {
            let mut failures = Vec::new();
            for seed in SEED..SEED + SEEDS {
                let label = format!("{name} with {artefact:?}, seed {seed}");
                if let Err(why) = judge(&label, &run_with(name, artefact, seed, config)) {
                    failures.push(why);
                }
            }
            for why in &failures {
                println!("  {why}");
            }
            let edges = match (
                config.prepare.drop_edge_pixels,
                config.prepare.trim_past_outline,
            ) {
                (true, _) => ", edge pixels dropped",
                (_, true) => ", past the outline trimmed",
                _ => "",
            };
            println!(
                "RATE {name} with {artefact:?}{edges}: {} of {SEEDS} recovered",
                SEEDS - failures.len() as u32
            );
        }
    }
}
