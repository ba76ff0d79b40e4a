//! The one place for floating-point functions beyond `+ - * /`.
//!
//! Every square root and transcendental the library computes goes through this module and
//! through `libm`, whose software routines give the same bits on every target. Hot loops (the
//! scoring of transformed points) use none of them: they compare squared distances and use
//! rotation matrices computed once per hypothesis.

pub use glam::{Mat3, Vec3};

/// Square root (correctly rounded, identical on every target).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// Sine and cosine of `angle` (radians).
#[inline]
pub fn sin_cos(angle: f32) -> (f32, f32) {
    (libm::sinf(angle), libm::cosf(angle))
}

/// Natural logarithm.
#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// Exponential.
#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// Natural logarithm of the gamma function (`ln (n - 1)!` at an integer `n`).
#[inline]
pub fn ln_gamma(x: f32) -> f32 {
    libm::lgammaf(x)
}

/// Arc cosine, with the argument clamped to `[-1, 1]`.
#[inline]
pub fn acos(x: f32) -> f32 {
    libm::acosf(x.clamp(-1.0, 1.0))
}

/// Unit vector in the direction of `v`, or `None` for a zero or non-finite vector.
#[inline]
pub fn normalize(v: Vec3) -> Option<Vec3> {
    let len2 = v.length_squared();
    if len2 > 1e-30 && len2.is_finite() {
        Some(v * (1.0 / sqrt(len2)))
    } else {
        None
    }
}

/// Two unit vectors that complete `n` (unit) to a right-handed orthonormal basis `(t1, t2, n)`.
///
/// Branch-free construction of Duff et al. (2017), "Building an Orthonormal Basis, Revisited".
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Rotation by `angle` about the unit `axis` (Rodrigues' formula).
pub fn rotation(axis: Vec3, angle: f32) -> Mat3 {
    let (s, c) = sin_cos(angle);
    rotation_sc(axis, s, c)
}

/// Rotation about the unit `axis` given the sine and cosine of its angle.
pub fn rotation_sc(axis: Vec3, s: f32, c: f32) -> Mat3 {
    let t = 1.0 - c;
    let (x, y, z) = (axis.x, axis.y, axis.z);
    Mat3::from_cols(
        Vec3::new(t * x * x + c, t * x * y + s * z, t * x * z - s * y),
        Vec3::new(t * x * y - s * z, t * y * y + c, t * y * z + s * x),
        Vec3::new(t * x * z + s * y, t * y * z - s * x, t * z * z + c),
    )
}

/// The outer product `u vᵀ`.
#[inline]
pub(crate) fn outer(u: Vec3, v: Vec3) -> Mat3 {
    Mat3::from_cols(u * v.x, u * v.y, u * v.z)
}

/// A running sum of outer products `v vᵀ` (second moments of points, or of differences),
/// kept as the upper triangle of the symmetric sum: xx, xy, xz, yy, yz, zz.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct OuterSum(pub [f32; 6]);

impl OuterSum {
    /// No terms.
    pub const ZERO: Self = Self([0.0; 6]);

    /// Add `v vᵀ`: six products and additions.
    #[inline]
    pub fn add(&mut self, v: Vec3) {
        let s = &mut self.0;
        s[0] += v.x * v.x;
        s[1] += v.x * v.y;
        s[2] += v.x * v.z;
        s[3] += v.y * v.y;
        s[4] += v.y * v.z;
        s[5] += v.z * v.z;
    }

    /// Each entry over `n` (the mean of `n` terms).
    pub fn over(&self, n: f32) -> Self {
        Self(self.0.map(|v| v / n))
    }

    /// The sum of the diagonal.
    pub fn trace(&self) -> f32 {
        self.0[0] + self.0[3] + self.0[5]
    }

    /// The whole symmetric matrix.
    pub fn matrix(&self) -> Mat3 {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        Mat3::from_cols(
            Vec3::new(xx, xy, xz),
            Vec3::new(xy, yy, yz),
            Vec3::new(xz, yz, zz),
        )
    }
}

/// The `i`-th of `n` directions spread evenly over the hemisphere `z >= 0`
/// (a Fibonacci lattice: equal-area, no pole clustering).
pub fn hemisphere_direction(i: usize, n: usize) -> Vec3 {
    const GOLDEN_ANGLE: f32 = 2.399_963_2;
    let z = 1.0 - (i as f32 + 0.5) / n as f32;
    let r = sqrt((1.0 - z * z).max(0.0));
    let (s, c) = sin_cos(GOLDEN_ANGLE * i as f32);
    Vec3::new(r * c, r * s, z)
}

/// An isometry `x -> linear * x + translation`: every symmetry map is one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometry {
    /// The rotation or reflection.
    pub linear: Mat3,
    /// The translation applied after it.
    pub translation: Vec3,
}

impl Isometry {
    /// The map that moves nothing.
    pub const IDENTITY: Self = Self {
        linear: Mat3::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// Apply to a point.
    #[inline(always)]
    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.linear * p + self.translation
    }

    /// `self` after `first`: `x -> self(first(x))`.
    pub fn after(&self, first: &Isometry) -> Isometry {
        Isometry {
            linear: self.linear * first.linear,
            translation: self.linear * first.translation + self.translation,
        }
    }

    /// Rotation by the matrix `r` about the point `center`.
    pub fn rotation_about(r: Mat3, center: Vec3) -> Isometry {
        Isometry {
            linear: r,
            translation: center - r * center,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal() {
        for i in 0..50 {
            let n = hemisphere_direction(i, 50) * if i % 2 == 0 { 1.0 } else { -1.0 };
            let (t1, t2) = orthonormal_basis(n);
            assert!((t1.length() - 1.0).abs() < 1e-5 && (t2.length() - 1.0).abs() < 1e-5);
            assert!(t1.dot(t2).abs() < 1e-5 && t1.dot(n).abs() < 1e-5 && t2.dot(n).abs() < 1e-5);
            assert!((t1.cross(t2) - n).length() < 1e-5);
        }
    }

    #[test]
    fn rotation_turns_about_its_axis() {
        let axis = normalize(Vec3::new(1.0, 2.0, 3.0)).unwrap();
        let r = rotation(axis, 0.7);
        assert!((r * axis - axis).length() < 1e-6);
        let p = Vec3::new(0.3, -0.1, 0.2);
        assert!(((r * p).length() - p.length()).abs() < 1e-6);
        let back = rotation(axis, -0.7) * (r * p);
        assert!((back - p).length() < 1e-6);
    }
}
