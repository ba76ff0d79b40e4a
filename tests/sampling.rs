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
    /// a reading, more than `min_height` above the table, or lower (but not below the table's
    /// noise band) and 4 pixels inside the mask in each of eight directions.
    fn is_object(&self, u: i32, v: i32) -> bool {
        let Some(h) = self.height(u, v) else {
            return false;
        };
        let sigma = Config::DEFAULT.sensor;
        let z = self.depth[v as usize * K.width as usize + u as usize] as f32 * 0.001;
        h > Config::DEFAULT.prepare.min_height
            || (h > -3.0 * sigma.sigma(z) && self.inside_mask(u, v))
    }

    /// The height above the table of pixel `(u, v)`, if it is in the mask with a reading.
    fn height(&self, u: i32, v: i32) -> Option<f32> {
        let i = self.index(u, v)?;
        let z = self.depth[i] as f32 * 0.001;
        let p = K.unproject(u as f32, v as f32, z);
        (self.mask[i] != 0 && self.depth[i] != 0).then(|| self.table.signed_distance(p))
    }

    /// Whether the pixels 4 away from `(u, v)` along its row, column and diagonals are the
    /// mask's.
    fn inside_mask(&self, u: i32, v: i32) -> bool {
        // The pixel itself is the mask's too: the centre of the 3 x 3 of steps adds nothing.
        let steps = [-4, 0, 4];
        let around = steps
            .iter()
            .flat_map(|&du| steps.iter().map(move |&dv| (du, dv)));
        around.into_iter().all(|(du, dv)| {
            self.index(u + du, v + dv)
                .is_some_and(|i| self.mask[i] != 0)
        })
    }

    fn index(&self, u: i32, v: i32) -> Option<usize> {
        let inside = (0..K.width as i32).contains(&u) && (0..K.height as i32).contains(&v);
        inside.then(|| v as usize * K.width as usize + u as usize)
    }

    /// The same scene with the mask grown by `pixels` (a square neighbourhood) onto what lies
    /// around the object: the support readings a loose mask takes in at the outline.
    fn widened(&self, pixels: i32) -> Self {
        let mut mask = self.mask.clone();
        for v in 0..K.height as i32 {
            for u in 0..K.width as i32 {
                let near = (-pixels..=pixels).any(|dv| {
                    (-pixels..=pixels).any(|du| {
                        self.index(u + du, v + dv)
                            .is_some_and(|i| self.mask[i] != 0)
                    })
                });
                if near {
                    mask[self.index(u, v).unwrap()] = 1;
                }
            }
        }
        Self {
            depth: self.depth.clone(),
            mask,
            table: self.table,
        }
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

#[test]
fn a_floor_the_mask_encloses_is_sampled_but_not_the_support_at_its_outline() {
    // Looking down into a bowl: its floor, the wall's thickness above the table, reads within
    // `min_height` of it where the sensor's noise puts it low.
    let scene = Rendered::new("bowl", view(75.0, 30.0));
    let min_height = Config::DEFAULT.prepare.min_height;
    let low = |s: &Rendered, &(u, v): &(u16, u16)| {
        s.height(u as i32, v as i32)
            .is_some_and(|h| h <= min_height)
    };
    let sampled = scene.sampled(Config::DEFAULT);
    let floor = sampled.iter().filter(|p| low(&scene, p)).count();
    assert!(floor > 0, "no floor point of {} sampled", sampled.len());
    // A mask grown 3 pixels onto the table: none of the table's readings it takes in is
    // sampled, and the floor still is.
    let loose = scene.widened(3);
    let sampled = loose.sampled(Config::DEFAULT);
    let taken_in = |&&(u, v): &&(u16, u16)| scene.height(u as i32, v as i32).is_none();
    let table: Vec<_> = sampled.iter().filter(taken_in).collect();
    assert!(table.is_empty(), "table readings sampled: {table:?}");
    assert!(sampled.iter().any(|p| low(&loose, p)));
}
