//! The eight symmetry types of the paper (Fig. 5), their geometry, and the point maps they induce
//! (eqs. 1-4).
//!
//! Every symmetry becomes a [`MapSet`]: a short list of isometries `Q = A P + t`. Reflections give
//! one map each; continuous symmetries are sampled (axial: rotations by `2πk/K`, spherical: a fixed
//! set of rotations about the centre); composites give every combination of their elements. Each
//! map of an *element* (a plane, the rotations about an axis) carries the element's index, so
//! that a composite is only as good as its weakest element (see the measurement model). The maps a
//! composite derives from its elements (two mirror planes give a half-turn) carry [`DERIVED`]:
//! they hold whenever the elements do, so they are not scored, only used for completion.

mod hierarchy;

pub use hierarchy::TypeSet;

use crate::geometry::{Axis, Plane};
use crate::math::{Isometry, Mat3, Vec3, rotation_sc};

/// The eight symmetry types, weakest first within each branch of the entailment hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum SymmetryType {
    /// One mirror plane.
    PlaneReflection = 0,
    /// A half turn about a line.
    LineReflection = 1,
    /// Inversion through a centre.
    PointReflection = 2,
    /// Any rotation about an axis.
    Axial = 3,
    /// Any rotation about a centre.
    Spherical = 4,
    /// Two orthogonal mirror planes.
    DualPlane = 5,
    /// Three mutually orthogonal mirror planes.
    TriplePlane = 6,
    /// An axis and the mirror plane orthogonal to it.
    AxialPlane = 7,
}

impl SymmetryType {
    /// The eight types, in the order of their values.
    pub const ALL: [SymmetryType; 8] = [
        SymmetryType::PlaneReflection,
        SymmetryType::LineReflection,
        SymmetryType::PointReflection,
        SymmetryType::Axial,
        SymmetryType::Spherical,
        SymmetryType::DualPlane,
        SymmetryType::TriplePlane,
        SymmetryType::AxialPlane,
    ];

    /// The binding name used in scene and result files.
    pub const fn name(self) -> &'static str {
        match self {
            SymmetryType::PlaneReflection => "plane_reflection",
            SymmetryType::LineReflection => "line_reflection",
            SymmetryType::PointReflection => "point_reflection",
            SymmetryType::Axial => "axial",
            SymmetryType::Spherical => "spherical",
            SymmetryType::DualPlane => "dual_plane",
            SymmetryType::TriplePlane => "triple_plane",
            SymmetryType::AxialPlane => "axial_plane",
        }
    }

    /// Parse a binding name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Rank in the entailment order: a type ranks above every type it entails
    /// (number of points a symmetry maps each point to, paper Fig. 5).
    pub const fn strength(self) -> u8 {
        match self {
            SymmetryType::PlaneReflection
            | SymmetryType::LineReflection
            | SymmetryType::PointReflection => 0,
            SymmetryType::DualPlane => 1,
            SymmetryType::TriplePlane => 2,
            SymmetryType::Axial => 3,
            SymmetryType::AxialPlane => 4,
            SymmetryType::Spherical => 5,
        }
    }
}

/// A symmetry with its geometry, in the camera frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Symmetry {
    /// Reflection through the plane.
    PlaneReflection(Plane),
    /// A 180° rotation about the axis.
    LineReflection(Axis),
    /// Inversion through the centre.
    PointReflection([f32; 3]),
    /// Continuous rotation about the axis.
    Axial(Axis),
    /// Any rotation about the centre.
    Spherical([f32; 3]),
    /// Two orthogonal mirror planes.
    DualPlane([Plane; 2]),
    /// Three mutually orthogonal mirror planes.
    TriplePlane([Plane; 3]),
    /// Continuous rotation about the axis and a mirror plane orthogonal to it.
    AxialPlane(Axis, Plane),
}

/// Most maps a symmetry expands to (axial + plane with `K = 7`: 6 rotations, 7 reflections).
pub const MAX_MAPS: usize = 16;
/// Most elements a composite is scored by.
pub const MAX_GROUPS: usize = 3;
/// Group of a map derived from a composite's elements (used for completion, not scored).
pub const DERIVED: u8 = u8::MAX;

