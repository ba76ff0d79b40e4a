//! Refinement: each symmetry found with a continuous rotation (axial, axial + plane, spherical)
//! is refined in closed form from the point pairs it matches, re-matched a few times, as ICP
//! does; the refined symmetry replaces the found one when the measurement model scores it at
//! least as well over the symmetry's domain. Reflections keep the climb's parameters (see
//! `is_refined`).
//!
//! The climb of the parameter search stops at a step of a fraction of the finest match σ, and
//! its score is flat near the optimum: the parameters are only as good as that step. The matched
//! pairs pin them down further:
//! 1. **Match**: each point `p` of the domain, mapped by each scored map of an element, is paired
//!    with the visible point `q` nearest to its image when the match is the likelier cause
//!    (its cost `d² / 2σ²` at most the occluded cost: the model's own boundary between a match
//!    and an unconfirmed image), at the finest σ.
//! 2. **Solve** from the pairs' moments: an axis of rotation is the direction the differences
//!    `p - q` are orthogonal to, and its point the least-squares meeting point of the pairs'
//!    bisector planes; a centre of rotation is the meeting point of the bisector planes. An axial
//!    + plane's plane stays where it crosses the axis, normal to the refined axis.
//! 3. **Re-match** with the refined maps; `config.search.refine_rounds` rounds in all (none:
//!    the symmetries stay as found).
//! 4. **Judge**: the found and the refined symmetry are scored over the same points; the
//!    refined one is kept if it scores no worse.
//!
//! Cost: [`UNITS_PER_MATCH`] work units per transformed point matched, one per transformed point
//! scored, one per [`MARKS_PER_UNIT`] points gathered into the domain, one per solve. Each symmetry costs about
//! `(rounds + 2) × domain points × scored maps` units. Memory: the moments of three
//! elements; the domain's point list is lent (the growth's queue, free once the search is over).

use crate::config::ModelConfig;
use crate::engine::Found;
use crate::geometry::{Axis, Plane};
use crate::math::{Mat3, Vec3, normalize};
use crate::score::{Evaluation, Evidence, Level};
use crate::search::domains::Owner;
use crate::symmetry::{DERIVED, MAX_GROUPS, Sampling, Symmetry};
use crate::work::{MARKS_PER_UNIT, Meter, Poll, UNITS_PER_MATCH};

/// Fewest pairs an element is solved from (fewer leave it as found): a plane has three degrees
/// of freedom, an axis four, and each pair constrains one or two; a dozen pairs outvote a few
/// wrong matches.
const MIN_PAIRS: u32 = 12;

/// The moments of one element's pairs `(p, q)`: `v = p - q`, `m = (p + q) / 2`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Moments {
    pairs: u32,
    /// `Σ v vᵀ`, the upper triangle: xx, xy, xz, yy, yz, zz.
    vv: [f32; 6],
    /// `Σ v (v · m)`.
    vm: Vec3,
}

impl Moments {
    const ZERO: Self = Self {
        pairs: 0,
        vv: [0.0; 6],
        vm: Vec3::ZERO,
    };

    fn add(&mut self, p: Vec3, q: Vec3) {
        let (v, m) = (p - q, (p + q) * 0.5);
        self.pairs += 1;
        let vv = &mut self.vv;
        vv[0] += v.x * v.x;
        vv[1] += v.x * v.y;
        vv[2] += v.x * v.z;
        vv[3] += v.y * v.y;
        vv[4] += v.y * v.z;
        vv[5] += v.z * v.z;
        self.vm += v * v.dot(m);
    }

    fn vv(&self) -> Mat3 {
        let [xx, xy, xz, yy, yz, zz] = self.vv;
        Mat3::from_cols(
            Vec3::new(xx, xy, xz),
            Vec3::new(xy, yy, yz),
            Vec3::new(xz, yz, zz),
        )
    }

    fn enough(&self) -> bool {
        self.pairs >= MIN_PAIRS
    }

    /// The direction every difference is orthogonal to (an axis of rotation), on the side of
    /// `old`.
    fn axis_direction(&self, old: Vec3) -> Option<Vec3> {
        let vv = self.vv();
        let trace = vv.x_axis.x + vv.y_axis.y + vv.z_axis.z;
        let shifted = Mat3::from_diagonal(Vec3::splat(trace)) - vv;
        Some(aligned(largest_eigenvector(shifted, old)?, old))
    }

