//! Malformed and degenerate input gets a typed error, never a panic, and the engine stays usable.

use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{
    CompletedPoint, Config, Engine, Error, Intrinsics, Plane, Scene, Status, SymmetryType, TypeSet,
};

const K: Intrinsics = Intrinsics {
    width: 64,
    height: 48,
    fx: 60.0,
    fy: 60.0,
    cx: 31.5,
    cy: 23.5,
};

type SmallEngine<'a> = Engine<'a, 256, 1024, 1024>;

/// Polls to the end (at most `limit` polls) and returns the outcome.
fn run<const P: usize, const V: usize, const C: usize>(
    engine: &mut Engine<'_, P, V, C>,
    limit: u32,
) -> Result<Status, Error> {
    for _ in 0..limit {
        match engine.poll(500)? {
            Status::Done => return Ok(Status::Done),
            Status::Working => {}
        }
    }
    Ok(Status::Working)
}

/// Starts `engine` on the scene (depth in millimetres) and polls it to the end.
fn search<'a, const P: usize, const V: usize, const C: usize>(
    engine: &mut Engine<'a, P, V, C>,
    out: &'a mut [CompletedPoint],
    depth: &'a [u16],
    mask: Option<&'a [u8]>,
    table: Option<Plane>,
    k: Intrinsics,
) -> Result<Status, Error> {
    let scene = Scene {
        depth,
        depth_scale: 0.001,
        intrinsics: k,
        table,
        mask,
        target: None,
    };
    engine.start(scene, out)?;
    run(engine, 100_000)
}

/// A whole search with a small engine.
fn start(
    depth: &[u16],
    mask: Option<&[u8]>,
    table: Option<Plane>,
    k: Intrinsics,
) -> Result<Status, Error> {
    let mut out = [CompletedPoint::ZERO; 64];
    let mut engine = SmallEngine::new(Config::DEFAULT);
    search(&mut engine, &mut out, depth, mask, table, k)
}

/// A flat table 0.8 m away, seen straight on.
fn wall() -> Vec<u16> {
    vec![800; K.pixel_count()]
}

#[test]
fn wrong_sizes_are_rejected_before_any_work() {
    let depth = wall();
    assert_eq!(
        start(&depth[1..], None, None, K),
        Err(Error::DepthSizeMismatch {
            expected: 3072,
            actual: 3071
        })
    );
    let mask = vec![1u8; 10];
    assert_eq!(
        start(&depth, Some(&mask), None, K),
        Err(Error::MaskSizeMismatch {
            expected: 3072,
            actual: 10
        })
    );
    assert_eq!(
        start(&[], None, None, Intrinsics { width: 0, ..K }),
        Err(Error::EmptyImage)
    );
}

#[test]
fn zero_or_nan_intrinsics_are_rejected() {
    let depth = wall();
    for k in [
        Intrinsics { fx: 0.0, ..K },
        Intrinsics { fy: f32::NAN, ..K },
        Intrinsics {
            cx: f32::INFINITY,
            ..K
        },
    ] {
        assert_eq!(start(&depth, None, None, k), Err(Error::InvalidIntrinsics));
    }
}

#[test]
fn bad_scale_and_table_are_rejected() {
    let depth = wall();
    let mut engine = SmallEngine::new(Config::DEFAULT);
    // NaN, non-positive, and so large that the coordinates would overflow (a fuzz finding:
    // 6.9e17 m per unit made the object's radius infinite and the search never ended).
    for depth_scale in [f32::NAN, 0.0, -0.001, 1.01, 6.9e17, f32::MAX, f32::INFINITY] {
        let scene = Scene {
            depth_scale,
            ..Scene::new(&depth, 0.001, K)
        };
        assert_eq!(
            engine.start(scene, &mut []),
            Err(Error::InvalidDepthScale),
            "{depth_scale}"
        );
    }
    let table = Plane {
        normal: [0.0, 0.0, 2.0],
        offset: 1.0,
    };
    let scene = Scene {
        table: Some(table),
        ..Scene::new(&depth, 0.001, K)
    };
    assert_eq!(engine.start(scene, &mut []), Err(Error::InvalidTablePlane));
}

