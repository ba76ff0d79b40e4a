//! Pinhole intrinsics: projection of camera-frame points to pixels and back.
//!
//! Camera frame, metres: x right, y down, z forward along the optical axis. Pixel `(u, v)` has
//! its centre at `(u, v)` in the continuous coordinates used here (as in OpenCV).

use crate::Error;
use crate::math::Vec3;

/// Pinhole camera intrinsics of the depth image.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Intrinsics {
    /// Image width, pixels.
    pub width: u16,
    /// Image height, pixels.
    pub height: u16,
    /// Focal length along x, pixels.
    pub fx: f32,
    /// Focal length along y, pixels.
    pub fy: f32,
    /// Principal point x, pixels (pixel `u` has its centre at `u`).
    pub cx: f32,
    /// Principal point y, pixels.
    pub cy: f32,
}

impl Intrinsics {
    /// Check that the focal lengths are positive and finite and the principal point finite.
    pub fn validate(&self) -> Result<(), Error> {
        let focal_ok = |f: f32| f.is_finite() && f > 1e-3 && f < 1e7;
        let centre_ok = |c: f32| c.is_finite() && c.abs() < 1e7;
        if self.width == 0 || self.height == 0 {
            return Err(Error::EmptyImage);
        }
        if !(focal_ok(self.fx) && focal_ok(self.fy) && centre_ok(self.cx) && centre_ok(self.cy)) {
            return Err(Error::InvalidIntrinsics);
        }
        Ok(())
    }

    /// Camera-frame point seen at pixel `(u, v)` with depth `z` (metres along the optical axis).
    #[inline]
    pub fn unproject(&self, u: f32, v: f32, z: f32) -> Vec3 {
        Vec3::new((u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z)
    }

    /// Continuous pixel coordinates of `p`, or `None` for a point not in front of the camera.
    #[inline]
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        if p.z <= 1e-6 {
            return None;
        }
        let inv_z = 1.0 / p.z;
        Some((
            self.fx * p.x * inv_z + self.cx,
            self.fy * p.y * inv_z + self.cy,
        ))
    }

    /// Number of pixels.
    #[inline]
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 320 x 240 camera with a 58° horizontal field of view (a Kinect-class sensor at QVGA).
    const K: Intrinsics = Intrinsics {
        width: 320,
        height: 240,
        fx: 285.0,
        fy: 285.0,
        cx: 159.5,
        cy: 119.5,
    };

    #[test]
    fn project_inverts_unproject() {
        let p = K.unproject(10.0, 200.0, 0.8);
        let (u, v) = K.project(p).unwrap();
        assert!((u - 10.0).abs() < 1e-3 && (v - 200.0).abs() < 1e-3);
    }

    #[test]
    fn rejects_bad_intrinsics() {
        assert_eq!(
            Intrinsics { fx: 0.0, ..K }.validate(),
            Err(Error::InvalidIntrinsics)
        );
        assert_eq!(
            Intrinsics { fy: f32::NAN, ..K }.validate(),
            Err(Error::InvalidIntrinsics)
        );
        assert_eq!(
            Intrinsics {
                cx: f32::INFINITY,
                ..K
            }
            .validate(),
            Err(Error::InvalidIntrinsics)
        );
        assert_eq!(
            Intrinsics { width: 0, ..K }.validate(),
            Err(Error::EmptyImage)
        );
        assert_eq!(K.validate(), Ok(()));
    }
}
