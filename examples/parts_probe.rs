//! Measures the domain search on a synthetic object of parts from four views: each symmetry
//! found, how its domain splits among the parts and, for an axis, its angle to the nearest true
//! part axis.
//! `cargo run --release --example parts_probe -- hammer|figure|mug [whole] [min_leftover]`; env
//! `TYPES=axial`, `MIN_SHARE`, `KEEP_PARTS=n` (render only the first n parts).
use sfs_testkit::synth::*;
use shape_from_symmetry::*;

fn run(name: &str, view: View, seed: u32, parts: bool, min_leftover: f32) {
    let object = sfs_testkit::synth::object(name).unwrap();
    let k = BUILTIN_INTRINSICS;
    let mut scene = object.scene(view, Noise::kinect(seed));
    if let Ok(n) = std::env::var("KEEP_PARTS") {
        let n: usize = n.parse().unwrap();
        scene.parts = &object.parts[..n];
    }
    let mut depth = vec![0u16; k.pixel_count()];
    let mut mask = vec![0u8; k.pixel_count()];
    let r = render(&scene, &k, &mut depth, &mut mask).unwrap();
    let mut out = vec![CompletedPoint::ZERO; 20000];
    let mut config = Config::DEFAULT;
    config.domains.parts = parts;
    config.domains.min_leftover = min_leftover;
    if let Ok(share) = std::env::var("MIN_SHARE") {
        config.domains.min_share = share.parse().unwrap();
    }
    if let Ok(types) = std::env::var("TYPES") {
        config.types = if types == "axial" {
            TypeSet::of(&[SymmetryType::Axial])
        } else {
            TypeSet::ALL
        };
    }
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
    let s = scene.input(k, (&depth, &mask), &r);
    engine.start(s, &mut out).unwrap();
    while engine.poll(5000).unwrap() != Status::Done {}
    let rep = engine.report().clone();
    for ps in object.part_symmetries {
        eprintln!(
            "TRUE part {} {:?} score {:?}",
            ps.part,
            transform_symmetry(&ps.symmetry, &r.object_to_camera),
            engine.score(&transform_symmetry(&ps.symmetry, &r.object_to_camera))
        );
    }
    // Part of each sampled point: the part whose surface is nearest (object frame).
    let m = r.object_to_camera;
    let rt = m.linear.transpose();
    let pts = engine.object_points();
    let nparts = object.parts.len();
    let part_of: Vec<usize> = pts
        .iter()
        .map(|p| {
            let q = rt * (*p - m.translation);
            (0..nparts)
                .min_by(|&a, &b| {
                    signed_distance(&object.parts[a..a + 1], q)
                        .abs()
                        .total_cmp(&signed_distance(&object.parts[b..b + 1], q).abs())
                })
                .unwrap()
        })
        .collect();
    let owners: Vec<u8> = engine.points()[..pts.len()]
        .iter()
        .map(|c| c.symmetry)
        .collect();
    print!(
        "{name} el{} az{} parts={parts}: ",
        view.elevation_deg, view.azimuth_deg
    );
    for (i, f) in rep.symmetries.iter().enumerate() {
        let mut per_part = vec![0; nparts];
        for (j, &o) in owners.iter().enumerate() {
            if o as usize == i {
                per_part[part_of[j]] += 1;
            }
        }
        // The angle (degrees) to the nearest true part axis, for a symmetry with an axis.
        let off = f.symmetry.axis().map(|a| {
            let d = math::Vec3::from_array(a.direction);
            object
                .part_symmetries
                .iter()
                .filter_map(|ps| {
                    let t = transform_symmetry(&ps.symmetry, &r.object_to_camera);
                    let t = math::Vec3::from_array(t.axis()?.direction);
                    Some(d.dot(t).abs().min(1.0).acos().to_degrees())
                })
                .fold(f32::INFINITY, f32::min)
        });
        print!(
            "[{} {:.2} n{} parts{:?}{}] ",
            f.symmetry.kind().name(),
            f.score,
            f.domain_points,
            per_part,
            off.map_or(String::new(), |o| format!(" {o:.1}°"))
        );
    }
    let mut totals = vec![0; nparts];
    for &p in &part_of {
        totals[p] += 1;
    }
    println!(
        "| part sizes {totals:?} gen {} drop {} work {}",
        rep.points_generated, rep.points_dropped, rep.work_units
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("mug");
    let parts = args.get(1).map(|a| a != "whole").unwrap_or(true);
    let min_leftover: f32 = args.get(2).map(|a| a.parse().unwrap()).unwrap_or(0.08);
    for (el, az) in [(45.0, 30.0), (30.0, 150.0), (60.0, 260.0), (30.0, 0.0)] {
        let view = View {
            distance: 0.5,
            elevation_deg: el,
            azimuth_deg: az,
            roll_deg: 0.0,
        };
        run(name, view, 7, parts, min_leftover);
    }
}
