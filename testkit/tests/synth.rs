//! The synthetic renderer: geometry, noise, determinism, errors, and the ready-made objects'
//! documented symmetries.

use sfs_testkit::synth::*;
use shape_from_symmetry::math::{Isometry, Mat3, Vec3, hemisphere_direction, rotation};
use shape_from_symmetry::symmetry::{Sampling, Symmetry};
use shape_from_symmetry::{Intrinsics, Plane};

const K: Intrinsics = BUILTIN_INTRINSICS;
const N: usize = 320 * 240;

fn buffers() -> (Vec<u16>, Vec<u8>) {
    (vec![0u16; N], vec![0u8; N])
}

fn render_vec(scene: &SynthScene) -> (Vec<u16>, Vec<u8>, Rendered) {
    let (mut depth, mut mask) = buffers();
    let r = render(scene, &K, &mut depth, &mut mask).expect("renders");
    (depth, mask, r)
}

fn inverse(iso: &Isometry) -> Isometry {
    let lt = iso.linear.transpose();
    Isometry {
        linear: lt,
        translation: -(lt * iso.translation),
    }
}

/// Camera-frame point of pixel `i` with depth value `raw`.
fn unproject(i: usize, raw: u16, scale: f32) -> Vec3 {
    let (u, v) = ((i % 320) as f32, (i / 320) as f32);
    K.unproject(u, v, raw as f32 * scale)
}

/// Object-frame points of the object pixels of a rendered scene.
fn object_points(scene: &SynthScene, depth: &[u16], mask: &[u8], r: &Rendered) -> Vec<Vec3> {
    let to_object = inverse(&r.object_to_camera);
    (0..N)
        .filter(|&i| mask[i] == 255 && depth[i] != 0)
        .map(|i| to_object.apply(unproject(i, depth[i], scene.depth_scale)))
        .collect()
}

/// Noise-free samples of the whole surface (object frame), seen from six sides, no table,
/// depth in 10 µm units so that rounding is negligible.
fn surface_samples(object: &ReadyObject, max: usize) -> Vec<Vec3> {
    let mut all = Vec::new();
    for (el, az) in [
        (50.0, 10.0),
        (50.0, 130.0),
        (50.0, 250.0),
        (-40.0, 70.0),
        (-40.0, 190.0),
        (-40.0, 310.0),
    ] {
        let view = View {
            distance: 0.35,
            elevation_deg: el,
            azimuth_deg: az,
            roll_deg: 0.0,
        };
        let scene = SynthScene {
            table_half_size: [0.0, 0.0],
            depth_scale: 1e-5,
            ..object.scene(view, Noise::OFF)
        };
        let (depth, mask, r) = render_vec(&scene);
        all.extend(object_points(&scene, &depth, &mask, &r));
    }
    let step = (all.len() / max).max(1);
    all.into_iter().step_by(step).collect()
}

#[test]
fn sphere_and_table_lie_where_they_should() {
    let ball = object("ball").unwrap();
    let scene = ball.scene(BUILTIN_VIEW, Noise::OFF);
    let (depth, mask, r) = render_vec(&scene);
    let centre = Vec3::new(0.0, 0.0, 0.048);
    let to_object = inverse(&r.object_to_camera);
    let (mut object, mut table) = (0, 0);
    for i in 0..N {
        if depth[i] == 0 {
            continue;
        }
        let p = unproject(i, depth[i], scene.depth_scale);
        if mask[i] == 255 {
            let err = ((to_object.apply(p) - centre).length() - 0.048).abs();
            assert!(err < 1e-3, "pixel {i}: {err} m off the sphere");
            object += 1;
        } else {
            let err = r.table.signed_distance(p).abs();
            assert!(err < 1e-3, "pixel {i}: {err} m off the table");
            table += 1;
        }
    }
    assert!(object > 1000 && table > 10_000, "{object} {table}");
    assert_eq!(object, r.valid_object_pixels);
    assert_eq!(
        r.object_pixels, r.valid_object_pixels,
        "noise off: every object pixel has depth"
    );
    let n = Vec3::from_array(r.table.normal);
    assert!((n.length() - 1.0).abs() < 1e-6);
    assert!(
        r.table.signed_distance(Vec3::ZERO) > 0.0,
        "camera on the positive side"
    );
    let height = 0.45 * (45f32).to_radians().sin() + 0.048; // target is the ball's centre
    assert!((r.table.signed_distance(Vec3::ZERO) - height).abs() < 1e-4);
}

