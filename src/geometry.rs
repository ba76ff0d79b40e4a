//! Planes and axes: the symmetry features of the paper (section 2.1), in the camera frame.

use crate::math::{Vec3, normalize};

/// A plane `normal · X = offset`, `normal` a unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plane {
    /// Unit normal.
    pub normal: [f32; 3],
    /// Signed distance of the plane from the origin along `normal`, metres.
    pub offset: f32,
}

impl Plane {
    /// A plane from any non-zero normal; `None` when the normal is zero or not finite.
    pub fn new(normal: Vec3, offset: f32) -> Option<Self> {
        let n = normalize(normal)?;
        let scale = 1.0 / normal.length();
        offset.is_finite().then_some(Self {
            normal: n.to_array(),
            offset: offset * scale,
        })
    }

    /// The plane through `point` with unit normal `normal`.
    pub fn through(point: Vec3, normal: Vec3) -> Self {
        Self {
            normal: normal.to_array(),
            offset: normal.dot(point),
        }
    }

    /// The unit normal.
    #[inline]
    pub fn n(&self) -> Vec3 {
        Vec3::from_array(self.normal)
    }

    /// Signed distance of `p`, positive on the side the normal points to.
    #[inline]
    pub fn signed_distance(&self, p: Vec3) -> f32 {
        self.n().dot(p) - self.offset
    }

    /// The mirror image of `p` (paper eq. 1).
    #[inline]
    pub fn reflect(&self, p: Vec3) -> Vec3 {
        p - self.n() * (2.0 * self.signed_distance(p))
    }

    /// The same plane with its normal pointing the other way.
    pub fn flipped(&self) -> Self {
        Self {
            normal: (-self.n()).to_array(),
            offset: -self.offset,
        }
    }
}

/// An infinite line through `point` along the unit vector `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Axis {
    /// Unit direction.
    pub direction: [f32; 3],
    /// A point on the line, metres.
    pub point: [f32; 3],
}

impl Axis {
    /// An axis through `point` along unit `direction`; `point` is moved to the foot of the
    /// perpendicular from `near`, so that equal lines get equal representations.
    pub fn new(direction: Vec3, point: Vec3, near: Vec3) -> Self {
        let along = direction.dot(near - point);
        Self {
            direction: direction.to_array(),
            point: (point + direction * along).to_array(),
        }
    }

    /// The direction as a vector.
    #[inline]
    pub fn d(&self) -> Vec3 {
        Vec3::from_array(self.direction)
    }

    /// The point as a vector.
    #[inline]
    pub fn p(&self) -> Vec3 {
        Vec3::from_array(self.point)
    }

    /// Squared distance of `q` from the line.
    #[inline]
    pub fn distance_squared(&self, q: Vec3) -> f32 {
        let r = q - self.p();
        let along = r.dot(self.d());
        (r.length_squared() - along * along).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_reflection_is_an_involution() {
        let plane = Plane::new(Vec3::new(0.3, -0.5, 0.8), 0.4).unwrap();
        let p = Vec3::new(0.1, 0.2, 0.9);
        assert!((plane.reflect(plane.reflect(p)) - p).length() < 1e-6);
        assert!((plane.signed_distance(plane.reflect(p)) + plane.signed_distance(p)).abs() < 1e-6);
    }

    #[test]
    fn plane_rejects_degenerate_normals() {
        assert!(Plane::new(Vec3::ZERO, 1.0).is_none());
        assert!(Plane::new(Vec3::new(f32::NAN, 0.0, 1.0), 1.0).is_none());
        assert!(Plane::new(Vec3::Z, f32::INFINITY).is_none());
    }
}
