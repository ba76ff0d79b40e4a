//! Families: the parametrisations the parameter search walks, one per symmetry type and
//! constraint of paper section 5.2 (Table 1). Each gives a coarse grid and the small moves of the
//! hill climber.
//!
//! | family | type | free parameters | constrained by |
//! |---|---|---|---|
//! | `Plane` | plane reflection | 3: normal (2), offset | — |
//! | `PlaneLevel` | plane reflection | 3: as `Plane`; its grid: planes level with the support, between it and twice the object's centre height | the support plane the object rests on |
//! | `AxialIn` | axial | 2: direction in the plane, offset in the plane | a mirror plane containing the axis |
//! | `AxialNormal` | axial | 2: where the axis pierces the plane | a mirror plane orthogonal to the axis, or the support plane the object rests on |
//! | `SphericalOn` | spherical | 1: centre along the axis | an axis |
//! | `AxialPlaneOn` | axial + plane | 1: plane position along the axis | an axis |
//! | `DualWith` | dual plane | 2: second normal about the first, offset; 5 in a retry's climbs (the pair turned about each plane's normal and their common line, both offsets) | the first plane |
//! | `DualLevel` | dual plane | 2: as `DualWith`; its grid: second planes level with the support, between it and twice the object's centre height | a first plane upright on the support plane the object rests on |
//! | `TripleWith` | triple plane | 1: third offset | two planes |
//! | `Point` | point reflection | 3: centre | — |
//! | `Line` | line reflection | 4: direction (2), position (2) | — |
//! | `LineNormal` | line reflection | 2: where the line pierces the plane | the support plane the object rests on |
//! | `AxialFree` | axial | 4: direction (2), position (2) | — (a part's axis, climbed free of the wider domain's planes) |
//! | `PlaneThrough` | plane reflection | 1: turn about the axis | an axis the plane contains (the plane through an accepted axis and the part its rotations contradict) |
//!
//! Moves are expressed as a displacement `rho` (metres) of the object's farthest points: a
//! rotation turns by `rho / radius`, a translation moves by `rho`, so every parameter is stepped
//! at the same geometric scale. A mirror plane has [`TILTS`] more moves ([`Family::tilt`]): a
//! turn about a tangent line half the radius from the centre's foot, which is a turn about the
//! foot and a shift by half the step at once.

use crate::config::GridConfig;
use crate::math::{Vec3, hemisphere_direction, orthonormal_basis, rotation, sqrt};
use crate::{Axis, Plane, Symmetry};

/// Where the object is: the centre of the sampled points and their radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub center: Vec3,
    pub radius: f32,
}

impl Frame {
    /// How near (metres, at the centre) two elements are one at finest match σ `sigma_fine`: two
    /// σ, or 5 % of the radius on a large object.
    pub fn same_within(&self, sigma_fine: f32) -> f32 {
        (2.0 * sigma_fine).max(0.05 * self.radius)
    }
}

/// Lines a mirror plane may be tilted about besides its tangents through the centre's foot
/// ([`Family::tilt`]): each tangent, through a point half the radius either side of the foot
/// along the other tangent.
pub const TILTS: u8 = 4;

/// A parametrised family of symmetries (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Family {
    Plane,
    /// The support plane the object rests on: climbed as [`Family::Plane`], from planes level
    /// with the support.
    PlaneLevel(Plane),
    AxialIn(Plane),
    AxialNormal(Plane),
    SphericalOn(Axis),
    AxialPlaneOn(Axis),
    DualWith(Plane),
    /// A first plane upright on the support plane the object rests on (the first field, the
    /// support the second): climbed as [`Family::DualWith`] the first plane, from second planes
    /// level with the support.
    DualLevel(Plane, Plane),
    TripleWith(Plane, Plane),
    Point,
    Line,
    /// Half-turns about the lines along the support plane's normal.
    LineNormal(Plane),
    AxialFree,
    /// The mirror planes that contain an axis.
    PlaneThrough(Axis),
}

