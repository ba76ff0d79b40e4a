//! Point colours, the same in the PLY file and the picture: seen (visible) points grey,
//! predicted (generated) points in the saturated colour of the symmetry that made them (the
//! strongest green). When the object has several domains (part symmetries), each seen point
//! takes a greyish tint of its domain's colour, so that the domains stay apart while seen and
//! predicted points still differ at a glance.

use shape_from_symmetry::{CompletedPoint, Provenance};

pub type Rgb = [u8; 3];

pub const VISIBLE: Rgb = [150, 150, 150];
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

/// Share of the domain's colour in a seen point's tint: enough to tell the domains apart, little
/// enough that seen points stay greyish beside the saturated predicted ones.
const TINT: f32 = 0.3;

/// The colour of the points symmetry `index` predicts.
pub fn predicted(index: usize) -> Rgb {
    GENERATED[index % GENERATED.len()]
}

/// The colour of the seen points in the domain of symmetry `index`, when there are several.
pub fn seen_in(index: usize) -> Rgb {
    let hue = predicted(index);
    std::array::from_fn(|i| (TINT * hue[i] as f32 + (1.0 - TINT) * VISIBLE[i] as f32).round() as u8)
}

/// The colour of `point` in a result with `domains` symmetries.
pub fn of(point: &CompletedPoint, domains: usize) -> Rgb {
    let index = point.symmetry as usize;
    match point.provenance {
        Provenance::Visible if domains > 1 && index < domains => seen_in(index),
        Provenance::Visible => VISIBLE,
        Provenance::Generated => predicted(index),
    }
}

/// How far `rgb` is from grey: its largest channel less its smallest.
pub fn saturation(rgb: Rgb) -> u8 {
    rgb.iter().max().unwrap() - rgb.iter().min().unwrap()
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
        assert_eq!(visible(1, 2), seen_in(1));
        assert_eq!(of(&point(Provenance::Generated, 1), 2), GENERATED[1]);
    }

    #[test]
    fn seen_points_are_much_greyer_than_predicted_ones_in_every_domain() {
        for index in 0..GENERATED.len() {
            let (seen, predicted) = (saturation(seen_in(index)), saturation(predicted(index)));
            assert!(
                seen * 2 < predicted,
                "domain {index}: {seen} against {predicted}"
            );
            assert_ne!(seen_in(index), VISIBLE, "domain {index} shows no tint");
        }
        assert_eq!(saturation(VISIBLE), 0);
    }
}
