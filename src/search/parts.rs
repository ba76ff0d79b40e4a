//! The part rules (paper section 5.3): when a domain is narrowed to a part, when a symmetry
//! found on a part is kept, and which symmetries of leftover points count.
//!
//! - **Decomposition** ([`decomposes`]): a domain is narrowed to an axial part only when the
//!   whole domain got nothing or only symmetries an axis entails (planes through it or normal to
//!   it, a half turn about it): an axial part of an object that has a mirror plane, two, three,
//!   or nothing. Never in place of a whole-domain symmetry that an axis does not entail (a
//!   spherical one, or an axis: the axial node's own results). A mug's handle breaks its body's
//!   axial symmetry: the whole mug gets a mirror plane or three, its body an axis.
//! - **A part's axis** ([`Judge::is_part`]) must refine the proposal the part was grown for
//!   (within a grid spacing of it over the part: the part was grown for that proposal, not for
//!   whatever axis a climb on it finds) and agree with what the whole domain got (each of its maps
//!   takes the axis onto itself: the part's symmetry then refines the wider one; an axis the
//!   wider symmetry moves contradicts it, and the wider domain's symmetry, found on more points,
//!   stands).
//! - **Leftovers** ([`Judge::shares_mirror`]): when nothing was carved out of the whole object,
//!   the points its symmetry contradicts are searched for symmetries that share a mirror plane
//!   with it: the appendage of an object symmetric as a whole lies on or across its mirror
//!   planes (a mug's handle is mirror symmetric about a plane through the body's axis).
//!
//! Two symmetries fitted to within the finest match σ each may disagree by twice that: every
//! tolerance here is 2σ. Cost: a few isometries applied to a few points per rule.

use super::family::Frame;
use super::params::Candidate;
use crate::math::Vec3;
use crate::symmetry::{Sampling, Symmetry, SymmetryType, TypeSet};
use crate::{Axis, Plane};

/// A narrowed domain on trial: what it was carved out of, and for which proposal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Trial {
    /// The frame of the domain the narrowing started from.
    pub wider: Frame,
    /// The proposal the narrowed domain was grown for.
    pub proposal: Symmetry,
    /// What the wider domain's walk got before it was narrowed.
    pub wider_best: Option<Candidate>,
}

/// Whether a domain is worth narrowing to an axial part: parts are searched, axes are wanted,
/// and the domain got nothing or only symmetries an axis entails.
pub(crate) fn decomposes(parts: bool, types: TypeSet, best: Option<&Candidate>) -> bool {
    use SymmetryType as T;
    let axial = [T::Axial, T::AxialPlane, T::Spherical];
    parts
        && axial.iter().any(|&t| types.contains(t))
        && best.is_none_or(|b| {
            matches!(
                b.symmetry.kind(),
                T::PlaneReflection | T::DualPlane | T::TriplePlane | T::LineReflection
            )
        })
}

/// The element of a symmetry of revolution that each plane through is a mirror of it: an axis,
/// or a sphere's centre.
#[derive(Clone, Copy, Debug)]
enum Pivot {
    Axis(Axis),
    Center(Vec3),
}

impl Pivot {
    fn of(symmetry: &Symmetry) -> Option<Self> {
        match symmetry {
            Symmetry::Axial(axis) | Symmetry::AxialPlane(axis, _) => Some(Self::Axis(*axis)),
            Symmetry::Spherical(center) => Some(Self::Center(Vec3::from_array(*center))),
            _ => None,
        }
    }
}

/// The part rules over one domain: its frame (where the rules sample the elements) and the
/// finest match σ (the tolerance).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Judge {
    pub frame: Frame,
    pub sigma_fine: f32,
}

impl Judge {
    /// Whether `found`, the axis found on a narrowed domain, makes it a part: it refines the
    /// trial's proposal to within `spacing` (a free axis's grid spacing on the part) and agrees
    /// with what the wider domain got.
    pub(crate) fn is_part(&self, trial: &Trial, spacing: f32, found: &Symmetry) -> bool {
        self.refines_proposal(&trial.proposal, spacing, found)
            && self.agrees_with_wider(trial.wider_best.as_ref(), found)
    }

