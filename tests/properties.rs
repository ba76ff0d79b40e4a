//! Property tests (proptest): random slicings of the work, capacity exhaustion, a tiny engine,
//! and garbage depth images. Small images (160x120, the built-in camera at half resolution) keep
//! the whole file to a few seconds of `cargo test`.

use std::sync::OnceLock;

use proptest::prelude::*;
use sfs_testkit::synth::{self, Noise, OBJECTS, View};
use shape_from_symmetry::{
    CompletedPoint, Config, DefaultEngine, Engine, Error, Intrinsics, Plane, Report, Scene, Status,
};

/// The built-in camera at half resolution.
const K: Intrinsics = Intrinsics {
    width: 160,
    height: 120,
    fx: 142.5,
    fy: 142.5,
    cx: 79.5,
    cy: 59.5,
};

/// Most work units one whole run may take on a scene of at most 160x120 pixels with the
/// `DefaultEngine`. Measured over the synthetic objects (`work_units_of_every_object_are_bounded`
/// prints the figures): at most about 1.0 M units. Where it comes from: preparation is linear
/// in the pixels (19 200 here, 8 per unit per pass); the search scores at most `POINTS` (1 024)
/// sampled points per hypothesis, with the number of hypotheses fixed by the grid sizes of
/// `Config::DEFAULT` (not by the image); the completion tests each sampled point once per map of
/// the found symmetry (at most `POINTS` x the maps of one `Sampling`) and is capped by the output
/// capacity. None of these grows with the image beyond preparation, so 2 M leaves room for noise
/// and views and still catches a runaway loop.
const WORK_BOUND: u64 = 2_000_000;

/// An ample output for 160x120 (the search samples at most 1 024 points).
const AMPLE: usize = 8192;

struct Rendered {
    name: &'static str,
    depth: Vec<u16>,
    mask: Vec<u8>,
    table: Plane,
}

fn render(object: usize, view: View, noise: Noise) -> Rendered {
    let o = &OBJECTS[object];
    let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
    let r = synth::render(&o.scene(view, noise), &K, &mut depth, &mut mask)
        .expect("the synthetic scenes render");
    Rendered {
        name: o.name,
        depth,
        mask,
        table: r.table,
    }
}

/// Every object from the built-in view, with Kinect noise: rendered once.
fn scenes() -> &'static [Rendered] {
    static SCENES: OnceLock<Vec<Rendered>> = OnceLock::new();
    SCENES.get_or_init(|| {
        (0..OBJECTS.len())
            .map(|i| render(i, synth::BUILTIN_VIEW, Noise::kinect(1)))
            .collect()
    })
}

fn scene(r: &Rendered, table: bool, mask: bool) -> Scene<'_> {
    Scene {
        depth: &r.depth,
        depth_scale: 0.001,
        intrinsics: K,
        table: table.then_some(r.table),
        mask: mask.then_some(&r.mask[..]),
        target: None,
    }
}

/// Polls with `budgets` (cycled) until done or an error, checking the budget contract and the
/// work bound on every poll.
fn run<const P: usize, const V: usize, const C: usize>(
    engine: &mut Engine<'_, P, V, C>,
    budgets: &[u32],
) -> Result<(), Error> {
    let mut polls = 0u64;
    loop {
        let b = budgets[(polls % budgets.len() as u64) as usize];
        let before = engine.report().work_units;
        let status = engine.poll(b)?;
        let used = engine.report().work_units - before;
        assert!(used <= u64::from(b.max(1)), "poll({b}) did {used} units");
        assert!(used >= 1 || status == Status::Done, "no progress");
        assert!(
            engine.report().work_units <= WORK_BOUND,
            "{} units, bound {WORK_BOUND}",
            engine.report().work_units
        );
        polls += 1;
        if status == Status::Done {
            return Ok(());
        }
    }
}

/// Everything in the report but the poll count, and every output point, as bits.
fn fingerprint(report: &Report, points: &[CompletedPoint]) -> Vec<u32> {
    let mut bits = vec![
        report.points_visible,
        report.points_generated,
        report.points_dropped,
        report.object_pixels,
        report.sampled_points,
        report.work_units as u32,
        (report.work_units >> 32) as u32,
        report.symmetries.len() as u32,
    ];
    for f in report.symmetries.iter().chain(&report.runner_up) {
        bits.extend(format!("{:?}", f.symmetry).bytes().map(u32::from));
        bits.extend([f.score.to_bits(), f.confidence.to_bits(), f.domain_points]);
    }
    for p in points {
        bits.extend(p.position.map(f32::to_bits));
        bits.extend([
            p.plausibility.to_bits(),
            p.provenance as u32,
            u32::from(p.symmetry),
        ]);
    }
    bits
}

/// A run's outcome, fingerprint and report.
type Outcome = (Result<(), Error>, Vec<u32>, Report);

