//! Part symmetries (the middle loop, `DomainConfig::parts`) on synthetic objects made of parts:
//! each part's symmetry is found with the domain it explains.
//!
//! A sampled point belongs to the part whose surface is nearest to it. A domain **covers** a part
//! when it holds at least 80 % of the part's sampled points, and **strays** by the share of its
//! points that belong to other parts (less than 10 % asked). Axes and planes within 3° and 10 mm
//! of the part's true ones (as for whole objects), measured at the centroid of the part's
//! visible points.

use sfs_testkit::synth::{
    BUILTIN_INTRINSICS, Noise, ReadyObject, SENSOR, View, object, render, signed_distance,
    transform_symmetry,
};
use shape_from_symmetry::math::{Isometry, Vec3};
use shape_from_symmetry::{
    CompletedPoint, Config, Engine, Provenance, Report, Scene, Status, Symmetry, SymmetryType,
    TypeSet,
};

const K: shape_from_symmetry::Intrinsics = BUILTIN_INTRINSICS;
/// Largest angle (degrees) between a found plane normal or axis and the part's: as for whole
/// objects (`tests/recovery.rs`).
const ANGLE_TOL_DEG: f32 = 3.0;
/// Largest distance (metres) between a found element and the part's, at the part's visible
/// points' centroid: as for whole objects.
const DIST_TOL: f32 = 0.01;

/// Distance of `p` (camera frame) to the surface of `object`'s part `part`.
fn surface_distance(object: &ReadyObject, to_camera: &Isometry, part: usize, p: Vec3) -> f32 {
    let q = to_camera.linear.transpose() * (p - to_camera.translation);
    signed_distance(&object.parts[part..=part], q).abs()
}

fn dir(axis: &shape_from_symmetry::Axis) -> Vec3 {
    Vec3::from_array(axis.direction)
}

/// What a search of a synthetic object found.
struct Outcome {
    report: Report,
    points: Vec<CompletedPoint>,
    /// The part of each visible point (the completion's, written first).
    part_of: Vec<usize>,
    /// The sampled points the search saw (a domain counts its points among them).
    sampled: usize,
    /// The true part symmetries, in the camera frame.
    truth: Vec<(usize, Symmetry)>,
    object: &'static ReadyObject,
    to_camera: Isometry,
}

fn view(elevation_deg: f32, azimuth_deg: f32) -> View {
    View {
        distance: 0.5,
        elevation_deg,
        azimuth_deg,
        roll_deg: 0.0,
    }
}

/// Every type but the dual and triple planes: the hammer lying on the table has a dual plane as
/// a whole (one plane along its handle, one level), which leaves no part to carve; without it
/// the whole hammer gets one mirror plane, and its handle is carved out as an axial part.
fn without_duals() -> TypeSet {
    use SymmetryType as T;
    TypeSet::of(&[
        T::PlaneReflection,
        T::LineReflection,
        T::PointReflection,
        T::Axial,
        T::Spherical,
        T::AxialPlane,
    ])
}

fn parts_config(types: TypeSet) -> Config {
    let mut config = Config::DEFAULT.with_types(types);
    config.domains.parts = true;
    config
}

/// `name` seen from (`elevation`, `azimuth`) searched for `types` without parts, then with;
/// both on the sampling lattice alone (a part search does not sample the outline,
/// `PrepareConfig::outline`).
fn without_and_with_parts(
    name: &str,
    elevation: f32,
    azimuth: f32,
    types: TypeSet,
) -> (Outcome, Outcome) {
    let mut lattice = Config::DEFAULT.with_types(types);
    lattice.prepare.outline = false;
    let whole = search(name, view(elevation, azimuth), lattice, |_| 50_000);
    let config = parts_config(types);
    (
        whole,
        search(name, view(elevation, azimuth), config, |_| 50_000),
    )
}

