//! The measurement model (paper section 4, eqs. 5-11): how well the visible points support a
//! hypothesised symmetry.
//!
//! Each transformed point `Q` has three possible causes, and costs the negative log-likelihood of
//! the most likely one (the "max-mixture" form of eq. 8; no logarithm or exponential is evaluated
//! per point, the constants below are already logarithms):
//! - **match**: `Q` lies on the visible surface: `d² / 2σ²`, `d` the distance to the nearest
//!   visible point (voxel hash, at most eight probes);
//! - **occluded**: `Q` lies where the camera could not see (behind the observed surface along its
//!   ray, in a block with no reading, or outside the image): `c_occluded + v² / 2σ_free²`, `v` the
//!   distance by which `Q` is in front of the observed depth or below the support plane (0 inside
//!   occluded space);
//! - **stray**: anything else, `c_stray`, the heavy tail that makes a false symmetry pay for every
//!   point it puts where the camera would have seen it.
//!
//! A hypothesis' score is the mean cost over its informative points (eq. 11). A composite
//! symmetry is scored per element (each plane; the rotations about an axis) and passes when its
//! elements pass on average and none of them is contradicted, i.e. none costs as much as leaving
//! every point unconfirmed in occluded space: `score = max(mean of element means,
//! worst element mean × accept / c_occluded)`, which is the plain mean for a single element. The
//! maps a composite derives from its elements are not scored (they hold when the elements do). A
//! transformed point within `self_radius` of its source tells nothing (a plane through a point
//! maps it onto itself) and is left out; a hypothesis with too few informative points is
//! rejected.
//!
//! Cost: one work unit per transformed point: one 3x3 transform, up to eight hash probes, and,
//! unless the match already costs less than `c_occluded`, one division (projection) and one depth
//! lookup. No square root, no transcendental.

use crate::config::ModelConfig;
use crate::depth::{DepthGrid, Observed};
use crate::math::Vec3;
use crate::symmetry::{MAX_GROUPS, MapSet, Sampling, Symmetry};
use crate::voxel::VoxelMap;
use crate::work::{Meter, Poll};
use crate::{Intrinsics, Plane};

impl ModelConfig {
    /// The finest match σ for a sampling of the given spacing.
    pub fn sigma_fine(&self, spacing: f32) -> f32 {
        self.sigma_min.max(self.sigma_per_spacing * spacing)
    }

    /// The per-point constants at match σ `sigma`; nearest points are looked up at the voxel
    /// level `voxels` gives for that width.
    pub fn level<const V: usize>(&self, sigma: f32, voxels: &VoxelMap<V>) -> Level {
        let free = sigma * self.free_per_match;
        Level {
            k_match: 0.5 / (sigma * sigma),
            k_free: 0.5 / (free * free),
            cost_occluded: self.cost_occluded,
            cost_stray: self.cost_stray,
            self_radius2: (self.self_radius * sigma) * (self.self_radius * sigma),
            voxel_level: voxels.level_for(sigma),
        }
    }
}

/// Per-point constants of one resolution of the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    k_match: f32,
    k_free: f32,
    cost_occluded: f32,
    cost_stray: f32,
    self_radius2: f32,
    /// The voxel level nearest points are looked up at (see [`VoxelMap::level_for`]).
    voxel_level: u8,
}

impl Level {
    /// Whether `q`, the image of `p`, is too close to `p` to tell anything.
    #[inline]
    pub fn is_self_map(&self, p: Vec3, q: Vec3) -> bool {
        (q - p).length_squared() < self.self_radius2
    }
}

/// What the camera saw: the free-space test of the measurement model.
#[derive(Clone, Copy, Debug)]
pub struct View<'s, const C: usize> {
    pub intrinsics: &'s Intrinsics,
    pub depth_scale: f32,
    pub observed: &'s DepthGrid<C>,
    pub table: Option<Plane>,
}

impl<'s, const C: usize> View<'s, C> {
    pub fn new(
        scene: &'s crate::Scene<'_>,
        observed: &'s DepthGrid<C>,
        table: Option<Plane>,
    ) -> Self {
        Self {
            intrinsics: &scene.intrinsics,
            depth_scale: scene.depth_scale,
            observed,
            table,
        }
    }

    /// How far `q` lies in space the camera saw to be empty: in front of the observed depth along
    /// its ray, or below the support plane. 0 in occluded space; infinite in the image outside the
    /// observed crop (where nothing of the object was seen).
    #[inline]
    pub fn free_space_violation(&self, q: Vec3) -> f32 {
        let below_table = self.table.map_or(0.0, |t| -t.signed_distance(q));
        let in_front = match self.intrinsics.project(q) {
            None => 0.0,
            Some((u, v)) => {
                let k = self.intrinsics;
                let in_image =
                    u >= -0.5 && v >= -0.5 && u < k.width as f32 - 0.5 && v < k.height as f32 - 0.5;
                match self.observed.lookup(u, v) {
                    _ if !in_image => 0.0,
                    Observed::Outside => f32::INFINITY,
                    Observed::Unknown => 0.0,
                    Observed::Depth(raw) => raw as f32 * self.depth_scale - q.z,
                }
            }
        };
        in_front.max(below_table).max(0.0)
    }
}