impl Family {
    /// Number of free parameters.
    pub fn dims(&self) -> u8 {
        match self {
            Family::SphericalOn(_)
            | Family::AxialPlaneOn(_)
            | Family::TripleWith(..)
            | Family::PlaneThrough(_) => 1,
            Family::AxialIn(_)
            | Family::AxialNormal(_)
            | Family::LineNormal(_)
            | Family::DualWith(_)
            | Family::DualLevel(..) => 2,
            Family::Plane | Family::PlaneLevel(_) | Family::Point => 3,
            Family::Line | Family::AxialFree => 4,
        }
    }

    /// Number of free parameters a retry's climbs step ([`super::params::ParamSearch::retry`]):
    /// for a dual plane 5, the first plane's three besides the second's two. The grid and the
    /// first climbs keep the first plane where the plane node found it; a scanned object is not
    /// exactly symmetric, so that plane (the single plane's optimum) may lie a few degrees off
    /// the pair's, where no second plane orthogonal to it passes. Paper section 5.1 grids a few
    /// parameters and hill-climbs in the whole parameter space.
    pub fn retry_dims(&self) -> u8 {
        match self {
            Family::DualWith(_) | Family::DualLevel(..) => 5,
            _ => self.dims(),
        }
    }

    /// Number of grid points.
    pub fn grid_len(&self, g: &GridConfig) -> u32 {
        let (o, a, l) = (
            g.offset_steps as u32,
            g.angle_steps as u32,
            g.lattice_steps as u32,
        );
        match self {
            Family::Plane => g.plane_normals as u32 * o,
            Family::AxialIn(_) | Family::DualWith(_) => a * o,
            Family::AxialNormal(_) | Family::LineNormal(_) => l * l,
            Family::SphericalOn(_)
            | Family::AxialPlaneOn(_)
            | Family::TripleWith(..)
            | Family::DualLevel(..)
            | Family::PlaneLevel(_) => o + o / 2,
            Family::Point => l * l * l,
            Family::Line | Family::AxialFree => g.line_directions as u32 * l * l,
            Family::PlaneThrough(_) => a,
        }
    }

    /// Largest displacement between a symmetry and its nearest grid point: the scale at which
    /// the hill climber starts.
    pub fn grid_spacing(&self, g: &GridConfig, frame: &Frame) -> f32 {
        let r = frame.radius;
        let offset = 2.0 * r / (g.offset_steps.max(2) - 1) as f32;
        let lattice = 2.0 * r / (g.lattice_steps.max(2) - 1) as f32;
        let hemisphere = |n: u16| sqrt(core::f32::consts::TAU / n.max(1) as f32) * r;
        let angle = core::f32::consts::PI / g.angle_steps.max(1) as f32 * r;
        match self {
            Family::Plane => hemisphere(g.plane_normals).max(offset),
            Family::Line | Family::AxialFree => hemisphere(g.line_directions).max(lattice),
            Family::AxialIn(_) | Family::DualWith(_) => angle.max(offset),
            Family::PlaneThrough(_) => angle,
            Family::AxialNormal(_) | Family::LineNormal(_) | Family::Point => lattice,
            Family::SphericalOn(_) | Family::AxialPlaneOn(_) | Family::TripleWith(..) => offset,
            Family::DualLevel(_, support) | Family::PlaneLevel(support) => {
                level_span(*support, frame) / (g.offset_steps + g.offset_steps / 2).max(1) as f32
            }
        }
    }

