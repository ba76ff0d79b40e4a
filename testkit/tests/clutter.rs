//! The clutter scenes: their layout, true masks, room, touching pairs, determinism, errors.

use sfs_testkit::clutter::*;
use sfs_testkit::metrics::iou;
use std::sync::OnceLock;

use sfs_testkit::synth::{self, Part, SynthScene};
use shape_from_symmetry::Intrinsics;
use shape_from_symmetry::math::{Isometry, Vec3};

fn inverse(iso: &Isometry) -> Isometry {
    let lt = iso.linear.transpose();
    Isometry {
        linear: lt,
        translation: -(lt * iso.translation),
    }
}

/// Object-frame point of pixel `p` with depth value `raw`.
fn point(k: &Intrinsics, to_object: &Isometry, p: usize, raw: u16, scale: f32) -> Vec3 {
    let w = k.width as usize;
    to_object.apply(k.unproject((p % w) as f32, (p / w) as f32, f32::from(raw) * scale))
}

/// The 8-neighbours of pixel `p` in a `w` x `h` image.
fn neighbours8(p: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (u, v) = ((p % w) as i64, (p / w) as i64);
    (-1i64..=1)
        .flat_map(move |dv| (-1i64..=1).map(move |du| (u + du, v + dv)))
        .filter(move |&(x, y)| (x, y) != (u, v) && x >= 0 && y >= 0 && x < w as i64 && y < h as i64)
        .map(move |(x, y)| y as usize * w + x as usize)
}

/// Half the distance between two solids, roughly: the least over points `p` of the larger of
/// their signed distances (coarse-to-fine grid search near both). Negative: they overlap.
fn half_gap(a: &[Part], b: &[Part]) -> f32 {
    let f = |p: Vec3| synth::signed_distance(a, p).max(synth::signed_distance(b, p));
    let (alo, ahi) = synth::bounds(a);
    let (blo, bhi) = synth::bounds(b);
    let margin = 0.004;
    let lo = Vec3::from_array([0, 1, 2].map(|i| alo[i].max(blo[i]) - margin));
    let hi = Vec3::from_array([0, 1, 2].map(|i| ahi[i].min(bhi[i]) + margin));
    if (hi - lo).min_element() < 0.0 {
        return f32::INFINITY;
    }
    let mut best = (f32::INFINITY, (lo + hi) * 0.5);
    let scan = |lo: Vec3, hi: Vec3, step: f32, best: &mut (f32, Vec3)| {
        let n = ((hi - lo) / step).ceil();
        for i in 0..=n.x as usize {
            for j in 0..=n.y as usize {
                for k in 0..=n.z as usize {
                    let p = lo + Vec3::new(i as f32, j as f32, k as f32) * step;
                    let d = f(p);
                    if d < best.0 {
                        *best = (d, p);
                    }
                }
            }
        }
    };
    scan(lo, hi, 0.002, &mut best);
    // Pattern search: recentre each window until it no longer improves, then narrow it.
    for (reach, step) in [(0.004, 0.0004), (0.0005, 0.00005), (0.00006, 0.000006)] {
        for _ in 0..50 {
            let before = best.0;
            let c = best.1;
            scan(
                c - Vec3::splat(reach),
                c + Vec3::splat(reach),
                step,
                &mut best,
            );
            if best.0 >= before {
                break;
            }
        }
    }
    best.0
}

/// Where a background pixel's reading lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Where {
    Table,
    Floor,
    Wall,
    Elsewhere,
}

fn classify(scene: &ClutterScene, layout: &ClutterLayout, q: Vec3, tol: f32) -> Where {
    let [hx, hy] = scene.table_half_size;
    if q.z.abs() < tol && q.x.abs() <= hx + tol && q.y.abs() <= hy + tol {
        return Where::Table;
    }
    if (q.z + scene.floor_drop).abs() < tol {
        return Where::Floor;
    }
    if let Some(wall) = layout.wall {
        if synth::signed_distance(&[wall], q).abs() < tol {
            return Where::Wall;
        }
    }
    Where::Elsewhere
}

