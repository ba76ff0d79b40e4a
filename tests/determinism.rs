//! The result is bit-identical however the work is sliced into polls, no poll does more than its
//! budget, and every poll makes progress.

use sfs_testkit::synth::{BUILTIN_INTRINSICS, Noise, View, builtin_scene, object, render};
use shape_from_symmetry::{CompletedPoint, Config, Engine, Plane, Report, Scene, Status};

const K: shape_from_symmetry::Intrinsics = BUILTIN_INTRINSICS;

fn builtin() -> (Vec<u16>, Vec<u8>, Plane) {
    let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
    let rendered =
        render(&builtin_scene(), &K, &mut depth, &mut mask).expect("the built-in scene renders");
    (depth, mask, rendered.table)
}

fn with_mask_and_table<'a>(depth: &'a [u16], mask: &'a [u8], table: Plane) -> Scene<'a> {
    Scene {
        depth,
        depth_scale: 0.001,
        intrinsics: K,
        table: Some(table),
        mask: Some(mask),
        target: None,
    }
}

/// Runs the search with the budget of each poll drawn by `budget(poll_index)`; checks the budget
/// and progress contract on every poll. Returns the report and the completed points.
fn run(scene: Scene<'_>, mut budget: impl FnMut(u32) -> u32) -> (Report, Vec<CompletedPoint>) {
    let mut out = vec![CompletedPoint::ZERO; 8192];
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(Config::DEFAULT));
    engine.start(scene, &mut out).expect("valid scene");
    let mut poll = 0;
    loop {
        let b = budget(poll);
        let before = engine.report().work_units;
        let status = engine.poll(b).expect("the search runs");
        let used = engine.report().work_units - before;
        assert!(
            used <= u64::from(b.max(1)),
            "poll {poll} used {used} units of a budget of {b}"
        );
        assert!(
            used >= 1 || status == Status::Done,
            "poll {poll} made no progress"
        );
        poll += 1;
        if status == Status::Done {
            break;
        }
    }
    let report = engine.report().clone();
    let points = engine.points().to_vec();
    (report, points)
}

/// Everything but the poll count, as bits.
fn fingerprint(report: &Report, points: &[CompletedPoint]) -> Vec<u32> {
    let mut bits = vec![
        report.points_visible,
        report.points_generated,
        report.points_dropped,
    ];
    bits.push(report.work_units as u32);
    for f in report.symmetries.iter().chain(&report.runner_up) {
        bits.push(f.score.to_bits());
        bits.push(f.domain_points);
        bits.extend(
            f.symmetry
                .planes()
                .iter()
                .flat_map(|p| p.normal.into_iter().chain([p.offset]))
                .map(f32::to_bits),
        );
        if let Some(a) = f.symmetry.axis() {
            bits.extend(a.direction.into_iter().chain(a.point).map(f32::to_bits));
        }
        bits.extend(f.symmetry.center().into_iter().flatten().map(f32::to_bits));
    }
    for p in points {
        bits.extend(p.position.map(f32::to_bits));
        bits.extend([
            p.plausibility.to_bits(),
            p.provenance as u32,
            p.symmetry as u32,
        ]);
    }
    bits
}

/// How much each poll may do, by poll index.
type Slicing = Box<dyn FnMut(u32) -> u32>;

/// xorshift32: reproducible budgets.
fn budgets(seed: u32, max: u32) -> impl FnMut(u32) -> u32 {
    let mut state = seed;
    move |_| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state % max + 1
    }
}

#[test]
fn any_slicing_gives_the_same_bits() {
    let (depth, mask, table) = builtin();
    let scene = with_mask_and_table(&depth, &mask, table);
    let (report, points) = run(scene, |_| u32::MAX);
    assert!(
        !report.symmetries.is_empty(),
        "the built-in can is symmetric"
    );
    assert!(report.points_generated > 0);
    let reference = fingerprint(&report, &points);
    let slicings: [(&str, Slicing); 6] = [
        ("1000 per poll", Box::new(|_| 1000)),
        ("7 per poll", Box::new(|_| 7)),
        ("random up to 50", Box::new(budgets(1, 50))),
        ("random up to 5000", Box::new(budgets(2, 5000))),
        ("random up to 100000", Box::new(budgets(3, 100_000))),
        (
            "alternating 1 and 333",
            Box::new(|i| if i % 2 == 0 { 1 } else { 333 }),
        ),
    ];
    for (name, budget) in slicings {
        let (r, p) = run(scene, budget);
        assert_eq!(fingerprint(&r, &p), reference, "{name}");
    }
}

#[test]
fn budget_of_one_and_zero_still_progress() {
    let (depth, mask, table) = builtin();
    let scene = with_mask_and_table(&depth, &mask, table);
    let (reference, ref_points) = run(scene, |_| u32::MAX);
    let (ones, points) = run(scene, |i| i % 2); // 0 counts as 1
    assert_eq!(
        fingerprint(&ones, &points),
        fingerprint(&reference, &ref_points)
    );
    assert_eq!(u64::from(ones.polls), ones.work_units, "one unit per poll");
}

#[test]
fn segmentation_path_is_slicing_invariant_too() {
    let (depth, _, _) = builtin();
    let scene = Scene::new(&depth, 0.001, K);
    let (report, points) = run(scene, |_| u32::MAX);
    assert!(!report.symmetries.is_empty());
    let (r, p) = run(scene, budgets(9, 700));
    assert_eq!(fingerprint(&r, &p), fingerprint(&report, &points));
}

#[test]
fn a_floor_the_mask_encloses_slices_like_any_work() {
    // Looking down into a bowl: the floor readings within `min_height` of the table are
    // probed against the mask (a dearer pixel, whose cost may run past a poll's budget).
    let object = object("bowl").expect("a ready-made object");
    let view = View {
        distance: 0.5,
        elevation_deg: 75.0,
        azimuth_deg: 30.0,
        roll_deg: 0.0,
    };
    let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
    let rendered = render(
        &object.scene(view, Noise::kinect(7)),
        &K,
        &mut depth,
        &mut mask,
    )
    .expect("the bowl renders");
    let scene = with_mask_and_table(&depth, &mask, rendered.table);
    let (report, points) = run(scene, |_| u32::MAX);
    let reference = fingerprint(&report, &points);
    let slicings: [(&str, Slicing); 4] = [
        ("1 per poll", Box::new(|_| 1)),
        ("7 per poll", Box::new(|_| 7)),
        ("random up to 50", Box::new(budgets(4, 50))),
        ("random up to 5000", Box::new(budgets(5, 5000))),
    ];
    for (name, budget) in slicings {
        let (r, p) = run(scene, budget);
        assert_eq!(fingerprint(&r, &p), reference, "{name}");
    }
}