    /// The `i`-th grid point.
    pub fn grid_point(&self, i: u32, g: &GridConfig, frame: &Frame) -> Option<Symmetry> {
        let o = g.offset_steps.max(1) as u32;
        let l = g.lattice_steps.max(1) as u32;
        let c = frame.center;
        // Offsets span the object's diameter around the centre.
        let offset =
            |k: u32, steps: u32| frame.radius * (2.0 * k as f32 / (steps.max(2) - 1) as f32 - 1.0);
        let half_turn = |k: u32| core::f32::consts::PI * k as f32 / g.angle_steps.max(1) as f32;
        Some(match *self {
            Family::Plane => {
                let n = hemisphere_direction((i / o) as usize, g.plane_normals as usize);
                Symmetry::PlaneReflection(Plane::through(c + n * offset(i % o, o), n))
            }
            Family::AxialIn(p) => {
                let (t1, _, foot) = tangents(p, c);
                let d = rotation(p.n(), half_turn(i / o)) * t1;
                let across = p.n().cross(d);
                Symmetry::Axial(Axis::new(d, foot + across * offset(i % o, o), c))
            }
            Family::AxialNormal(p) | Family::LineNormal(p) => {
                let (t1, t2, foot) = tangents(p, c);
                let at = foot + t1 * offset(i % l, l) + t2 * offset(i / l, l);
                self.about(Axis::new(p.n(), at, c))
            }
            Family::SphericalOn(a) => {
                Symmetry::Spherical((a.p() + a.d() * offset(i, o + o / 2)).to_array())
            }
            Family::AxialPlaneOn(a) => Symmetry::AxialPlane(
                a,
                Plane::through(a.p() + a.d() * offset(i, o + o / 2), a.d()),
            ),
            Family::DualWith(p1) => {
                let (t1, _) = orthonormal_basis(p1.n());
                let n2 = rotation(p1.n(), half_turn(i / o)) * t1;
                Symmetry::DualPlane([p1, Plane::through(c + n2 * offset(i % o, o), n2)])
            }
            Family::DualLevel(p1, support) => {
                // The support's normal made orthogonal to the upright first plane.
                let up = crate::math::normalize(support.n() - p1.n() * p1.n().dot(support.n()))?;
                Symmetry::DualPlane([p1, level_plane(i, o, up, support, frame)])
            }
            Family::PlaneLevel(support) => {
                Symmetry::PlaneReflection(level_plane(i, o, support.n(), support, frame))
            }
            Family::TripleWith(p1, p2) => {
                let n3 = crate::math::normalize(p1.n().cross(p2.n()))?;
                Symmetry::TriplePlane([p1, p2, Plane::through(c + n3 * offset(i, o + o / 2), n3)])
            }
            Family::Point => {
                let (x, y, z) = (i % l, i / l % l, i / (l * l));
                let at = c + Vec3::new(offset(x, l), offset(y, l), offset(z, l));
                Symmetry::PointReflection(at.to_array())
            }
            Family::Line | Family::AxialFree => {
                let d = hemisphere_direction((i / (l * l)) as usize, g.line_directions as usize);
                let (t1, t2) = orthonormal_basis(d);
                let at = c + t1 * offset(i % l, l) + t2 * offset(i / l % l, l);
                let line = Axis::new(d, at, c);
                match self {
                    Family::Line => Symmetry::LineReflection(line),
                    _ => Symmetry::Axial(line),
                }
            }
            Family::PlaneThrough(a) => {
                let (t1, _) = orthonormal_basis(a.d());
                Symmetry::PlaneReflection(Plane::through(a.p(), rotation(a.d(), half_turn(i)) * t1))
            }
        })
    }

    /// The symmetry about `axis` of a family of lines along a plane's normal: half-turns for
    /// [`Family::LineNormal`], continuous rotations for [`Family::AxialNormal`].
    fn about(&self, axis: Axis) -> Symmetry {
        match self {
            Family::LineNormal(_) => Symmetry::LineReflection(axis),
            _ => Symmetry::Axial(axis),
        }
    }

