//! Readings missing beside depth jumps: along each row of a depth image, the run of pixels
//! without a reading between two readings of different surfaces, by the side the nearer
//! surface lies on. A structured-light camera leaves such a run where its projector cannot
//! light the farther surface (the shadow beside a foreground object, on the side away from the
//! projector) and where the reading of a surface seen at grazing incidence drops out; depth
//! registered to another camera (the real frames') is warped across the baseline between the
//! two, which opens runs on the other side too. Rows only: the Kinect's and the Xtion's
//! projector, depth and colour cameras lie on one horizontal line.

use shape_from_symmetry::SensorConfig;

use crate::synth::GRAZING_END_DEG;

/// The runs of missing readings at the depth jumps of an image, in pixels, by the side of the
/// jump the nearer surface lies on.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct JumpGaps {
    /// Jumps whose nearer surface lies left of the run (the run lies along its right side).
    pub nearer_left: Vec<u32>,
    /// Jumps whose nearer surface lies right of the run (the run lies along its left side).
    pub nearer_right: Vec<u32>,
}

impl JumpGaps {
    /// Add `other`'s jumps to these.
    pub fn extend(&mut self, other: JumpGaps) {
        self.nearer_left.extend(other.nearer_left);
        self.nearer_right.extend(other.nearer_right);
    }
}

/// The jumps of a depth image (`width` columns, row-major, `scale` metres per unit, 0 = no
/// reading, focal length `focal` pixels) and the run of missing readings at each: between every
/// two consecutive readings of a row that lie on different surfaces, the pixels without a
/// reading between them (0: the two are neighbours). Two readings are of different surfaces
/// when they differ by more than a surface at the grazing limit ([`GRAZING_END_DEG`]: beyond
/// it a depth camera returns nothing) steps between neighbouring pixels, `z / f` times its
/// slope, plus three σ of the sensor's noise, however many pixels without a reading lie between
/// them: the run a jump leaves is what is measured. A hole of several pixels in a surface seen
/// near grazing incidence may count as a jump too.
///
/// ```
/// # use sfs_testkit::gaps::jump_gaps;
/// // 1 m, then three pixels without a reading, then 0.7 m: the nearer surface on the right.
/// // A hole in one surface (1.000 m, 1.001 m) is no jump.
/// let row = [1000, 1000, 0, 0, 0, 700, 700, 0, 701, 0, 1000];
/// let gaps = jump_gaps(&row, row.len(), 0.001, 285.0);
/// assert_eq!(gaps.nearer_right, vec![3]);
/// assert_eq!(gaps.nearer_left, vec![1]);
/// ```
pub fn jump_gaps(depth: &[u16], width: usize, scale: f32, focal: f32) -> JumpGaps {
    let sensor = SensorConfig::DEFAULT;
    let step_per_z = libm::tanf(GRAZING_END_DEG.to_radians()) / focal;
    let mut gaps = JumpGaps::default();
    for row in depth.chunks_exact(width.max(1)) {
        let mut last: Option<(usize, f32)> = None;
        for (u, &raw) in row.iter().enumerate() {
            if raw == 0 {
                continue;
            }
            let z = raw as f32 * scale;
            if let Some((at, before)) = last {
                let near = z.min(before);
                let apart = near * step_per_z + 3.0 * sensor.sigma(near);
                if (z - before).abs() > apart {
                    let run = (u - at - 1) as u32;
                    if before < z {
                        gaps.nearer_left.push(run);
                    } else {
                        gaps.nearer_right.push(run);
                    }
                }
            }
            last = Some((u, z));
        }
    }
    gaps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steep_surface_read_throughout_is_no_jump() {
        // 80° incidence at 0.5 m, f = 285 px: 5.67 x 0.5 / 285 = 9.9 mm a pixel, some missing.
        let row: Vec<u16> = (0..40)
            .map(|u| if u % 7 == 3 { 0 } else { 500 + 10 * u })
            .collect();
        let gaps = jump_gaps(&row, row.len(), 0.001, 285.0);
        assert_eq!(gaps, JumpGaps::default());
    }

    #[test]
    fn each_row_is_measured_on_its_own() {
        // Two rows: the first ends near, the second starts far; no jump joins them.
        let rows = [700, 0, 0, 700, 1000, 0, 0, 1000];
        let gaps = jump_gaps(&rows, 4, 0.001, 285.0);
        assert_eq!(gaps, JumpGaps::default());
        let jumps = [700, 0, 0, 1000, 1000, 0, 0, 700];
        let gaps = jump_gaps(&jumps, 4, 0.001, 285.0);
        assert_eq!((gaps.nearer_left, gaps.nearer_right), (vec![2], vec![2]));
    }
}
