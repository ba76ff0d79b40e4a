//! Host only: render the built-in scene and compare it with (or write it to) the committed file.
//!
//! STAND-IN: until `shape_from_symmetry::synth` lands on `main`, [`render`] ray-casts a small
//! analytic scene (a ball on a table, seen from above at 30°). When `synth` lands, `render`
//! becomes
//! ```ignore
//! let scene = synth::builtin_scene();
//! let k = synth::BUILTIN_INTRINSICS;
//! let (mut depth, mut mask) = (vec![0u16; k.pixel_count()], vec![0u8; k.pixel_count()]);
//! let rendered = synth::render(&scene, &k, &mut depth, &mut mask)?;
//! (k, DEPTH_SCALE_OF_SYNTH, Some(rendered.table), depth)
//! ```
//! and `builtin_scene.bin` is regenerated with `--write-scene`.

use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Intrinsics, Plane};

use super::scene_file;

/// The built-in scene: intrinsics, depth scale, table plane, depth image.
pub fn render() -> (Intrinsics, f32, Option<Plane>, Vec<u16>) {
    const K: Intrinsics = Intrinsics {
        width: 320,
        height: 240,
        fx: 285.0,
        fy: 285.0,
        cx: 159.5,
        cy: 119.5,
    };
    const SCALE: f32 = 0.001; // millimetres
    let (s30, c30) = (0.5f32, 0.866_025_4f32);
    // World "up" in the camera frame (x right, y down, z forward) for a camera pitched down 30°.
    let up = Vec3::new(0.0, -c30, -s30);
    let radius = 0.05f32;
    let centre = Vec3::new(0.0, 0.0, 0.6);
    let table = Plane::through(centre - up * radius, up);
    let mut depth = vec![0u16; K.pixel_count()];
    for v in 0..K.height {
        for u in 0..K.width {
            // Ray X = t·d with d.z = 1, so t is the depth along the optical axis.
            let d = Vec3::new((u as f32 - K.cx) / K.fx, (v as f32 - K.cy) / K.fy, 1.0);
            let mut t_hit = f32::INFINITY;
            // Table: n·(t d) = offset.
            let nd = table.n().dot(d);
            if nd.abs() > 1e-6 {
                let t = table.offset / nd;
                if t > 0.0 {
                    t_hit = t;
                }
            }
            // Ball: |t d - c|² = r².
            let (a, b, c) = (
                d.dot(d),
                -2.0 * d.dot(centre),
                centre.dot(centre) - radius * radius,
            );
            let disc = b * b - 4.0 * a * c;
            if disc >= 0.0 {
                let t = (-b - disc.sqrt()) / (2.0 * a);
                if t > 0.0 && t < t_hit {
                    t_hit = t;
                }
            }
            let units = (t_hit / SCALE).round();
            if t_hit.is_finite() && units < 4000.0 {
                depth[v as usize * K.width as usize + u as usize] = units as u16;
            }
        }
    }
    (K, SCALE, Some(table), depth)
}

/// The bytes the committed file must hold.
pub fn expected_file() -> Vec<u8> {
    let (k, scale, table, depth) = render();
    scene_file::encode(&k, scale, table, &depth)
}
