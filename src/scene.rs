//! The input: one depth image, its intrinsics, and optionally the table plane and an object mask.
//!
//! A [`Scene`] borrows the caller's buffers; [`Scene::validate`] checks everything that can be
//! checked without reading the pixels (O(1)). The pixels themselves are read only while the
//! engine prepares the search (its first polls).

use crate::depth::Rect;
use crate::math::Vec3;
use crate::{Error, Intrinsics, Plane};

/// Largest accepted depth scale: 1 m per unit, so that depths stay below 65 536 m and every
/// coordinate, squared and summed over the whole image, stays finite in `f32`.
pub const MAX_DEPTH_SCALE: f32 = 1.0;

/// The caller's hint naming the object when the engine segments it (no mask given).
///
/// ```
/// use shape_from_symmetry::{Rect, Target};
/// let on_the_can = Target::Pixel { u: 320, v: 250 };
/// let left_half = Target::Region(Rect { u0: 0, v0: 0, width: 320, height: 480 });
/// # let _ = (on_the_can, left_half);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Target {
    /// A pixel on the object: column `u`, row `v`. The object is the candidate region that
    /// holds it.
    Pixel {
        /// Column.
        u: u16,
        /// Row.
        v: u16,
    },
    /// A region of interest (a detector's box): the object is the part inside it of the
    /// candidate region with the most of its pixel blocks inside it (the first found on a
    /// tie).
    Region(Rect),
}

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
    /// Which object to segment when no mask is given (ignored with a mask). `None`: the
    /// candidate of plausible size at the optical axis (its box holding the principal point,
    /// the largest such), or else the one nearest it ([`crate::PrepareConfig`]).
    pub target: Option<Target>,
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
            target: None,
        }
    }

    /// Check sizes, scale, intrinsics, table plane and target (no pixel is read).
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
        let (w, h) = (self.intrinsics.width as u32, self.intrinsics.height as u32);
        match self.target {
            Some(Target::Pixel { u, v }) if u as u32 >= w || v as u32 >= h => {
                return Err(Error::TargetOutsideImage);
            }
            Some(Target::Region(r))
                if r.width == 0
                    || r.height == 0
                    || r.u0 as u32 + r.width as u32 > w
                    || r.v0 as u32 + r.height as u32 > h =>
            {
                return Err(Error::TargetOutsideImage);
            }
            _ => {}
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