/// Render `name` from `view` and search it with `config` and the renderer's sensor
/// (`synth::SENSOR`), `budget` units a poll.
fn search(name: &str, view: View, config: Config, budget: impl Fn(u32) -> u32) -> Outcome {
    let config = Config {
        sensor: SENSOR,
        ..config
    };
    let object: &ReadyObject = object(name).expect("a synthetic object");
    let scene = object.scene(view, Noise::kinect(7));
    let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
    let rendered = render(&scene, &K, &mut depth, &mut mask).expect("the object renders");
    let mut out = vec![CompletedPoint::ZERO; 20_000];
    let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
    let input = Scene {
        depth: &depth,
        depth_scale: 0.001,
        intrinsics: K,
        table: Some(rendered.table),
        mask: Some(&mask),
        target: None,
    };
    engine.start(input, &mut out).expect("a valid scene");
    let mut poll = 0;
    while engine.poll(budget(poll)).expect("the search runs") != Status::Done {
        poll += 1;
    }
    let to_camera = rendered.object_to_camera;
    let distance = |part: usize, p: Vec3| surface_distance(object, &to_camera, part, p);
    // The completed visible points (written first): each tagged with its domain's symmetry.
    let part_of = engine
        .points()
        .iter()
        .take_while(|p| p.provenance == Provenance::Visible)
        .map(|p| {
            let p = Vec3::from_array(p.position);
            (0..object.parts.len())
                .min_by(|&a, &b| distance(a, p).total_cmp(&distance(b, p)))
                .expect("an object has parts")
        })
        .collect();
    let truth = object
        .part_symmetries
        .iter()
        .map(|s| (s.part, transform_symmetry(&s.symmetry, &to_camera)))
        .collect();
    Outcome {
        report: engine.report().clone(),
        points: engine.points().to_vec(),
        part_of,
        sampled: engine.object_points().len(),
        truth,
        object,
        to_camera,
    }
}

impl Outcome {
    /// Points of `parts` in the domain of symmetry `index`, the domain's size, the parts' size.
    fn overlap(&self, index: usize, parts: &[usize]) -> (usize, usize, usize) {
        let visible = &self.points[..self.part_of.len()];
        let in_domain = |j: usize| visible[j].symmetry as usize == index;
        let domain = (0..visible.len()).filter(|&j| in_domain(j)).count();
        let shared = (0..visible.len())
            .filter(|&j| in_domain(j) && parts.contains(&self.part_of[j]))
            .count();
        let size = self.part_of.iter().filter(|p| parts.contains(p)).count();
        (shared, domain, size)
    }

    /// The symmetry whose domain covers `parts` (at least 80 % of their points, less than 10 %
    /// of the domain elsewhere), if one does.
    fn covering(&self, parts: &[usize]) -> Option<&Symmetry> {
        (0..self.report.symmetries.len())
            .find(|&i| {
                let (shared, domain, size) = self.overlap(i, parts);
                shared * 10 >= size * 8 && (domain - shared) * 10 < domain
            })
            .map(|i| &self.report.symmetries[i].symmetry)
    }

    fn true_symmetry(&self, part: usize) -> &Symmetry {
        &self
            .truth
            .iter()
            .find(|(p, _)| *p == part)
            .expect("a part symmetry")
            .1
    }

    /// The centroid of the visible points of `part`.
    fn centroid(&self, part: usize) -> Vec3 {
        let points = (0..self.part_of.len()).filter(|&j| self.part_of[j] == part);
        let (sum, n) = points.fold((Vec3::ZERO, 0.0), |(s, n), j| {
            (s + Vec3::from_array(self.points[j].position), n + 1.0)
        });
        sum / n
    }

    /// Assert that a domain covers `parts` (the first of them and those coaxial with it) with an
    /// axis near the first part's true one.
    fn assert_axial_part(&self, parts: &[usize], kinds: &[SymmetryType]) {
        let part = parts[0];
        let found = self
            .covering(parts)
            .unwrap_or_else(|| panic!("no domain covers part {part}: {}", self.describe()));
        assert!(kinds.contains(&found.kind()), "part {part}: {found:?}");
        let (axis, truth) = (found.axis().expect("an axis"), self.true_symmetry(part));
        let true_axis = truth.axis().expect("a true axis");
        let (d, t) = (dir(axis), dir(true_axis));
        let degrees = d.dot(t).abs().min(1.0).acos().to_degrees();
        let c = self.centroid(part);
        let foot = |a: &shape_from_symmetry::Axis| {
            let (p, u) = (Vec3::from_array(a.point), dir(a));
            p + u * (c - p).dot(u)
        };
        let offset = (foot(axis) - foot(true_axis)).length();
        assert!(
            degrees < ANGLE_TOL_DEG && offset < DIST_TOL,
            "part {part}: axis {degrees:.2}° / {:.1} mm off",
            offset * 1e3
        );
    }

