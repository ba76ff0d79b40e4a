//! Preparation: from the depth image to the sampled object points, the compact depth buffer of the
//! observed scene, and the voxel hash of the visible points.
//!
//! Steps, each resumable after any number of work units (the pixel loops keep their position):
//! 1. **Support plane** (when the scene gives none): RANSAC over a regular subsample of the valid
//!    pixels (the object's pixels excluded when a mask is given), a fixed pseudo-random sequence of
//!    triples, then two least-squares refinements on the inliers. Deterministic.
//! 2. **Segmentation** (when the scene gives no mask): pixels between `min_height` and
//!    `max_height` above the support plane are object candidates; their nearest depth per block
//!    goes into a [`DepthGrid`]; the largest 8-connected component of candidate blocks (neighbours
//!    joined when their depths differ by less than a jump threshold) is the object.
//! 3. **Sampling**: object pixels on a regular pixel lattice, its stride the smallest that keeps
//!    the count within `POINTS` (with `drop_edge_pixels`, none next to a depth jump).
//! 4. **Observed depth**: the nearest reading per block of a crop around the object (margin
//!    included): the free-space test of the measurement model.
//! 5. **Voxels**: the sampled points into the voxel hash, at every level.
//!
//! Cost in work units ([`crate::work`]): one unit per `PIXELS_PER_UNIT` pixels visited, per
//! `LATTICE_POINTS_PER_UNIT` sampling-lattice points, per `SAMPLES_PER_UNIT` RANSAC residuals,
//! per sampled point (two: its voxel at every level); the segmentation as [`crate::component`]
//! charges it, with `BLOCK_SEEDS_PER_UNIT` blocks scanned for a seed per unit.

use crate::component::{self, Graph, LargestComponent, Scratch};
use crate::config::PrepareConfig;
use crate::depth::{DepthGrid, Rect};
use crate::math::{Mat3, Vec3, normalize};
use crate::voxel::{Insert, VoxelMap};
use crate::work::{
    BLOCK_SEEDS_PER_UNIT, LATTICE_POINTS_PER_UNIT, LATTICE_POINTS_WITH_EDGES_PER_UNIT, Meter,
    PIXELS_PER_UNIT, Poll, SAMPLES_PER_UNIT,
};
use crate::{Error, Plane, Scene};

/// tan of the steepest incidence at which a depth camera still returns a reading (85°; beyond
/// it structured-light and time-of-flight readings drop out): neighbouring pixels of one surface
/// differ in depth by at most `z / f` times this.
const EDGE_SLOPE: f32 = 11.43;

/// Whether pixel `i` (at column `u`, row `v`, with a reading) lies on a depth discontinuity: a
/// 4-neighbour's reading differs from its own by more than one surface can step between
/// neighbouring pixels ([`EDGE_SLOPE`]). Such a pixel's footprint may straddle two surfaces: a
/// mixed ("flying") pixel, or one jittered across the silhouette. Mixed pixels come in chains
/// along an edge, so one with a neighbour at its own depth may be mixed too: every pixel next to
/// a jump counts. `jump_per_unit`: [`EDGE_SLOPE`] over the focal length (pixels), the step per
/// depth unit.
#[inline]
fn on_edge(scene: &Scene<'_>, i: u32, (u, v): (u16, u16), jump_per_unit: f32) -> bool {
    let k = &scene.intrinsics;
    let (depth, i, w) = (scene.depth, i as usize, k.width as usize);
    let raw = depth[i];
    let jump = raw as f32 * jump_per_unit;
    let apart = |n: u16| n != 0 && (n.abs_diff(raw) as f32) > jump;
    (u > 0 && apart(depth[i - 1]))
        || (u + 1 < k.width && apart(depth[i + 1]))
        || (v > 0 && apart(depth[i - w]))
        || (v + 1 < k.height && apart(depth[i + w]))
}

/// Fewest sampled object points a search accepts.
pub const MIN_POINTS: u32 = 24;
/// Largest sampling stride tried (pixels).
const MAX_STRIDE: u16 = 16;
const RANSAC_SAMPLES: usize = 600;
const RANSAC_HYPOTHESES: u32 = 64;

/// The sampled object points: camera-frame positions and the pixels they came from.
#[derive(Clone, Debug)]
pub struct Points<const N: usize> {
    pub pos: [Vec3; N],
    pub pixel: [[u16; 2]; N],
    pub len: usize,
}