/// Everything the cost of a transformed point needs: the view and the visible points.
#[derive(Clone, Copy, Debug)]
pub struct Evidence<'s, const V: usize, const C: usize> {
    pub view: View<'s, C>,
    pub voxels: &'s VoxelMap<V>,
    pub points: &'s [Vec3],
}

impl<const V: usize, const C: usize> Evidence<'_, V, C> {
    /// Squared distance from `q` to the nearest visible point (within the voxel block), and the
    /// hash slots the lookup read.
    #[inline]
    pub fn nearest_visible2(&self, q: Vec3) -> (f32, u32) {
        self.voxels.nearest_probed(q, self.points, 0)
    }

    /// The cost of transformed point `q` (see the module docs). Always inlined, like the voxel
    /// lookup it makes: the scoring loop runs it once per work unit, and called out of line (as
    /// the compiler may choose once it has several callers) it costs 15 % more instructions.
    #[inline(always)]
    pub fn cost(&self, q: Vec3, level: &Level) -> f32 {
        let matched = self.voxels.nearest(q, self.points, level.voxel_level) * level.k_match;
        // An unseen point costs at least `cost_occluded`: a closer match needs no free-space test.
        if matched <= level.cost_occluded {
            return matched;
        }
        let v = self.view.free_space_violation(q);
        let unseen = (level.cost_occluded + v * v * level.k_free).min(level.cost_stray);
        matched.min(unseen)
    }
}

/// A hypothesis being scored a bounded number of points at a time. The sums run in one fixed
/// order whatever the slicing, so the score is bit-identical however the work is split.
#[derive(Clone, Debug)]
pub struct Evaluation {
    maps: MapSet,
    level: Option<Level>,
    stride: u16,
    end: u16,
    next: u16,
    map: u8,
    sums: [f32; MAX_GROUPS],
    counts: [u32; MAX_GROUPS],
    uninformative: u32,
}

impl Default for Evaluation {
    fn default() -> Self {
        Self::new()
    }
}

impl Evaluation {
    pub const fn new() -> Self {
        Self {
            maps: MapSet::new(),
            level: None,
            stride: 1,
            end: 0,
            next: 0,
            map: 0,
            sums: [0.0; MAX_GROUPS],
            counts: [0; MAX_GROUPS],
            uninformative: 0,
        }
    }

    /// Start scoring `symmetry` at match σ `sigma` over about `transformed` transformed points,
    /// drawn from the `active` points on a regular stride.
    pub fn begin(
        &mut self,
        symmetry: &Symmetry,
        sampling: Sampling,
        level: Level,
        active: usize,
        transformed: u32,
    ) {
        let maps = symmetry.maps(sampling);
        let sources = (transformed / maps.scored().max(1) as u32).max(1) as usize;
        *self = Self {
            stride: active.div_ceil(sources).clamp(1, u16::MAX as usize) as u16,
            end: active.min(u16::MAX as usize) as u16,
            maps,
            level: Some(level),
            ..Self::new()
        };
    }

    /// Score transformed points, one unit each, spending what is left on `meter`; once every
    /// point is scored, the score (see the module docs; again at every later call, at no cost).
    /// `point(j)` is the index of the `j`-th active point (`j` below the count given to
    /// [`Evaluation::begin`]).
    pub(crate) fn advance<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        point: impl Fn(usize) -> usize,
        meter: &mut Meter,
    ) -> Poll<()> {
        let Some(level) = self.level else {
            return Poll::Ready(());
        };
        let (budget, mut used) = (meter.left(), 0);
        while self.next < self.end && used < budget {
            let p = evidence.points[point(self.next as usize)];
            let (map, group) = self.maps.maps[self.map as usize];
            if let Some(sum) = self.sums.get_mut(group as usize) {
                let q = map.apply(p);
                if level.is_self_map(p, q) {
                    self.uninformative += 1;
                } else {
                    *sum += evidence.cost(q, &level);
                    self.counts[group as usize] += 1;
                }
                used += 1;
            }
            self.map += 1;
            if self.map as usize == self.maps.maps.len() {
                self.map = 0;
                self.next = self.next.saturating_add(self.stride);
            }
        }
        meter.spend(used);
        if self.next < self.end {
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }

    /// The score once finished (see the module docs), or infinity when fewer than
    /// `min_informative` of the transformed points were informative.
    pub(crate) fn score(&self, model: &ModelConfig) -> f32 {
        let informative: u32 = self.counts.iter().sum();
        let total = informative + self.uninformative;
        if total == 0 || (informative as f32) < model.min_informative * total as f32 {
            return f32::INFINITY;
        }
        let (mut sum, mut worst, mut elements) = (0.0f32, 0.0f32, 0);
        for g in (0..self.maps.groups as usize).filter(|&g| self.counts[g] > 0) {
            let mean = self.sums[g] / self.counts[g] as f32;
            (sum, worst, elements) = (sum + mean, worst.max(mean), elements + 1);
        }
        (sum / elements as f32).max(worst * model.accept / model.cost_occluded)
    }
}