/// How continuous symmetries are sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sampling {
    /// Rotations `2πk/K`, `k = 1..K`, sample an axial symmetry. An odd prime `K` keeps n-fold
    /// prisms (boxes, hexagonal nuts) from passing as axial. `2..=7`.
    pub axial_steps: u8,
}

impl Default for Sampling {
    fn default() -> Self {
        Self { axial_steps: 7 }
    }
}

/// The isometries a symmetry maps each point through, each tagged with the element it tests.
#[derive(Clone, Debug, Default)]
pub struct MapSet {
    /// Each map, with the index of the element it tests ([`DERIVED`] for a map derived from the
    /// others, which is not scored).
    pub maps: heapless::Vec<(Isometry, u8), MAX_MAPS>,
    /// How many elements the maps test.
    pub groups: u8,
}

impl MapSet {
    /// No map.
    pub const fn new() -> Self {
        Self {
            maps: heapless::Vec::new(),
            groups: 0,
        }
    }

    fn push(&mut self, map: Isometry, group: u8) {
        // Capacity is MAX_MAPS, which every symmetry below stays within (checked in tests).
        let _ = self.maps.push((map, group));
        if group != DERIVED {
            self.groups = self.groups.max(group + 1);
        }
    }

    /// The maps that are scored (those of the elements).
    pub fn scored(&self) -> usize {
        self.maps.iter().filter(|(_, g)| *g != DERIVED).count()
    }
}

/// Rotation axes and angles (axis, sin, cos) that sample a sphere's rotations: four axes spread
/// like a tetrahedron's vertices, each turned by ±100°; the angle is no divisor of 360° so that no
/// polyhedron maps onto itself.
const SPHERE_ROTATIONS: [([f32; 3], f32, f32); 8] = {
    const S: f32 = 0.984_807_7; // sin 100°
    const C: f32 = -0.173_648_18; // cos 100°
    const A: f32 = 0.577_350_26; // 1/sqrt(3)
    [
        ([A, A, A], S, C),
        ([A, A, A], -S, C),
        ([A, -A, -A], S, C),
        ([A, -A, -A], -S, C),
        ([-A, A, -A], S, C),
        ([-A, A, -A], -S, C),
        ([-A, -A, A], S, C),
        ([-A, -A, A], -S, C),
    ]
};

fn plane_map(plane: &Plane) -> Isometry {
    let n = plane.n();
    let linear = Mat3::IDENTITY - Mat3::from_cols(n * n.x, n * n.y, n * n.z) * 2.0;
    Isometry {
        linear,
        translation: n * (2.0 * plane.offset),
    }
}

fn axis_rotation(axis: &Axis, sin: f32, cos: f32) -> Isometry {
    Isometry::rotation_about(rotation_sc(axis.d(), sin, cos), axis.p())
}

/// `(sin, cos)` of `2πk/steps`, computed once per symmetry, not per point.
fn axial_angle(k: u8, steps: u8) -> (f32, f32) {
    crate::math::sin_cos(core::f32::consts::TAU * k as f32 / steps as f32)
}

impl Symmetry {
    /// The type of this symmetry.
    pub const fn kind(&self) -> SymmetryType {
        match self {
            Symmetry::PlaneReflection(_) => SymmetryType::PlaneReflection,
            Symmetry::LineReflection(_) => SymmetryType::LineReflection,
            Symmetry::PointReflection(_) => SymmetryType::PointReflection,
            Symmetry::Axial(_) => SymmetryType::Axial,
            Symmetry::Spherical(_) => SymmetryType::Spherical,
            Symmetry::DualPlane(_) => SymmetryType::DualPlane,
            Symmetry::TriplePlane(_) => SymmetryType::TriplePlane,
            Symmetry::AxialPlane(..) => SymmetryType::AxialPlane,
        }
    }

    /// The mirror planes this symmetry lists (0 to 3).
    pub fn planes(&self) -> &[Plane] {
        match self {
            Symmetry::PlaneReflection(p) | Symmetry::AxialPlane(_, p) => core::slice::from_ref(p),
            Symmetry::DualPlane(ps) => ps,
            Symmetry::TriplePlane(ps) => ps,
            _ => &[],
        }
    }

