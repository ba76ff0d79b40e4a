//! The sampled points (`prepare`, step 3b): the sampling lattice and, with
//! `PrepareConfig::outline`, the object's outline where the lattice's rows and columns leave it.

mod common;

use sfs_testkit::synth::{BUILTIN_INTRINSICS, Noise, View, object, render};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{CompletedPoint, Config, Engine, Plane, Scene, Status};

const K: shape_from_symmetry::Intrinsics = BUILTIN_INTRINSICS;

/// A rendered scene: depth (mm), mask and table.
struct Rendered {
    depth: Vec<u16>,
    mask: Vec<u8>,
    table: Plane,
}

impl Rendered {
    fn new(name: &str, view: View) -> Self {
        let object = object(name).expect("a ready-made object");
        let scene = object.scene(view, Noise::kinect(7));
        let (mut depth, mut mask) = (vec![0u16; K.pixel_count()], vec![0u8; K.pixel_count()]);
        let rendered = render(&scene, &K, &mut depth, &mut mask).expect("the object renders");
        Self {
            depth,
            mask,
            table: rendered.table,
        }
    }

    /// The pixels of the sampled points of a search with `config`.
    fn sampled(&self, config: Config) -> Vec<(u16, u16)> {
        let mut out = vec![CompletedPoint::ZERO; 4096];
        let mut engine: Box<Engine<'_>> = Box::new(Engine::new(config));
        let scene = Scene {
            depth: &self.depth,
            depth_scale: 0.001,
            intrinsics: K,
            table: Some(self.table),
            mask: Some(&self.mask),
            target: None,
        };
        engine.start(scene, &mut out).expect("a valid scene");
        while engine.poll(50_000).expect("the search runs") != Status::Done {}
        let pixel = |p: &Vec3| {
            let u = (K.fx * p.x / p.z + K.cx).round() as u16;
            let v = (K.fy * p.y / p.z + K.cy).round() as u16;
            (u, v)
        };
        engine.object_points().iter().map(pixel).collect()
    }

    /// Whether `(u, v)` is an object pixel as the engine tests it with a mask: in the mask, with
    /// a reading, more than `min_height` above the table.
    fn is_object(&self, u: i32, v: i32) -> bool {
        if u < 0 || v < 0 || u >= K.width as i32 || v >= K.height as i32 {
            return false;
        }
        let i = v as usize * K.width as usize + u as usize;
        let z = self.depth[i] as f32 * 0.001;
        let p = K.unproject(u as f32, v as f32, z);
        self.mask[i] != 0
            && self.depth[i] != 0
            && self.table.signed_distance(p) > Config::DEFAULT.prepare.min_height
    }
}

/// 0.5 m from the object, looking down at `elevation_deg`.
fn view(elevation_deg: f32, azimuth_deg: f32) -> View {
    common::view(0.5, elevation_deg, azimuth_deg, 0.0)
}

/// The largest stride every pixel of `pixels` lies on the lattice of.
fn stride(pixels: &[(u16, u16)]) -> u16 {
    (1..=16)
        .rev()
        .find(|s| pixels.iter().all(|(u, v)| u % s == 0 && v % s == 0))
        .unwrap_or(1)
}

#[test]
fn the_outline_is_sampled_where_the_lattice_lines_leave_the_object() {
    let scene = Rendered::new("cereal_box", view(45.0, 30.0));
    let mut lattice_only = Config::DEFAULT;
    lattice_only.prepare.outline = false;
    let lattice = scene.sampled(lattice_only);
    let s = stride(&lattice);
    assert!(s > 1, "a sparse lattice (stride {s})");
    let with_outline = scene.sampled(Config::DEFAULT);
    // The same lattice points (the stride was kept), in the same raster order...
    let on_lattice = |&&(u, v): &&(u16, u16)| u % s == 0 && v % s == 0;
    let kept: Vec<_> = with_outline.iter().filter(on_lattice).copied().collect();
    assert_eq!(kept, lattice);
    // ... and the outline: pixels of a lattice row or column, each with a neighbour along it
    // that is not an object pixel.
    let outline: Vec<_> = with_outline.iter().filter(|p| !on_lattice(p)).collect();
    assert!(
        outline.len() * 20 > lattice.len(),
        "{} outline points beside {} lattice points",
        outline.len(),
        lattice.len()
    );
    for &&(u, v) in &outline {
        let (u, v) = (u as i32, v as i32);
        let leaves = if v % s as i32 == 0 {
            !scene.is_object(u - 1, v) || !scene.is_object(u + 1, v)
        } else {
            u % s as i32 == 0 && (!scene.is_object(u, v - 1) || !scene.is_object(u, v + 1))
        };
        assert!(leaves, "({u}, {v}) is no outline point at stride {s}");
    }
}

#[test]
fn with_parts_only_the_lattice_is_sampled() {
    let scene = Rendered::new("mug", view(45.0, 30.0));
    let mut parts = Config::DEFAULT;
    parts.domains.parts = true;
    let mut lattice_only = Config::DEFAULT;
    lattice_only.prepare.outline = false;
    assert_eq!(scene.sampled(parts), scene.sampled(lattice_only));
}