    /// The point of the line along `u` nearest `near` that best meets every pair's bisector
    /// plane `v · x = v · m` (least squares, weighted by `|v|²`).
    fn axis_point(&self, u: Vec3, near: Vec3) -> Option<Vec3> {
        let (e1, e2) = crate::math::orthonormal_basis(u);
        let vv = self.vv();
        let r = self.vm - vv * near;
        let (a11, a12, a22) = (e1.dot(vv * e1), e1.dot(vv * e2), e2.dot(vv * e2));
        let (b1, b2) = (e1.dot(r), e2.dot(r));
        let det = a11 * a22 - a12 * a12;
        // A singular system: the pairs do not pin the point down (all differences parallel).
        if !det.is_finite() || det <= f32::EPSILON * (a11 * a22).abs() {
            return None;
        }
        let (x1, x2) = ((b1 * a22 - b2 * a12) / det, (a11 * b2 - a12 * b1) / det);
        Some(near + e1 * x1 + e2 * x2)
    }

    /// The point that best meets every pair's bisector plane (a centre of rotation).
    fn center(&self) -> Option<Vec3> {
        let vv = self.vv();
        let det = vv.determinant();
        let scale = self.vv[0] + self.vv[3] + self.vv[5];
        if !det.is_finite() || det.abs() <= f32::EPSILON * scale * scale * scale {
            return None;
        }
        Some(vv.inverse() * self.vm)
    }
}

/// `v` turned to the side of `reference`.
fn aligned(v: Vec3, reference: Vec3) -> Vec3 {
    if v.dot(reference) < 0.0 { -v } else { v }
}

/// The eigenvector of the largest eigenvalue of the symmetric positive semi-definite `m`, by
/// power iteration from `start` (32 steps: the climb leaves the answer near `start`).
fn largest_eigenvector(m: Mat3, start: Vec3) -> Option<Vec3> {
    let mut v = normalize(start)?;
    for _ in 0..32 {
        v = normalize(m * v)?;
    }
    Some(v)
}

/// Whether `symmetry` is refined: the types with a continuous rotation (axial, axial + plane,
/// spherical). A rotation maps the visible points onto other visible points all along the seen
/// arc, so its pairs surround the axis or centre. A reflection (a mirror plane, a half turn, a
/// point reflection) maps most of them to the unseen side: its matched pairs come from a band on
/// the camera's side of the element, and a fit to them is pulled towards the camera (measured:
/// mirror planes fitted this way were further from the truth than the climb's on both scene
/// sets). A reflection keeps the climb's parameters.
fn is_refined(symmetry: &Symmetry) -> bool {
    matches!(
        symmetry,
        Symmetry::Axial(_) | Symmetry::AxialPlane(..) | Symmetry::Spherical(_)
    )
}

/// The symmetry `old` solved from its elements' moments (`None`: an element has too few pairs
/// or a degenerate system, or the type is not refined; the symmetry stays as found).
fn solve(old: &Symmetry, g: &[Moments; MAX_GROUPS]) -> Option<Symmetry> {
    let enough = |i: usize| g[i].enough().then_some(&g[i]);
    Some(match old {
        Symmetry::Spherical(_) => Symmetry::Spherical(enough(0)?.center()?.to_array()),
        Symmetry::Axial(a) => Symmetry::Axial(axis(enough(0)?, a)?),
        Symmetry::AxialPlane(a, p) => {
            // The plane stays where it crosses the refined axis, normal to it.
            let axis = axis(enough(0)?, a)?;
            let along = p.signed_distance(axis.p()) / p.n().dot(axis.d());
            let crossing = axis.p() - axis.d() * along;
            Symmetry::AxialPlane(axis, Plane::through(crossing, aligned(axis.d(), p.n())))
        }
        _ => return None,
    })
}

/// An axis solved from its rotations' moments, near `old`.
fn axis(m: &Moments, old: &Axis) -> Option<Axis> {
    let u = m.axis_direction(old.d())?;
    let point = m.axis_point(u, old.p())?;
    Some(Axis::new(u, point, old.p()))
}