    /// `s` moved along parameter `dim` by displacement `rho` (signed).
    pub fn step(&self, s: &Symmetry, dim: u8, rho: f32, frame: &Frame) -> Option<Symmetry> {
        let c = frame.center;
        let angle = rho / frame.radius.max(1e-6);
        Some(match (*self, *s) {
            (Family::Plane | Family::PlaneLevel(_), Symmetry::PlaneReflection(p)) => {
                Symmetry::PlaneReflection(step_plane(p, dim, rho, angle, c))
            }
            (Family::AxialIn(plane), Symmetry::Axial(a)) => {
                let moved = if dim == 0 {
                    Axis::new(rotation(plane.n(), angle) * a.d(), a.p(), c)
                } else {
                    Axis::new(a.d(), a.p() + plane.n().cross(a.d()) * rho, c)
                };
                Symmetry::Axial(moved)
            }
            (Family::AxialNormal(plane), Symmetry::Axial(a))
            | (Family::LineNormal(plane), Symmetry::LineReflection(a)) => {
                let (t1, t2) = orthonormal_basis(plane.n());
                self.about(Axis::new(
                    a.d(),
                    a.p() + if dim == 0 { t1 } else { t2 } * rho,
                    c,
                ))
            }
            (Family::SphericalOn(a), Symmetry::Spherical(center)) => {
                Symmetry::Spherical((Vec3::from_array(center) + a.d() * rho).to_array())
            }
            (Family::AxialPlaneOn(a), Symmetry::AxialPlane(_, p)) => Symmetry::AxialPlane(
                a,
                Plane {
                    offset: p.offset + rho,
                    ..p
                },
            ),
            // The pair's own first plane: the family's, but in a retry's climbs (dims 2-4).
            (Family::DualWith(_) | Family::DualLevel(..), Symmetry::DualPlane([p1, p2])) => {
                let turn = |u: Vec3, p: Plane| turn_plane(p, u, angle, c);
                let shift = |p: Plane| Plane {
                    offset: p.offset + rho,
                    ..p
                };
                Symmetry::DualPlane(match dim {
                    0 => [p1, turn(p1.n(), p2)],
                    1 => [p1, shift(p2)],
                    2 => [turn(p2.n(), p1), p2],
                    3 => {
                        let line = p1.n().cross(p2.n());
                        [turn(line, p1), turn(line, p2)]
                    }
                    _ => [shift(p1), p2],
                })
            }
            (Family::TripleWith(p1, p2), Symmetry::TriplePlane([_, _, p3])) => {
                Symmetry::TriplePlane([
                    p1,
                    p2,
                    Plane {
                        offset: p3.offset + rho,
                        ..p3
                    },
                ])
            }
            (Family::Point, Symmetry::PointReflection(center)) => {
                let mut moved = Vec3::from_array(center);
                moved[dim as usize % 3] += rho;
                Symmetry::PointReflection(moved.to_array())
            }
            (Family::Line, Symmetry::LineReflection(a)) => {
                Symmetry::LineReflection(step_line(a, dim, rho, angle, c))
            }
            (Family::AxialFree, Symmetry::Axial(a)) => {
                Symmetry::Axial(step_line(a, dim, rho, angle, c))
            }
            (Family::PlaneThrough(a), Symmetry::PlaneReflection(p)) => {
                Symmetry::PlaneReflection(Plane::through(a.p(), rotation(a.d(), angle) * p.n()))
            }
            _ => return None,
        })
    }

    /// Whether [`Family::tilt`] moves this family's symmetries (the mirror-plane families).
    pub fn tilts(&self) -> bool {
        matches!(self, Family::Plane | Family::PlaneLevel(_))
    }

    /// `s` turned by `rho / radius` (signed) about tilt line `k` < [`TILTS`]: for the mirror-plane
    /// families ([`Family::Plane`], [`Family::PlaneLevel`]), the plane's tangent `t1` (`k` 0, 1)
    /// or `t2` (`k` 2, 3) (the tangents [`Family::step`] turns about) through the point half the
    /// radius from the centre's foot along the other tangent, on its positive (`k` even) or
    /// negative side; `None` for the other families and for `k` ≥ [`TILTS`].
    ///
    /// The turn tilts the plane by the step and moves it at its foot by half the step: a tilt
    /// and a shift at once, the diagonal the climb tries when neither alone improves (see
    /// [`super::params`]). Half the radius: midway between the foot and the farthest points.
    pub fn tilt(&self, s: &Symmetry, k: u8, rho: f32, frame: &Frame) -> Option<Symmetry> {
        let Symmetry::PlaneReflection(p) = *s else {
            return None;
        };
        if !self.tilts() || k >= TILTS {
            return None;
        }
        let (t1, t2, foot) = tangents(p, frame.center);
        let (axis, along) = if k < 2 { (t1, t2) } else { (t2, t1) };
        let side = if k.is_multiple_of(2) { 0.5 } else { -0.5 };
        let pivot = foot + along * (side * frame.radius);
        let angle = rho / frame.radius.max(1e-6);
        Some(Symmetry::PlaneReflection(Plane::through(
            pivot,
            rotation(axis, angle) * p.n(),
        )))
    }
}