impl<const N: usize> Points<N> {
    pub const fn new() -> Self {
        Self {
            pos: [Vec3::ZERO; N],
            pixel: [[0; 2]; N],
            len: 0,
        }
    }

    pub fn positions(&self) -> &[Vec3] {
        &self.pos[..self.len]
    }

    /// Index of the point sampled at pixel `(u, v)`. The points are stored in raster order
    /// (row by row), so this is a binary search: O(log n), no extra storage.
    pub fn index_of(&self, u: u16, v: u16) -> Option<usize> {
        self.pixel[..self.len]
            .binary_search_by(|p| (p[1], p[0]).cmp(&(v, u)))
            .ok()
    }

    /// Store a point; `false` when full.
    fn push(&mut self, p: Vec3, u: u16, v: u16) -> bool {
        let room = self.len < N;
        if room {
            self.pos[self.len] = p;
            self.pixel[self.len] = [u, v];
            self.len += 1;
        }
        room
    }
}

impl<const N: usize> Default for Points<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// What the search needs to know about the object's size and sampling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ObjectStats {
    /// Mean of the sampled points.
    pub centroid: [f32; 3],
    /// Largest distance of a sampled point from the centroid.
    pub radius: f32,
    /// Mean distance between neighbouring samples (stride × pixel footprint at the mean depth).
    pub spacing: f32,
    /// Object pixels with a reading (before sampling).
    pub object_pixels: u32,
    /// Sampling stride in pixels.
    pub stride: u16,
}

/// A block of the object (the largest component).
const OBJECT: u8 = component::MARKED;

/// The candidate blocks of the depth buffer as a graph: two neighbours are joined when their
/// depths lie on one surface (a jump under `jump_absolute + jump_relative × depth`).
struct Blocks<'a, 's, const C: usize> {
    scene: &'a Scene<'s>,
    grid: &'a DepthGrid<C>,
    config: &'a PrepareConfig,
}

impl<const C: usize> Graph for Blocks<'_, '_, C> {
    const SEEDS_PER_UNIT: u32 = BLOCK_SEEDS_PER_UNIT;

    fn seeds(&self) -> u32 {
        self.grid.len() as u32
    }

    fn seed(&self, s: u32) -> usize {
        s as usize
    }

    fn can_seed(&self, _: &[u8], block: usize) -> bool {
        self.grid.get(block) != 0
    }

    fn joined(&self, _: &[u8], block: usize, k: usize) -> Option<usize> {
        let n = self.grid.neighbour(block, k)?;
        let (a, b) = (self.grid.get(block), self.grid.get(n));
        let (za, zb) = (
            a as f32 * self.scene.depth_scale,
            b as f32 * self.scene.depth_scale,
        );
        let jump = self.config.jump_absolute + self.config.jump_relative * za.min(zb);
        (b != 0 && (za - zb).abs() < jump).then_some(n)
    }
}

/// The preparation state machine's position.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    CollectPlaneSamples {
        next: u32,
    },
    Ransac {
        hypothesis: u32,
        sample: u32,
        inliers: u32,
        candidate: Option<Plane>,
    },
    RefinePlane {
        round: u8,
        sample: u32,
        sums: Moments,
    },
    Candidates {
        next: u32,
    },
    Components(LargestComponent),
    CountObject {
        next: u32,
    },
    Sample {
        next: u32,
    },
    Observed {
        next: u32,
    },
    Voxels {
        next: u32,
    },
    Done,
}

/// First and second moments of inlier points, about a reference point (for the plane fit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Moments {
    n: u32,
    sum: Vec3,
    xx: Vec3,
    xy: Vec3,
}

impl Moments {
    fn add(&mut self, d: Vec3) {
        self.n += 1;
        self.sum += d;
        self.xx += d * d;
        self.xy += Vec3::new(d.x * d.y, d.x * d.z, d.y * d.z);
    }