#[test]
fn every_object_pixel_lies_on_the_object() {
    for object in &OBJECTS {
        let scene = SynthScene {
            depth_scale: 1e-5,
            ..object.scene(BUILTIN_VIEW, Noise::OFF)
        };
        let (depth, mask, r) = render_vec(&scene);
        let points = object_points(&scene, &depth, &mask, &r);
        assert_eq!(points.len() as u32, r.object_pixels, "{}", object.name);
        let worst = points
            .iter()
            .map(|p| signed_distance(object.parts, *p).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-4,
            "{}: a pixel is {worst} m off the surface",
            object.name
        );
        let lowest = points.iter().map(|p| p.z).fold(f32::INFINITY, f32::min);
        assert!(lowest > -1e-4, "{}: {lowest}", object.name);
    }
}

#[test]
fn rendering_is_deterministic_and_noise_is_bounded() {
    let scene = builtin_scene();
    let (d1, m1, r1) = render_vec(&scene);
    let (d2, m2, r2) = render_vec(&scene);
    assert!(d1 == d2 && m1 == m2 && r1 == r2);

    let (clean, clean_mask, _) = render_vec(&SynthScene {
        noise: Noise::OFF,
        ..scene
    });
    assert_eq!(m1, clean_mask, "the mask is the noise-free silhouette");
    let (other_seed, _, _) = render_vec(&SynthScene {
        noise: Noise::kinect(2),
        ..scene
    });
    assert_ne!(d1, other_seed);

    let (mut changed, mut both, mut dropped, mut sum2) = (0usize, 0usize, 0usize, 0.0f64);
    for i in 0..N {
        if clean[i] == 0 {
            continue;
        }
        if d1[i] == 0 {
            dropped += 1;
            continue;
        }
        both += 1;
        let (z, zn) = (clean[i] as f32 * 1e-3, d1[i] as f32 * 1e-3);
        let dz = zn - z;
        changed += (dz != 0.0) as usize;
        sum2 += (dz as f64) * (dz as f64);
        // Worst case: the grazing limit's sigma, 6 sigma, plus quantisation and rounding.
        let quant = z * z / (580.0 * 0.075 * 8.0);
        let bound = 6.0 * axial_sigma(z, 85f32.to_radians()) + quant + 1e-3;
        assert!(dz.abs() <= bound, "pixel {i}: {dz} m");
    }
    let rms = (sum2 / both as f64).sqrt() as f32;
    assert!(changed > both / 2, "{changed} of {both}");
    // Near fronto-parallel at 0.45-0.6 m, sigma is about 1.2 mm: the RMS stays a few mm.
    assert!(rms > 0.8e-3 && rms < 4e-3, "rms {rms}");
    let drop_rate = dropped as f32 / (both + dropped) as f32;
    assert!(drop_rate > 0.001 && drop_rate < 0.1, "{drop_rate}");
    assert!(r1.valid_object_pixels < r1.object_pixels);
}