    /// Whether a part's axis agrees with what the wider domain got: each map of the wider
    /// domain's symmetry takes the axis onto itself (a mirror plane through the axis or normal
    /// to it, a half-turn about it or across it) over the part's extent (both ends of the axis's
    /// chord through the part's frame).
    fn agrees_with_wider(&self, wider: Option<&Candidate>, part: &Symmetry) -> bool {
        let (Some(wider), Some(axis)) = (wider, part.axis()) else {
            return true;
        };
        let ends = self.chord_ends(axis);
        // A map moves a point by twice its distance from the map's element (a mirror plane, a
        // half-turn's axis): elements within the tolerance of each other move the axis by up to
        // twice it.
        let tolerance = 4.0 * self.tolerance_squared();
        // A part is only carved out of a domain that got reflections (`decomposes`), whose maps
        // do not depend on the sampling of continuous symmetries.
        let maps = wider.symmetry.maps(Sampling::default()).maps;
        maps.iter().all(|(map, _)| {
            ends.iter()
                .all(|&end| axis.distance_squared(map.apply(end)) <= tolerance)
        })
    }

    /// Whether the axis found on a narrowed domain is the proposal's, refined: both ends of the
    /// axis's chord through the part lie within `spacing` of the proposal's axis.
    fn refines_proposal(&self, proposal: &Symmetry, spacing: f32, part: &Symmetry) -> bool {
        let (Some(proposal), Some(axis)) = (proposal.axis(), part.axis()) else {
            return true;
        };
        self.chord_ends(axis)
            .iter()
            .all(|&end| proposal.distance_squared(end) <= spacing * spacing)
    }

    /// Whether `found`, the symmetry of points the whole object's symmetry `object` contradicts,
    /// shares a mirror plane with it: one of its planes is a mirror of `object`, one of the
    /// object's planes is a mirror of it, or both are symmetries of revolution whose axes (or
    /// centres) lie in one plane, which is then a mirror of both. With no object symmetry, any
    /// symmetry counts.
    pub(crate) fn shares_mirror(&self, object: Option<&Symmetry>, found: &Symmetry) -> bool {
        let Some(object) = object else {
            return true;
        };
        let pivots = match (Pivot::of(found), Pivot::of(object)) {
            (Some(Pivot::Axis(a)), Some(Pivot::Axis(b))) => self.coplanar(&a, &b),
            (Some(_), Some(_)) => true,
            _ => false,
        };
        pivots
            || found.planes().iter().any(|p| self.is_mirror(p, object))
            || object.planes().iter().any(|p| self.is_mirror(p, found))
    }

    /// Whether `plane` is a mirror of `symmetry` over the domain: one of its planes (three
    /// points of it around the domain lie on `plane`), or a plane through its axis or centre
    /// of revolution.
    fn is_mirror(&self, plane: &Plane, symmetry: &Symmetry) -> bool {
        let tolerance = self.tolerance_squared();
        let on_plane = |q: Vec3| {
            let d = plane.signed_distance(q);
            d * d <= tolerance
        };
        let planes = symmetry.planes().iter();
        let one_of = planes
            .map(|p| self.plane_points(p))
            .any(|q| q.into_iter().all(on_plane));
        let through = match Pivot::of(symmetry) {
            Some(Pivot::Axis(axis)) => self.chord_ends(&axis).into_iter().all(on_plane),
            Some(Pivot::Center(center)) => on_plane(center),
            None => false,
        };
        one_of || through
    }

    /// Whether two axes lie in one plane: the distance between their lines is within the
    /// tolerance (parallel axes always do).
    fn coplanar(&self, a: &Axis, b: &Axis) -> bool {
        let normal = a.d().cross(b.d());
        let gap = (b.p() - a.p()).dot(normal);
        gap * gap <= self.tolerance_squared() * normal.length_squared()
    }

    /// The square of how far two symmetries' elements may lie apart and be one: each was fitted
    /// to within the finest match σ, so 2σ.
    fn tolerance_squared(&self) -> f32 {
        4.0 * self.sigma_fine * self.sigma_fine
    }

    /// The ends of `axis`'s chord through the domain's frame: ± the frame's radius from the
    /// foot of its centre.
    fn chord_ends(&self, axis: &Axis) -> [Vec3; 2] {
        let middle = Axis::new(axis.d(), axis.p(), self.frame.center).p();
        [-1.0, 1.0].map(|side| middle + axis.d() * (side * self.frame.radius))
    }

