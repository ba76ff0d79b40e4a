//! The engine's contract on the built-in scene (a can: axial + orthogonal plane): type
//! restriction, a full output reported (never silent), the dense completion an output with room
//! gets, the best result so far while searching, scoring any hypothesis, and a restart in the
//! middle of a search.

use sfs_testkit::synth::{
    self, BUILTIN_INTRINSICS as K, builtin_scene, render, transform_symmetry,
};
use shape_from_symmetry::{
    CompletedPoint, Config, DefaultEngine, Engine, Report, Scene, Status, Symmetry, SymmetryType,
    TypeSet,
};

struct Builtin {
    depth: Vec<u16>,
    mask: Vec<u8>,
    rendered: synth::Rendered,
}

fn builtin() -> Builtin {
    let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
    let rendered = render(&builtin_scene(), &K, &mut depth, &mut mask).expect("renders");
    Builtin {
        depth,
        mask,
        rendered,
    }
}

impl Builtin {
    fn scene(&self) -> Scene<'_> {
        Scene {
            depth: &self.depth,
            depth_scale: 0.001,
            intrinsics: K,
            table: Some(self.rendered.table),
            mask: Some(&self.mask),
            target: None,
        }
    }
}

fn search(scene: Scene<'_>, config: Config, output: usize) -> (Report, usize) {
    search_with::<4096>(scene, config, output)
}