#[test]
fn bad_input_is_a_typed_error() {
    let scene = builtin_scene();
    let (mut depth, mut mask) = buffers();
    let mut short = vec![0u16; N - 1];
    let mut short_mask = vec![0u8; N + 1];
    assert_eq!(
        render(&scene, &K, &mut short, &mut mask),
        Err(SynthError::BufferSize)
    );
    assert_eq!(
        render(&scene, &K, &mut depth, &mut short_mask),
        Err(SynthError::BufferSize)
    );
    assert_eq!(
        render(&scene, &K, &mut [], &mut []),
        Err(SynthError::BufferSize)
    );
    assert_eq!(
        render(
            &SynthScene {
                parts: &[],
                ..scene
            },
            &K,
            &mut depth,
            &mut mask
        ),
        Err(SynthError::EmptyScene)
    );
    for distance in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let bad = SynthScene {
            view: View {
                distance,
                ..scene.view
            },
            ..scene
        };
        assert_eq!(
            render(&bad, &K, &mut depth, &mut mask),
            Err(SynthError::InvalidView)
        );
    }
    let bad = SynthScene {
        view: View {
            azimuth_deg: f32::NAN,
            ..scene.view
        },
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidView)
    );
    let bad = SynthScene {
        target: [0.0, f32::INFINITY, 0.0],
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidView)
    );
    for depth_scale in [0.0, -0.001, f32::NAN] {
        let bad = SynthScene {
            depth_scale,
            ..scene
        };
        assert_eq!(
            render(&bad, &K, &mut depth, &mut mask),
            Err(SynthError::InvalidDepthScale)
        );
    }
    let bad = SynthScene {
        noise: Noise {
            dropout: 1.5,
            ..scene.noise
        },
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidNoise)
    );
    let bad = SynthScene {
        noise: Noise {
            axial_scale: f32::NAN,
            ..scene.noise
        },
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidNoise)
    );
    let bad = SynthScene {
        table_half_size: [-1.0, 0.4],
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidTable)
    );
    let bad_k = Intrinsics { fx: 0.0, ..K };
    assert_eq!(
        render(&scene, &bad_k, &mut depth, &mut mask),
        Err(SynthError::InvalidIntrinsics)
    );

    let pose = Isometry::IDENTITY;
    let bad_parts = [
        Part {
            shape: Shape::Sphere { radius: 0.05 },
            pose,
        },
        Part {
            shape: Shape::Box {
                half: [0.1, 0.0, 0.1],
            },
            pose,
        },
    ];
    let bad = SynthScene {
        parts: &bad_parts,
        ..scene
    };
    assert_eq!(
        render(&bad, &K, &mut depth, &mut mask),
        Err(SynthError::InvalidPart { index: 1 })
    );
    let bowl = [Part {
        shape: Shape::Bowl {
            radius: 0.05,
            thickness: 0.06,
        },
        pose,
    }];
    assert_eq!(
        render(
            &SynthScene {
                parts: &bowl,
                ..scene
            },
            &K,
            &mut depth,
            &mut mask
        ),
        Err(SynthError::InvalidPart { index: 0 })
    );
    let sheared = Isometry {
        linear: Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0)),
        ..pose
    };
    let sheared = [Part {
        shape: Shape::Sphere { radius: 0.05 },
        pose: sheared,
    }];
    assert_eq!(
        render(
            &SynthScene {
                parts: &sheared,
                ..scene
            },
            &K,
            &mut depth,
            &mut mask
        ),
        Err(SynthError::InvalidPart { index: 0 })
    );
    let nan_pose = Isometry {
        translation: Vec3::new(f32::NAN, 0.0, 0.0),
        ..pose
    };
    let nan_parts = [Part {
        shape: Shape::Sphere { radius: 0.05 },
        pose: nan_pose,
    }];
    assert_eq!(
        render(
            &SynthScene {
                parts: &nan_parts,
                ..scene
            },
            &K,
            &mut depth,
            &mut mask
        ),
        Err(SynthError::InvalidPart { index: 0 })
    );
    assert!(
        depth.iter().all(|&d| d == 0) && mask.iter().all(|&m| m == 0),
        "errors write nothing"
    );
}

