//! The one-plane baseline the accuracy issue measures the search against (in the style of Bohg
//! et al. 2011, "Mind the gap"): one mirror plane containing the support's normal, found by a
//! grid over its angle about that normal and its offset, then hill climbing, under a
//! visibility-aware cost. It always reports a plane. Host only: it reads the whole depth image.
//!
//! Cost of a reflected object point `q` (the mean over the points is the plane's cost):
//! - 0 where the camera saw the object at `q`'s pixel within [`NEAR`] of `q`'s depth (a match);
//! - the library's `cost_stray` where `q` lies in free space: in front of the reading at its
//!   pixel by more than [`FREE_MARGIN`], or below the support by as much (the camera, or the
//!   support, would have shown it there);
//! - the library's `cost_occluded` otherwise (hidden behind what the camera saw, on a pixel
//!   without a reading, or outside the image).
//!
//! Cost: one projection a point a plane; at most [`MAX_POINTS`] points, 36 angles, the offsets
//! 5 mm apart across the object, then four planes a climbing step (each step lowers the cost).

use shape_from_symmetry::math::{Vec3, orthonormal_basis};
use shape_from_symmetry::{Config, Plane};

use crate::metrics::{FREE_MARGIN, NEAR};
use crate::scene::LoadedScene;

/// The most object points scored (every k-th object pixel, raster order): a cap on the cost
/// only (the scene sets' objects have 350 to 27 000 pixels; larger ones are thinned evenly).
pub const MAX_POINTS: usize = 1500;
/// The grid: 36 angles (5° apart, a half turn: a plane's normal and its opposite are one plane)
/// and offsets 5 mm apart (a match's reach, [`NEAR`]).
const ANGLES: usize = 36;
const OFFSET_STEP: f32 = 0.005;
/// The climb halves its steps (5°, 5 mm) this many times: down to 0.3° and 0.3 mm.
const CLIMB_ROUNDS: usize = 5;

/// The baseline's plane for `scene`'s object: its mask's pixels with a reading, about the
/// support's normal (the camera's up without a support). `None` without a mask or object pixels.
pub fn one_plane(scene: &LoadedScene) -> Option<Plane> {
    scene.mask.as_ref()?;
    let all = scene.object_points();
    if all.is_empty() {
        return None;
    }
    let step = all.len().div_ceil(MAX_POINTS);
    let points: Vec<Vec3> = all.iter().copied().step_by(step).collect();
    let centroid = points.iter().copied().sum::<Vec3>() / points.len() as f32;
    let up = scene.up();
    // Two directions across the support: the plane normals are their combinations.
    let (across, other) = orthonormal_basis(up);
    let normal = |angle: f32| {
        let (s, c) = angle.sin_cos();
        across * c + other * s
    };
    let plane =
        |angle: f32, offset: f32| Plane::through(centroid + normal(angle) * offset, normal(angle));
    let cost = |angle: f32, offset: f32| mean_cost(&plane(angle, offset), &points, scene);
    // The grid: every angle, the offsets across the object's extent along the normal.
    let mut best = (f32::INFINITY, 0.0, 0.0);
    for i in 0..ANGLES {
        let angle = i as f32 * core::f32::consts::PI / ANGLES as f32;
        let n = normal(angle);
        let along = points.iter().map(|&p| (p - centroid).dot(n));
        let (low, high) = along.fold((0.0f32, 0.0f32), |(l, h), t| (l.min(t), h.max(t)));
        let mut offset = (low / OFFSET_STEP).floor() * OFFSET_STEP;
        while offset <= high {
            let c = cost(angle, offset);
            if c < best.0 {
                best = (c, angle, offset);
            }
            offset += OFFSET_STEP;
        }
    }
    // The climb: the best of the four neighbours at the current steps, else halve them.
    let (mut angle_step, mut offset_step) = (core::f32::consts::PI / ANGLES as f32, OFFSET_STEP);
    for _ in 0..CLIMB_ROUNDS {
        loop {
            let (c, a, o) = best;
            let moves = [
                (angle_step, 0.0),
                (-angle_step, 0.0),
                (0.0, offset_step),
                (0.0, -offset_step),
            ];
            let next = moves
                .iter()
                .map(|&(da, doff)| (cost(a + da, o + doff), a + da, o + doff))
                .min_by(|x, y| x.0.total_cmp(&y.0));
            match next {
                Some(n) if n.0 < c => best = n,
                _ => break,
            }
        }
        angle_step *= 0.5;
        offset_step *= 0.5;
    }
    Some(plane(best.1, best.2))
}

/// The mean cost of `points` reflected through `plane` (see the module docs).
fn mean_cost(plane: &Plane, points: &[Vec3], scene: &LoadedScene) -> f32 {
    let model = Config::DEFAULT.model;
    let cost = |p: Vec3| {
        let q = plane.reflect(p);
        let below = scene
            .table
            .is_some_and(|t| t.signed_distance(q) < -FREE_MARGIN);
        match scene.observed_depth(q) {
            _ if below => model.cost_stray,
            Some(z) if z > q.z + FREE_MARGIN => model.cost_stray,
            Some(z) if (z - q.z).abs() <= NEAR && scene.is_object_at(q) => 0.0,
            _ => model.cost_occluded,
        }
    };
    points.iter().map(|&p| cost(p)).sum::<f32>() / points.len().max(1) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{Surface, validity};
    use crate::truth::GroundTruth;
    use shape_from_symmetry::Symmetry;
    use std::path::Path;

    /// On a development can (its mirror planes contain the table normal), the baseline's plane
    /// is a true symmetry; it always reports a plane.
    #[test]
    fn the_baseline_finds_a_cans_upright_mirror() {
        let json = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/dev/ycb_005_tomato_soup_can_wrist_0.json");
        let scene = LoadedScene::load(&json).unwrap();
        let truth = GroundTruth::load(&json).unwrap().expect("ground truth");
        let plane = one_plane(&scene).expect("a masked scene");
        let surface = Surface::new(&truth);
        let judged = validity(&Symmetry::PlaneReflection(plane), &surface);
        assert!(judged.of_object(), "{plane:?}: {:?}", judged.worst);
        // Without a mask there is no object to mirror.
        let unmasked = LoadedScene {
            mask: None,
            ..scene
        };
        assert!(one_plane(&unmasked).is_none());
    }
}