    /// Assert that a domain covers `part` with mirror planes of the part: each plane takes the
    /// part's visible points onto the part's surface (mean distance at most 4 mm, 90 % within
    /// 8 mm, as the evaluation's validity test; the planes listed in the truth are not all of a
    /// box's with a square section).
    fn assert_plane_part(&self, part: usize) {
        let found = self
            .covering(&[part])
            .unwrap_or_else(|| panic!("no domain covers part {part}: {}", self.describe()));
        let planes = found.planes();
        assert!(!planes.is_empty(), "part {part}: {found:?}");
        let sources = (0..self.part_of.len()).filter(|&j| self.part_of[j] == part);
        for plane in planes {
            let mut misses: Vec<f32> = sources
                .clone()
                .map(|j| {
                    let q = plane.reflect(Vec3::from_array(self.points[j].position));
                    surface_distance(self.object, &self.to_camera, part, q)
                })
                .collect();
            misses.sort_by(f32::total_cmp);
            let mean = misses.iter().sum::<f32>() / misses.len() as f32;
            let p90 = misses[misses.len() * 9 / 10];
            assert!(
                mean <= 0.004 && p90 <= 0.008,
                "part {part}: {plane:?} is no plane of the part: mean {:.1} mm, p90 {:.1} mm",
                mean * 1e3,
                p90 * 1e3
            );
        }
    }

    fn describe(&self) -> String {
        let parts = self.part_of.iter().max().map_or(0, |&m| m + 1);
        let domains: Vec<String> = (0..self.report.symmetries.len())
            .map(|i| {
                let per_part: Vec<_> = (0..parts).map(|p| self.overlap(i, &[p]).0).collect();
                format!(
                    "{} {per_part:?}",
                    self.report.symmetries[i].symmetry.kind().name()
                )
            })
            .collect();
        let sizes: Vec<_> = (0..parts).map(|p| self.overlap(0, &[p]).2).collect();
        format!("domains {domains:?}, part sizes {sizes:?}")
    }
}

#[test]
fn hammer_handle_is_axial_and_its_head_mirror_symmetric() {
    // On (45, 30) the best-scoring rejected axis turns the whole hammer behind itself: it grows
    // no part, and the handle's axis, offered next, does. The head, the rest of the hammer,
    // keeps the whole hammer's plane, one of the head's. Known gap: on (30, 0) the handle's
    // axis is found (0.4°), but its domain takes 144 of the head's points and the rest of the
    // head is split in two.
    for (elevation, azimuth) in [(60.0, 260.0), (30.0, 150.0), (45.0, 30.0)] {
        let found = search(
            "hammer",
            view(elevation, azimuth),
            parts_config(without_duals()),
            |_| 50_000,
        );
        found.assert_axial_part(&[0], &[SymmetryType::Axial, SymmetryType::AxialPlane]);
        found.assert_plane_part(1);
    }
}

#[test]
fn figure_searched_with_axial_only_gets_each_of_its_parts() {
    let axial = TypeSet::of(&[SymmetryType::Axial]);
    // Parts: torso, head, two legs, two arms. The ball head is coaxial with the torso and shares
    // its domain. Each part is found on (30, 0); on (30, 150) the arm on the left (part 4) is
    // not; on (45, 30) the legs are mostly hidden and one arm is found.
    for (elevation, azimuth, parts) in [
        (30.0, 0.0, &[&[0, 1][..], &[2], &[3], &[4], &[5]][..]),
        (30.0, 150.0, &[&[0, 1][..], &[2], &[3], &[5]]),
        (45.0, 30.0, &[&[0, 1][..], &[4]]),
    ] {
        let found = search(
            "figure",
            view(elevation, azimuth),
            parts_config(axial),
            |_| 50_000,
        );
        for part in parts {
            found.assert_axial_part(part, &[SymmetryType::Axial]);
        }
    }
}