#[test]
fn all_zero_depth_is_no_valid_depth() {
    let depth = vec![0u16; K.pixel_count()];
    assert_eq!(start(&depth, None, None, K), Err(Error::NoValidDepth));
}

#[test]
fn a_bare_table_leaves_no_object() {
    // The wall is the support plane; nothing stands on it.
    assert_eq!(start(&wall(), None, None, K), Err(Error::NoObject));
}

#[test]
fn a_mask_that_selects_nothing_leaves_no_object() {
    let mask = vec![0u8; K.pixel_count()];
    let table = Plane::new(Vec3::new(0.0, 0.0, -1.0), -0.8);
    assert_eq!(start(&wall(), Some(&mask), table, K), Err(Error::NoObject));
}

#[test]
fn a_single_valid_pixel_is_too_few_points() {
    let mut depth = vec![0u16; K.pixel_count()];
    depth[100] = 500;
    let mut mask = vec![0u8; K.pixel_count()];
    mask[100] = 255;
    let table = Plane::new(Vec3::new(0.0, -1.0, 0.0), -0.2);
    assert_eq!(
        start(&depth, Some(&mask), table, K),
        Err(Error::TooFewPoints {
            found: 1,
            needed: 24
        })
    );
}

#[test]
fn poll_before_start_and_after_failure() {
    let mut engine = SmallEngine::new(Config::DEFAULT);
    assert_eq!(engine.poll(10), Err(Error::NotStarted));
    let depth = vec![0u16; K.pixel_count()];
    let mut out = [CompletedPoint::ZERO; 4];
    engine
        .start(Scene::new(&depth, 0.001, K), &mut out)
        .unwrap();
    assert_eq!(run(&mut engine, 1000), Err(Error::NoValidDepth));
    assert_eq!(
        engine.poll(10),
        Err(Error::NoValidDepth),
        "a failed engine keeps its error"
    );
}

#[test]
fn an_invalid_config_is_rejected() {
    let depth = wall();
    let mut nan_sigma = Config::DEFAULT;
    nan_sigma.model.sigma_min = f32::NAN;
    let mut share_over_one = Config::DEFAULT;
    share_over_one.domains.min_share = 1.5;
    let mut negative_noise = Config::DEFAULT;
    negative_noise.sensor.noise_growth = -0.001;
    for (config, field) in [
        (nan_sigma, "model.sigma_min"),
        (share_over_one, "domains.min_share"),
        (negative_noise, "sensor.noise_growth"),
    ] {
        let mut engine = SmallEngine::new(config);
        assert_eq!(
            engine.start(Scene::new(&depth, 0.001, K), &mut []),
            Err(Error::InvalidConfig { field })
        );
    }
}

#[test]
fn set_config_checks_and_discards_the_search() {
    let depth = wall();
    let mut out = [CompletedPoint::ZERO; 4];
    let mut engine = SmallEngine::new(Config::DEFAULT);
    engine
        .start(Scene::new(&depth, 0.001, K), &mut out)
        .unwrap();
    assert_eq!(engine.poll(10), Ok(Status::Working));
    let mut bad = Config::DEFAULT;
    bad.model.sigma_min = f32::NAN;
    let field = "model.sigma_min";
    assert_eq!(engine.set_config(bad), Err(Error::InvalidConfig { field }));
    assert_eq!(
        engine.config(),
        &Config::DEFAULT,
        "nothing changes on error"
    );
    assert_eq!(engine.poll(10), Ok(Status::Working), "the search goes on");
    let axial = Config::DEFAULT.with_types(TypeSet::of(&[SymmetryType::Axial]));
    assert_eq!(engine.set_config(axial), Ok(()));
    assert_eq!(engine.config(), &axial);
    assert_eq!(
        engine.poll(10),
        Err(Error::NotStarted),
        "the search is discarded"
    );
    assert_eq!(engine.report().polls, 0);
}

