//! Degraded copies of a scene, for the robustness sweeps of `evaluate`: more depth noise and
//! dropouts, fewer pixels (the object seen from farther away), and a missing table plane or mask.
//!
//! Every degradation is deterministic: the noise of a pixel depends only on the seed, the scene's
//! name and the pixel's index (a counter-based hash, no random state), so a sweep repeats exactly.

use serde::Serialize;
use shape_from_symmetry::Intrinsics;

use super::scene::LoadedScene;

/// One way to degrade a scene. [`Degradation::NONE`] leaves it as recorded.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Degradation {
    /// Standard deviation (mm) of the zero-mean Gaussian noise added to every valid depth value.
    pub sigma_mm: f32,
    /// Probability that a valid depth value is dropped (set to 0, no reading), on top of the
    /// recorded dropouts.
    pub extra_dropout: f32,
    /// Keep every `downsample`-th pixel in each direction (1: all), intrinsics scaled to match.
    pub downsample: u16,
    /// Keep the scene's table plane (`false`: the engine must find it).
    pub table: bool,
    /// Keep the scene's object mask (`false`: the engine must segment the object).
    pub mask: bool,
}

impl Degradation {
    pub const NONE: Degradation = Degradation {
        sigma_mm: 0.0,
        extra_dropout: 0.0,
        downsample: 1,
        table: true,
        mask: true,
    };

    /// Whether this leaves the scene as it is.
    pub fn is_none(&self) -> bool {
        *self == Self::NONE
    }

    /// The degraded scene. The noise is seeded by `seed` and the scene's name.
    pub fn apply(&self, scene: &LoadedScene, seed: u64) -> LoadedScene {
        let mut out = downsample(scene, self.downsample.max(1));
        if self.sigma_mm > 0.0 || self.extra_dropout > 0.0 {
            let seed = seed ^ fnv1a(scene.name.as_bytes());
            let sigma_units = self.sigma_mm * 1e-3 / out.depth_scale;
            for (i, raw) in out.depth.iter_mut().enumerate().filter(|(_, r)| **r != 0) {
                let [a, b, c] = uniforms(seed, i as u64);
                if c < self.extra_dropout as f64 {
                    *raw = 0;
                } else if sigma_units > 0.0 {
                    let noisy = *raw as f64 + gaussian(a, b) * sigma_units as f64;
                    // A reading stays a reading: never 0, never beyond the format.
                    *raw = noisy.round().clamp(1.0, u16::MAX as f64) as u16;
                }
            }
        }
        if !self.table {
            out.table = None;
        }
        if !self.mask {
            out.mask = None;
        }
        out
    }
}

/// Every `k`-th pixel of every `k`-th row (pixel `(u, v)` of the result is `(k u, k v)` of the
/// scene), with the intrinsics of that pixel grid: `fx/k, fy/k, cx/k, cy/k`, `width/k` x
/// `height/k` (rounded down). The same object seen from `k` times farther with the same sensor,
/// less the sensor's growing noise.
pub fn downsample(scene: &LoadedScene, k: u16) -> LoadedScene {
    if k <= 1 {
        return scene.clone();
    }
    let k_in = &scene.intrinsics;
    let intrinsics = Intrinsics {
        width: k_in.width / k,
        height: k_in.height / k,
        fx: k_in.fx / k as f32,
        fy: k_in.fy / k as f32,
        cx: k_in.cx / k as f32,
        cy: k_in.cy / k as f32,
    };
    let (w, k) = (k_in.width as usize, k as usize);
    let (w_out, h_out) = (intrinsics.width as usize, intrinsics.height as usize);
    LoadedScene {
        name: scene.name.clone(),
        depth: pick(&scene.depth, w, k, (w_out, h_out)),
        depth_scale: scene.depth_scale,
        intrinsics,
        table: scene.table,
        mask: scene.mask.as_deref().map(|m| pick(m, w, k, (w_out, h_out))),
    }
}

/// Every `k`-th value of every `k`-th row of a row-major image `w` wide, `w_out` x `h_out` of them.
fn pick<T: Copy>(values: &[T], w: usize, k: usize, (w_out, h_out): (usize, usize)) -> Vec<T> {
    (0..h_out)
        .flat_map(|v| (0..w_out).map(move |u| values[v * k * w + u * k]))
        .collect()
}

/// Three uniform numbers in `[0, 1)` for pixel `index` (SplitMix64 of the seed and the index).
fn uniforms(seed: u64, index: u64) -> [f64; 3] {
    let mut state = seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03);
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    [next(), next(), next()]
}