#[test]
fn mug_body_is_axial_with_its_base_plane() {
    // On (45, 30) and (60, 260) the handle is in view: the body is a part of the mug (on
    // (60, 260) one carved out of the whole mug's triple plane).
    for (elevation, azimuth) in [(30.0, 150.0), (45.0, 30.0), (60.0, 260.0)] {
        let found = search(
            "mug",
            view(elevation, azimuth),
            parts_config(TypeSet::ALL),
            |_| 50_000,
        );
        found.assert_axial_part(&[0], &[SymmetryType::AxialPlane]);
    }
}

#[test]
fn mug_handle_is_mirror_symmetric() {
    // On (60, 260) the body is found too (`mug_body_is_axial_with_its_base_plane`). Known gap:
    // on (45, 30) the handle's domain holds 66 of its 84 points (79 %).
    let found = search("mug", view(60.0, 260.0), parts_config(TypeSet::ALL), |_| {
        50_000
    });
    found.assert_plane_part(1);
}

#[test]
fn without_parts_the_whole_object_is_the_only_domain() {
    let found = search("hammer", view(60.0, 260.0), Config::DEFAULT, |_| 50_000);
    assert_eq!(found.report.symmetries.len(), 1, "{}", found.describe());
    let whole = found.report.symmetries[0].domain_points;
    assert_eq!(whole as usize, found.sampled);
}

#[test]
fn a_whole_symmetric_object_is_completed_as_without_parts() {
    // The ball's spherical symmetry, accepted on the whole ball, claims every point it does not
    // contradict: all of them. Nothing is left to search, and the completion is the one a
    // search without parts makes.
    let generated = |found: &Outcome| -> Vec<[u32; 3]> {
        let points = found.points.iter();
        let generated = points.filter(|p| p.provenance == Provenance::Generated);
        generated.map(|p| p.position.map(f32::to_bits)).collect()
    };
    let (whole, parts) = without_and_with_parts("ball", 30.0, 0.0, TypeSet::ALL);
    let [domain] = &parts.report.symmetries[..] else {
        panic!("one domain: {}", parts.describe());
    };
    assert_eq!(domain.domain_points as usize, parts.sampled);
    assert_eq!(domain.symmetry, whole.report.symmetries[0].symmetry);
    assert_eq!(generated(&parts), generated(&whole));
}

#[test]
fn the_rest_of_a_domain_carved_for_a_part_keeps_the_domains_symmetry() {
    // The hammer on (60, 260): the whole hammer gets a mirror plane, its handle is carved out
    // of it as an axial part, and the head, the rest, keeps the hammer's plane (searched as a
    // domain of its own, it passed as a triple plane), refined over the head's points alone:
    // the same plane as the whole hammer's within the tolerances of a found one.
    let (whole, parts) = without_and_with_parts("hammer", 60.0, 260.0, without_duals());
    let Symmetry::PlaneReflection(plane) = whole.report.symmetries[0].symmetry else {
        panic!("a mirror plane: {}", whole.describe());
    };
    parts.assert_axial_part(&[0], &[SymmetryType::Axial]);
    let Some(Symmetry::PlaneReflection(kept)) = parts.covering(&[1]) else {
        panic!("the head keeps a mirror plane: {}", parts.describe());
    };
    let visible = whole
        .points
        .iter()
        .filter(|p| p.provenance == Provenance::Visible);
    let (sum, n) = visible.fold((Vec3::ZERO, 0.0), |(s, n), p| {
        (s + Vec3::from_array(p.position), n + 1.0)
    });
    let centroid = sum / n;
    let (a, b) = (
        Vec3::from_array(plane.normal),
        Vec3::from_array(kept.normal),
    );
    let angle = a.dot(b).clamp(-1.0, 1.0).acos().to_degrees();
    let apart = (b.dot(centroid) - kept.offset - (a.dot(centroid) - plane.offset)).abs();
    assert!(
        angle < ANGLE_TOL_DEG && apart < DIST_TOL,
        "{angle}° {apart} m apart"
    );
}

