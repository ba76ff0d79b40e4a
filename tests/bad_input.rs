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
fn run(engine: &mut SmallEngine<'_>, limit: u32) -> Result<Status, Error> {
    for _ in 0..limit {
        match engine.poll(500)? {
            Status::Done => return Ok(Status::Done),
            Status::Working => {}
        }
    }
    Ok(Status::Working)
}

fn start(
    depth: &[u16],
    mask: Option<&[u8]>,
    table: Option<Plane>,
    k: Intrinsics,
) -> Result<Status, Error> {
    let mut engine = SmallEngine::new(Config::DEFAULT);
    let mut out = [CompletedPoint::ZERO; 64];
    let scene = Scene {
        depth,
        depth_scale: 0.001,
        intrinsics: k,
        table,
        mask,
    };
    engine.start(scene, &mut out)?;
    run(&mut engine, 10_000)
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
    let scene = Scene {
        depth_scale: f32::NAN,
        ..Scene::new(&depth, 0.001, K)
    };
    assert_eq!(engine.start(scene, &mut []), Err(Error::InvalidDepthScale));
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
    let mut config = Config::DEFAULT;
    config.model.sigma_min = f32::NAN;
    let mut engine = SmallEngine::new(config);
    assert_eq!(
        engine.start(Scene::new(&depth, 0.001, K), &mut []),
        Err(Error::InvalidConfig)
    );
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
    assert_eq!(engine.set_config(bad), Err(Error::InvalidConfig));
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