    /// The least-squares plane through the points, its normal found by power iteration on
    /// `trace(C) I - C` (largest eigenvector = smallest of the covariance C), started at `guess`.
    fn plane(&self, reference: Vec3, guess: Vec3) -> Option<Plane> {
        let n = self.n as f32;
        let mean = self.sum / n;
        let c_xx = self.xx / n - mean * mean;
        let c_xy = self.xy / n - Vec3::new(mean.x * mean.y, mean.x * mean.z, mean.y * mean.z);
        let cov = Mat3::from_cols(
            Vec3::new(c_xx.x, c_xy.x, c_xy.y),
            Vec3::new(c_xy.x, c_xx.y, c_xy.z),
            Vec3::new(c_xy.y, c_xy.z, c_xx.z),
        );
        let shifted = Mat3::from_diagonal(Vec3::splat(c_xx.x + c_xx.y + c_xx.z)) - cov;
        let mut normal = guess;
        for _ in 0..32 {
            normal = normalize(shifted * normal)?;
        }
        Some(Plane::through(reference + mean, normal))
    }
}

/// The preparation stage: its settings, position and results.
#[derive(Clone, Debug)]
pub struct Preparation {
    config: PrepareConfig,
    step: Step,
    /// The support plane, given or fitted, normal toward the camera.
    table: Option<Plane>,
    stats: ObjectStats,
    /// Pixel bounding box of the object.
    bounds: Rect,
    /// Inliers of the best RANSAC plane so far.
    best_inliers: u32,
    /// Squared distance of the farthest sampled point from the centroid.
    radius2: f32,
    sum: Vec3,
    depth_sum: f32,
    rng: u32,
}

/// What preparation found, handed to the search and the completion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Prepared {
    /// The support plane, given or fitted, normal toward the camera.
    pub table: Option<Plane>,
    /// The object's size and sampling.
    pub stats: ObjectStats,
}

/// Borrowed storage the preparation writes into.
#[derive(Debug)]
pub struct Storage<'s, const P: usize, const V: usize, const C: usize> {
    pub points: &'s mut Points<P>,
    pub grid: &'s mut DepthGrid<C>,
    /// The segmentation's component search.
    pub scratch: &'s mut Scratch<C>,
    pub voxels: &'s mut VoxelMap<V>,
}

/// Items to process now and the units they cost, given what is left and the budget.
fn chunk(left: u32, budget: u32, per_unit: u32) -> (u32, u32) {
    let items = left.min(budget.saturating_mul(per_unit)).max(1).min(left);
    (items, items.div_ceil(per_unit).max(1))
}

impl Preparation {
    pub const fn new(config: PrepareConfig) -> Self {
        Self {
            config,
            step: Step::Done,
            table: None,
            stats: ObjectStats {
                centroid: [0.0; 3],
                radius: 0.0,
                spacing: 0.0,
                object_pixels: 0,
                stride: 1,
            },
            bounds: Rect {
                u0: 0,
                v0: 0,
                width: 0,
                height: 0,
            },
            best_inliers: 0,
            radius2: 0.0,
            sum: Vec3::ZERO,
            depth_sum: 0.0,
            rng: 0,
        }
    }

    /// Begin preparing `scene` (already validated).
    pub fn begin(&mut self, scene: &Scene<'_>) {
        *self = Self::new(self.config);
        self.table = scene.table;
        self.rng = 0x9E37_79B9;
        self.step = if scene.table.is_none() {
            Step::CollectPlaneSamples { next: 0 }
        } else {
            self.after_plane(scene)
        };
    }

    fn after_plane(&self, scene: &Scene<'_>) -> Step {
        if scene.mask.is_some() {
            Step::CountObject { next: 0 }
        } else {
            Step::Candidates { next: 0 }
        }
    }