#[test]
fn points_of_no_domain_are_completed_through_the_whole_objects_symmetry() {
    // The hammer on (45, 30): its handle's axis, found on a part carved out of the whole
    // hammer, claims the points it explains; the rest of the hammer keeps the whole hammer's
    // mirror plane where the plane does not contradict it; the points left are of no domain,
    // and are completed through the whole hammer's plane, as without parts (they were
    // completed through the first symmetry found, the handle's axis).
    let (whole, found) = without_and_with_parts("hammer", 45.0, 30.0, without_duals());
    let visible = &found.points[..found.part_of.len()];
    let orphans: Vec<Vec3> = visible
        .iter()
        .filter(|p| p.symmetry == u8::MAX)
        .map(|p| Vec3::from_array(p.position))
        .collect();
    assert!(!orphans.is_empty(), "{}", found.describe());
    let generated: std::collections::HashSet<[u32; 3]> = found
        .points
        .iter()
        .filter(|p| p.provenance == Provenance::Generated)
        .map(|p| p.position.map(f32::to_bits))
        .collect();
    // The whole hammer's plane, as the part search kept it for the rest of the hammer: each
    // symmetry is refined over its own domain (there the rest, here the whole hammer), so the
    // two may differ by a fraction of a millimetre.
    let whole_plane = whole.report.symmetries[0].symmetry;
    let same = |s: &Symmetry| match (s, &whole_plane) {
        (Symmetry::PlaneReflection(p), Symmetry::PlaneReflection(q)) => {
            let cos = Vec3::from_array(p.normal).dot(Vec3::from_array(q.normal));
            let degrees = cos.abs().min(1.0).acos().to_degrees();
            degrees < ANGLE_TOL_DEG && (p.offset - q.offset * cos.signum()).abs() < DIST_TOL
        }
        _ => false,
    };
    let object = (found.report.symmetries.iter().map(|f| f.symmetry))
        .find(same)
        .unwrap_or_else(|| panic!("the whole hammer's plane is kept: {}", found.describe()));
    let maps = object.maps(Config::DEFAULT.sampling).maps;
    let completed = orphans
        .iter()
        .filter(|&&p| {
            maps.iter()
                .any(|(m, _)| generated.contains(&m.apply(p).to_array().map(f32::to_bits)))
        })
        .count();
    // The others' images land where a point is already kept or in free space; without the
    // whole hammer's plane none would be generated.
    assert!(
        completed > 0,
        "none of {} points of no domain completed",
        orphans.len()
    );
}

#[test]
fn each_domain_is_completed_through_its_own_symmetry() {
    let found = search(
        "hammer",
        view(60.0, 260.0),
        parts_config(without_duals()),
        |_| 50_000,
    );
    let count = found.report.symmetries.len();
    assert!(count >= 2, "{}", found.describe());
    for index in 0..count {
        let generated = found
            .points
            .iter()
            .filter(|p| p.provenance == Provenance::Generated && p.symmetry as usize == index);
        assert!(generated.count() > 0, "symmetry {index} generated nothing");
    }
    let domains: u32 = found
        .report
        .symmetries
        .iter()
        .map(|f| f.domain_points)
        .sum();
    assert!(domains as usize <= found.sampled);
}

#[test]
fn domain_search_is_bit_identical_however_sliced() {
    let bits = |budget: fn(u32) -> u32| {
        let found = search(
            "hammer",
            view(30.0, 150.0),
            parts_config(TypeSet::ALL),
            budget,
        );
        let mut bits: Vec<u32> = found
            .points
            .iter()
            .flat_map(|p| {
                p.position
                    .map(f32::to_bits)
                    .into_iter()
                    .chain([p.symmetry as u32])
            })
            .collect();
        for f in &found.report.symmetries {
            bits.extend([f.score.to_bits(), f.domain_points]);
        }
        bits.push(found.report.work_units as u32);
        bits
    };
    let whole = bits(|_| u32::MAX);
    assert_eq!(bits(|_| 1), whole);
    assert_eq!(bits(|poll| 1 + poll % 13), whole);
}