/// The `i`-th of the `o + o / 2` level planes of [`Family::DualLevel`] and
/// [`Family::PlaneLevel`], with normal `up` (the support's, made orthogonal to any plane it is
/// paired with), evenly spaced over [`level_span`] above `support`.
fn level_plane(i: u32, o: u32, up: Vec3, support: Plane, frame: &Frame) -> Plane {
    let height = level_span(support, frame) * (i + 1) as f32 / (o + o / 2) as f32;
    Plane::through(
        frame.center - up * (support.signed_distance(frame.center) - height),
        up,
    )
}

/// The heights above `support` that [`Family::DualLevel`] and [`Family::PlaneLevel`] span: up to
/// twice the height of the object's centre. A resting object's level mirror plane lies halfway
/// up it (its base on the support, its top as high above the plane), and the centre of its seen
/// points lies between the plane and its top: at most twice the centre's height holds it. The
/// span, not the object's diameter, sets the grid's spacing, and with it the match σ the grid
/// is scored at: a lying object is thin, and at a σ of its diameter a level mirror moves none
/// of its points by more than the self radius (every image uninformative, the plane invisible
/// to the grid).
/// At least 1 mm, a fraction of the sensor's noise: a centre on or under the support (a support
/// fitted through the object) leaves a positive spacing, whose planes the score then rejects.
fn level_span(support: Plane, frame: &Frame) -> f32 {
    (2.0 * support.signed_distance(frame.center)).max(1e-3)
}

/// The plane's two tangents ([`orthonormal_basis`] of its normal) and the foot of `center` on
/// it (its point nearest `center`).
fn tangents(p: Plane, center: Vec3) -> (Vec3, Vec3, Vec3) {
    let (t1, t2) = orthonormal_basis(p.n());
    (t1, t2, center - p.n() * p.signed_distance(center))
}

/// A plane tilted about one of its tangents (about the point nearest the centre) or shifted.
fn step_plane(p: Plane, dim: u8, rho: f32, angle: f32, center: Vec3) -> Plane {
    let (t1, t2, foot) = tangents(p, center);
    match dim {
        0 => Plane::through(foot, rotation(t1, angle) * p.n()),
        1 => Plane::through(foot, rotation(t2, angle) * p.n()),
        _ => Plane {
            offset: p.offset + rho,
            ..p
        },
    }
}

/// `p` turned by `angle` about direction `u` through the foot of `center` on it (the planes of
/// a dual turned alike stay orthogonal).
fn turn_plane(p: Plane, u: Vec3, angle: f32, center: Vec3) -> Plane {
    let (_, _, foot) = tangents(p, center);
    Plane::through(foot, rotation(u, angle) * p.n())
}

/// A line tilted about one of its normals (about its point nearest the centre) or shifted.
fn step_line(a: Axis, dim: u8, rho: f32, angle: f32, center: Vec3) -> Axis {
    let (t1, t2) = orthonormal_basis(a.d());
    match dim {
        0 => Axis::new(rotation(t1, angle) * a.d(), a.p(), center),
        1 => Axis::new(rotation(t2, angle) * a.d(), a.p(), center),
        2 => Axis::new(a.d(), a.p() + t1 * rho, center),
        _ => Axis::new(a.d(), a.p() + t2 * rho, center),
    }
}

/// Two symmetries whose planes or axes are within 5° of each other are one (the merge of refined
/// duplicates, and the alternatives of a walk).
pub const COS_5_DEG: f32 = 0.996_194_7;
/// sin² 5°: an element within 5° of a plane has a squared component along its normal at most
/// this.
pub const SIN2_5_DEG: f32 = 1.0 - COS_5_DEG * COS_5_DEG;