fn noise_free(scene: &ClutterScene<'static>) -> ClutterScene<'static> {
    ClutterScene {
        noise: false,
        flying_pixels: 0.0,
        ..*scene
    }
}

/// Every case rendered as given and without noise or flying pixels, once for all tests.
fn renders() -> &'static [(ClutterCase, ClutterFrame, ClutterFrame)] {
    static RENDERS: OnceLock<Vec<(ClutterCase, ClutterFrame, ClutterFrame)>> = OnceLock::new();
    RENDERS.get_or_init(|| {
        clutter_cases()
            .map(|case| {
                let frame = ClutterFrame::render(&case.scene, &case.intrinsics).expect("renders");
                let clean = ClutterFrame::render(&noise_free(&case.scene), &case.intrinsics)
                    .expect("renders");
                (case, frame, clean)
            })
            .collect()
    })
}

#[test]
fn the_cases_cover_the_issue() {
    let cases: Vec<ClutterCase> = clutter_cases().collect();
    assert!(cases.len() >= 20);
    let mut names: Vec<&str> = cases.iter().map(|c| c.scene.name).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), cases.len(), "names are unique");
    let mut seeds: Vec<u32> = cases.iter().map(|c| c.scene.seed).collect();
    seeds.sort();
    seeds.dedup();
    assert_eq!(seeds.len(), cases.len(), "seeds are unique");
    let count = |f: &dyn Fn(&ClutterCase) -> bool| cases.iter().filter(|c| f(c)).count();
    assert!(count(&|c| c.scene.table_half_size == SMALL_SUPPORT_HALF_SIZE) >= 4);
    assert!(count(&|c| c.scene.flying_pixels > 0.0) >= 8);
    assert!(count(&|c| c.intrinsics == synth::XTION_INTRINSICS) >= 12);
    assert!(count(&|c| c.intrinsics == synth::BUILTIN_INTRINSICS) >= 4);
    assert!(count(&|c| c.scene.objects.len() == 5) >= 1);
    assert!(count(&|c| c.scene.wall_gap.is_some()) >= 12);
    for case in &cases {
        let s = &case.scene;
        let xtion = case.intrinsics == synth::XTION_INTRINSICS;
        let scale = if xtion {
            synth::XTION_DEPTH_SCALE
        } else {
            0.001
        };
        assert_eq!(s.depth_scale, scale, "{}", s.name);
        assert!((2..=MAX_OBJECTS).contains(&s.objects.len()), "{}", s.name);
        assert!((30.0..=60.0).contains(&s.view.elevation_deg), "{}", s.name);
        assert!((0.5..=1.0).contains(&s.view.distance), "{}", s.name);
        assert!(s.noise, "{}", s.name);
        assert!(s.touching().count() >= 1, "{}: nothing touches", s.name);
    }
    // Both kinds of contact, many times over: one object in front of another (a depth
    // discontinuity where their masks meet), and side by side.
    assert!(count(&|c| c.scene.touching().any(|t| t.in_depth())) >= 12);
    assert!(count(&|c| c.scene.touching().any(|t| !t.in_depth())) >= 12);
    assert!(
        count(&|c| c
            .scene
            .touching()
            .map(|t| t.in_depth())
            .collect::<Vec<_>>()
            .len()
            >= 2)
            >= 10
    );
    // The objects vary.
    let mut kinds: Vec<&str> = cases
        .iter()
        .flat_map(|c| c.scene.objects.iter().map(|o| o.object.name))
        .collect();
    kinds.sort();
    kinds.dedup();
    assert!(kinds.len() >= 8, "{kinds:?}");
}