#[test]
fn odd_but_valid_scenes_do_not_panic() {
    let (mut depth, mut mask) = buffers();
    let scene = builtin_scene();
    for (el, roll) in [
        (90.0, 0.0),
        (-90.0, 30.0),
        (0.0, 180.0),
        (135.0, -45.0),
        (-30.0, 1e6),
    ] {
        let view = View {
            elevation_deg: el,
            roll_deg: roll,
            ..scene.view
        };
        render(&SynthScene { view, ..scene }, &K, &mut depth, &mut mask).unwrap();
    }
    // Camera inside the object, far away, depth unit too fine to hold the depth (saturates).
    let inside = SynthScene {
        view: View {
            distance: 0.01,
            ..scene.view
        },
        ..scene
    };
    render(&inside, &K, &mut depth, &mut mask).unwrap();
    let far = SynthScene {
        view: View {
            distance: 100.0,
            ..scene.view
        },
        ..scene
    };
    let r = render(&far, &K, &mut depth, &mut mask).unwrap();
    assert_eq!(r.valid_object_pixels, 0, "beyond 4 m: no reading");
    let fine = SynthScene {
        depth_scale: 1e-6,
        noise: Noise::OFF,
        ..scene
    };
    render(&fine, &K, &mut depth, &mut mask).unwrap();
    assert!(depth.contains(&u16::MAX));
    // Tiny images, all shapes at once, a spindle torus.
    let pose = Isometry {
        translation: Vec3::new(0.0, 0.0, 0.05),
        ..Isometry::IDENTITY
    };
    let parts = [
        Part {
            shape: Shape::Torus {
                major: 0.01,
                minor: 0.03,
            },
            pose,
        },
        Part {
            shape: Shape::Torus {
                major: 0.0,
                minor: 0.02,
            },
            pose,
        },
        Part {
            shape: Shape::Cone {
                radius: 0.2,
                height: 1e-3,
            },
            pose,
        },
    ];
    let tiny = Intrinsics {
        width: 3,
        height: 1,
        fx: 1.0,
        fy: 1.0,
        cx: 1.0,
        cy: 0.0,
    };
    let (mut d3, mut m3) = ([0u16; 3], [0u8; 3]);
    render(
        &SynthScene {
            parts: &parts,
            ..scene
        },
        &tiny,
        &mut d3,
        &mut m3,
    )
    .unwrap();
    render(
        &SynthScene {
            parts: &parts,
            ..scene
        },
        &K,
        &mut depth,
        &mut mask,
    )
    .unwrap();
}