/// Whether two symmetries of one type are the same within `angle_cos` (cosine of the largest
/// angle between their planes or axes) and `distance` (metres, measured near the object centre).
pub fn same_symmetry(
    a: &Symmetry,
    b: &Symmetry,
    angle_cos: f32,
    distance: f32,
    center: Vec3,
) -> bool {
    let same_plane = |p: &Plane, q: &Plane| {
        let cos = p.n().dot(q.n());
        cos.abs() >= angle_cos
            && (p.signed_distance(center) - q.signed_distance(center) * cos.signum()).abs()
                <= distance
    };
    let same_axis = |p: &Axis, q: &Axis| {
        p.d().dot(q.d()).abs() >= angle_cos
            && (p.p() - q.p()).length_squared() <= distance * distance
    };
    let same_point = |p: [f32; 3], q: [f32; 3]| {
        (Vec3::from_array(p) - Vec3::from_array(q)).length_squared() <= distance * distance
    };
    match (a, b) {
        (Symmetry::PlaneReflection(p), Symmetry::PlaneReflection(q)) => same_plane(p, q),
        (Symmetry::LineReflection(p), Symmetry::LineReflection(q))
        | (Symmetry::Axial(p), Symmetry::Axial(q)) => same_axis(p, q),
        (Symmetry::PointReflection(p), Symmetry::PointReflection(q))
        | (Symmetry::Spherical(p), Symmetry::Spherical(q)) => same_point(*p, *q),
        (Symmetry::DualPlane(p), Symmetry::DualPlane(q)) => {
            // Either plane may be listed first.
            p.iter().all(|x| q.iter().any(|y| same_plane(x, y)))
        }
        (Symmetry::TriplePlane(p), Symmetry::TriplePlane(q)) => {
            p.iter().all(|x| q.iter().any(|y| same_plane(x, y)))
        }
        (Symmetry::AxialPlane(a1, p1), Symmetry::AxialPlane(a2, p2)) => {
            same_axis(a1, a2) && same_plane(p1, p2)
        }
        _ => false,
    }
}