#[test]
fn objects_stand_on_the_table_apart_or_touching_as_placed() {
    for case in clutter_cases() {
        let s = &case.scene;
        let layout = s.layout().unwrap();
        assert_eq!(layout.len(), s.objects.len());
        let [hx, hy] = s.table_half_size;
        for i in 0..layout.len() {
            let (lo, hi) = synth::bounds(layout.object(i));
            assert!(lo[2].abs() < 1e-5, "{} {i}: stands on the table", s.name);
            assert!(
                lo[0] > -hx && hi[0] < hx && lo[1] > -hy && hi[1] < hy,
                "{} {i}: off the table: {lo:?} {hi:?}",
                s.name
            );
        }
        // The wall stands beyond the table, the floor below it.
        if let Some(wall) = layout.wall {
            for corner in [[-hx, -hy], [-hx, hy], [hx, -hy], [hx, hy]] {
                let d = synth::signed_distance(&[wall], Vec3::new(corner[0], corner[1], 0.0));
                assert!(d > 0.0, "{}: the wall cuts the table", s.name);
            }
        }
        let (_, floor_top) = synth::bounds(&[layout.floor]);
        assert!((floor_top[2] + s.floor_drop).abs() < 1e-5);
        // Touching pairs are the nominal gap apart (the cone's signed distance is only a bound
        // near its base's edge: 0.15 mm short); no other pair overlaps.
        for a in 0..layout.len() {
            for b in a + 1..layout.len() {
                let gap = 2.0 * half_gap(layout.object(a), layout.object(b));
                let touch = s.touching().find(|t| (t.of, t.object) == (a, b));
                match touch {
                    Some(t) => assert!(
                        (gap - t.gap).abs() < 2e-4,
                        "{} {a}-{b}: gap {gap}, placed {}",
                        s.name,
                        t.gap
                    ),
                    None => assert!(gap > 1e-3, "{} {a}-{b}: gap {gap}", s.name),
                }
            }
        }
    }
}

#[test]
fn masks_are_the_true_nearest_hits_and_disjoint() {
    for (case, frame, clean) in renders() {
        let (s, k) = (&case.scene, &case.intrinsics);
        let (w, h) = (k.width as usize, k.height as usize);
        let n = w * h;
        let r = &frame.rendered;
        assert_eq!(r.depth_mismatches, 0, "{}", s.name);
        assert_eq!(r.contested_pixels, 0, "{}", s.name);
        assert_eq!(clean.rendered.depth_mismatches, 0, "{}", s.name);
        assert_eq!(r.flying_pixels > 0, s.flying_pixels > 0.0, "{}", s.name);
        // The masks are noise-free: the same with and without noise and flying pixels.
        assert_eq!(frame.masks, clean.masks, "{}", s.name);
        for p in 0..n {
            let owners = (0..s.objects.len())
                .filter(|&i| frame.mask(i)[p] != 0)
                .count();
            assert!(owners <= 1, "{}: pixel {p} in {owners} masks", s.name);
        }
        // Together they are the pixels of all objects: one render with every object as the
        // object.
        let layout = s.layout().unwrap();
        let (room, rooms) = layout.room();
        let all = SynthScene {
            parts: layout.all_objects(),
            occluders: &room[..rooms],
            artefacts: synth::Artefacts::OFF,
            target: layout.target,
            view: s.view,
            noise: synth::Noise::OFF,
            depth_scale: s.depth_scale,
            table_half_size: s.table_half_size,
        };
        let (mut depth, mut union) = (vec![0u16; n], vec![0u8; n]);
        synth::render(&all, k, &mut depth, &mut union).unwrap();
        assert_eq!(union, frame.union_mask(), "{}", s.name);
        assert_eq!(depth, clean.depth, "{}", s.name);

        let to_object = inverse(&r.object_to_camera);
        let min_pixels = if w == 640 { 1500 } else { 400 };
        for (i, o) in r.objects().iter().enumerate() {
            let name = format!("{} object {i} ({})", s.name, s.objects[i].object.name);
            let mask = frame.mask(i);
            let pixels: Vec<usize> = (0..n).filter(|&p| mask[p] != 0).collect();
            assert_eq!(o.pixels as usize, pixels.len(), "{name}");
            assert!(
                pixels.len() >= min_pixels,
                "{name}: {} pixels",
                pixels.len()
            );
            let valid = pixels.iter().filter(|&&p| frame.depth[p] != 0).count();
            assert_eq!(o.valid_pixels as usize, valid, "{name}");
            // The box is tight.
            let b = o.pixel_box;
            let (us, vs) = (pixels.iter().map(|p| p % w), pixels.iter().map(|p| p / w));
            assert_eq!(
                (b.u0 as usize, b.v0 as usize),
                (us.clone().min().unwrap(), vs.clone().min().unwrap()),
                "{name}"
            );
            assert_eq!(
                ((b.u0 + b.width) as usize, (b.v0 + b.height) as usize),
                (us.max().unwrap() + 1, vs.max().unwrap() + 1),
                "{name}"
            );
            // The hint lies on the object, with a reading, away from its silhouette.
            let [hu, hv] = o.hint.expect("a hint");
            let hp = hv as usize * w + hu as usize;
            assert!(b.contains(hu, hv), "{name}");
            assert!(frame.depth[hp] != 0, "{name}");
            assert!(neighbours8(hp, w, h).all(|q| mask[q] != 0), "{name}");
            // Noise-free, every reading of the mask lies on the object (the depth unit's
            // rounding along the ray: 0.05 mm or 0.5 mm); with noise and flying pixels, nearly
            // every one within the noise (the Kinect's sigma is 3-4 mm at 1 m at a grazing
            // incidence, the disparity step 3 mm), the rest flying pixels on the silhouette.
            let tol = if w == 640 { 2e-4 } else { 6e-4 };
            let parts = layout.object(i);
            for &p in pixels.iter().filter(|&&p| clean.depth[p] != 0) {
                let q = point(k, &to_object, p, clean.depth[p], s.depth_scale);
                let d = synth::signed_distance(parts, q);
                assert!(d.abs() < tol, "{name}: pixel {p} is {d} m off the object");
            }
            let off = pixels
                .iter()
                .filter(|&&p| frame.depth[p] != 0)
                .filter(|&&p| {
                    let q = point(k, &to_object, p, frame.depth[p], s.depth_scale);
                    synth::signed_distance(parts, q).abs() > 0.01
                })
                .count();
            assert!(
                off * 10 < valid,
                "{name}: {off} of {valid} readings off the object"
            );
        }
    }
}