/// Where the refinement is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Collecting the points of symmetry `index`'s domain into the list, from this point on.
    Gather {
        next: usize,
    },
    /// Round `round`: the next domain point and map to match.
    Match {
        round: u8,
        next: usize,
        map: u8,
    },
    /// Scoring the found symmetry, then the refined one, over the domain.
    Score {
        refined: bool,
    },
    Done,
}

/// The refinement state machine: the symmetries found, one after the other.
#[derive(Clone, Debug)]
pub(crate) struct Refinement {
    phase: Phase,
    /// The symmetry being refined (index into the found list).
    index: u8,
    /// Its domain's length in the lent list.
    len: usize,
    /// The symmetry as the last round solved it.
    current: Symmetry,
    moments: [Moments; MAX_GROUPS],
    /// The found symmetry's score over the domain.
    found_score: f32,
    rounds: u8,
    /// Units of a match done but not yet paid: the next call pays them before anything else, so
    /// no poll exceeds its budget and the total does not depend on the slicing.
    owed: u32,
}

impl Refinement {
    /// An idle refinement (`const`: part of an engine that may live in a `static`).
    pub(crate) const fn new() -> Self {
        Self {
            phase: Phase::Done,
            index: 0,
            len: 0,
            current: Symmetry::PointReflection([0.0; 3]),
            moments: [Moments::ZERO; MAX_GROUPS],
            found_score: 0.0,
            rounds: 0,
            owed: 0,
        }
    }

    /// Begin with the first symmetry found; `rounds` of matching and solving each (0: done).
    pub(crate) fn begin(&mut self, rounds: u8) {
        *self = Self::new();
        self.rounds = rounds;
        if rounds > 0 {
            self.phase = Phase::Gather { next: 0 };
        }
    }

