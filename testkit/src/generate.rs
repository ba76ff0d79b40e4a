//! Host only: render the built-in scene and compare it with (or write it to) the committed file.
//!
//! The scene is the library's own: [`synth::builtin_scene`] rendered with
//! [`synth::BUILTIN_INTRINSICS`], the same scene the demo and the benchmarks use. The renderer's
//! object mask is not stored: the engine segments the object itself, using the table plane.

use shape_from_symmetry::{Intrinsics, Plane};

use crate::{scene_file, synth};

/// The built-in scene: intrinsics, depth scale, table plane, depth image.
pub fn render() -> (Intrinsics, f32, Option<Plane>, Vec<u16>) {
    let scene = synth::builtin_scene();
    let k = synth::BUILTIN_INTRINSICS;
    let mut depth = vec![0u16; k.pixel_count()];
    let mut mask = vec![0u8; k.pixel_count()];
    let rendered = synth::render(&scene, &k, &mut depth, &mut mask)
        .unwrap_or_else(|e| panic!("the built-in scene does not render: {e}"));
    (k, scene.depth_scale, Some(rendered.table), depth)
}

/// The bytes the committed file must hold.
pub fn expected_file() -> Vec<u8> {
    let (k, scale, table, depth) = render();
    scene_file::encode(&k, scale, table, &depth)
}

#[cfg(test)]
mod tests {
    use super::{expected_file, render};
    use crate::scene_file;

    #[test]
    fn scene_file_round_trips() {
        let (k, scale, table, depth) = render();
        let bytes = scene_file::encode(&k, scale, table, &depth);
        assert_eq!(bytes.len(), scene_file::HEADER_BYTES + 2 * depth.len());
        assert_eq!(&bytes[..8], &scene_file::MAGIC);
    }

    #[test]
    fn committed_scene_is_current() {
        assert!(
            expected_file() == scene_file::FILE,
            "regenerate with `cargo run --example firmware -- --write-scene`"
        );
        assert_eq!(scene_file::scene().validate(), Ok(()));
    }
}
