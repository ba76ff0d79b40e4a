//! How a depth camera's noise correlates between neighbouring pixels, measured on the planar
//! patches of a depth image: each square patch with a reading at every pixel gets the
//! least-squares plane through its readings; a patch is planar when its residuals' RMS is at
//! most twice the sensor's σ at its depth (`SensorConfig::DEFAULT`: a patch across an edge or
//! on a curved object leaves residuals well beyond the noise); the autocorrelation of its
//! residuals at a lag of `d` pixels, along rows and columns, is the noise's.
//!
//! A structured-light camera finds each pixel's depth by matching a window of its projected
//! pattern, so neighbouring pixels share much of their error; a renderer that draws each
//! pixel's noise on its own (`synth::Noise`) does not. A Gaussian kernel of σ `s` pixels
//! smoothing white noise correlates pixels `d` apart by `exp(-d² / 4s²)`, so the correlation
//! at one pixel gives the kernel ([`kernel_sigma_px`]) the renderer imitates with
//! ([`crate::synth::Artefacts::noise_correlation_px`]).

use shape_from_symmetry::SensorConfig;

/// Lags (pixels) the autocorrelation is measured at.
pub const LAGS: [usize; 3] = [1, 2, 4];

/// A planar patch's residuals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// Its mean depth, metres.
    pub depth: f32,
    /// The RMS of its residuals about its plane, metres.
    pub rms: f32,
    /// Their autocorrelation at each of [`LAGS`], rows and columns pooled.
    pub correlation: [f32; 3],
}

/// The planar patches of a depth image (`width` x `height`, row-major, `scale` metres per
/// unit, 0 = no reading), cut into squares of `side` pixels (at least 5: a plane and the
/// largest lag need them).
///
/// ```
/// # use sfs_testkit::correlation::planar_patches;
/// // A tilted plane with no noise: planar, residuals 0, no correlation to measure.
/// let depth: Vec<u16> = (0..32 * 32).map(|i| 800 + (i % 32) as u16 + (i / 32) as u16).collect();
/// let patches = planar_patches(&depth, 32, 32, 0.001, 16);
/// assert_eq!(patches.len(), 0);
/// ```
pub fn planar_patches(
    depth: &[u16],
    width: usize,
    height: usize,
    scale: f32,
    side: usize,
) -> Vec<Patch> {
    let side = side.max(5);
    let mut patches = Vec::new();
    for v0 in (0..height.saturating_sub(side - 1)).step_by(side) {
        for u0 in (0..width.saturating_sub(side - 1)).step_by(side) {
            let at = |u: usize, v: usize| depth[(v0 + v) * width + u0 + u];
            let full = (0..side).all(|v| (0..side).all(|u| at(u, v) != 0));
            if full && let Some(patch) = fit(&at, side, scale) {
                patches.push(patch);
            }
        }
    }
    patches
}

/// The plane through a full patch and its residuals' statistics, if planar and not exact.
fn fit(at: &impl Fn(usize, usize) -> u16, side: usize, scale: f32) -> Option<Patch> {
    // Least squares z = a u + b v + c over a full square grid centred on 0: u and v are
    // orthogonal to each other and to the constant, so each coefficient is its own ratio.
    let h = (side - 1) as f64 / 2.0;
    let (mut su, mut sv, mut sz, mut suu) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for v in 0..side {
        for u in 0..side {
            let (x, y, z) = (u as f64 - h, v as f64 - h, at(u, v) as f64);
            su += x * z;
            sv += y * z;
            sz += z;
            suu += x * x;
        }
    }
    let n = (side * side) as f64;
    let (a, b, c) = (su / suu, sv / suu, sz / n);
    // The residuals about the plane, row-major.
    let residuals: Vec<f64> = (0..side * side)
        .map(|i| {
            let (u, v) = (i % side, i / side);
            at(u, v) as f64 - (a * (u as f64 - h) + b * (v as f64 - h) + c)
        })
        .collect();
    let residual = |u: usize, v: usize| residuals[v * side + u];
    let variance = residuals.iter().map(|r| r * r).sum::<f64>() / n;
    let (depth, rms) = (
        (c * scale as f64) as f32,
        (variance.sqrt() * scale as f64) as f32,
    );
    if variance == 0.0 || rms > 2.0 * SensorConfig::DEFAULT.sigma(depth) {
        return None;
    }
    let mut correlation = [0.0; 3];
    for (slot, &d) in correlation.iter_mut().zip(&LAGS) {
        let (mut sum, mut count) = (0.0f64, 0usize);
        for v in 0..side {
            for u in 0..side - d {
                sum += residual(u, v) * residual(u + d, v) + residual(v, u) * residual(v, u + d);
                count += 2;
            }
        }
        *slot = (sum / count as f64 / variance) as f32;
    }
    Some(Patch {
        depth,
        rms,
        correlation,
    })
}

/// σ (pixels) of the Gaussian kernel whose smoothing of white noise correlates adjacent pixels
/// by `rho1`: `1 / (2 sqrt(-ln rho1))`; 0 for no positive correlation.
///
/// ```
/// # use sfs_testkit::correlation::kernel_sigma_px;
/// let s = kernel_sigma_px((-0.25f32).exp()); // exp(-1 / 4s²) with s = 1
/// assert!((s - 1.0).abs() < 1e-5);
/// assert_eq!(kernel_sigma_px(-0.1), 0.0);
/// ```
pub fn kernel_sigma_px(rho1: f32) -> f32 {
    if rho1 > 0.0 && rho1 < 1.0 {
        0.5 / (-rho1.ln()).sqrt()
    } else {
        0.0
    }
}

/// The median of `values` (0 for none).
pub fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A patch of white noise about a plane measures no correlation; the same noise summed
    /// over pairs of neighbours along rows measures 1/2 at one pixel along rows and none along
    /// columns: 1/4 pooled.
    #[test]
    fn white_noise_is_uncorrelated_and_pair_smoothed_noise_is_not() {
        let (w, h) = (64usize, 64usize);
        let mut state = 12345u32;
        let mut noise = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state % 7) as f32 - 3.0
        };
        let white: Vec<f32> = (0..w * h).map(|_| noise()).collect();
        let image = |f: &dyn Fn(usize) -> f32| -> Vec<u16> {
            (0..w * h)
                .map(|i| (8000.0 + (i % w) as f32 + f(i)) as u16)
                .collect()
        };
        let scale = 0.0001; // 0.1 mm units: 0.8 m, σ about 0.2 mm
        let plain = planar_patches(&image(&|i| white[i]), w, h, scale, 16);
        let smooth = planar_patches(
            &image(&|i| white[i] + white[i - i % w + (i + 1) % w]),
            w,
            h,
            scale,
            16,
        );
        assert_eq!((plain.len(), smooth.len()), (16, 16));
        let rho = |p: &[Patch]| median(p.iter().map(|p| p.correlation[0]).collect());
        assert!(rho(&plain).abs() < 0.1, "{}", rho(&plain));
        assert!((rho(&smooth) - 0.25).abs() < 0.1, "{}", rho(&smooth));
    }
}