/// Number of 4-connected components of the mask.
fn components(mask: &[u8]) -> usize {
    let mut seen = vec![false; N];
    let mut count = 0;
    for start in 0..N {
        if mask[start] == 0 || seen[start] {
            continue;
        }
        count += 1;
        let mut stack = vec![start];
        seen[start] = true;
        while let Some(i) = stack.pop() {
            let (u, v) = (i % 320, i / 320);
            let mut push = |j: usize| {
                if mask[j] != 0 && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if u > 0 {
                push(i - 1);
            }
            if u < 319 {
                push(i + 1);
            }
            if v > 0 {
                push(i - 320);
            }
            if v < 239 {
                push(i + 320);
            }
        }
    }
    count
}

#[test]
fn ready_made_objects_are_well_seen_in_the_builtin_view() {
    for object in &OBJECTS {
        let (depth, mask, r) = render_vec(&object.scene(BUILTIN_VIEW, Noise::kinect(1)));
        assert!(
            r.valid_object_pixels >= 300,
            "{}: {}",
            object.name,
            r.valid_object_pixels
        );
        assert_eq!(
            components(&mask),
            1,
            "{}: the object is one piece",
            object.name
        );
        let border = (0..N).any(|i| {
            mask[i] != 0 && (i % 320 == 0 || i % 320 == 319 || !(320..N - 320).contains(&i))
        });
        assert!(!border, "{} leaves the image", object.name);
        let table_readings = (0..N).filter(|&i| mask[i] == 0 && depth[i] != 0).count();
        assert!(table_readings > 10_000, "{}", object.name);
        println!(
            "{}: {} object pixels, {} valid",
            object.name, r.object_pixels, r.valid_object_pixels
        );
    }
    let builtin = builtin_scene();
    assert_eq!(builtin.parts, can());
    assert_eq!(builtin.view, BUILTIN_VIEW);
}

/// How badly `map` maps the samples onto the object: the mean of `min(|distance|, 1 cm)`, the
/// fraction of samples mapped more than 1 mm off the surface, and the worst distance.
fn misfit(parts: &[Part], samples: &[Vec3], map: &Isometry) -> (f32, f32, f32) {
    let mut sum = 0.0;
    let mut off = 0;
    let mut worst = 0.0f32;
    for p in samples {
        let d = signed_distance(parts, map.apply(*p)).abs();
        sum += d.min(0.01);
        off += (d > 1e-3) as usize;
        worst = worst.max(d);
    }
    let n = samples.len() as f32;
    (sum / n, off as f32 / n, worst)
}

fn check_symmetry(name: &str, parts: &[Part], samples: &[Vec3], symmetry: &Symmetry) {
    let maps = symmetry.maps(Sampling::default());
    for (map, _) in &maps.maps {
        let (mean, _, worst) = misfit(parts, samples, map);
        assert!(
            worst < 1e-4,
            "{name}: {symmetry:?} maps a surface point {worst} m off the surface (mean {mean})"
        );
    }
}

#[test]
fn documented_symmetries_map_each_object_onto_itself() {
    for object in OBJECTS.iter().chain(&LYING_OBJECTS) {
        let samples = surface_samples(object, 1500);
        assert!(samples.len() > 500, "{}", object.name);
        if let Some(s) = &object.symmetry {
            check_symmetry(object.name, object.parts, &samples, s);
        }
        for ps in object.part_symmetries {
            let part = &object.parts[ps.part..ps.part + 1];
            // The part's visible surface: samples on it (not only on another part).
            let own: Vec<Vec3> = samples
                .iter()
                .copied()
                .filter(|p| signed_distance(part, *p).abs() < 2e-5)
                .collect();
            assert!(
                own.len() > 50,
                "{} part {}: {}",
                object.name,
                ps.part,
                own.len()
            );
            check_symmetry(object.name, part, &own, &ps.symmetry);
        }
    }
}

#[test]
fn mug_handle_stays_out_of_the_cup() {
    let mug = object("mug").unwrap();
    let view = View {
        distance: 0.4,
        elevation_deg: 90.0,
        azimuth_deg: 0.0,
        roll_deg: 0.0,
    };
    let scene = SynthScene {
        depth_scale: 1e-5,
        ..mug.scene(view, Noise::OFF)
    };
    let (depth, mask, r) = render_vec(&scene);
    let points = object_points(&scene, &depth, &mask, &r);
    let mut floor = 0;
    for p in &points {
        if (p.x * p.x + p.y * p.y).sqrt() < 0.0299 {
            assert!(
                (p.z - 0.01).abs() < 1e-4,
                "inside the cup, above the floor: {p:?}"
            );
            floor += 1;
        }
    }
    assert!(floor > 500, "{floor}");
}

#[test]
fn symmetries_follow_the_object_into_the_camera_frame() {
    let object = object("two_plane_object").unwrap();
    let view = View {
        distance: 0.5,
        elevation_deg: 40.0,
        azimuth_deg: 77.0,
        roll_deg: 3.0,
    };
    let scene = SynthScene {
        depth_scale: 1e-5,
        ..object.scene(view, Noise::OFF)
    };
    let (depth, mask, r) = render_vec(&scene);
    let to_object = inverse(&r.object_to_camera);
    let in_camera = transform_symmetry(&object.symmetry.unwrap(), &r.object_to_camera);
    let Symmetry::DualPlane(planes) = in_camera else {
        panic!()
    };
    for plane in planes {
        assert!((plane.n().length() - 1.0).abs() < 1e-5);
    }
    // Camera-frame points reflected through the camera-frame planes stay on the object.
    for i in (0..N).filter(|&i| mask[i] == 255).step_by(7) {
        let p = unproject(i, depth[i], scene.depth_scale);
        for plane in &planes {
            let q = to_object.apply(plane.reflect(p));
            assert!(signed_distance(object.parts, q).abs() < 1e-4);
        }
    }
}

/// Centre of mass of the solid (grid of 1.5 mm cells).
fn volume_centroid(object: &ReadyObject) -> Vec3 {
    let h = 0.0015;
    let (lo, hi) = (
        Vec3::from_array(object.bounds_min),
        Vec3::from_array(object.bounds_max),
    );
    let n = ((hi - lo) / h).ceil();
    let (mut sum, mut count) = (Vec3::ZERO, 0u32);
    for i in 0..n.x as u32 {
        for j in 0..n.y as u32 {
            for k in 0..n.z as u32 {
                let p = lo + Vec3::new(i as f32 + 0.5, j as f32 + 0.5, k as f32 + 0.5) * h;
                if signed_distance(object.parts, p) < 0.0 {
                    sum += p;
                    count += 1;
                }
            }
        }
    }
    sum / count as f32
}

/// The symmetries an object must NOT have: every mirror plane and every 2-fold axis through its
/// centre of mass (a symmetry fixes it), and the inversion through it, except those the
/// documentation lists (within 5°). Reports the best fit of a forbidden element.
#[test]
fn objects_have_no_undocumented_symmetry() {
    let directions = 3000;
    for name in [
        "point_reflection_object",
        "line_reflection_object",
        "asymmetric_object",
        "mug",
        "two_plane_object",
        "bent_rod_tilted",
    ] {
        let object = object(name).unwrap();
        let samples = surface_samples(object, 400);
        let c = volume_centroid(object);
        // The documented mirror-plane normals and 2-fold axis directions, and whether the
        // inversion through the centre of mass is documented.
        let (planes, axes, centre_ok): (Vec<Vec3>, Vec<Vec3>, bool) = match object.symmetry {
            None => (vec![], vec![], false),
            Some(Symmetry::PointReflection(_)) => (vec![], vec![], true),
            Some(Symmetry::LineReflection(a)) => (vec![], vec![a.d()], false),
            Some(Symmetry::PlaneReflection(p)) => (vec![p.n()], vec![], false),
            Some(Symmetry::DualPlane([p1, p2])) => {
                (vec![p1.n(), p2.n()], vec![p1.n().cross(p2.n())], false)
            }
            Some(other) => panic!("{name}: no forbidden-element check for {other:?}"),
        };
        let allowed = |d: Vec3, list: &[Vec3]| {
            list.iter()
                .any(|a| a.dot(d).abs() > 5f32.to_radians().cos())
        };
        // (mean misfit, fraction off) of the best-fitting forbidden plane and axis.
        let mut best_plane = (f32::INFINITY, f32::INFINITY);
        let mut best_axis = (f32::INFINITY, f32::INFINITY);
        let keep_best = |best: &mut (f32, f32), (mean, off, _): (f32, f32, f32)| {
            best.0 = best.0.min(mean);
            best.1 = best.1.min(off);
        };
        for i in 0..directions {
            let d = hemisphere_direction(i, directions);
            if !allowed(d, &planes) {
                let plane = Plane::through(c, d);
                let n = plane.n();
                let linear = Mat3::IDENTITY - Mat3::from_cols(n * n.x, n * n.y, n * n.z) * 2.0;
                let map = Isometry {
                    linear,
                    translation: n * (2.0 * plane.offset),
                };
                keep_best(&mut best_plane, misfit(object.parts, &samples, &map));
            }
            if !allowed(d, &axes) {
                let map = Isometry::rotation_about(rotation(d, core::f32::consts::PI), c);
                keep_best(&mut best_axis, misfit(object.parts, &samples, &map));
            }
        }
        let inversion = Isometry {
            linear: -Mat3::IDENTITY,
            translation: c * 2.0,
        };
        let (inv_mean, inv_off, _) = misfit(object.parts, &samples, &inversion);
        println!(
            "{name}: best forbidden plane {:.4} m / {:.3} off, axis {:.4} m / {:.3} off, inversion {inv_mean:.4} m / {inv_off:.3} off",
            best_plane.0, best_plane.1, best_axis.0, best_axis.1
        );
        assert!(
            best_plane.1 > 0.05 && best_axis.1 > 0.05,
            "{name}: plane {best_plane:?} axis {best_axis:?}"
        );
        if centre_ok {
            assert!(inv_off == 0.0, "{name}: {inv_mean}");
            let documented = object.symmetry.unwrap().center().unwrap();
            assert!((Vec3::from_array(documented) - c).length() < 1e-3);
        } else {
            assert!(inv_off > 0.1, "{name}: inversion {inv_mean} {inv_off}");
        }
    }
}
