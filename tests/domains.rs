//! Part symmetries (the middle loop, `DomainConfig::parts`) on synthetic objects made of parts:
//! each part's symmetry is found with the domain it explains (`sfs_testkit::parts`: what covers
//! a part, the tolerances, and the cases with what each check claims over its noise draws,
//! asserted here; `examples/parts.rs` tabulates the same counts).

use sfs_testkit::parts::{
    self, ANGLE_TOL_DEG, Camera, Case, DIST_TOL, DRAWS, Outcome, TEST_SEED, parts_config, search,
    view, without_duals,
};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Config, Provenance, Symmetry, SymmetryType, TypeSet};

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
    let whole = search(name, view(elevation, azimuth), lattice, TEST_SEED, |_| {
        50_000
    });
    let config = parts_config(types);
    (
        whole,
        search(name, view(elevation, azimuth), config, TEST_SEED, |_| {
            50_000
        }),
    )
}

/// Every check of every view of `case`, read by `camera`, holds on at least as many of the noise
/// draws as it claims (`Claim::least`); a failure lists how the check failed on each draw.
fn assert_case(case: &Case, camera: Camera) {
    for (index, &(elevation, azimuth, checks)) in case.views.iter().enumerate() {
        let mut failures = Vec::new();
        let held = case.held(index, camera, |seed, check, how| {
            failures.push((check.label(), format!("draw {seed}: {how}")))
        });
        for (&(check, claim), held) in checks.iter().zip(held) {
            let label = check.label();
            let how: Vec<&str> = failures
                .iter()
                .filter(|(l, _)| *l == label)
                .map(|(_, how)| how.as_str())
                .collect();
            assert!(
                held >= claim.least(),
                "{label} on ({elevation}, {azimuth}) claims {} (at least {} of {DRAWS} draws) \
                 and holds on {held}:\n{}",
                claim.name(),
                claim.least(),
                how.join("\n")
            );
        }
    }
}

#[test]
fn hammer_handle_is_axial_and_its_head_mirror_symmetric() {
    assert_case(&parts::HAMMER, Camera::Axial);
}

#[test]
fn figure_searched_with_axial_only_gets_each_of_its_parts() {
    assert_case(&parts::FIGURE, Camera::Axial);
}

#[test]
fn mug_body_is_axial_with_its_base_plane() {
    assert_case(&parts::MUG_BODY, Camera::Axial);
}

/// With the lateral noise of a structured-light camera too (a thin part's silhouette pixels read
/// the background), the mug's body is still carved out with its axis; the hammer's and the
/// figure's parts mostly are not (`docs/figures.md`, part symmetries).
#[test]
fn mug_body_is_axial_with_its_base_plane_under_lateral_noise() {
    assert_case(&parts::MUG_BODY, Camera::Lateral);
}

#[test]
fn mug_handle_is_mirror_symmetric() {
    assert_case(&parts::MUG_HANDLE, Camera::Axial);
}

#[test]
fn without_parts_the_whole_object_is_the_only_domain() {
    let found = search(
        "hammer",
        view(60.0, 260.0),
        Config::DEFAULT,
        TEST_SEED,
        |_| 50_000,
    );
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
    (parts.axial_part(&[0], &[SymmetryType::Axial])).unwrap_or_else(|why| panic!("{why}"));
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
        TEST_SEED,
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
            TEST_SEED,
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
