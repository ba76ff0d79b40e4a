//! Point colours, the same in the PLY file and the picture: visible points blue-grey, generated
//! points coloured by the symmetry that made them (the strongest green). When the object has
//! several domains (part symmetries), each visible point takes a dark shade of its domain's
//! colour.

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

/// The colour of `point` in a result with `domains` symmetries.
pub fn of(point: &CompletedPoint, domains: usize) -> Rgb {
    let symmetry = GENERATED[point.symmetry as usize % GENERATED.len()];
    match point.provenance {
        Provenance::Visible if domains > 1 && (point.symmetry as usize) < domains => {
            symmetry.map(|c| c / 2)
        }
        Provenance::Visible => VISIBLE,
        Provenance::Generated => symmetry,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(provenance: Provenance, symmetry: u8) -> CompletedPoint {
        CompletedPoint {
            provenance,
            symmetry,
            ..CompletedPoint::ZERO
        }
    }

    #[test]
    fn visible_points_show_their_domain_only_when_there_are_several() {
        let visible = |symmetry, domains| of(&point(Provenance::Visible, symmetry), domains);
        assert_eq!(visible(0, 1), VISIBLE);
        assert_eq!(visible(u8::MAX, 3), VISIBLE);
        assert_ne!(visible(0, 2), visible(1, 2));
        assert_eq!(visible(1, 2), GENERATED[1].map(|c| c / 2));
        assert_eq!(of(&point(Provenance::Generated, 1), 2), GENERATED[1]);
    }
}