/// Whether symmetry `strong` entails `weak` within `angle_cos` and `distance` (as
/// [`same_symmetry`]): each plane of `weak` is one of `strong`'s, or holds `strong`'s continuous
/// axis, or passes through its centre of spherical symmetry; `weak`'s axis is `strong`'s (or
/// passes through that centre); `weak`'s centre is that centre. A symmetry entails itself.
pub fn entails(
    strong: &Symmetry,
    weak: &Symmetry,
    angle_cos: f32,
    distance: f32,
    center: Vec3,
) -> bool {
    if same_symmetry(strong, weak, angle_cos, distance, center) {
        return true;
    }
    let near = |p: Vec3, q: Vec3| (p - q).length_squared() <= distance * distance;
    let sphere = strong
        .center()
        .filter(|_| strong.kind() == crate::SymmetryType::Spherical);
    let axis = match strong {
        Symmetry::Axial(a) | Symmetry::AxialPlane(a, _) => Some(*a),
        _ => None,
    };
    let plane_ok = |q: &Plane| {
        let listed = strong.planes().iter().any(|p| {
            let one = Symmetry::PlaneReflection(*p);
            same_symmetry(
                &one,
                &Symmetry::PlaneReflection(*q),
                angle_cos,
                distance,
                center,
            )
        });
        // cos of the angle to the axis small: the plane holds the axis direction.
        let holds_axis = axis.is_some_and(|a| {
            q.n().dot(a.d()).abs() <= sqrt(1.0 - angle_cos * angle_cos)
                && q.signed_distance(a.p()).abs() <= distance
        });
        let through_center =
            sphere.is_some_and(|c| q.signed_distance(Vec3::from_array(c)).abs() <= distance);
        listed || holds_axis || through_center
    };
    let axis_ok = |b: &Axis| {
        let same = axis.is_some_and(|a| {
            a.d().dot(b.d()).abs() >= angle_cos && a.distance_squared(b.p()) <= distance * distance
        });
        let through_center =
            sphere.is_some_and(|c| b.distance_squared(Vec3::from_array(c)) <= distance * distance);
        same || through_center
    };
    let center_ok =
        |c: [f32; 3]| sphere.is_some_and(|o| near(Vec3::from_array(o), Vec3::from_array(c)));
    weak.planes().iter().all(plane_ok)
        && weak.axis().is_none_or(axis_ok)
        && weak.center().is_none_or(center_ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAME: Frame = Frame {
        center: Vec3::new(0.01, -0.02, 0.6),
        radius: 0.08,
    };

    fn families() -> [Family; 14] {
        let p = Plane::through(FRAME.center, Vec3::Z);
        let q = Plane::through(FRAME.center, Vec3::X);
        let a = Axis::new(Vec3::Y, FRAME.center, FRAME.center);
        let support = Plane::through(FRAME.center + Vec3::Y * 0.05, Vec3::NEG_Y);
        [
            Family::Plane,
            Family::PlaneLevel(support),
            Family::AxialIn(p),
            Family::AxialNormal(p),
            Family::SphericalOn(a),
            Family::AxialPlaneOn(a),
            Family::DualWith(p),
            Family::DualLevel(q, support),
            Family::TripleWith(p, q),
            Family::Point,
            Family::Line,
            Family::LineNormal(p),
            Family::AxialFree,
            Family::PlaneThrough(a),
        ]
    }

    #[test]
    fn every_grid_point_is_distinct() {
        let g = GridConfig::DEFAULT;
        for f in families() {
            let n = f.grid_len(&g);
            let points: heapless::Vec<Symmetry, 4096> =
                (0..n).filter_map(|i| f.grid_point(i, &g, &FRAME)).collect();
            assert_eq!(points.len() as u32, n, "{f:?}");
            for (i, a) in points.iter().enumerate() {
                for b in &points[i + 1..] {
                    assert!(
                        !same_symmetry(a, b, 0.999_999, 1e-6, FRAME.center),
                        "{f:?}: {a:?} twice"
                    );
                }
            }
        }
    }

    #[test]
    fn a_symmetry_entails_its_elements_and_not_others() {
        let c = FRAME.center;
        let (px, py) = (Plane::through(c, Vec3::X), Plane::through(c, Vec3::Y));
        let pz = Plane::through(c, Vec3::Z);
        let entails = |a: &Symmetry, b: &Symmetry| entails(a, b, 0.999, 0.002, c);
        let dual = Symmetry::DualPlane([px, py]);
        assert!(entails(&dual, &Symmetry::PlaneReflection(py)));
        assert!(!entails(&dual, &Symmetry::PlaneReflection(pz)));
        let axial = Symmetry::Axial(Axis::new(Vec3::Z, c, c));
        // Every plane through the axis, none across it.
        assert!(entails(&axial, &dual));
        assert!(!entails(&axial, &Symmetry::PlaneReflection(pz)));
        let ball = Symmetry::Spherical(c.to_array());
        assert!(entails(&ball, &axial));
        assert!(entails(&ball, &Symmetry::PlaneReflection(pz)));
        assert!(!entails(&Symmetry::PlaneReflection(px), &dual));
        let moved = Symmetry::PlaneReflection(Plane::through(c + Vec3::X * 0.01, Vec3::X));
        assert!(!entails(&dual, &moved));
    }

    #[test]
    fn planes_through_an_axis_contain_it_however_stepped() {
        let d = Vec3::new(0.3, 0.9, 0.2).normalize();
        let a = Axis::new(d, FRAME.center, FRAME.center);
        let family = Family::PlaneThrough(a);
        let g = GridConfig::DEFAULT;
        let contains = |s: &Symmetry| match s {
            Symmetry::PlaneReflection(p) => [-0.1, 0.0, 0.1].iter().all(|&t| {
                let on_axis = a.p() + a.d() * t;
                p.signed_distance(on_axis).abs() < 1e-5
            }),
            _ => false,
        };
        for i in 0..family.grid_len(&g) {
            let s = family.grid_point(i, &g, &FRAME).unwrap();
            assert!(contains(&s), "{s:?}");
            let stepped = family.step(&s, 0, 0.01, &FRAME).unwrap();
            assert!(contains(&stepped), "{stepped:?}");
            assert!(!same_symmetry(&s, &stepped, 0.999_999, 1e-6, FRAME.center));
        }
    }

    #[test]
    fn odd_lattices_hold_the_centre() {
        let g = GridConfig::DEFAULT;
        assert_eq!(g.lattice_steps % 2, 1);
        let hit = (0..Family::Point.grid_len(&g))
            .filter_map(|i| Family::Point.grid_point(i, &g, &FRAME))
            .any(|s| {
                s.center()
                    .is_some_and(|c| (Vec3::from_array(c) - FRAME.center).length() < 1e-6)
            });
        assert!(hit, "the point lattice holds the object's centre");
    }
}
