//! Planes and axes as the binding files write them (`SCENES.md`): shared by the scene's ground
//! truth (read) and the result (written).

use serde::{Deserialize, Serialize};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Axis, Plane};

use super::Result;

/// `{"normal": [x, y, z], "offset": d}`: the plane `normal · X = offset`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct PlaneJson {
    pub normal: [f32; 3],
    pub offset: f32,
}

/// `{"direction": [x, y, z], "point": [x, y, z]}`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct AxisJson {
    pub direction: [f32; 3],
    pub point: [f32; 3],
}

impl PlaneJson {
    /// The library's plane (normal scaled to unit length), or an error for a degenerate one.
    pub fn plane(&self) -> Result<Plane> {
        Plane::new(Vec3::from_array(self.normal), self.offset)
            .ok_or_else(|| format!("plane {self:?} has no usable normal"))
    }
}

impl From<&Plane> for PlaneJson {
    fn from(p: &Plane) -> Self {
        Self {
            normal: p.normal,
            offset: p.offset,
        }
    }
}

impl AxisJson {
    /// The library's axis (direction scaled to unit length), or an error for a degenerate one.
    pub fn axis(&self) -> Result<Axis> {
        let point = Vec3::from_array(self.point);
        let direction = shape_from_symmetry::math::normalize(Vec3::from_array(self.direction))
            .ok_or_else(|| format!("axis {self:?} has no usable direction"))?;
        Ok(Axis::new(direction, point, point))
    }
}

impl From<&Axis> for AxisJson {
    fn from(a: &Axis) -> Self {
        Self {
            direction: a.direction,
            point: a.point,
        }
    }
}
