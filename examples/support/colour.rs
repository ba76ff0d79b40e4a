//! Point colours, the same in the PLY file and the picture: visible points blue-grey, generated
//! points coloured by the symmetry that made them (the strongest green).

use shape_from_symmetry::{CompletedPoint, Provenance};

pub type Rgb = [u8; 3];

pub const VISIBLE: Rgb = [120, 135, 160];
pub const BACKGROUND: Rgb = [246, 245, 240];

/// Generated points of symmetry 0, 1, 2, ... (cycling).
const GENERATED: [Rgb; 6] = [
    [40, 170, 80],
    [235, 140, 30],
    [200, 60, 160],
    [30, 170, 190],
    [190, 180, 40],
    [150, 90, 60],
];

pub fn of(point: &CompletedPoint) -> Rgb {
    match point.provenance {
        Provenance::Visible => VISIBLE,
        Provenance::Generated => GENERATED[point.symmetry as usize % GENERATED.len()],
    }
}