    /// Refine the symmetries of `found` in place, spending at most what is left on `meter`.
    /// `owners[i]` names the symmetry whose domain holds point `i`; `list` holds a domain's
    /// point indices while it is refined (at least one entry per point); `evaluation` scores.
    /// Out of line: inlined into the engine's poll it would crowd the scoring loop's registers.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn advance<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        owners: &[Owner],
        found: &mut [Found],
        list: &mut [u16],
        evaluation: &mut Evaluation,
        (model, sampling, level): (&ModelConfig, Sampling, &Level),
        meter: &mut Meter,
    ) -> Poll<()> {
        let paid = self.owed.min(meter.left());
        meter.spend(paid);
        self.owed -= paid;
        while meter.has_left() {
            let Some(f) = found.get_mut(self.index as usize) else {
                self.phase = Phase::Done;
                return Poll::Ready(());
            };
            match self.phase {
                Phase::Gather { next: 0 } if !is_refined(&f.symmetry) => self.index += 1,
                Phase::Gather { next } => {
                    let end = (next + MARKS_PER_UNIT * meter.left() as usize).min(owners.len());
                    if next == 0 {
                        self.len = 0;
                    }
                    for (i, owner) in owners.iter().enumerate().take(end).skip(next) {
                        if owner.0 == self.index {
                            list[self.len] = i as u16;
                            self.len += 1;
                        }
                    }
                    meter.spend((end - next).div_ceil(MARKS_PER_UNIT).max(1) as u32);
                    self.phase = if end < owners.len() {
                        Phase::Gather { next: end }
                    } else {
                        self.current = f.symmetry;
                        self.moments = [Moments::ZERO; MAX_GROUPS];
                        Phase::Match {
                            round: 0,
                            next: 0,
                            map: 0,
                        }
                    };
                }
                Phase::Match { round, next, map } => {
                    let at = (round, next, map);
                    self.phase = self.match_pairs(evidence, list, (level, sampling), at, meter);
                    if let Phase::Score { .. } = self.phase {
                        evaluation.begin(&f.symmetry, sampling, *level, self.len, u32::MAX);
                    }
                }
                Phase::Score { refined } => {
                    let domain = &list[..self.len];
                    let point = |j: usize| domain[j] as usize;
                    if evaluation.advance(evidence, point, meter).is_pending() {
                        continue;
                    }
                    let score = evaluation.score(model);
                    if !refined {
                        self.found_score = score;
                        evaluation.begin(&self.current, sampling, *level, self.len, u32::MAX);
                        self.phase = Phase::Score { refined: true };
                    } else {
                        if score <= self.found_score && self.current != f.symmetry {
                            f.symmetry = self.current;
                        }
                        self.index += 1;
                        self.phase = Phase::Gather { next: 0 };
                    }
                }
                Phase::Done => return Poll::Ready(()),
            }
        }
        Poll::Pending
    }

    /// Match transformed points of round `round` until the meter is spent or the round ends;
    /// at its end, solve (one unit) and begin the next round or the scoring.
    #[allow(clippy::too_many_arguments)]
    fn match_pairs<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        list: &[u16],
        (level, sampling): (&Level, Sampling),
        (round, mut next, mut map): (u8, usize, u8),
        meter: &mut Meter,
    ) -> Phase {
        let gate2 = level.match_gate2();
        // Recomputed at each call rather than stored: a map set is larger than the rest of the
        // refinement's state, and a few dozen operations once per poll are cheap.
        let maps = self.current.maps(sampling);
        while next < self.len {
            if !meter.has_left() {
                return Phase::Match { round, next, map };
            }
            let (m, group) = maps.maps[map as usize];
            if group != DERIVED {
                let p = evidence.points[list[next] as usize];
                let q = m.apply(p);
                if !level.is_self_map(p, q) {
                    if let Some((d2, nearest)) = evidence.nearest_visible(q) {
                        if d2 <= gate2 {
                            // `nearest` is where the map should have taken p.
                            self.moments[group as usize].add(p, nearest);
                        }
                    }
                }
                // What the poll cannot pay now is paid first by the next (see `owed`).
                let now = UNITS_PER_MATCH.min(meter.left());
                meter.spend(now);
                self.owed = UNITS_PER_MATCH - now;
            }
            map += 1;
            if map as usize == maps.maps.len() {
                (map, next) = (0, next + 1);
            }
        }
        if !meter.has_left() {
            return Phase::Match { round, next, map };
        }
        meter.spend(1);
        if let Some(solved) = solve(&self.current, &self.moments) {
            self.current = solved;
        }
        self.moments = [Moments::ZERO; MAX_GROUPS];
        if round + 1 < self.rounds {
            Phase::Match {
                round: round + 1,
                next: 0,
                map: 0,
            }
        } else {
            Phase::Score { refined: false }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rotation_sc;

    /// A can's axis, tilted off the camera axes, through a point 0.6 m in front of the camera.
    fn true_axis() -> Axis {
        let d = normalize(Vec3::new(0.2, -0.9, 0.3)).unwrap();
        Axis::new(d, Vec3::new(0.01, 0.02, 0.6), Vec3::new(0.0, 0.0, 0.6))
    }

    /// The moments of the pairs `(p, R p)` of a rotation about `axis` by each of the six
    /// non-zero sevenths of a turn, over points on a cylinder of radius 4 cm around it: the half
    /// of the cylinder a camera sees (one side), six rings 1 cm apart. `jitter` metres of
    /// deterministic noise move each image (a sensor's error on the matched point).
    fn rotation_moments(axis: &Axis, jitter: f32) -> Moments {
        let (u, v) = crate::math::orthonormal_basis(axis.d());
        let mut m = Moments::ZERO;
        let mut k = 0u32;
        for ring in 0..6 {
            for step in 0..12 {
                // Half a turn of the cylinder: the side the camera sees.
                let angle = core::f32::consts::PI * step as f32 / 12.0;
                let (s, c) = crate::math::sin_cos(angle);
                let p = axis.p() + axis.d() * (0.01 * ring as f32) + (u * c + v * s) * 0.04;
                for turn in 1..7 {
                    let (s, c) = crate::math::sin_cos(core::f32::consts::TAU * turn as f32 / 7.0);
                    let q = axis.p() + rotation_sc(axis.d(), s, c) * (p - axis.p());
                    // A fixed pseudo-random sign pattern, the same on every run.
                    k = k.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                    let sign = |bit: u32| if k >> bit & 1 == 0 { jitter } else { -jitter };
                    m.add(p, q + Vec3::new(sign(16), sign(17), sign(18)));
                }
            }
        }
        m
    }

    fn angle_deg(a: Vec3, b: Vec3) -> f32 {
        crate::math::acos(a.dot(b).abs().min(1.0)).to_degrees()
    }

    /// The climb's answer: the true axis turned by 3° and moved 4 mm.
    fn perturbed(axis: &Axis) -> Axis {
        let (u, _) = crate::math::orthonormal_basis(axis.d());
        let (s, c) = crate::math::sin_cos(3f32.to_radians());
        let d = rotation_sc(u.cross(axis.d()), s, c) * axis.d();
        Axis::new(d, axis.p() + u * 0.004, axis.p())
    }

    #[test]
    fn exact_rotation_pairs_give_the_axis_from_a_perturbed_start() {
        let truth = true_axis();
        let m = rotation_moments(&truth, 0.0);
        let found = axis(&m, &perturbed(&truth)).unwrap();
        assert!(angle_deg(found.d(), truth.d()) < 0.01);
        assert!(truth.distance_squared(found.p()) < 1e-10, "within 10 µm");
    }

    #[test]
    fn noisy_pairs_give_the_axis_within_a_fraction_of_the_noise() {
        // 2 mm of noise on every coordinate of every matched point: a Kinect-class sensor at
        // about 1 m.
        let truth = true_axis();
        let start = perturbed(&truth);
        let found = axis(&rotation_moments(&truth, 0.002), &start).unwrap();
        let (before, after) = (
            angle_deg(start.d(), truth.d()),
            angle_deg(found.d(), truth.d()),
        );
        assert!(after < 0.5 && after < before, "{after}° (from {before}°)");
        let distance = crate::math::sqrt(truth.distance_squared(found.p()));
        assert!(distance < 0.001, "{distance} m off the axis");
    }

    #[test]
    fn an_axial_plane_keeps_its_crossing_and_turns_normal_to_the_refined_axis() {
        let truth = true_axis();
        let start = perturbed(&truth);
        let crossing = start.p() + start.d() * 0.03;
        let plane = Plane::through(crossing, start.d());
        let mut g = [Moments::ZERO; MAX_GROUPS];
        g[0] = rotation_moments(&truth, 0.0);
        let Some(Symmetry::AxialPlane(a, p)) = solve(&Symmetry::AxialPlane(start, plane), &g)
        else {
            panic!("an axial + plane stays one");
        };
        assert!(
            angle_deg(p.n(), a.d()) < 1e-3,
            "the plane is normal to the axis"
        );
        // Where the refined axis crosses the plane is where the found axis crossed it, moved
        // along with the axis (at most the 4 mm offset and 3° turn over 3 cm).
        let crossing_now = a.p() - a.d() * (p.signed_distance(a.p()) / p.n().dot(a.d()));
        assert!(p.signed_distance(crossing_now).abs() < 1e-5);
        assert!((crossing_now - crossing).length() < 0.006);
    }

    #[test]
    fn too_few_pairs_or_a_reflection_stay_as_found() {
        let truth = true_axis();
        let mut g = [Moments::ZERO; MAX_GROUPS];
        let p = truth.p();
        for i in 0..MIN_PAIRS - 1 {
            g[0].add(p + Vec3::X * (0.01 * i as f32), p);
        }
        assert_eq!(solve(&Symmetry::Axial(truth), &g), None);
        g[0] = rotation_moments(&truth, 0.0);
        let plane = Plane::through(p, Vec3::X);
        assert_eq!(solve(&Symmetry::PlaneReflection(plane), &g), None);
    }

    #[test]
    fn rotation_pairs_about_a_centre_give_the_centre() {
        let centre = Vec3::new(0.02, -0.01, 0.7);
        let mut m = Moments::ZERO;
        for (i, axis) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
            let (s, c) = crate::math::sin_cos(1.0 + i as f32);
            for j in 0..8 {
                let (sj, cj) = crate::math::sin_cos(j as f32 * 0.7);
                let p = centre + Vec3::new(cj * 0.05, sj * 0.05, 0.03 * (j % 3) as f32 - 0.03);
                m.add(p, centre + rotation_sc(axis, s, c) * (p - centre));
            }
        }
        let found = m.center().unwrap();
        assert!((found - centre).length() < 1e-4, "{found:?}");
    }
}