    /// One step of preparation, spending at most what is left on `meter`; once done, what was
    /// found. A content error (no valid depth, no object, too few points) ends the preparation.
    /// (One step a call, not a loop: looping here changed how the poll loop was inlined and cost
    /// 3 % more M4F instructions in every stage.)
    pub(crate) fn advance<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        meter: &mut Meter,
    ) -> Result<Poll<Prepared>, Error> {
        if meter.has_left() && self.step != Step::Done {
            let used = self.step(scene, store, meter.left())?;
            meter.spend(used);
        }
        Ok(if self.step == Step::Done {
            Poll::Ready(Prepared {
                table: self.table,
                stats: self.stats,
            })
        } else {
            Poll::Pending
        })
    }

    /// One step of at most `budget` units (at least one); returns the units used.
    fn step<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        budget: u32,
    ) -> Result<u32, Error> {
        Ok(match self.step {
            Step::CollectPlaneSamples { next } => {
                self.collect_plane_samples(scene, store.points, next, budget)
            }
            Step::Ransac { .. } => self.ransac(scene, store.points, budget)?,
            Step::RefinePlane { .. } => self.refine_plane(scene, store.points, budget)?,
            Step::Candidates { next } => self.candidates(scene, store.grid, next, budget)?,
            Step::Components(_) => self.components(scene, store.grid, store.scratch, budget)?,
            Step::CountObject { next } => self.count_object(scene, store, next, budget)?,
            Step::Sample { next } => self.sample(scene, store, next, budget)?,
            Step::Observed { next } => self.observed(scene, store.grid, next, budget),
            Step::Voxels { next } => self.voxels(store.points, store.voxels, next, budget),
            Step::Done => 0,
        })
    }

    /// Step 1a: a regular subsample of the valid, non-object pixels into the point buffer.
    fn collect_plane_samples<const P: usize>(
        &mut self,
        scene: &Scene<'_>,
        points: &mut Points<P>,
        next: u32,
        budget: u32,
    ) -> u32 {
        let total = scene.depth.len() as u32;
        let (w, h) = (
            scene.intrinsics.width as u32,
            scene.intrinsics.height as u32,
        );
        let cap = P.min(RANSAC_SAMPLES) as u32;
        // Lattice stride so that the whole image gives about `cap` samples.
        let stride = ((w * h / cap.max(1)) as f32).max(1.0);
        let stride = (crate::math::sqrt(stride) as u32).max(1) + 1;
        if next == 0 {
            points.len = 0;
        }
        let (items, units) = chunk(total - next, budget, PIXELS_PER_UNIT);
        for i in next..next + items {
            let (u, v) = (i % w, i / w);
            if u % stride != 0
                || v % stride != 0
                || (scene.mask.is_some() && scene.masked(i as usize))
            {
                continue;
            }
            if let Some(z) = scene.metres(i as usize) {
                let p = scene.intrinsics.unproject(u as f32, v as f32, z);
                if !points.push(p, u as u16, v as u16) {
                    break;
                }
            }
        }
        let done = next + items >= total || points.len >= cap as usize;
        self.step = if done {
            Step::Ransac {
                hypothesis: 0,
                sample: 0,
                inliers: 0,
                candidate: None,
            }
        } else {
            Step::CollectPlaneSamples { next: next + items }
        };
        units
    }

    fn next_random(&mut self, below: usize) -> usize {
        // xorshift32: a fixed sequence, the same on every target.
        self.rng ^= self.rng << 13;
        self.rng ^= self.rng >> 17;
        self.rng ^= self.rng << 5;
        (self.rng as usize) % below.max(1)
    }

    /// The plane through three samples, normal toward the camera (at the origin).
    fn plane_through(a: Vec3, b: Vec3, c: Vec3) -> Option<Plane> {
        let n = normalize((b - a).cross(c - a))?;
        let plane = Plane::through(a, n);
        Some(if plane.offset > 0.0 {
            plane.flipped()
        } else {
            plane
        })
    }

    /// Step 1b: RANSAC hypotheses, each counted over all samples; the best is kept in
    /// `self.table`. Resumable within a hypothesis.
    fn ransac<const P: usize>(
        &mut self,
        scene: &Scene<'_>,
        points: &Points<P>,
        budget: u32,
    ) -> Result<u32, Error> {
        let Step::Ransac {
            hypothesis,
            sample,
            inliers,
            candidate,
        } = self.step
        else {
            return Ok(0);
        };
        let n = points.len;
        if n < 3 {
            return Err(if scene.mask.is_some() {
                Error::NoSupportPlane
            } else {
                Error::NoValidDepth
            });
        }
        let candidate = match candidate {
            Some(plane) => Some(plane),
            None => {
                let (i, j, k) = (
                    self.next_random(n),
                    self.next_random(n),
                    self.next_random(n),
                );
                Self::plane_through(points.pos[i], points.pos[j], points.pos[k])
            }
        };
        let Some(plane) = candidate else {
            self.step = self.next_hypothesis(hypothesis);
            return Ok(1);
        };
        let (items, units) = chunk(n as u32 - sample, budget, SAMPLES_PER_UNIT);
        let tol = self.config.plane_tolerance;
        let hits = points.pos[sample as usize..(sample + items) as usize]
            .iter()
            .filter(|p| plane.signed_distance(**p).abs() < tol)
            .count() as u32;
        let inliers = inliers + hits;
        if sample + items < n as u32 {
            self.step = Step::Ransac {
                hypothesis,
                sample: sample + items,
                inliers,
                candidate: Some(plane),
            };
            return Ok(units);
        }
        if inliers > self.best_inliers {
            self.best_inliers = inliers;
            self.table = Some(plane);
        }
        self.step = self.next_hypothesis(hypothesis);
        Ok(units)
    }

    fn next_hypothesis(&self, hypothesis: u32) -> Step {
        if hypothesis + 1 < RANSAC_HYPOTHESES {
            Step::Ransac {
                hypothesis: hypothesis + 1,
                sample: 0,
                inliers: 0,
                candidate: None,
            }
        } else {
            Step::RefinePlane {
                round: 0,
                sample: 0,
                sums: Moments::default(),
            }
        }
    }

    /// Step 1c: two least-squares refinements on the inliers, the second with half the tolerance.
    fn refine_plane<const P: usize>(
        &mut self,
        scene: &Scene<'_>,
        points: &Points<P>,
        budget: u32,
    ) -> Result<u32, Error> {
        let Step::RefinePlane {
            round,
            sample,
            mut sums,
        } = self.step
        else {
            return Ok(0);
        };
        let min_inliers = (points.len as u32 / 10).max(16);
        let Some(plane) = self.table.filter(|_| self.best_inliers >= min_inliers) else {
            return Err(Error::NoSupportPlane);
        };
        let tol = self.config.plane_tolerance / (1 << round) as f32;
        let reference = points.pos[0];
        let (items, units) = chunk(points.len as u32 - sample, budget, SAMPLES_PER_UNIT);
        for p in &points.pos[sample as usize..(sample + items) as usize] {
            if plane.signed_distance(*p).abs() < tol {
                sums.add(*p - reference);
            }
        }
        if sample + items < points.len as u32 {
            self.step = Step::RefinePlane {
                round,
                sample: sample + items,
                sums,
            };
            return Ok(units);
        }
        if sums.n >= 3 {
            if let Some(fitted) = sums.plane(reference, plane.n()) {
                self.table = Some(if fitted.offset > 0.0 {
                    fitted.flipped()
                } else {
                    fitted
                });
            }
        }
        self.step = if round == 0 {
            Step::RefinePlane {
                round: 1,
                sample: 0,
                sums: Moments::default(),
            }
        } else {
            self.after_plane(scene)
        };
        Ok(units)
    }

    /// Whether pixel `i` (valid, at `p`) may belong to the object.
    #[inline]
    fn is_candidate(&self, scene: &Scene<'_>, i: usize, p: Vec3) -> bool {
        if scene.mask.is_some() {
            // With a mask, the table only trims background readings at the silhouette.
            return scene.masked(i)
                && self
                    .table
                    .is_none_or(|t| t.signed_distance(p) > self.config.min_height * 0.5);
        }
        let h = self.table.map_or(f32::INFINITY, |t| t.signed_distance(p));
        h > self.config.min_height && h < self.config.max_height
    }

    /// Pixel `i` as a point, if it has a reading and may belong to the object.
    #[inline]
    fn candidate_point(&self, scene: &Scene<'_>, i: u32) -> Option<(u16, u16, Vec3)> {
        let w = scene.intrinsics.width as u32;
        let z = scene.metres(i as usize)?;
        let (u, v) = ((i % w) as u16, (i / w) as u16);
        let p = scene.intrinsics.unproject(u as f32, v as f32, z);
        self.is_candidate(scene, i as usize, p).then_some((u, v, p))
    }

    /// Step 2a: nearest candidate depth per block over the whole image.
    fn candidates<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &mut DepthGrid<C>,
        next: u32,
        budget: u32,
    ) -> Result<u32, Error> {
        let total = scene.depth.len() as u32;
        if next == 0 {
            let k = &scene.intrinsics;
            grid.reset(Rect {
                u0: 0,
                v0: 0,
                width: k.width,
                height: k.height,
            });
        }
        let (items, units) = chunk(total - next, budget, PIXELS_PER_UNIT);
        for i in next..next + items {
            if let Some((u, v, _)) = self.candidate_point(scene, i) {
                grid.add(u, v, scene.depth[i as usize]);
            }
        }
        self.step = if next + items >= total {
            Step::Components(LargestComponent::NEW)
        } else {
            Step::Candidates { next: next + items }
        };
        Ok(units)
    }

    /// Step 2b: the largest connected component of the candidate blocks is the object.
    fn components<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> Result<u32, Error> {
        let Step::Components(mut search) = self.step else {
            return Ok(0);
        };
        let cells = grid.len();
        if search == LargestComponent::NEW {
            scratch.lend(C).flags[..cells].fill(0);
        }
        let blocks = Blocks {
            scene,
            grid,
            config: &self.config,
        };
        let mut used = 0;
        while used < budget {
            used += 1;
            let lent = scratch.lend(C);
            match search.step(&blocks, &mut lent.flags[..cells], lent.queue) {
                component::Progress::Searching => {}
                component::Progress::Marking => break,
                component::Progress::Marked => {
                    self.step = Step::CountObject { next: 0 };
                    return Ok(used);
                }
                component::Progress::Empty => return Err(Error::NoObject),
            }
        }
        self.step = Step::Components(search);
        Ok(used)
    }

    /// Whether pixel `i` is an object pixel, and its point.
    #[inline]
    fn object_point<const C: usize>(
        &self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &Scratch<C>,
        i: u32,
    ) -> Option<(u16, u16, Vec3)> {
        let (u, v, p) = self.candidate_point(scene, i)?;
        (scene.mask.is_some() || scratch.flags()[grid.cell_of(u, v)] & OBJECT != 0)
            .then_some((u, v, p))
    }

    /// Step 3a: count the object pixels and find their bounding box; choose the sampling stride
    /// that should keep the lattice within `P` points (7/8 of it, for aliasing).
    fn count_object<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        next: u32,
        budget: u32,
    ) -> Result<u32, Error> {
        let total = scene.depth.len() as u32;
        if next == 0 {
            self.stats.object_pixels = 0;
            self.bounds = Rect {
                u0: u16::MAX,
                v0: u16::MAX,
                width: 0,
                height: 0,
            };
        }
        let (items, units) = chunk(total - next, budget, PIXELS_PER_UNIT);
        for i in next..next + items {
            if let Some((u, v, _)) = self.object_point(scene, store.grid, store.scratch, i) {
                self.stats.object_pixels += 1;
                self.grow_bounds(u, v);
            }
        }
        if next + items < total {
            self.step = Step::CountObject { next: next + items };
            return Ok(units);
        }
        let found = self.stats.object_pixels as u64;
        if found == 0 {
            return Err(Error::NoObject);
        }
        let target = (P as u64 * 7 / 8).max(1);
        let mut stride = 1u16;
        while stride < MAX_STRIDE && found > (stride as u64).pow(2) * target {
            stride += 1;
        }
        self.begin_sampling(store.points, stride);
        Ok(units)
    }

    fn begin_sampling<const P: usize>(&mut self, points: &mut Points<P>, stride: u16) {
        self.stats.stride = stride;
        points.len = 0;
        self.sum = Vec3::ZERO;
        self.depth_sum = 0.0;
        self.step = Step::Sample { next: 0 };
    }

    fn grow_bounds(&mut self, u: u16, v: u16) {
        let b = &mut self.bounds;
        let (u1, v1) = if b.width == 0 {
            (u, v)
        } else {
            (b.u0 + b.width - 1, b.v0 + b.height - 1)
        };
        let (u0, v0) = (b.u0.min(u), b.v0.min(v));
        *b = Rect {
            u0,
            v0,
            width: u1.max(u) - u0 + 1,
            height: v1.max(v) - v0 + 1,
        };
    }

    /// Step 3b: the object pixels on the lattice of the chosen stride (multiples of the stride,
    /// within the object's box) become the sampled points. Should they overflow `P`, sampling
    /// starts again with the next stride (at [`MAX_STRIDE`], the first `P` are kept).
    fn sample<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        next: u32,
        budget: u32,
    ) -> Result<u32, Error> {
        let s = self.stats.stride;
        let b = self.bounds;
        let first = |start: u16| start.div_ceil(s);
        let (c0, r0) = (first(b.u0), first(b.v0));
        let cols = (b.u0 + b.width - 1) / s + 1 - c0;
        let rows = (b.v0 + b.height - 1) / s + 1 - r0;
        let total = cols as u32 * rows as u32;
        let drop_edges = self.config.drop_edge_pixels;
        let per_unit = if drop_edges {
            LATTICE_POINTS_WITH_EDGES_PER_UNIT
        } else {
            LATTICE_POINTS_PER_UNIT
        };
        let (items, units) = chunk(total - next, budget, per_unit);
        let w = scene.intrinsics.width as u32;
        let jump_per_unit = EDGE_SLOPE / scene.intrinsics.fx.min(scene.intrinsics.fy);
        for j in next..next + items {
            let (u, v) = (
                (c0 + (j % cols as u32) as u16) * s,
                (r0 + (j / cols as u32) as u16) * s,
            );
            let i = v as u32 * w + u as u32;
            let Some((u, v, p)) = self.object_point(scene, store.grid, store.scratch, i) else {
                continue;
            };
            if drop_edges && on_edge(scene, i, (u, v), jump_per_unit) {
                continue;
            }
            if store.points.len == P && s < MAX_STRIDE {
                self.begin_sampling(store.points, s + 1);
                return Ok(units);
            }
            if store.points.push(p, u, v) {
                self.sum += p;
                self.depth_sum += p.z;
            }
        }
        if next + items < total {
            self.step = Step::Sample { next: next + items };
            return Ok(units);
        }
        let n = store.points.len as u32;
        if n < MIN_POINTS {
            return Err(Error::TooFewPoints {
                found: n,
                needed: MIN_POINTS,
            });
        }
        let centroid = self.sum / n as f32;
        let focal = scene.intrinsics.fx.min(scene.intrinsics.fy);
        self.stats.centroid = centroid.to_array();
        self.stats.spacing = s as f32 * self.depth_sum / n as f32 / focal;
        self.step = Step::Observed { next: 0 };
        Ok(units)
    }

    /// Step 4: nearest reading per block over the object's box plus a margin of 15 % of its
    /// larger side (at least 4 pixels).
    fn observed<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &mut DepthGrid<C>,
        next: u32,
        budget: u32,
    ) -> u32 {
        let k = &scene.intrinsics;
        let b = self.bounds;
        let margin = (b.width.max(b.height) as u32 * 15 / 100).max(4) as u16;
        let u0 = b.u0.saturating_sub(margin);
        let v0 = b.v0.saturating_sub(margin);
        let crop = Rect {
            u0,
            v0,
            width: (b.u0 as u32 + b.width as u32 + margin as u32).min(k.width as u32) as u16 - u0,
            height: (b.v0 as u32 + b.height as u32 + margin as u32).min(k.height as u32) as u16
                - v0,
        };
        if next == 0 {
            grid.reset(crop);
        }
        let total = crop.width as u32 * crop.height as u32;
        let (items, units) = chunk(total - next, budget, PIXELS_PER_UNIT);
        for j in next..next + items {
            let (u, v) = (
                crop.u0 + (j % crop.width as u32) as u16,
                crop.v0 + (j / crop.width as u32) as u16,
            );
            grid.add(
                u,
                v,
                scene.depth[v as usize * k.width as usize + u as usize],
            );
        }
        self.step = if next + items >= total {
            Step::Voxels { next: 0 }
        } else {
            Step::Observed { next: next + items }
        };
        units
    }

    /// Step 5: the sampled points into the voxel hash (voxel edge = sample spacing), and the
    /// object's radius.
    fn voxels<const P: usize, const V: usize>(
        &mut self,
        points: &Points<P>,
        voxels: &mut VoxelMap<V>,
        next: u32,
        budget: u32,
    ) -> u32 {
        let centroid = Vec3::from_array(self.stats.centroid);
        if next == 0 {
            voxels.reset(centroid, self.stats.spacing);
        }
        // Two units a point: `next` counts halves, its voxel (even) then its coarser ones (odd).
        let halves = 2 * points.len as u32;
        let (items, units) = chunk(halves - next, budget, 1);
        for half in next..next + items {
            let i = half / 2;
            // A full map only coarsens the nearest-point queries; a point out of range is far
            // from the object centre by 512 voxels and cannot match anything anyway.
            let _: Insert = if half % 2 == 0 {
                let p = points.pos[i as usize];
                self.radius2 = self.radius2.max((p - centroid).length_squared());
                voxels.insert(p, i as u16)
            } else {
                voxels.insert_coarse(i as u16, points.positions())
            };
        }
        if next + items < halves {
            self.step = Step::Voxels { next: next + items };
        } else {
            self.stats.radius = crate::math::sqrt(self.radius2);
            self.step = Step::Done;
        }
        units
    }
}