#[test]
fn the_room_gives_readings_beyond_the_table() {
    let (mut with_floor, mut table_cases) = (0, 0);
    for (case, _, clean) in renders() {
        let (s, k) = (&case.scene, &case.intrinsics);
        let n = k.pixel_count();
        let layout = s.layout().unwrap();
        let to_object = inverse(&clean.rendered.object_to_camera);
        let union = clean.union_mask();
        let mut depths: [Vec<f32>; 4] = Default::default();
        for p in (0..n).filter(|&p| union[p] == 0 && clean.depth[p] != 0) {
            let q = point(k, &to_object, p, clean.depth[p], s.depth_scale);
            let at = classify(s, &layout, q, 0.002);
            depths[at as usize].push(f32::from(clean.depth[p]) * s.depth_scale);
        }
        let [table, floor, wall, elsewhere] = &depths;
        assert!(
            elsewhere.is_empty(),
            "{}: {} readings on nothing",
            s.name,
            elsewhere.len()
        );
        assert!(table.len() * 10 > n, "{}: the table fills little", s.name);
        let median = |v: &[f32]| {
            let mut v = v.to_vec();
            v.sort_by(f32::total_cmp);
            v[v.len() / 2]
        };
        let table_median = median(table);
        let table_far = table.iter().copied().fold(0.0, f32::max);
        let beyond = floor.len() + wall.len();
        assert!(
            beyond * 100 > n,
            "{}: {beyond} readings beyond the table",
            s.name
        );
        for (what, v) in [("floor", floor), ("wall", wall)] {
            if !v.is_empty() {
                assert!(
                    median(v) > table_median,
                    "{}: the {what} is nearer than the table",
                    s.name
                );
            }
        }
        assert_eq!(
            s.wall_gap.is_some(),
            !wall.is_empty(),
            "{}: the wall",
            s.name
        );
        if s.table_half_size == SMALL_SUPPORT_HALF_SIZE {
            // The floor around the small support, out to about 2 m.
            let far = floor.iter().copied().fold(0.0, f32::max);
            assert!(floor.len() * 100 > n, "{}: floor", s.name);
            assert!(
                (1.5..3.0).contains(&far) && far > table_far + 0.5,
                "{}: {far}",
                s.name
            );
        } else {
            table_cases += 1;
            with_floor += usize::from(!floor.is_empty());
        }
    }
    assert!(
        3 * with_floor >= table_cases,
        "{with_floor} of {table_cases}"
    );
}