/// Search with a default engine but `VOXELS` voxel slots.
fn search_with<const VOXELS: usize>(
    scene: Scene<'_>,
    config: Config,
    output: usize,
) -> (Report, usize) {
    let mut out = vec![CompletedPoint::ZERO; output];
    let mut engine = Box::new(Engine::<'_, 1024, VOXELS, 8192>::new(config));
    engine.start(scene, &mut out).expect("valid scene");
    while engine.poll(10_000).expect("search runs") != Status::Done {}
    (engine.report().clone(), engine.points().len())
}

fn strongest(report: &Report) -> Option<SymmetryType> {
    report.symmetries.first().map(|f| f.symmetry.kind())
}

#[test]
fn restricted_searches_report_only_the_types_asked_for() {
    let b = builtin();
    let only = |t: &[SymmetryType]| Config::DEFAULT.with_types(TypeSet::of(t));
    let (all, _) = search(b.scene(), Config::DEFAULT, 8192);
    assert_eq!(strongest(&all), Some(SymmetryType::AxialPlane));
    let (plane, _) = search(b.scene(), only(&[SymmetryType::PlaneReflection]), 8192);
    assert_eq!(strongest(&plane), Some(SymmetryType::PlaneReflection));
    let (axial, _) = search(b.scene(), only(&[SymmetryType::Axial]), 8192);
    assert_eq!(
        strongest(&axial),
        Some(SymmetryType::Axial),
        "planes are searched on the way but not reported"
    );
    let (sphere, _) = search(b.scene(), only(&[SymmetryType::Spherical]), 8192);
    assert_eq!(strongest(&sphere), None, "a can is no sphere");
}

#[test]
fn a_full_output_is_reported_not_silent() {
    let b = builtin();
    // With twice the default voxel slots, nothing is left out of the built-in can's completion.
    let (full, written) = search_with::<8192>(b.scene(), Config::DEFAULT, 8192);
    assert_eq!(full.points_dropped, 0);
    assert_eq!(written as u32, full.points_visible + full.points_generated);
    let (small, written_small) = search_with::<8192>(b.scene(), Config::DEFAULT, 300);
    assert_eq!(written_small, 300);
    assert_eq!(small.points_visible + small.points_generated, 300);
    assert_eq!(
        small.points_dropped,
        full.points_visible + full.points_generated - 300,
        "every point that did not fit is counted"
    );
    // The default table fills on it (axial + plane predicts the whole surface): what does not
    // fit is counted.
    let (default, _) = search(b.scene(), Config::DEFAULT, 8192);
    assert!(default.points_dropped > 0);
    assert!(default.points_generated < full.points_generated);
    assert!(
        default.points_generated + default.points_dropped >= full.points_generated,
        "every generated point the table could not hold is counted"
    );
    assert_eq!(
        small.symmetries, full.symmetries,
        "the search does not depend on the output size"
    );
}

#[test]
fn an_output_with_room_gets_the_dense_completion_of_object_pixels() {
    // The can's sampled completion (about 3 900 points with 8192 voxel slots) fits 16 times
    // over: the dense pass writes each object pixel of every sample's cell, and their images.
    let b = builtin();
    let mut out = vec![CompletedPoint::ZERO; 65_536];
    let mut engine = Box::new(Engine::<'_, 1024, 8192, 8192>::new(Config::DEFAULT));
    engine.start(b.scene(), &mut out).expect("valid scene");
    while engine.poll(10_000).expect("search runs") != Status::Done {}
    let report = engine.report();
    assert_eq!(report.points_dropped, 0);
    assert!(
        report.points_visible > 2 * report.sampled_points,
        "{} visible points of {} sampled",
        report.points_visible,
        report.sampled_points
    );
    let pixel = |p: &CompletedPoint| {
        let [x, y, z] = p.position;
        let (u, v) = ((K.fx * x / z + K.cx).round(), (K.fy * y / z + K.cy).round());
        v as usize * K.width as usize + u as usize
    };
    let points = engine.points();
    let (visible, generated) = points.split_at(report.points_visible as usize);
    assert!(
        visible.iter().all(|p| b.mask[pixel(p)] != 0),
        "every visible point is an object pixel"
    );
    // Generated points lie where the camera could not see: behind the observed depth (10 mm
    // beyond it would be free space; the completion allows a σ, 3 mm, against the nearest
    // reading of a few pixels' block).
    let free = generated
        .iter()
        .filter(|p| {
            let raw = b.depth[pixel(p)];
            raw != 0 && p.position[2] < raw as f32 * 0.001 - 0.010
        })
        .count();
    assert!(
        free * 200 <= generated.len(),
        "{free} of {} generated points in free space",
        generated.len()
    );
}

#[test]
fn the_best_result_so_far_shows_before_the_end() {
    let b = builtin();
    let mut out = vec![CompletedPoint::ZERO; 8192];
    let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
    engine.start(b.scene(), &mut out).unwrap();
    let mut seen_early = None;
    while engine.poll(1000).unwrap() != Status::Done {
        if seen_early.is_none() {
            seen_early = strongest(engine.report());
        }
    }
    assert_eq!(
        seen_early,
        Some(SymmetryType::PlaneReflection),
        "the plane is found first (Table 1)"
    );
    assert_eq!(strongest(engine.report()), Some(SymmetryType::AxialPlane));
}

#[test]
fn true_symmetries_score_below_the_threshold_and_false_ones_above() {
    let b = builtin();
    let mut out = vec![CompletedPoint::ZERO; 8192];
    let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
    engine.start(b.scene(), &mut out).unwrap();
    assert_eq!(
        engine.score(&Symmetry::PointReflection([0.0, 0.0, 0.5])),
        None,
        "not prepared yet"
    );
    while engine.poll(u32::MAX).unwrap() != Status::Done {}
    let truth = transform_symmetry(
        &synth::object("can").unwrap().symmetry.unwrap(),
        &b.rendered.object_to_camera,
    );
    let accept = Config::DEFAULT.model.accept;
    assert!(engine.score(&truth).unwrap() < accept);
    let Symmetry::AxialPlane(axis, plane) = truth else {
        panic!("the can is axial + plane")
    };
    // The mirror plane moved 3 cm along the axis is no symmetry.
    let shifted = shape_from_symmetry::Plane {
        offset: plane.offset + 0.03,
        ..plane
    };
    assert!(engine.score(&Symmetry::PlaneReflection(shifted)).unwrap() > accept);
    // Nor is the axis tilted by 30 degrees.
    let tilted = shape_from_symmetry::math::rotation(
        shape_from_symmetry::math::orthonormal_basis(axis.d()).0,
        0.52,
    ) * axis.d();
    let wrong = Symmetry::Axial(shape_from_symmetry::Axis {
        direction: tilted.to_array(),
        ..axis
    });
    assert!(engine.score(&wrong).unwrap() > accept);
}

#[test]
fn a_restart_mid_search_on_a_smaller_object_runs_to_the_end() {
    let b = builtin();
    // The same view with the lower half of the object masked out: fewer sampled points, so a
    // smaller domain than the one an evaluation of the first start indexes.
    let mut half = b.mask.clone();
    let rows = half.len() / K.width as usize;
    half[(rows / 2) * K.width as usize..].fill(0);
    let small = Scene {
        mask: Some(&half),
        ..b.scene()
    };
    let (mut out, mut out_small) = (
        vec![CompletedPoint::ZERO; 8192],
        vec![CompletedPoint::ZERO; 8192],
    );
    let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
    engine.start(b.scene(), &mut out).unwrap();
    // Into the search, with an evaluation under way (one-unit polls stop inside it).
    while engine.stage() != shape_from_symmetry::Stage::Searching {
        engine.poll(1000).unwrap();
    }
    for _ in 0..5 {
        engine.poll(1).unwrap();
    }
    let whole = engine.report().sampled_points;
    engine.start(small, &mut out_small).unwrap();
    while engine.poll(1000).unwrap() != Status::Done {}
    assert!(engine.report().sampled_points < whole);
    let (fresh, _) = search(small, Config::DEFAULT, 8192);
    assert_eq!(
        engine.report().symmetries,
        fresh.symmetries,
        "nothing of the first run leaks into the second"
    );
}
