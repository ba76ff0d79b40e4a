//! The input: one depth image, its intrinsics, and optionally the table plane and an object mask.
//!
//! A [`Scene`] borrows the caller's buffers; [`Scene::validate`] checks everything that can be
//! checked without reading the pixels (O(1)). The pixels themselves are read only while the
//! engine prepares the search (its first polls).

use crate::math::Vec3;
use crate::{Error, Intrinsics, Plane};

/// Largest accepted depth scale: 1 m per unit, so that depths stay below 65 536 m and every
/// coordinate, squared and summed over the whole image, stays finite in `f32`.
pub const MAX_DEPTH_SCALE: f32 = 1.0;

/// One depth image with its camera, as the engine reads it.
#[derive(Clone, Copy, Debug)]
pub struct Scene<'a> {
    /// Row-major depth values, `width * height` of them; `0` = no reading.
    pub depth: &'a [u16],
    /// Metres per depth unit (0.001 for millimetres), in `(0, MAX_DEPTH_SCALE]`. Depth is along
    /// the optical axis.
    pub depth_scale: f32,
    /// The depth camera's intrinsics.
    pub intrinsics: Intrinsics,
    /// The support surface `n · X + d = 0` as `(n, -d)`, i.e. a [`Plane`] whose normal points
    /// away from the table toward the camera's side. `None`: the engine fits it.
    pub table: Option<Plane>,
    /// Row-major, nonzero = object pixel. `None`: the engine segments the object itself.
    pub mask: Option<&'a [u8]>,
}

impl<'a> Scene<'a> {
    /// Whether `scale` is a usable depth scale: in `(0, MAX_DEPTH_SCALE]` (false for NaN).
    pub fn depth_scale_ok(scale: f32) -> bool {
        scale > 0.0 && scale <= MAX_DEPTH_SCALE
    }

    /// A scene with neither table plane nor mask.
    pub fn new(depth: &'a [u16], depth_scale: f32, intrinsics: Intrinsics) -> Self {
        Self {
            depth,
            depth_scale,
            intrinsics,
            table: None,
            mask: None,
        }
    }

    /// Check sizes, scale, intrinsics and table plane (no pixel is read).
    pub fn validate(&self) -> Result<(), Error> {
        self.intrinsics.validate()?;
        let expected = self.intrinsics.pixel_count();
        let clamp = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        if self.depth.len() != expected {
            return Err(Error::DepthSizeMismatch {
                expected: clamp(expected),
                actual: clamp(self.depth.len()),
            });
        }
        if let Some(mask) = self.mask {
            if mask.len() != expected {
                return Err(Error::MaskSizeMismatch {
                    expected: clamp(expected),
                    actual: clamp(mask.len()),
                });
            }
        }
        if !Scene::depth_scale_ok(self.depth_scale) {
            return Err(Error::InvalidDepthScale);
        }
        if let Some(table) = self.table {
            let n = Vec3::from_array(table.normal);
            if !(n.is_finite()
                && (n.length_squared() - 1.0).abs() < 1e-3
                && table.offset.is_finite())
            {
                return Err(Error::InvalidTablePlane);
            }
        }
        Ok(())
    }

    /// Depth in metres at pixel index `i`, `None` for no reading.
    #[inline]
    pub(crate) fn metres(&self, i: usize) -> Option<f32> {
        let raw = self.depth[i];
        (raw != 0).then_some(raw as f32 * self.depth_scale)
    }

    /// Whether the mask (if any) selects pixel `i`.
    #[inline]
    pub(crate) fn masked(&self, i: usize) -> bool {
        self.mask.is_none_or(|m| m[i] != 0)
    }
}