#[test]
fn touching_objects_meet_in_the_image() {
    for (case, _, clean) in renders() {
        let (s, k) = (&case.scene, &case.intrinsics);
        let (w, h) = (k.width as usize, k.height as usize);
        for t in s.touching() {
            let (a, b) = (clean.mask(t.of), clean.mask(t.object));
            // Depth steps (metres) between 8-adjacent pixels of the two masks, both read.
            let mut steps = Vec::new();
            for p in (0..w * h).filter(|&p| a[p] != 0) {
                for q in neighbours8(p, w, h).filter(|&q| b[q] != 0) {
                    if clean.depth[p] != 0 && clean.depth[q] != 0 {
                        let step = f32::from(clean.depth[p]) - f32::from(clean.depth[q]);
                        steps.push(step.abs() * s.depth_scale);
                    }
                }
            }
            let name = format!("{} {}-{}", s.name, t.of, t.object);
            assert!(
                steps.len() >= 10,
                "{name}: the masks meet at {} pixels",
                steps.len()
            );
            let (least, most) = steps
                .iter()
                .fold((f32::INFINITY, 0.0f32), |(l, m), x| (l.min(*x), m.max(*x)));
            if t.in_depth() {
                assert!(most > 0.03, "{name}: no depth discontinuity ({most} m)");
            } else {
                // Side by side: where they touch, their surfaces meet.
                assert!(least < 0.035, "{name}: {least} m apart");
            }
        }
        // Side by side at similar depth: somewhere in the set every few scenes.
    }
    let similar = renders()
        .iter()
        .filter(|(case, _, clean)| {
            let (s, k) = (&case.scene, &case.intrinsics);
            let (w, h) = (k.width as usize, k.height as usize);
            s.touching().filter(|t| !t.in_depth()).any(|t| {
                let (a, b) = (clean.mask(t.of), clean.mask(t.object));
                (0..w * h)
                    .filter(|&p| a[p] != 0 && clean.depth[p] != 0)
                    .any(|p| {
                        neighbours8(p, w, h).any(|q| {
                            b[q] != 0
                                && clean.depth[q] != 0
                                && (f32::from(clean.depth[p]) - f32::from(clean.depth[q])).abs()
                                    * s.depth_scale
                                    < 0.002
                        })
                    })
            })
        })
        .count();
    assert!(
        similar >= 10,
        "{similar} scenes with a pair side by side at similar depth"
    );
}

#[test]
fn renders_are_deterministic() {
    let cases = renders();
    for (case, frame, _) in cases
        .iter()
        .filter(|(c, _, _)| c.scene.flying_pixels > 0.0)
        .take(3)
    {
        let again = ClutterFrame::render(&case.scene, &case.intrinsics).unwrap();
        assert_eq!(&again, frame, "{}", case.scene.name);
        // Another seed: other noise and flying pixels, the same masks.
        let other = ClutterScene {
            seed: case.scene.seed + 1000,
            ..case.scene
        };
        let other = ClutterFrame::render(&other, &case.intrinsics).unwrap();
        assert_eq!(other.masks, frame.masks);
        assert_ne!(other.depth, frame.depth);
    }
}

#[test]
fn the_no_alloc_renderer_writes_what_the_frame_holds() {
    let (case, frame, _) = &renders()[0];
    let k = &case.intrinsics;
    let n = k.pixel_count();
    let count = case.scene.objects.len();
    let (mut depth, mut masks, mut scratch) = (vec![1u16; n], vec![7u8; n * count], vec![0u16; n]);
    let r = render_clutter(&case.scene, k, &mut depth, &mut masks, &mut scratch).unwrap();
    assert_eq!(
        (&depth, &masks, &r),
        (&frame.depth, &frame.masks, &frame.rendered)
    );
}