/// The built-in can rendered with `k` (its depth, mask and table plane).
fn rendered(k: Intrinsics) -> (Vec<u16>, Vec<u8>, Plane) {
    use sfs_testkit::synth::{builtin_scene, render};
    let (mut depth, mut mask) = (vec![0u16; k.pixel_count()], vec![0u8; k.pixel_count()]);
    let r = render(&builtin_scene(), &k, &mut depth, &mut mask).expect("renders");
    (depth, mask, r.table)
}

/// A whole search with `DefaultEngine` (room for the built-in 320x240 scene).
fn outcome(
    depth: &[u16],
    mask: Option<&[u8]>,
    table: Option<Plane>,
    k: Intrinsics,
) -> Result<Status, Error> {
    let mut out = vec![CompletedPoint::ZERO; 4096];
    let mut engine = Box::new(shape_from_symmetry::DefaultEngine::new(Config::DEFAULT));
    search(&mut engine, &mut out, depth, mask, table, k)
}

#[test]
fn extreme_near_and_far_readings_are_searched_or_rejected() {
    // A checkerboard of 1 mm and 65.535 m readings: no surface anywhere.
    let depth: Vec<u16> = (0..K.pixel_count())
        .map(|i| if (i + i / 64) % 2 == 0 { 1 } else { u16::MAX })
        .collect();
    let result = outcome(&depth, None, None, K);
    assert!(
        matches!(
            result,
            Ok(Status::Done)
                | Err(Error::NoSupportPlane | Error::NoObject | Error::TooFewPoints { .. })
        ),
        "{result:?}"
    );
    // The same with every pixel in the mask.
    let mask = vec![255u8; K.pixel_count()];
    let table = Plane::new(Vec3::new(0.0, -1.0, 0.0), -0.5);
    let result = outcome(&depth, Some(&mask), table, K);
    assert!(
        matches!(
            result,
            Ok(Status::Done) | Err(Error::NoObject | Error::TooFewPoints { .. })
        ),
        "{result:?}"
    );
}

#[test]
fn huge_intrinsics_are_searched_or_rejected() {
    let k = sfs_testkit::synth::BUILTIN_INTRINSICS;
    let (depth, mask, table) = rendered(k);
    for huge in [
        Intrinsics {
            fx: 9.0e6,
            fy: 9.0e6,
            ..k
        },
        Intrinsics {
            cx: 9.0e6,
            cy: -9.0e6,
            ..k
        },
    ] {
        let result = outcome(&depth, Some(&mask), Some(table), huge);
        assert!(
            matches!(
                result,
                Ok(Status::Done) | Err(Error::NoObject | Error::TooFewPoints { .. })
            ),
            "{result:?}"
        );
    }
    // Beyond the documented range they are rejected before any work.
    let result = outcome(
        &depth,
        Some(&mask),
        Some(table),
        Intrinsics { fx: 1.0e8, ..k },
    );
    assert_eq!(result, Err(Error::InvalidIntrinsics));
}

#[test]
fn an_object_cut_by_the_image_border_is_still_searched() {
    // Shift the principal point so the can straddles the left border of the image.
    let k = sfs_testkit::synth::BUILTIN_INTRINSICS;
    let cut = Intrinsics { cx: 0.0, ..k };
    let (depth, mask, table) = rendered(cut);
    let columns_at_border = (0..k.height as usize)
        .filter(|v| mask[v * k.width as usize] != 0)
        .count();
    assert!(columns_at_border > 5, "the object touches the border");
    assert_eq!(
        outcome(&depth, Some(&mask), Some(table), cut),
        Ok(Status::Done)
    );
    assert_eq!(
        outcome(&depth, None, None, cut),
        Ok(Status::Done),
        "segmented and fitted"
    );
}

#[test]
fn a_mask_that_selects_everything_is_searched() {
    let k = sfs_testkit::synth::BUILTIN_INTRINSICS;
    let (depth, _, table) = rendered(k);
    let everything = vec![255u8; k.pixel_count()];
    // The table plane trims the table's readings from the mask: the can is what is left.
    assert_eq!(
        outcome(&depth, Some(&everything), Some(table), k),
        Ok(Status::Done)
    );
}