/// A standard normal number from two uniform ones (Box-Muller).
fn gaussian(a: f64, b: f64) -> f64 {
    (-2.0 * (1.0 - a).ln()).sqrt() * (std::f64::consts::TAU * b).cos()
}

/// FNV-1a: a stable hash of the scene name, so that every scene gets its own noise.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shape_from_symmetry::math::Vec3;

    /// The synthetic can rendered with its object mask (the built-in scene file has none).
    fn scene() -> LoadedScene {
        use crate::synth;
        let (object, k) = (synth::builtin_scene(), synth::BUILTIN_INTRINSICS);
        let (mut depth, mut mask) = (vec![0; k.pixel_count()], vec![0; k.pixel_count()]);
        let rendered = synth::render(&object, &k, &mut depth, &mut mask).unwrap();
        LoadedScene {
            name: "can".into(),
            depth,
            depth_scale: object.depth_scale,
            intrinsics: k,
            table: Some(rendered.table),
            mask: Some(mask),
        }
    }

    #[test]
    fn none_changes_nothing() {
        let s = scene();
        let d = Degradation::NONE.apply(&s, 7);
        assert!(Degradation::NONE.is_none());
        assert_eq!((d.depth, d.mask, d.table), (s.depth, s.mask, s.table));
    }

    #[test]
    fn noise_is_deterministic_zero_mean_and_of_the_asked_sigma() {
        let s = scene();
        let noisy = Degradation {
            sigma_mm: 2.0,
            ..Degradation::NONE
        };
        let (a, b) = (noisy.apply(&s, 1), noisy.apply(&s, 1));
        assert_eq!(a.depth, b.depth);
        assert_ne!(a.depth, noisy.apply(&s, 2).depth);
        let diffs: Vec<f64> = s
            .depth
            .iter()
            .zip(&a.depth)
            .filter(|(r, _)| **r != 0)
            .map(|(&r, &n)| n as f64 - r as f64)
            .collect();
        assert!(
            a.depth
                .iter()
                .zip(&s.depth)
                .all(|(n, r)| (*n == 0) == (*r == 0))
        );
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        let sd =
            (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / diffs.len() as f64).sqrt();
        assert!(mean.abs() < 0.05, "mean {mean}");
        // Rounding to whole millimetres adds 1/12 mm² of variance.
        assert!((sd - (4.0f64 + 1.0 / 12.0).sqrt()).abs() < 0.05, "sd {sd}");
    }

    #[test]
    fn dropouts_remove_about_the_asked_share_of_readings() {
        let s = scene();
        let d = Degradation {
            extra_dropout: 0.05,
            ..Degradation::NONE
        }
        .apply(&s, 3);
        let valid = |depth: &[u16]| depth.iter().filter(|&&r| r != 0).count() as f64;
        let share = 1.0 - valid(&d.depth) / valid(&s.depth);
        assert!((share - 0.05).abs() < 0.005, "share {share}");
    }

    #[test]
    fn downsampling_keeps_every_kth_pixel_and_its_3d_point() {
        let s = scene();
        let d = downsample(&s, 3);
        let (k, k3) = (&s.intrinsics, &d.intrinsics);
        assert_eq!((k3.width, k3.height), (106, 80));
        assert_eq!((k3.fx, k3.cx), (k.fx / 3.0, k.cx / 3.0));
        let (u, v) = (40usize, 30usize);
        let (raw, raw3) = (
            s.depth[3 * v * k.width as usize + 3 * u],
            d.depth[v * k3.width as usize + u],
        );
        assert_eq!(raw, raw3);
        assert_eq!(
            d.mask.as_ref().unwrap()[v * k3.width as usize + u],
            s.mask.as_ref().unwrap()[3 * v * k.width as usize + 3 * u]
        );
        let z = raw as f32 * s.depth_scale;
        let p: Vec3 = k.unproject((3 * u) as f32, (3 * v) as f32, z);
        let p3 = k3.unproject(u as f32, v as f32, z);
        assert!((p - p3).length() < 1e-6);
        assert!(d.scene().validate().is_ok());
    }

    #[test]
    fn table_and_mask_can_be_left_out() {
        let d = Degradation {
            table: false,
            mask: false,
            ..Degradation::NONE
        }
        .apply(&scene(), 0);
        assert!(d.table.is_none() && d.mask.is_none());
    }
}