#[test]
fn invalid_scenes_and_buffers_are_errors() {
    let case = clutter_cases().next().unwrap();
    let (s, k) = (case.scene, case.intrinsics);
    let n = k.pixel_count();
    let count = s.objects.len();
    let (mut depth, mut masks, mut scratch) = (vec![0u16; n], vec![0u8; n * count], vec![0u16; n]);
    let mut check = |scene: &ClutterScene, expected: ClutterError| {
        assert_eq!(
            render_clutter(scene, &k, &mut depth, &mut masks, &mut scratch),
            Err(expected),
            "{scene:?}"
        );
    };
    let bad_place = |place: Place| {
        [
            s.objects[0],
            ClutterObject {
                place,
                ..s.objects[1]
            },
        ]
    };
    check(
        &ClutterScene { objects: &[], ..s },
        ClutterError::ObjectCount,
    );
    let six = [s.objects[0]; MAX_OBJECTS + 1];
    check(
        &ClutterScene { objects: &six, ..s },
        ClutterError::ObjectCount,
    );
    for place in [
        Place::Beside {
            of: 1,
            bearing_deg: 0.0,
            gap: 0.0,
        },
        Place::Beside {
            of: 0,
            bearing_deg: f32::NAN,
            gap: 0.0,
        },
        Place::Beside {
            of: 0,
            bearing_deg: 0.0,
            gap: -0.001,
        },
        Place::At {
            x: f32::INFINITY,
            y: 0.0,
        },
    ] {
        let objects = bad_place(place);
        check(
            &ClutterScene {
                objects: &objects,
                ..s
            },
            ClutterError::InvalidObject { index: 1 },
        );
    }
    let yawed = [ClutterObject {
        yaw_deg: f32::NAN,
        ..s.objects[0]
    }];
    check(
        &ClutterScene {
            objects: &yawed,
            ..s
        },
        ClutterError::InvalidObject { index: 0 },
    );
    for room in [
        ClutterScene {
            floor_drop: 0.0,
            ..s
        },
        ClutterScene {
            floor_half: f32::NAN,
            ..s
        },
        ClutterScene {
            wall_gap: Some(-0.1),
            ..s
        },
        ClutterScene {
            flying_pixels: 1.5,
            ..s
        },
    ] {
        check(&room, ClutterError::InvalidRoom);
    }
    check(
        &ClutterScene {
            view: synth::View {
                distance: -1.0,
                ..s.view
            },
            ..s
        },
        ClutterError::Synth(synth::SynthError::InvalidView),
    );
    check(
        &ClutterScene {
            view: synth::View {
                azimuth_deg: f32::NAN,
                ..s.view
            },
            ..s
        },
        ClutterError::Synth(synth::SynthError::InvalidView),
    );
    check(
        &ClutterScene {
            depth_scale: 0.0,
            ..s
        },
        ClutterError::Synth(synth::SynthError::InvalidDepthScale),
    );
    assert!(
        depth.iter().all(|d| *d == 0) && masks.iter().all(|m| *m == 0),
        "untouched"
    );
    let mut short = vec![0u8; n];
    assert_eq!(
        render_clutter(&s, &k, &mut depth, &mut short, &mut scratch),
        Err(ClutterError::BufferSize)
    );
    let mut small = vec![0u16; n - 1];
    assert_eq!(
        render_clutter(&s, &k, &mut depth, &mut masks, &mut small),
        Err(ClutterError::BufferSize)
    );
}

#[test]
fn iou_counts_nonzero_as_in() {
    assert_eq!(iou(&[0, 1, 2, 0], &[0, 255, 0, 3]), 1.0 / 3.0);
    assert_eq!(iou(&[0, 0], &[0, 0]), 1.0);
    assert_eq!(iou(&[9, 0], &[0, 9]), 0.0);
    assert_eq!(iou(&[1, 1], &[1]), 0.5);
    let (_, frame, _) = &renders()[0];
    assert_eq!(iou(frame.mask(0), frame.mask(0)), 1.0);
    assert_eq!(iou(frame.mask(0), frame.mask(1)), 0.0);
}
