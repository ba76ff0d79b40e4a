//! Synthetic scenes with a chosen number of object pixels, for the scaling example and benchmark:
//! a ready-made object (`synth::OBJECTS`) on the table, seen from the built-in view's direction
//! at the distance that gives about the wanted number of valid object pixels.
//!
//! The camera is a VGA one ([`INTRINSICS`], 640 x 480, f = 570 px), so that 50 000 object pixels
//! fit in the image; the engine takes any size. Kinect noise as in the dev scenes (its sigma grows
//! with distance, so the nearer, larger views are also the less noisy ones).

use crate::synth::{self, Noise, ReadyObject, View};
use shape_from_symmetry::Intrinsics;

use super::scene::LoadedScene;
use super::{Context, Result};

/// The camera of the scaling scenes: the Xtion's VGA depth image.
pub const INTRINSICS: Intrinsics = synth::XTION_INTRINSICS;

/// Object pixel counts the scaling run aims at.
pub const TARGETS: [u32; 5] = [1_000, 3_000, 10_000, 30_000, 50_000];

/// Nearest camera distance tried (metres to the object's centre): the sensor reads from 0.15 m.
const NEAREST: f32 = 0.2;

/// A rendered scaling scene and the distance it was rendered from.
pub struct SizedScene {
    pub scene: LoadedScene,
    pub distance: f32,
    /// Valid object pixels (mask and a reading).
    pub pixels: u32,
}

/// `object` rendered at the distance that gives about `target` valid object pixels (within a
/// few per cent; the pixel count falls as the square of the distance).
pub fn scene_with_pixels(object: &ReadyObject, target: u32) -> Result<SizedScene> {
    let mut distance = 0.5f32;
    let mut best: Option<SizedScene> = None;
    for _ in 0..8 {
        let sized = render(object, distance)?;
        let ratio = sized.pixels.max(1) as f32 / target as f32;
        let closer = |s: &SizedScene| (s.pixels as f32 / target as f32).ln().abs();
        let done = (ratio - 1.0).abs() < 0.02;
        if best.as_ref().is_none_or(|b| closer(&sized) < closer(b)) {
            best = Some(sized);
        }
        if done {
            break;
        }
        distance = (distance * ratio.sqrt()).max(NEAREST);
    }
    best.ok_or_else(|| "no rendering".into())
}

/// `object` seen from the built-in view's direction at `distance`.
pub fn render(object: &ReadyObject, distance: f32) -> Result<SizedScene> {
    let view = View {
        distance,
        ..synth::BUILTIN_VIEW
    };
    let scene = object.scene(view, Noise::kinect(1));
    let mut depth = vec![0; INTRINSICS.pixel_count()];
    let mut mask = vec![0; INTRINSICS.pixel_count()];
    let rendered = synth::render(&scene, &INTRINSICS, &mut depth, &mut mask)
        .context(|| format!("cannot render {}", object.name))?;
    Ok(SizedScene {
        scene: LoadedScene {
            name: format!("{}@{distance:.3}m", object.name),
            depth,
            depth_scale: scene.depth_scale,
            intrinsics: INTRINSICS,
            table: Some(rendered.table),
            mask: Some(mask),
        },
        distance,
        pixels: rendered.valid_object_pixels,
    })
}

#[cfg(test)]
mod tests {
    // The benchmarks include this module without a test harness, which drops the tests.
    #![allow(unused_imports)]
    use super::*;

    #[test]
    fn finds_a_distance_for_the_pixel_count() {
        let can = synth::object("can").unwrap();
        for target in [3_000, 30_000] {
            let sized = scene_with_pixels(can, target).unwrap();
            let error = (sized.pixels as f32 / target as f32 - 1.0).abs();
            assert!(error < 0.05, "{target}: {} pixels", sized.pixels);
        }
    }
}