    /// The axis, for line reflection, axial and axial + plane symmetries.
    pub fn axis(&self) -> Option<&Axis> {
        match self {
            Symmetry::LineReflection(a) | Symmetry::Axial(a) | Symmetry::AxialPlane(a, _) => {
                Some(a)
            }
            _ => None,
        }
    }

    /// The centre, for point reflection and spherical symmetry.
    pub fn center(&self) -> Option<[f32; 3]> {
        match self {
            Symmetry::PointReflection(c) | Symmetry::Spherical(c) => Some(*c),
            _ => None,
        }
    }

    /// The maps this symmetry sends each point through (the identity excluded).
    pub fn maps(&self, sampling: Sampling) -> MapSet {
        let mut set = MapSet::default();
        let steps = sampling.axial_steps.clamp(2, 7);
        match self {
            Symmetry::PlaneReflection(p) => set.push(plane_map(p), 0),
            Symmetry::LineReflection(a) => set.push(axis_rotation(a, 0.0, -1.0), 0),
            Symmetry::PointReflection(c) => {
                let c = Vec3::from_array(*c);
                set.push(
                    Isometry {
                        linear: -Mat3::IDENTITY,
                        translation: c * 2.0,
                    },
                    0,
                )
            }
            Symmetry::Axial(a) => {
                for k in 1..steps {
                    let (s, c) = axial_angle(k, steps);
                    set.push(axis_rotation(a, s, c), 0);
                }
            }
            Symmetry::Spherical(center) => {
                let center = Vec3::from_array(*center);
                for (axis, s, c) in SPHERE_ROTATIONS {
                    let r = rotation_sc(Vec3::from_array(axis), s, c);
                    set.push(Isometry::rotation_about(r, center), 0);
                }
            }
            Symmetry::DualPlane([p1, p2]) => {
                let (m1, m2) = (plane_map(p1), plane_map(p2));
                set.push(m1, 0);
                set.push(m2, 1);
                set.push(m2.after(&m1), DERIVED);
            }
            Symmetry::TriplePlane([p1, p2, p3]) => {
                let (m1, m2, m3) = (plane_map(p1), plane_map(p2), plane_map(p3));
                set.push(m1, 0);
                set.push(m2, 1);
                set.push(m3, 2);
                set.push(m2.after(&m1), DERIVED);
                set.push(m3.after(&m1), DERIVED);
                set.push(m3.after(&m2), DERIVED);
                set.push(m3.after(&m2.after(&m1)), DERIVED);
            }
            Symmetry::AxialPlane(a, p) => {
                let mirror = plane_map(p);
                set.push(mirror, 1);
                for k in 1..steps {
                    let (s, c) = axial_angle(k, steps);
                    let turn = axis_rotation(a, s, c);
                    set.push(turn, 0);
                    set.push(mirror.after(&turn), DERIVED);
                }
            }
        }
        set
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::normalize;

    fn plane(n: [f32; 3], d: f32) -> Plane {
        Plane::new(Vec3::from_array(n), d).unwrap()
    }

    fn samples() -> impl Iterator<Item = Vec3> {
        (0..40).map(|i| {
            let f = i as f32;
            Vec3::new(
                (f * 0.37).sin() * 0.1,
                (f * 0.91).cos() * 0.08,
                0.6 + (f * 0.13).sin() * 0.05,
            )
        })
    }

    fn all_examples() -> [Symmetry; 8] {
        let axis = Axis::new(
            normalize(Vec3::new(0.2, -0.9, 0.3)).unwrap(),
            Vec3::new(0.01, 0.0, 0.6),
            Vec3::ZERO,
        );
        let p1 = plane([0.0, 0.0, 1.0], 0.6);
        let p2 = plane([1.0, 0.0, 0.0], 0.02);
        let p3 = plane([0.0, 1.0, 0.0], -0.01);
        let ortho = Plane::through(Vec3::new(0.0, 0.0, 0.6), axis.d());
        [
            Symmetry::PlaneReflection(plane([0.3, 0.4, 0.5], 0.3)),
            Symmetry::LineReflection(axis),
            Symmetry::PointReflection([0.0, 0.01, 0.62]),
            Symmetry::Axial(axis),
            Symmetry::Spherical([0.0, 0.01, 0.62]),
            Symmetry::DualPlane([p1, p2]),
            Symmetry::TriplePlane([p1, p2, p3]),
            Symmetry::AxialPlane(axis, ortho),
        ]
    }

    #[test]
    fn names_round_trip_and_every_type_has_an_example() {
        for (t, s) in SymmetryType::ALL.into_iter().zip(all_examples()) {
            assert_eq!(SymmetryType::from_name(t.name()), Some(t));
            assert_eq!(s.kind(), t);
        }
    }

    #[test]
    fn reflections_are_involutions() {
        for s in all_examples() {
            if !matches!(
                s.kind(),
                SymmetryType::PlaneReflection
                    | SymmetryType::LineReflection
                    | SymmetryType::PointReflection
            ) {
                continue;
            }
            let m = s.maps(Sampling::default()).maps[0].0;
            for p in samples() {
                assert!((m.apply(m.apply(p)) - p).length() < 1e-5, "{s:?}");
                assert!((m.apply(p) - p).length() > 0.0 || p == m.apply(p));
            }
        }
    }

    #[test]
    fn maps_are_isometries_and_fit_capacity() {
        for s in all_examples() {
            let set = s.maps(Sampling::default());
            assert!(
                !set.maps.is_empty()
                    && set.maps.len() <= MAX_MAPS
                    && (set.groups as usize) <= MAX_GROUPS
            );
            for (m, _) in &set.maps {
                let pts: heapless::Vec<Vec3, 40> = samples().collect();
                for w in pts.windows(2) {
                    let d0 = (w[0] - w[1]).length();
                    let d1 = (m.apply(w[0]) - m.apply(w[1])).length();
                    assert!((d0 - d1).abs() < 1e-5, "{s:?}");
                }
            }
        }
    }

    #[test]
    fn axial_samples_stay_on_their_circle() {
        let [.., axial, _, _, _, _] = all_examples();
        let Symmetry::Axial(a) = axial else {
            unreachable!()
        };
        for p in samples() {
            for (m, _) in &axial.maps(Sampling::default()).maps {
                let q = m.apply(p);
                assert!((a.distance_squared(q) - a.distance_squared(p)).abs() < 1e-6);
                assert!(
                    (a.d().dot(q - p)).abs() < 1e-6,
                    "stays in the plane orthogonal to the axis"
                );
            }
        }
    }

    #[test]
    fn spherical_samples_stay_on_their_sphere() {
        let s = Symmetry::Spherical([0.0, 0.01, 0.62]);
        let c = Vec3::new(0.0, 0.01, 0.62);
        for p in samples() {
            for (m, _) in &s.maps(Sampling::default()).maps {
                assert!(((m.apply(p) - c).length() - (p - c).length()).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn composites_are_products_of_their_elements() {
        let examples = all_examples();
        let Symmetry::TriplePlane([p1, p2, p3]) = examples[6] else {
            unreachable!()
        };
        let maps = examples[6].maps(Sampling::default());
        for p in samples() {
            let chained = p3.reflect(p2.reflect(p1.reflect(p)));
            let last = maps.maps.last().unwrap().0.apply(p);
            assert!((chained - last).length() < 1e-5);
            assert!((maps.maps[0].0.apply(p) - p1.reflect(p)).length() < 1e-5);
        }
        let Symmetry::AxialPlane(axis, ortho) = examples[7] else {
            unreachable!()
        };
        let ap = examples[7].maps(Sampling::default());
        let axial = Symmetry::Axial(axis).maps(Sampling::default());
        for p in samples() {
            assert!((ap.maps[0].0.apply(p) - ortho.reflect(p)).length() < 1e-5);
            for (k, (turn, _)) in axial.maps.iter().enumerate() {
                assert!((ap.maps[1 + 2 * k].0.apply(p) - turn.apply(p)).length() < 1e-5);
                assert!(
                    (ap.maps[2 + 2 * k].0.apply(p) - ortho.reflect(turn.apply(p))).length() < 1e-5
                );
            }
        }
    }
}