/// The reference result of object `i` (table and mask given), one poll of a huge budget.
fn reference(i: usize) -> &'static Outcome {
    static REFS: OnceLock<Vec<Outcome>> = OnceLock::new();
    &REFS.get_or_init(|| {
        scenes()
            .iter()
            .map(|r| {
                let mut out = vec![CompletedPoint::ZERO; AMPLE];
                let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
                engine.start(scene(r, true, true), &mut out).unwrap();
                let result = run(&mut engine, &[u32::MAX]);
                let report = engine.report().clone();
                (result, fingerprint(&report, engine.points()), report)
            })
            .collect()
    })[i]
}

#[test]
fn work_units_of_every_object_are_bounded() {
    let mut max = 0;
    for (i, r) in scenes().iter().enumerate() {
        let (result, _, report) = reference(i);
        println!(
            "{:<24} {:?} {:>8} work units, {} symmetries",
            r.name,
            result,
            report.work_units,
            report.symmetries.len()
        );
        assert_eq!(*result, Ok(()), "{}", r.name);
        max = max.max(report.work_units);
    }
    println!("max {max} work units (bound {WORK_BOUND})");
    assert!(max <= WORK_BOUND);
}

/// With a small voxel table the completion fills it, and its tests near the load limit cost more
/// than one unit (their long probe runs are charged): polls of 1 or 7 units pay such a test off
/// over several polls, never exceeding their budget (`run` checks), and the result, work units
/// included, is the one of a single poll.
#[test]
fn completion_tests_charged_by_probes_slice_like_any_work() {
    let mut filled = 0;
    for r in scenes() {
        let outcome = |budgets: &[u32]| {
            let mut out = vec![CompletedPoint::ZERO; AMPLE];
            let mut engine = Box::new(Engine::<'_, 1024, 1024, 8192>::new(Config::DEFAULT));
            engine.start(scene(r, true, true), &mut out).unwrap();
            run(&mut engine, budgets).unwrap();
            (
                fingerprint(engine.report(), engine.points()),
                engine.report().points_dropped,
            )
        };
        let (whole, dropped) = outcome(&[u32::MAX]);
        filled += usize::from(dropped > 0);
        for budgets in [&[1][..], &[7]] {
            assert!(
                outcome(budgets).0 == whole,
                "{} sliced by {budgets:?}",
                r.name
            );
        }
    }
    assert!(
        filled > 0,
        "no completion reached the load limit: the test tests nothing"
    );
}

/// Budgets for one run: mostly 1 and other tiny values, some large.
fn budgets() -> impl Strategy<Value = Vec<u32>> {
    prop::collection::vec(
        prop_oneof![
            3 => Just(1u32),
            2 => 0u32..=16,
            2 => 1u32..=1000,
            1 => Just(140u32),
            1 => 1000u32..=200_000,
        ],
        1..24,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// The result is bit-identical however the work is sliced (budgets down to 1, and 0).
    #[test]
    fn slicing_does_not_change_the_result(object in 0..OBJECTS.len(), budgets in budgets()) {
        let (expected, bits, _) = reference(object);
        let mut out = vec![CompletedPoint::ZERO; AMPLE];
        let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
        engine.start(scene(&scenes()[object], true, true), &mut out).unwrap();
        let result = run(&mut engine, &budgets);
        prop_assert_eq!(&result, expected);
        prop_assert_eq!(&fingerprint(engine.report(), engine.points()), bits);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Any view of any object, with or without table and mask, finishes within the bound with
    /// a result or a content error.
    #[test]
    fn any_view_finishes_within_the_bound(
        object in 0..OBJECTS.len(),
        distance in 0.3f32..0.9,
        elevation in 10.0f32..85.0,
        azimuth in 0.0f32..360.0,
        seed in any::<u32>(),
        table in any::<bool>(),
        mask in any::<bool>(),
    ) {
        let view = View { distance, elevation_deg: elevation, azimuth_deg: azimuth, roll_deg: 0.0 };
        let r = render(object, view, Noise::kinect(seed));
        let mut out = vec![CompletedPoint::ZERO; AMPLE];
        let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
        engine.start(scene(&r, table, mask), &mut out).unwrap();
        match run(&mut engine, &[5_000]) {
            Ok(()) => prop_assert!(engine.report().work_units <= WORK_BOUND),
            Err(e) => prop_assert!(matches!(
                e,
                Error::NoObject | Error::NoSupportPlane | Error::TooFewPoints { .. }
            ), "{:?}", e),
        }
    }

    /// A tiny output: `points_dropped` is exactly what did not fit, and what fits is the start
    /// of the sampled completion (what an output with room for exactly it holds); an ample
    /// output holds at least as many points (the dense pass).
    #[test]
    fn a_tiny_output_counts_what_it_drops(object in 0..OBJECTS.len(), capacity in 0usize..64) {
        let (_, _, full) = reference(object);
        let r = &scenes()[object];
        let complete = |output: &mut [CompletedPoint]| {
            let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
            engine.start(scene(r, true, true), output).unwrap();
            run(&mut engine, &[u32::MAX]).unwrap();
            (engine.report().clone(), engine.points().to_vec())
        };
        let total = |r: &Report| {
            u64::from(r.points_visible) + u64::from(r.points_generated) + u64::from(r.points_dropped)
        };
        let (s, tiny) = complete(&mut vec![CompletedPoint::ZERO; capacity]);
        let sampled = total(&s) as usize;
        let (e, exact) = complete(&mut vec![CompletedPoint::ZERO; sampled]);
        let written = (s.points_visible + s.points_generated) as usize;
        prop_assert_eq!(written, tiny.len());
        prop_assert_eq!(written, sampled.min(capacity));
        prop_assert_eq!(e.points_dropped, 0);
        prop_assert_eq!(exact.len(), sampled, "an output of exactly the sampled pass holds it");
        prop_assert_eq!(&tiny[..], &exact[..written]);
        let full_written = (full.points_visible + full.points_generated) as usize;
        prop_assert!(full_written >= sampled, "an ample output holds at least as many");
        prop_assert_eq!(&s.symmetries, &full.symmetries);
    }

    /// The smallest engine the const checks allow still ends with a result or a typed error.
    #[test]
    fn a_tiny_engine_ends_with_a_result_or_an_error(
        object in 0..OBJECTS.len(),
        table in any::<bool>(),
        mask in any::<bool>(),
        budgets in budgets(),
    ) {
        let r = &scenes()[object];
        let mut out = vec![CompletedPoint::ZERO; 16];
        let mut engine = Box::new(Engine::<'_, 32, 64, 64>::new(Config::DEFAULT));
        engine.start(scene(r, table, mask), &mut out).unwrap();
        match run(&mut engine, &budgets) {
            Ok(()) => prop_assert!(engine.points().len() <= 16),
            Err(e) => prop_assert!(matches!(
                e,
                Error::NoObject | Error::NoSupportPlane | Error::TooFewPoints { .. }
            ), "{:?}", e),
        }
    }
}

/// A garbage image: random size (1..=64 a side), intrinsics (valid or not), depth values
/// (often zero or repeated), scale, mask and table.
#[derive(Debug, Clone)]
struct Garbage {
    k: Intrinsics,
    depth: Vec<u16>,
    scale: f32,
    mask: Option<Vec<u8>>,
    table: Option<Plane>,
}

fn float() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(0.0f32),
        1 => Just(1e30f32),
        1 => any::<f32>(),
        6 => 0.5f32..200.0,
    ]
}

fn garbage() -> impl Strategy<Value = Garbage> {
    (1u16..=64, 1u16..=64).prop_flat_map(|(w, h)| {
        let n = w as usize * h as usize;
        let depth = prop_oneof![
            prop::collection::vec(any::<u16>(), n),
            prop::collection::vec(prop_oneof![Just(0u16), Just(800u16), 300u16..1200], n),
        ];
        let mask = prop::option::of(prop::collection::vec(0u8..=1, n));
        let table = prop::option::of((float(), float(), float(), float()).prop_map(
            |(a, b, c, d)| Plane {
                normal: [a, b, c],
                offset: d,
            },
        ));
        let scale = prop_oneof![Just(0.001f32), float()];
        (
            float(),
            float(),
            float(),
            float(),
            depth,
            scale,
            mask,
            table,
        )
            .prop_map(move |(fx, fy, cx, cy, depth, scale, mask, table)| Garbage {
                k: Intrinsics {
                    width: w,
                    height: h,
                    fx,
                    fy,
                    cx,
                    cy,
                },
                depth,
                scale,
                mask,
                table,
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Garbage never panics: `start` rejects it with an input error, or `poll` ends with a result
    /// or a content error, within the bound.
    #[test]
    fn garbage_gets_a_typed_error_or_a_result(g in garbage(), budget in 0u32..100_000) {
        let mut out = vec![CompletedPoint::ZERO; 256];
        let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT));
        let s = Scene {
            depth: &g.depth,
            depth_scale: g.scale,
            intrinsics: g.k,
            table: g.table,
            mask: g.mask.as_deref(),
            target: None,
        };
        match engine.start(s, &mut out) {
            Ok(()) => {}
            Err(e) => {
                prop_assert!(matches!(
                    e,
                    Error::InvalidIntrinsics | Error::InvalidDepthScale | Error::InvalidTablePlane
                ), "{:?}", e);
                return Ok(());
            }
        }
        match run(&mut engine, &[budget]) {
            Ok(()) => prop_assert!(engine.points().len() <= 256),
            Err(e) => prop_assert!(matches!(
                e,
                Error::NoValidDepth | Error::NoObject | Error::NoSupportPlane | Error::TooFewPoints { .. }
            ), "{:?}", e),
        }
    }
}