    /// Three points of `plane` around the domain: the foot of the frame's centre, and one frame
    /// radius from it along each of two directions in the plane.
    fn plane_points(&self, plane: &Plane) -> [Vec3; 3] {
        let foot = self.frame.center - plane.n() * plane.signed_distance(self.frame.center);
        let (u, v) = crate::math::orthonormal_basis(plane.n());
        [
            foot,
            foot + u * self.frame.radius,
            foot + v * self.frame.radius,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CENTER: Vec3 = Vec3::new(0.0, 0.0, 0.5);

    /// The rules on a part of radius 0.1 m at the finest match σ 3 mm.
    const JUDGE: Judge = Judge {
        frame: Frame {
            center: CENTER,
            radius: 0.1,
        },
        sigma_fine: 0.003,
    };

    fn candidate(symmetry: Symmetry) -> Candidate {
        Candidate {
            symmetry,
            score: 0.5,
            family: 0,
        }
    }

    fn axial(direction: Vec3, through: Vec3) -> Symmetry {
        let direction = crate::math::normalize(direction).unwrap();
        Symmetry::Axial(Axis::new(direction, through, CENTER))
    }

    fn plane(normal: Vec3) -> Plane {
        Plane::through(CENTER, normal)
    }

    fn agrees(wider: Symmetry, part: &Symmetry) -> bool {
        JUDGE.agrees_with_wider(Some(&candidate(wider)), part)
    }

    #[test]
    fn a_part_axis_agrees_with_the_planes_it_lies_in_or_pierces_at_right_angles() {
        let dual = Symmetry::DualPlane([plane(Vec3::X), plane(Vec3::Y)]);
        assert!(agrees(dual, &axial(Vec3::Z, CENTER)));
        // Tilted by 0.5° (the chord's ends 0.9 mm off the plane), or 5 mm beside it: within the
        // two fits' 2σ of it, though the mirror moves the axis by twice that.
        assert!(agrees(dual, &axial(Vec3::new(0.0087, 0.0, 1.0), CENTER)));
        assert!(agrees(dual, &axial(Vec3::Z, CENTER + Vec3::X * 0.005)));
        // 7 mm beside the first plane, or tilted out of it by 5° (8.7 mm at the chord's ends).
        assert!(!agrees(dual, &axial(Vec3::Z, CENTER + Vec3::X * 0.007)));
        assert!(!agrees(dual, &axial(Vec3::new(0.0875, 0.0, 1.0), CENTER)));
        // Normal to a plane: the plane is the axial + plane's own; wherever it pierces it.
        let single = Symmetry::PlaneReflection(plane(Vec3::X));
        assert!(agrees(single, &axial(Vec3::X, CENTER + Vec3::Y * 0.05)));
        assert!(!agrees(single, &axial(Vec3::new(1.0, 0.1, 0.0), CENTER)));
    }

    #[test]
    fn a_part_axis_agrees_with_a_half_turn_about_it_or_across_it() {
        let line = Symmetry::LineReflection(Axis::new(Vec3::Z, CENTER, CENTER));
        assert!(agrees(line, &axial(Vec3::Z, CENTER)));
        assert!(agrees(line, &axial(Vec3::X, CENTER)));
        // Across the line but 10 mm past it: the half-turn moves it 20 mm.
        assert!(!agrees(line, &axial(Vec3::X, CENTER + Vec3::Y * 0.01)));
        // 5 mm past it: within 2σ, though the half-turn moves it 10 mm.
        assert!(agrees(line, &axial(Vec3::X, CENTER + Vec3::Y * 0.005)));
    }

    #[test]
    fn a_part_axis_refines_its_proposal_within_a_grid_spacing() {
        let proposal = axial(Vec3::Z, CENTER);
        // A free axis's grid spacing on a part of radius 0.1 m: 51 mm at the chord's ends.
        let grid = crate::config::SearchConfig::DEFAULT.grid;
        let spacing = super::super::family::Family::AxialFree.grid_spacing(&grid, &JUDGE.frame);
        let refines = |part: &Symmetry| JUDGE.refines_proposal(&proposal, spacing, part);
        let tilted = Vec3::new(0.176, 0.0, 1.0);
        assert!(refines(&axial(tilted, CENTER)));
        assert!(refines(&axial(Vec3::Z, CENTER + Vec3::Y * 0.03)));
        assert!(!refines(&axial(Vec3::Y, CENTER)));
        assert!(!refines(&axial(Vec3::Z, CENTER + Vec3::Y * 0.06)));
    }

    #[test]
    fn only_what_an_axis_entails_is_narrowed_to_parts() {
        let planes = [plane(Vec3::X), plane(Vec3::Y), plane(Vec3::Z)];
        let entailed = [
            Symmetry::PlaneReflection(planes[0]),
            Symmetry::DualPlane([planes[0], planes[1]]),
            Symmetry::TriplePlane(planes),
            Symmetry::LineReflection(Axis::new(Vec3::Z, CENTER, CENTER)),
        ];
        for wider in entailed {
            let best = candidate(wider);
            assert!(decomposes(true, TypeSet::ALL, Some(&best)), "{wider:?}");
            assert!(!decomposes(false, TypeSet::ALL, Some(&best)), "{wider:?}");
        }
        let axis = candidate(axial(Vec3::Z, CENTER));
        assert!(!decomposes(true, TypeSet::ALL, Some(&axis)));
        assert!(decomposes(true, TypeSet::ALL, None));
        use SymmetryType as T;
        let no_axes = TypeSet::of(&[T::PlaneReflection, T::DualPlane, T::TriplePlane]);
        assert!(!decomposes(true, no_axes, None));
    }

    #[test]
    fn a_leftover_symmetry_counts_only_if_it_shares_a_mirror_with_the_whole_objects() {
        let reflection = |normal: Vec3, through: Vec3| {
            Symmetry::PlaneReflection(Plane::through(through, normal))
        };
        let shares = |object: &Symmetry, found: &Symmetry| JUDGE.shares_mirror(Some(object), found);
        // The object axial about z: a mirror through its axis, an axis that meets it or runs
        // parallel to it (the plane through both is a mirror of both).
        let object = axial(Vec3::Z, CENTER);
        assert!(shares(&object, &reflection(Vec3::X, CENTER)));
        assert!(shares(&object, &axial(Vec3::X, CENTER + Vec3::Z * 0.05)));
        assert!(shares(&object, &axial(Vec3::Z, CENTER + Vec3::X * 0.05)));
        // 10 mm beside the axis, across it, or an axis that passes it 10 mm away: no mirror
        // in common.
        assert!(!shares(
            &object,
            &reflection(Vec3::X, CENTER + Vec3::X * 0.01)
        ));
        assert!(!shares(&object, &reflection(Vec3::Z, CENTER)));
        assert!(!shares(&object, &axial(Vec3::X, CENTER + Vec3::Y * 0.01)));
        // The object mirror symmetric about x = 0: its own plane, or an axis in it.
        let object = reflection(Vec3::X, CENTER);
        let dual = Symmetry::DualPlane([plane(Vec3::Y), plane(Vec3::X)]);
        assert!(shares(&object, &dual));
        assert!(shares(&object, &axial(Vec3::Y, CENTER)));
        assert!(!shares(&object, &reflection(Vec3::Y, CENTER)));
        assert!(!shares(&object, &axial(Vec3::X, CENTER)));
        // A spherical object: planes through its centre, any symmetry of revolution.
        let object = Symmetry::Spherical(CENTER.to_array());
        assert!(shares(&object, &reflection(Vec3::Y, CENTER)));
        assert!(!shares(
            &object,
            &reflection(Vec3::Y, CENTER + Vec3::Y * 0.01)
        ));
        assert!(shares(&object, &axial(Vec3::X, CENTER + Vec3::Y * 0.05)));
        // No object symmetry: anything counts.
        let anything = reflection(Vec3::Y, CENTER + Vec3::Y * 0.01);
        assert!(JUDGE.shares_mirror(None, &anything));
    }

    #[test]
    fn with_nothing_found_on_the_wider_domain_any_part_axis_agrees() {
        let axis = axial(Vec3::new(1.0, 1.0, 0.0), CENTER);
        assert!(JUDGE.agrees_with_wider(None, &axis));
    }
}
