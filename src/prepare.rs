//! Preparation: from the depth image to the sampled object points, the compact depth buffer of the
//! observed scene, and the voxel hash of the visible points.
//!
//! Steps, each resumable after any number of work units (the pixel loops keep their position):
//! 1. **Support plane** (when the scene gives none): RANSAC over a regular subsample of the valid
//!    pixels (the object's pixels excluded when a mask is given), a fixed pseudo-random sequence of
//!    triples, planes facing down in the image left out ([`SUPPORT_FACING_DOWN`]: a face or a
//!    wall), then two least-squares refinements on the inliers. Deterministic.
//! 2. **Segmentation** (when the scene gives no mask): pixels within the working range
//!    (`max_range`) between `min_height` (or three σ of the sensor's noise, if more) and
//!    `max_height` above the support plane are object candidates. Each block of a
//!    [`DepthGrid`] samples its surface at its central pixels
//!    (leaving out pixels on a depth discontinuity, and flagging blocks that hold one); with
//!    `part_at_creases` (the default), blocks on a concave crease (where touching objects meet)
//!    are flagged too. 4-neighbouring blocks join one region when one surface can step between
//!    their samples and no crease runs between them (see [`Blocks`]). Each
//!    region is a candidate when its extent is a plausible object size; the object is the
//!    region the [`crate::Target`] names, or else the candidate at the optical axis (see
//!    [`Blocks::rank`]). With `split_necks`, a region that narrows to a neck is split there
//!    when the segment between its parts crosses the gap between two touching objects (see
//!    [`Cores`], [`at_gap`]), and the part the target, or the optical axis, is nearest kept.
//!    The cells the object (the part kept) encloses join it, and with a region of interest every
//!    other region wholly within it (see [`Preparation::boxed`]); without one, every region
//!    the creases parted from it that hangs from it (a mug's handle, see [`Hanging`]). Its
//!    pixels are those of its blocks (of a block that holds a depth discontinuity, those not
//!    behind its surface, see [`on_block_surface`]) and, from neighbouring blocks, those on its
//!    surface.
//! 3. **Sampling**: object pixels on a regular pixel lattice, and where its rows and columns
//!    leave the object (its outline), the stride the smallest that keeps the count within
//!    `POINTS` (with `drop_edge_pixels`, none next to a depth jump). With a mask, the object
//!    pixels are the mask's above `min_height`, and the lower ones the mask encloses (a
//!    container's floor, [`inside_mask`]); with `trim_past_outline`, less those at its outline
//!    that read what lies past it ([`past_outline`]: a mask takes in pixels across the
//!    silhouette).
//! 4. **Observed depth**: the nearest reading per block of a crop around the object (margin
//!    included): the free-space test of the measurement model; with lateral sensor noise
//!    (`SensorConfig::lateral_noise`), also each block's 3 x 3 neighbourhood minimum, kept in
//!    the segmentation's queue beyond the `POINTS` entries the search lends out.
//! 5. **Voxels**: the sampled points into the voxel hash, at every level; each point marked
//!    when its reading is mixed ([`between_surfaces`]), in the segmentation's flags beyond the
//!    `POINTS` the search lends out ([`Scratch::marks_mut`]): the scoring leaves its images out.
//! 6. **Radius**: the object's radius, the farthest sampled point that no empty shell a
//!    surface's step thick parts from the rest ([`Shells`]).
//!
//! Cost in work units ([`crate::work`]): one unit per `PIXELS_PER_UNIT` pixels visited, per
//! `LATTICE_POINTS_PER_UNIT` sampling-lattice points (`LINE_PIXELS_PER_UNIT` pixels of its
//! lines when the outline is sampled), per `SAMPLES_PER_UNIT` RANSAC residuals, per
//! `CELLS_SPREAD_PER_UNIT` neighbourhood minima, per sampled point (two: its voxel at every
//! level, and its mark), per `SAMPLES_PER_UNIT` points measured for the radius; the
//! segmentation as [`crate::component`] charges it, with `BLOCK_SEEDS_PER_UNIT` blocks scanned
//! for a seed per unit, `DISTANCE_CELLS_PER_UNIT` blocks of a distance-transform pass and one
//! point of a segment tested for a gap per unit.

use crate::component::{self, BestComponent, Graph, Scratch};
use crate::config::{PrepareConfig, SensorConfig};
use crate::depth::{DepthGrid, Rect};
use crate::math::{Mat3, Vec3, normalize};
use crate::voxel::{Insert, VoxelMap};
use crate::work::{
    BLOCK_SEEDS_PER_UNIT, CANDIDATE_PIXELS_PER_UNIT, CELLS_SPREAD_PER_UNIT, CREASE_BLOCKS_PER_UNIT,
    DISTANCE_CELLS_PER_UNIT, HANGING_SEEDS_PER_UNIT, LATTICE_POINTS_PER_UNIT,
    LATTICE_POINTS_WITH_EDGES_PER_UNIT, LINE_PIXELS_PER_UNIT, Meter, OBJECT_AREA_PIXELS_PER_UNIT,
    PIXELS_PER_UNIT, Poll, SAMPLES_PER_UNIT,
};
use crate::{Error, Intrinsics, Plane, Scene, Target};
use core::f32::consts::SQRT_2;

/// tan of the steepest incidence at which a depth camera still returns a reading (85°; beyond
/// it structured-light and time-of-flight readings drop out): neighbouring pixels of one surface
/// differ in depth by at most `z / f` times this.
pub(crate) const EDGE_SLOPE: f32 = 11.43;

/// Whether pixel `i` (at column `u`, row `v`, with a reading) lies on a depth discontinuity: a
/// 4-neighbour's reading differs from its own by more than one surface can step between
/// neighbouring pixels ([`EDGE_SLOPE`]). Such a pixel's footprint may straddle two surfaces: a
/// mixed ("flying") pixel, or one jittered across the silhouette. Mixed pixels come in chains
/// along an edge, so one with a neighbour at its own depth may be mixed too: every pixel next to
/// a jump counts. `jump_per_unit`: [`EDGE_SLOPE`] over the focal length (pixels), the step per
/// depth unit.
#[inline]
fn on_edge(scene: &Scene<'_>, i: u32, (u, v): (u16, u16), jump_per_unit: f32) -> bool {
    let raw = scene.depth[i as usize];
    let jump = raw as f32 * jump_per_unit;
    let apart = |n: u16| n != 0 && (n.abs_diff(raw) as f32) > jump;
    readings_at(scene, i as usize, (u, v), 1)
        .into_iter()
        .any(apart)
}

/// Whether the reading at pixel `[u, v]` lies between two surfaces: a 4-neighbour's reading is
/// nearer by more than one surface can step between neighbouring pixels ([`EDGE_SLOPE`]), and
/// another's farther by more than that, or, two pixels out on the side away from the nearer
/// one, a reading farther by more than two such steps (the far surface past a second blended
/// pixel: across an edge both pixels may be mixed). No surface the camera reads is that steep,
/// so the reading samples neither surface: it is a mixed ("flying") pixel, whose footprint
/// straddled a depth discontinuity and whose depth blends both sides. A pixel on a silhouette
/// (only farther readings beside it) or on the surface behind one (only nearer) is not. Cost:
/// at most nine reads.
///
/// ```text
/// 600 600 600 700 900 900   the 700 (f = 285 px: jumps beyond 28 units at 700) is mixed;
/// 600 600 700 690 900 900   the 700 is mixed (the 900 two pixels out), the 690 is not.
/// ```
/// In the first row the last 600 and the first 900 are not.
#[inline]
pub(crate) fn between_surfaces(scene: &Scene<'_>, [u, v]: [u16; 2]) -> bool {
    let k = &scene.intrinsics;
    let i = v as usize * k.width as usize + u as usize;
    let raw = scene.depth[i];
    let jump = raw as f32 * (EDGE_SLOPE / k.fx.min(k.fy));
    let beside = readings_at(scene, i, (u, v), 1);
    let nearer = beside.map(|n| n != 0 && n < raw && ((raw - n) as f32) > jump);
    if !nearer.contains(&true) {
        return false;
    }
    let farther = |n: u16, steps: f32| n > raw && ((n - raw) as f32) > steps * jump;
    let beyond = readings_at(scene, i, (u, v), 2);
    beside.into_iter().any(|n| farther(n, 1.0))
        || (0..4).any(|k| nearer[k] && farther(beyond[k ^ 1], 2.0))
}

/// Whether masked pixel `i` (at column `u`, row `v`) reads what lies past the object's
/// outline, not the object: it lies at the mask's outline (a 4-neighbour is outside the mask
/// or the image), behind a masked 4-neighbour, and it shares a surface with none of its masked
/// 4-neighbours, of which at least two have a reading (their depths all differ from its own by
/// more than one surface steps between pixels, [`EDGE_SLOPE`], and both readings' noise). A
/// mask from another camera or a detector takes in pixels across the silhouette, and a reading
/// there may blend the object and the background by any weight (a mixed pixel;
/// [`between_surfaces`] tells only those well apart from both surfaces, and the support plane
/// trims only what lies on it). A pixel of the object's own surface shares it with a
/// neighbour: a face seen edge-on steps less than that a pixel, and the far side of a rim (a
/// bowl's inside) lies within the mask. With a single masked neighbour read (the last pixel
/// of a round silhouette, its neighbours along the outline dropped out) the pixel is kept: one
/// step is no evidence. Each neighbour read (its depth and its mask, until one of the object's
/// surface ends the test) is added to `mask_reads`.
///
/// ```text
/// depth  600  600  | 1000   the masked 950, behind the object's 600 mm readings on three
///        600  950  | 1000   sides and beside the unmasked background (past the `|`), shares
///        600  600  | 1000   no surface with them: a mixed pixel. At 610 it would share one.
/// ```
fn past_outline(
    scene: &Scene<'_>,
    sensor: &SensorConfig,
    i: usize,
    (u, v): (u16, u16),
    mask_reads: &mut u32,
) -> bool {
    let k = &scene.intrinsics;
    let raw = scene.depth[i];
    // A step of one surface between neighbours, and both readings' noise (3 σ of the
    // difference of two: 3 √2 σ), in depth units.
    let noise = 3.0 * SQRT_2 * sensor.sigma(raw as f32 * scene.depth_scale) / scene.depth_scale;
    let jump = raw as f32 * (EDGE_SLOPE / k.fx.min(k.fy)) + noise;
    let (mut outline, mut behind, mut apart) = (false, false, 0u8);
    let w = k.width as usize;
    let neighbours = [
        (u > 0).then(|| i - 1),
        (u + 1 < k.width).then(|| i + 1),
        (v > 0).then(|| i - w),
        (v + 1 < k.height).then(|| i + w),
    ];
    for j in neighbours {
        let Some(j) = j else {
            outline = true;
            continue;
        };
        *mask_reads += 1;
        let n = scene.depth[j];
        let within = n != 0 && (n.abs_diff(raw) as f32) <= jump;
        match (scene.masked(j), within) {
            // A neighbour of the object on its surface: the pixel is the object's.
            (true, true) => return false,
            (false, _) => outline = true,
            (true, false) if n != 0 => {
                apart += 1;
                behind |= n < raw;
            }
            (true, false) => {}
        }
    }
    outline && behind && apart >= 2
}

/// Point `i` and whether it is marked a mixed reading in `marks` (step 5,
/// [`between_surfaces`]; a point beyond `marks` is not): what the scoring takes of a source
/// ([`crate::score::Evaluation::advance`]).
#[inline]
pub(crate) fn with_mark(marks: &[u8], i: usize) -> (usize, bool) {
    (i, marks.get(i).is_some_and(|&m| m != 0))
}

/// The readings `d` pixels from pixel `i` (at column `u`, row `v`): left, right, above,
/// below (the one opposite `k` is `k ^ 1`); 0 (no reading) beyond the image.
#[inline]
fn readings_at(scene: &Scene<'_>, i: usize, (u, v): (u16, u16), d: u16) -> [u16; 4] {
    let (k, depth) = (&scene.intrinsics, scene.depth);
    let (w, s) = (k.width as usize, d as usize);
    [
        if u >= d { depth[i - s] } else { 0 },
        if (u as u32 + d as u32) < k.width as u32 {
            depth[i + s]
        } else {
            0
        },
        if v >= d { depth[i - s * w] } else { 0 },
        if (v as u32 + d as u32) < k.height as u32 {
            depth[i + s * w]
        } else {
            0
        },
    ]
}

/// tan 60°: where a block holds a depth discontinuity, its sample joins a neighbour's only when
/// they differ by less than a surface seen at 60° from the line of sight steps between them.
/// Beyond 60° a structured-light camera's projected pattern spreads by more than 1/cos 60° = 2
/// and its readings thin out: beside a discontinuity, a steeper step is taken for the gap
/// between two surfaces (an object in front of another, a silhouette against the table).
const SURFACE_SLOPE: f32 = 1.732;

/// Flags of a candidate block, set before the component search (which uses bits 6 and 7): on
/// a concave crease (it joins no region), and holding a pixel on a depth discontinuity.
const CREASE: u8 = 1;
const STRADDLES: u8 = 2;
/// Flag of a cell reached from the grid's border without crossing the object
/// ([`Step::Enclosed`]).
const OUTSIDE: u8 = 4;
/// Half the side of a block's core, pixels: the segmentation samples each block's surface at
/// its central 3 x 3 pixels (the nearest reading among them), so that a block that straddles
/// two surfaces is still a sample of one of them; nine pixels, so that a few dropouts leave
/// the sample.
const CORE: u16 = 1;

/// Pixels by which a masked reading below `min_height` must lie inside the mask to stay the
/// object's ([`inside_mask`]). A mask's outline may be off the depth silhouette by the depth
/// camera's own error at an edge (a pixel of lateral noise) and, when the mask comes from a
/// colour image, by the depth-to-colour registration (2-3 pixels for Kinect-class cameras): the
/// support readings a mask takes in at the silhouette lie within this margin of its outline.
const MASK_MARGIN: i32 = 4;

/// The pixels [`inside_mask`] reads around a pixel: [`MASK_MARGIN`] away along its row, its
/// column and both diagonals.
const PROBES: [(i32, i32); 8] = {
    let m = MASK_MARGIN;
    [
        (m, 0),
        (-m, 0),
        (0, m),
        (0, -m),
        (m, m),
        (m, -m),
        (-m, m),
        (-m, -m),
    ]
};

/// Mask reads of one [`inside_mask`] test.
const MASK_PROBES: u32 = PROBES.len() as u32;

/// Whether pixel `(u, v)` lies inside the mask by [`MASK_MARGIN`]: the [`PROBES`] around it are
/// the mask's. A reading there that lies low on the support is not the support's seen past the
/// object's outline, which the mask may take in, but the object's own surface the support
/// carries (a container's floor, seen through its opening). Without a mask, false.
fn inside_mask(scene: &Scene<'_>, (u, v): (u16, u16)) -> bool {
    let (w, h) = (
        scene.intrinsics.width as i32,
        scene.intrinsics.height as i32,
    );
    let (u, v) = (u as i32, v as i32);
    scene.mask.is_some()
        && PROBES.into_iter().all(|(du, dv)| {
            let (x, y) = (u + du, v + dv);
            let inside = (0..w).contains(&x) && (0..h).contains(&y);
            inside && scene.masked(y as usize * w as usize + x as usize)
        })
}

/// The segmented object's blocks near pixel `(u, v)`: its own block, if it is the object's
/// (`Near::Own`; `Near::Straddling` if it holds a depth discontinuity, [`STRADDLES`], whose
/// pixels are tested, [`on_block_surface`]), or else those of its 4-neighbours that are
/// (`Near::Beside`, up to four). The flags only, no depth is read.
#[derive(Clone, Copy)]
enum Near {
    None,
    Own,
    Straddling {
        cell: usize,
    },
    Beside {
        cell: usize,
        neighbours: [Option<usize>; 4],
    },
}

#[inline]
fn near_object<const C: usize>(grid: &DepthGrid<C>, flags: &[u8], (u, v): (u16, u16)) -> Near {
    let cell = grid.cell_of(u, v);
    if flags[cell] & OBJECT != 0 {
        return if flags[cell] & STRADDLES == 0 {
            Near::Own
        } else {
            Near::Straddling { cell }
        };
    }
    let neighbours = object_neighbours(grid, flags, cell);
    if neighbours.iter().all(Option::is_none) {
        Near::None
    } else {
        Near::Beside { cell, neighbours }
    }
}

/// The 4-neighbours of block `cell` that are the segmented object's.
#[inline]
fn object_neighbours<const C: usize>(
    grid: &DepthGrid<C>,
    flags: &[u8],
    cell: usize,
) -> [Option<usize>; 4] {
    let object = |n: usize| (flags[n] & OBJECT != 0).then_some(n);
    grid.four_neighbours(cell).map(|n| n.and_then(object))
}

/// Whether a pixel at depth `z` beside the object's blocks (`Near::Beside`) lies on the
/// object's surface: its block has no sample (its core unread or on a discontinuity) and a
/// neighbour of the object's has its sample within the step of a surface the camera still
/// reads ([`EDGE_SLOPE`]) over one and a half block edges; or its block's sample is not the
/// object's (another surface, a crease) and such a neighbour's lies within the step of a
/// surface at 60° incidence ([`SURFACE_SLOPE`]). Three σ of the sensor's noise are allowed on
/// top. A pixel of a straddling object block behind that block's surface
/// (`Near::Straddling`, [`on_block_surface`]) is tested the same way against the block's
/// object neighbours: its block has a sample, the 60° step.
#[inline]
fn on_object_surface<const C: usize>(
    scene: &Scene<'_>,
    grid: &DepthGrid<C>,
    cell: usize,
    neighbours: [Option<usize>; 4],
    z: f32,
    sensor: &SensorConfig,
) -> bool {
    let slope = if grid.get(cell) == 0 {
        EDGE_SLOPE
    } else {
        SURFACE_SLOPE
    };
    let near = |n| within_step(scene, grid, n, z, slope, sensor);
    neighbours.into_iter().flatten().any(near)
}

/// Whether pixel `(u, v)`, at depth `z`, of an object block that holds a depth discontinuity
/// (`Near::Straddling`) is not behind the block's sampled surface: no farther than the step a
/// surface the camera still reads ([`EDGE_SLOPE`], as [`on_edge`] tells one surface from two)
/// makes over the pixels between it and the farthest pixel of the block's core (where the
/// sample, the core's nearest reading, was read), three σ of the sensor's noise on top. The
/// block joined the object by its sample; what lies behind it beyond the discontinuity is what
/// the object stands in front of (an object behind it, the floor), which a block as wide as a
/// can's rim would otherwise bring along: at 0.75 m and f = 1067 px a 7-pixel block takes a
/// surface 4 pixels from its core's far side up to 37 mm behind, where the step over one and a
/// half blocks ([`on_object_surface`]) would take one 9 cm behind. A nearer pixel is kept (a
/// part standing out in front of the sampled surface), and so is every pixel of a block
/// without a sample (enclosed by the object).
#[inline]
fn on_block_surface<const C: usize>(
    scene: &Scene<'_>,
    grid: &DepthGrid<C>,
    cell: usize,
    (u, v): (u16, u16),
    z: f32,
    sensor: &SensorConfig,
) -> bool {
    let zs = grid.get(cell) as f32 * scene.depth_scale;
    // Nearer than the sample, or no sample: kept, no step to work out.
    if z <= zs || zs == 0.0 {
        return true;
    }
    let block = grid.block();
    // Pixels from the core's edge, then across the core: the farthest core pixel.
    let beyond = |c: u16| (c % block).abs_diff(block / 2).saturating_sub(CORE);
    let pixels = (beyond(u).max(beyond(v)) + 2 * CORE) as f32;
    let step = pixels * EDGE_SLOPE / scene.intrinsics.fx.min(scene.intrinsics.fy);
    z - zs <= step * zs + 3.0 * sensor.sigma(zs)
}

/// Whether depth `z` lies within the step a surface of slope `slope` (tan of its incidence)
/// makes over one and a half block edges from block `n`'s sample, three σ of the sensor's noise
/// on top.
#[inline]
fn within_step<const C: usize>(
    scene: &Scene<'_>,
    grid: &DepthGrid<C>,
    n: usize,
    z: f32,
    slope: f32,
    sensor: &SensorConfig,
) -> bool {
    let reach = 1.5 * slope * grid.block() as f32 / scene.intrinsics.fx.min(scene.intrinsics.fy);
    let zn = grid.get(n) as f32 * scene.depth_scale;
    (z - zn).abs() <= reach * zn + 3.0 * sensor.sigma(zn)
}

/// sin 10°: the most a support plane's normal may point down in the image (its `y` component,
/// camera frame, `y` down). A support is seen from above: with the camera not upside down
/// (its image's up within 90° of the world's up), a level support's normal points up in the
/// image (`y < 0`), or across it when the camera looks straight down (`y` near 0: 10° allows
/// for the fit's noise and a tilted support); a vertical face or wall seen from 10° or more
/// above points down in the image by more (`y = sin(elevation)`), and would otherwise win when
/// it fills more of the view than the support (a wrist camera close to a box).
const SUPPORT_FACING_DOWN: f32 = 0.174;

/// tan 45°: the least turn of a concave crease that a block lies on. Two convex objects that
/// touch meet at a concave crease of at least 90° (flat faces: a can's top against a box's
/// face, from any viewpoint; curved faces near their contact turn towards grazing, up to 180°).
/// A block sees a crease's whole turn when the crease passes its sample, and at worst about
/// half of it when the crease runs between two samples; the edge between those two samples
/// then sees the whole turn ([`Blocks::crease_between`]). A smooth concavity (a bowl's inside)
/// turns by a few degrees from block to block. A part that meets its body at a right angle (a
/// mug's handle) is parted from it too, unless [`PrepareConfig::part_at_creases`] is off.
const CREASE_TURN: f32 = 1.0;

/// Whether two surfaces that both recede toward a common line, rising `a` and `b` over a
/// step `step` (tan of their incidence: `a / step`, `b / step`), turn by more than
/// [`CREASE_TURN`]: `atan(a / step) + atan(b / step) > 45°`, without arc tangents or divisions.
#[inline]
fn concave_turn(a: f32, b: f32, step: f32) -> bool {
    let (product, square) = (a * b, step * step);
    product >= square || (a + b) * step > CREASE_TURN * (square - product)
}

/// How the engine chose the object when it segmented the scene itself (no mask given).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Segmentation {
    /// Candidate object regions: connected regions above the support plane, within the working
    /// range, of a plausible object size ([`crate::PrepareConfig`]).
    pub candidates: u16,
    /// The chosen region's position among the candidates, in raster order of their first block
    /// (0: the first); `None` when the target named a region of implausible size.
    pub chosen: Option<u16>,
    /// The chosen object's pixel box.
    pub object_box: Rect,
}

/// Fewest sampled object points a search accepts.
pub const MIN_POINTS: u32 = 24;
/// Largest sampling stride tried (pixels).
const MAX_STRIDE: u16 = 16;
/// Readings the support-plane RANSAC scores each plane on (a regular subsample of the valid
/// ones): a plane's share of inliers is known to 2 % (a standard error, √(0.25 / 600), at half).
const RANSAC_SAMPLES: usize = 600;
/// Triples RANSAC draws: when the support holds a share `w` of the readings, one triple at least
/// lies wholly on it with probability `1 - (1 - w³)^64`: 0.9998 at a half, 0.91 at a third.
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
        index_of(&self.pixel[..self.len], u, v)
    }

    /// The pixels the points were sampled at, in the points' order.
    pub fn pixels(&self) -> &[[u16; 2]] {
        &self.pixel[..self.len]
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

/// Index of pixel `(u, v)` in `pixels`, raster-ordered (row by row) sampled pixels: a binary
/// search.
pub(crate) fn index_of(pixels: &[[u16; 2]], u: u16, v: u16) -> Option<usize> {
    pixels.binary_search_by(|p| (p[1], p[0]).cmp(&(v, u))).ok()
}

/// What the search needs to know about the object's size and sampling.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ObjectStats {
    /// Mean of the sampled points.
    pub centroid: [f32; 3],
    /// Largest distance from the centroid of a sampled point on the object's surface: of the
    /// points that no empty shell a surface's step thick parts from the mean distance
    /// ([`Shells`]). Readings apart from the surface (a silhouette pixel a mask kept that read
    /// the background) do not count.
    pub radius: f32,
    /// Greatest height of a sampled point above the support plane (0 without one): how tall
    /// the object is at least.
    pub top: f32,
    /// Mean distance between neighbouring samples (stride × pixel footprint at the mean depth).
    pub spacing: f32,
    /// Object pixels with a reading (before sampling).
    pub object_pixels: u32,
    /// Sampling stride in pixels.
    pub stride: u16,
}

/// Shells [`Shells`] bins distances into (one bit each): 16 gaps out from the centre (about
/// 260 sample spacings, beyond the half-sphere of 1024 samples, 13). Points beyond share the
/// last shell: a gap among them is not seen.
const SHELLS: u32 = 128;
/// Shells a surface's step ([`ObjectStats::surface_gap`]) is split into: an empty run of them
/// that long parts two surfaces, and an empty gap 1.125 steps wide always holds one.
const SHELLS_PER_GAP: u32 = 8;

impl ObjectStats {
    /// The farthest apart (metres) two neighbouring samples of one surface lie, for samples
    /// `spacing` apart at the mean depth (the centroid's) seen by `sensor`: a diagonal
    /// neighbour on the sampling lattice (√2 strides; the part search's growth takes
    /// 8-neighbours too) on a surface as steep as the camera reads (each stride at most
    /// [`EDGE_SLOPE`] spacings deeper: √(1 + EDGE_SLOPE²) spacings apart), and both readings'
    /// noise (3 √2 σ).
    pub(crate) fn surface_gap(&self, sensor: &SensorConfig) -> f32 {
        // √2 × √(1 + EDGE_SLOPE²) = 16.23 (a test checks it against EDGE_SLOPE).
        16.23 * self.spacing + 3.0 * SQRT_2 * sensor.sigma(self.centroid[2])
    }
}

/// Which shells about a centre, an eighth of a surface's step ([`ObjectStats::surface_gap`])
/// thick, hold a point: to tell the object's surface from readings that lie apart from it.
/// Neighbouring samples of one surface lie less than a step apart, so their distances from any
/// centre leave no empty shell a step thick between them: points beyond such a shell, out from
/// the mean distance's, are on another surface (the table or the background a silhouette pixel
/// read through a mask). Memory: 28 bytes. Cost: a square root per point added.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shells {
    /// Bit `k % 32` of word `k / 32`: a point lies in shell `k` (words, not a `u128`: the
    /// engine's alignment stays that of its `f32`s and `u32`s).
    occupied: [u32; SHELLS as usize / 32],
    /// Shell thickness, metres.
    width: f32,
    /// Sum of the points' distances, metres, and their number.
    sum: f32,
    count: u32,
}

impl Shells {
    /// No points yet; shells a [`SHELLS_PER_GAP`]th of `gap` (metres, `> 0`; infinite: one
    /// shell, nothing parted) thick.
    pub(crate) const fn new(gap: f32) -> Self {
        Self {
            occupied: [0; SHELLS as usize / 32],
            width: gap / SHELLS_PER_GAP as f32,
            sum: 0.0,
            count: 0,
        }
    }

    /// The shell at distance `d` (the last takes all beyond).
    fn shell(&self, d: f32) -> u32 {
        let shell = d / self.width;
        if shell < (SHELLS - 1) as f32 {
            shell as u32
        } else {
            SHELLS - 1
        }
    }

    /// Add a point at squared distance `d2` from the centre.
    pub(crate) fn add(&mut self, d2: f32) {
        let d = crate::math::sqrt(d2);
        let k = self.shell(d);
        self.occupied[k as usize / 32] |= 1 << (k % 32);
        self.sum += d;
        self.count += 1;
    }

    /// The squared distance below which the points are on the surface: the middle of the first
    /// run of [`SHELLS_PER_GAP`] empty shells out from the mean distance's shell (no point lies
    /// within half a gap of it), or infinite when there is no such run (nothing is parted).
    pub(crate) fn within2(&self) -> f32 {
        let start = self.shell(self.sum / self.count.max(1) as f32);
        let mut empty = 0;
        for k in start..SHELLS {
            if self.occupied[k as usize / 32] >> (k % 32) & 1 == 1 {
                empty = 0;
                continue;
            }
            empty += 1;
            if empty == SHELLS_PER_GAP {
                let cut = (k + 1 - SHELLS_PER_GAP / 2) as f32 * self.width;
                return cut * cut;
            }
        }
        f32::INFINITY
    }

    /// The largest distance among `d2s` (squared distances from the centre, those added) below
    /// [`Shells::within2`]: the radius of the surface; 0 without any.
    pub(crate) fn radius(&self, d2s: impl Iterator<Item = f32>) -> f32 {
        crate::math::sqrt(Self::farthest2(self.within2(), d2s, 0.0))
    }

    /// The largest of `d2s` below `within2`, or `so_far` if that is larger: the squared radius
    /// of the surface over `d2s` and the points before them.
    pub(crate) fn farthest2(within2: f32, d2s: impl Iterator<Item = f32>, so_far: f32) -> f32 {
        d2s.filter(|&d2| d2 < within2).fold(so_far, f32::max)
    }
}

/// A block of the object (the chosen component).
const OBJECT: u8 = component::MARKED;

/// Bits 3 to 5 of a block's flags from [`Step::Distances`] on: its chessboard distance, in
/// blocks, to the nearest block not the chosen region's (1 on its outline), at most
/// [`DISTANCE_MAX`] (the three bits the flag byte has free); 0 off the region. No later step
/// reads them but the enclosing fill (a block the split left out has one); the domain growth
/// clears the flags it borrows.
const DISTANCE_SHIFT: u8 = 3;
const DISTANCE_MAX: u8 = 7;
const DISTANCE: u8 = DISTANCE_MAX << DISTANCE_SHIFT;

#[inline]
fn distance(flag: u8) -> u8 {
    (flag & DISTANCE) >> DISTANCE_SHIFT
}

/// The target in blocks of the segmentation grid.
#[derive(Clone, Copy, Debug, PartialEq)]
enum TargetCells {
    None,
    /// The block holding the target pixel: the region holding it, or, when it belongs to none
    /// (no reading at its core, a crease), the region holding most of its eight neighbours.
    Cell(usize),
    /// The blocks from `(c0, r0)` to `(c1, r1)`, inclusive.
    Cells((u16, u16), (u16, u16)),
}

/// What the segmentation keeps of a region while it is searched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Region {
    /// Block box: first and last column and row (valid once a block is added).
    lo: (u16, u16),
    hi: (u16, u16),
    /// Sums of the blocks' columns, rows and raw depth samples (at most 65 536 blocks, the
    /// queue's `u16` index, of at most 65 535 each: below `u32::MAX`).
    cols: u32,
    rows: u32,
    depth: u32,
    /// Blocks of the region the target covers.
    on_target: u32,
}

impl Region {
    /// The pixels of the region's blocks and of their 4-neighbours (which lend pixels to it),
    /// as a box in an image of `k`'s size cut into blocks of `block` pixels; with `and`, the box
    /// holding both.
    fn area(&self, block: u16, k: &Intrinsics, and: Option<Rect>) -> Rect {
        let block = block as u32;
        let mut u0 = (self.lo.0 as u32).saturating_sub(1) * block;
        let mut v0 = (self.lo.1 as u32).saturating_sub(1) * block;
        let mut u1 = ((self.hi.0 as u32 + 2) * block).min(k.width as u32);
        let mut v1 = ((self.hi.1 as u32 + 2) * block).min(k.height as u32);
        if let Some(a) = and {
            (u0, v0) = (u0.min(a.u0 as u32), v0.min(a.v0 as u32));
            u1 = u1.max(a.u0 as u32 + a.width as u32);
            v1 = v1.max(a.v0 as u32 + a.height as u32);
        }
        Rect {
            u0: u0 as u16,
            v0: v0 as u16,
            width: (u1 - u0) as u16,
            height: (v1 - v0) as u16,
        }
    }
}

/// The candidate blocks not yet the object's as a graph ([`Preparation::boxed`]): joined as in
/// [`Blocks`], a region ranked by its size when it lies wholly within the blocks from `lo` to
/// `hi` (the caller's region of interest), never otherwise. Blocks the neck split parted from
/// the object (their distance kept) are another object's and take no part.
struct Boxed<'g, 'a, 's, const C: usize> {
    blocks: &'g Blocks<'a, 's, C>,
    lo: (u16, u16),
    hi: (u16, u16),
}

/// Whether a block is free to join the object: not the object's, and not parted from it by
/// the neck split (its distance kept: another object's).
fn free_block(flags: &[u8], block: usize) -> bool {
    flags[block] & OBJECT == 0 && distance(flags[block]) == 0
}

impl<const C: usize> Graph for Boxed<'_, '_, '_, C> {
    const SEEDS_PER_UNIT: u32 = BLOCK_SEEDS_PER_UNIT;
    type Summary = Region;

    fn seeds(&self) -> u32 {
        self.blocks.seeds()
    }

    fn seed(&self, s: u32) -> usize {
        self.blocks.seed(s)
    }

    fn can_seed(&self, flags: &[u8], block: usize) -> bool {
        free_block(flags, block) && self.blocks.can_seed(flags, block)
    }

    fn joined(&self, flags: &[u8], block: usize, k: usize) -> Option<usize> {
        (self.blocks.joined(flags, block, k)).filter(|&n| free_block(flags, n))
    }

    fn add(&self, flags: &[u8], r: &mut Region, block: usize) {
        self.blocks.add(flags, r, block);
    }

    fn rank(&self, r: &Region, size: u32) -> u32 {
        let (lo, hi) = (self.lo, self.hi);
        let within = lo.0 <= r.lo.0 && lo.1 <= r.lo.1 && r.hi.0 <= hi.0 && r.hi.1 <= hi.1;
        if within { size } else { 0 }
    }
}

/// What the search for hanging parts keeps of a region ([`Hanging`]); each field valid once
/// a block is added.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Hang {
    /// Blocks added.
    blocks: u32,
    /// Sum of the blocks' points ([`block_sample`]).
    sum: Vec3,
    /// Least and greatest height of a block's point above the support...
    lowest: f32,
    highest: f32,
    /// ... and of a block that touches the object ([`Hanging::touches`]; `(∞, -∞)`: none).
    junctions: (f32, f32),
    /// Whether another region may hold it up ([`Hanging::held_elsewhere`]).
    held_elsewhere: bool,
}

/// The candidate blocks not yet the object's as a graph ([`Preparation::hanging`]): joined as
/// in [`Blocks`], a region seeded only from a block that touches the object across a concave
/// crease ([`Hanging::touches`]), and ranked by its size when nothing but the object holds it
/// up (a mug's handle), never otherwise:
/// - it meets the object above and below: the heights of its blocks that touch the object span
///   at least half its own height. A handle meets its body at two junctions near its top and
///   bottom (a ring attached on its inner side, unless it stands out from the body by more
///   than 87 % of its radius, at more than half its height apart); a second object leaning on
///   the object touches it in one patch;
/// - no other region below it may hold it up ([`Hanging::held_elsewhere`]);
/// - it is clear of the support ([`Hanging::clear`]) and the camera sees the column below its
///   centroid empty down to the support ([`Hanging::empty_below`]): a second object standing
///   or lying on the support fills that column, or hides it behind its seen surface (a ball's
///   underside curves back below the centroid of what the camera sees of it).
///
/// Blocks the neck split parted from the object take no part ([`free_block`]).
struct Hanging<'g, 'a, 's, const C: usize> {
    blocks: &'g Blocks<'a, 's, C>,
    support: Plane,
}

impl<const C: usize> Hanging<'_, '_, '_, C> {
    /// A loop's junctions span at least this share of its height (see [`Hanging`]).
    const JUNCTION_SPAN: f32 = 0.5;

    /// Whether block `i`, not the object's, touches it across a concave crease: one surface
    /// steps ([`Blocks::surface_step`]) from `i` to a 4-neighbour of the object (the crease
    /// then ran between the two, [`Blocks::crease_between`]), or to a 4-neighbour on a crease
    /// ([`CREASE`]) and on from it to a 4-neighbour of the object.
    fn touches(&self, flags: &[u8], i: usize) -> bool {
        let (blocks, grid) = (self.blocks, self.blocks.grid);
        let steps = |a: usize, b: usize| blocks.surface_step(flags, a, b).is_some();
        grid.four_neighbours(i).into_iter().flatten().any(|n| {
            let across = |m: usize| flags[m] & OBJECT != 0 && steps(n, m);
            (flags[n] & OBJECT != 0
                || flags[n] & CREASE != 0
                    && grid.four_neighbours(n).into_iter().flatten().any(across))
                && steps(i, n)
        })
    }

    /// Whether another region than the object's may hold block `i` of a region (its sample
    /// `own` above the support) up: a 4-neighbour lower down (its sample nearer the support),
    /// not the object's nor on a crease, that the block graph does not join to `i`
    /// ([`Blocks::joined`]) and that touches it (one surface steps between them across a
    /// crease, [`Blocks::surface_step`]: a bowl's flaring wall on its own base) or may hide its
    /// support (nearer the camera across a depth jump: the near rim below the far wall), or
    /// that the neck split parted from the object. A region farther away across a jump is seen
    /// past `i`'s edge and does not touch it; one beside or above it holds nothing up.
    fn held_elsewhere(&self, flags: &[u8], i: usize, own: f32) -> bool {
        let (blocks, grid) = (self.blocks, self.blocks.grid);
        let height = |b: usize| {
            let p = block_sample(blocks.scene, grid, b);
            self.support.signed_distance(p)
        };
        (0..component::AROUND.len()).any(|k| {
            let Some(n) = grid.side_neighbour(i, k) else {
                return false;
            };
            if grid.get(n) == 0 || flags[n] & (OBJECT | CREASE) != 0 || height(n) >= own {
                return false;
            }
            if !free_block(flags, n) {
                return true;
            }
            let touches = blocks.surface_step(flags, i, n).is_some();
            let hides = grid.get(n) < grid.get(i);
            blocks.joined(flags, i, k).is_none() && (touches || hides)
        })
    }

    /// Whether a region whose lowest point lies `h` above the support (at depth `z`) is clear
    /// of it: a region standing on the support has a block within a candidate's least height
    /// (the larger of `min_height` and three σ of the sensor's noise) plus one block's extent
    /// (its sample lies anywhere in it) and three σ more (the sample's own noise).
    fn clear(&self, h: f32, z: f32) -> bool {
        let blocks = self.blocks;
        let noise = 3.0 * blocks.sensor.sigma(z);
        h > blocks.config.min_height.max(noise) + blocks.block_per_z * z + noise
    }

    /// Whether the camera sees the column below `centroid` empty, from the support up to
    /// `lowest` (the region's least height): at its foot the reading lies on the support, and
    /// at a quarter, half and three quarters of the way up beyond the point, each within three
    /// σ of the sensor's noise. Cost: four projections and reads.
    fn empty_below(&self, centroid: Vec3, lowest: f32) -> bool {
        let up = Vec3::from_array(self.support.normal);
        let foot = centroid - up * self.support.signed_distance(centroid);
        (0..4).all(|j| {
            let q = foot + up * (lowest * j as f32 * 0.25);
            self.reading_at(q).is_some_and(|seen| {
                let noise = 3.0 * self.blocks.sensor.sigma(seen.z);
                if j == 0 {
                    self.support.signed_distance(seen).abs() < noise
                } else {
                    seen.z > q.z + noise
                }
            })
        })
    }

    /// The point the camera read at the pixel `q` projects into, if it lies in the image and
    /// the pixel has a reading.
    fn reading_at(&self, q: Vec3) -> Option<Vec3> {
        let scene = self.blocks.scene;
        let k = &scene.intrinsics;
        // The pixel whose centre is nearest the projection.
        let (u, v) = k.project(q)?;
        let (u, v) = pixel_at(k, u + 0.5, v + 0.5)?;
        let z = scene.metres(v as usize * k.width as usize + u as usize)?;
        Some(k.unproject(u as f32, v as f32, z))
    }
}

impl<const C: usize> Graph for Hanging<'_, '_, '_, C> {
    const SEEDS_PER_UNIT: u32 = HANGING_SEEDS_PER_UNIT;
    type Summary = Hang;

    fn seeds(&self) -> u32 {
        self.blocks.seeds()
    }

    fn seed(&self, s: u32) -> usize {
        self.blocks.seed(s)
    }

    fn can_seed(&self, flags: &[u8], block: usize) -> bool {
        free_block(flags, block) && self.blocks.can_seed(flags, block) && self.touches(flags, block)
    }

    fn joined(&self, flags: &[u8], block: usize, k: usize) -> Option<usize> {
        (self.blocks.joined(flags, block, k)).filter(|&n| free_block(flags, n))
    }

    fn add(&self, flags: &[u8], h: &mut Hang, block: usize) {
        let p = block_sample(self.blocks.scene, self.blocks.grid, block);
        let height = self.support.signed_distance(p);
        if h.blocks == 0 {
            (h.lowest, h.highest) = (height, height);
            h.junctions = (f32::INFINITY, f32::NEG_INFINITY);
        }
        h.blocks += 1;
        h.sum += p;
        h.lowest = h.lowest.min(height);
        h.highest = h.highest.max(height);
        if self.touches(flags, block) {
            h.junctions = (h.junctions.0.min(height), h.junctions.1.max(height));
        }
        h.held_elsewhere |= self.held_elsewhere(flags, block, height);
    }

    fn rank(&self, h: &Hang, size: u32) -> u32 {
        let centroid = h.sum / h.blocks.max(1) as f32;
        let span = h.junctions.1 - h.junctions.0;
        let hangs = span >= Self::JUNCTION_SPAN * (h.highest - h.lowest)
            && !h.held_elsewhere
            && self.clear(h.lowest, centroid.z)
            && self.empty_below(centroid, h.lowest);
        if hangs { size } else { 0 }
    }
}

/// The candidate blocks of the depth buffer as a graph: two 4-neighbours are joined when one
/// surface can pass between their samples: they differ by less than a surface the camera
/// still reads steps ([`EDGE_SLOPE`]), or, where either block holds a depth discontinuity
/// ([`STRADDLES`]), a surface at 60° incidence ([`SURFACE_SLOPE`]); three σ of noise on top;
/// and, with [`PrepareConfig::part_at_creases`], no concave crease runs between them
/// ([`Blocks::crease_between`]). A block on a concave crease ([`CREASE`],
/// [`Blocks::on_crease`]) joins none.
///
/// Diagonal neighbours are not joined: a diagonal step crosses a crease obliquely, where its
/// turn reads smaller, and leaks past it.
struct Blocks<'a, 's, const C: usize> {
    scene: &'a Scene<'s>,
    grid: &'a DepthGrid<C>,
    config: &'a PrepareConfig,
    sensor: SensorConfig,
    /// Block edge over the focal length: a block's width per metre of depth.
    block_per_z: f32,
    target: TargetCells,
}

impl<const C: usize> Blocks<'_, '_, C> {
    /// Whether block `i` lies on a concave crease: on one of the four lines through it (the
    /// columns, rows and diagonals of blocks), the surfaces on both sides recede into it,
    /// turning by more than [`CREASE_TURN`].
    fn on_crease(&self, i: usize) -> bool {
        let z = self.depth(i);
        if z == 0.0 {
            return false;
        }
        let (cols, rows) = (self.grid.cols(), self.grid.rows());
        let (c, r) = self.grid.cell_position(i);
        if c == 0 || r == 0 || c + 1 >= cols || r + 1 >= rows {
            return false;
        }
        let cols = cols as usize;
        let noise = 3.0 * self.sensor.sigma(z);
        let across = self.block_per_z * z;
        // The four lines through the block: (offset of one neighbour, the line's step in block
        // edges); the other neighbour is opposite.
        let lines = [
            (1, across),
            (cols, across),
            (cols + 1, SQRT_2 * across),
            (cols - 1, SQRT_2 * across),
        ];
        lines.iter().any(|&(offset, step)| {
            let (p, q) = (self.depth(i - offset), self.depth(i + offset));
            // Rises into this block from both sides, in metres: slopes `rise / step`.
            let (a, b) = (z - p, z - q);
            p != 0.0 && q != 0.0 && a > -noise && b > -noise && concave_turn(a, b, step)
        })
    }

    /// Whether a concave crease runs between block `a` and its neighbour `b` (neighbour `k`,
    /// [`component::AROUND`]): the surfaces beyond them on their line, from `a`'s other
    /// neighbour into `a` and from `b`'s far neighbour into `b`, both recede toward the gap
    /// and turn by more than [`CREASE_TURN`]. A crease midway between two samples shows each of
    /// them about half its turn ([`Blocks::on_crease`]); across the gap the whole turn shows.
    /// Symmetric in `a` and `b`.
    fn crease_between(&self, a: usize, b: usize, k: usize, near: f32, noise: f32) -> bool {
        // The blocks beyond the pair on its line: one step back from `a`, one on from `b`
        // (index arithmetic; only a step along a row can leave the grid sideways).
        let (cols, cells) = (self.grid.cols() as isize, self.grid.len() as isize);
        let (dx, dy) = component::AROUND[k];
        let (step, a) = ((dy as isize) * cols + dx as isize, a as isize);
        let (p, q) = (a - step, a + 2 * step);
        let inside = |i: isize| (0..cells).contains(&i);
        let in_row = |c: isize| (0..cols).contains(&c);
        let dx = dx as isize;
        if !inside(p)
            || !inside(q)
            || dx != 0 && {
                let column = a % cols.max(1);
                !(in_row(column - dx) && in_row(column + 2 * dx))
            }
        {
            return false;
        }
        let (za, zb) = (self.depth(a as usize), self.depth(b));
        let (zp, zq) = (self.depth(p as usize), self.depth(q as usize));
        if zp == 0.0 || zq == 0.0 {
            return false;
        }
        let (rise_a, rise_b) = (za - zp, zb - zq);
        rise_a > -noise && rise_b > -noise && concave_turn(rise_a, rise_b, self.block_per_z * near)
    }

    /// Whether one surface can step from block `a` to its 4-neighbour `n`: their samples differ
    /// by less than a surface the camera still reads steps between them ([`EDGE_SLOPE`]; a
    /// surface at 60° incidence, [`SURFACE_SLOPE`], where either holds a depth discontinuity,
    /// [`STRADDLES`]) and three σ of noise. If so, the nearer depth and those three σ; `None`
    /// when `n` has no sample.
    fn surface_step(&self, flags: &[u8], a: usize, n: usize) -> Option<(f32, f32)> {
        let (za, zb) = (self.depth(a), self.depth(n));
        if zb == 0.0 {
            return None;
        }
        let near = za.min(zb);
        let slope = if (flags[a] | flags[n]) & STRADDLES != 0 {
            SURFACE_SLOPE
        } else {
            EDGE_SLOPE
        };
        let noise = 3.0 * self.sensor.sigma(near);
        let step = slope * self.block_per_z * near + noise;
        ((za - zb).abs() < step).then_some((near, noise))
    }

    /// Depth of block `i` in metres (0 for none).
    #[inline]
    fn depth(&self, i: usize) -> f32 {
        self.grid.get(i) as f32 * self.scene.depth_scale
    }

    /// The region's extent (m): the larger side of its block box at its mean depth.
    fn extent(&self, r: &Region, size: u32) -> f32 {
        let side = (r.hi.0 - r.lo.0).max(r.hi.1 - r.lo.1) as f32 + 1.0;
        let z = r.depth as f32 / size.max(1) as f32 * self.scene.depth_scale;
        side * self.block_per_z * z
    }
}

impl<const C: usize> Graph for Blocks<'_, '_, C> {
    const SEEDS_PER_UNIT: u32 = BLOCK_SEEDS_PER_UNIT;
    type Summary = Region;

    fn seeds(&self) -> u32 {
        self.grid.len() as u32
    }

    fn seed(&self, s: u32) -> usize {
        s as usize
    }

    fn can_seed(&self, flags: &[u8], block: usize) -> bool {
        self.grid.get(block) != 0 && flags[block] & CREASE == 0
    }

    fn joined(&self, flags: &[u8], block: usize, k: usize) -> Option<usize> {
        let n = self.grid.side_neighbour(block, k)?;
        if flags[n] & CREASE != 0 {
            return None;
        }
        let (near, noise) = self.surface_step(flags, block, n)?;
        let creased = self.config.part_at_creases && self.crease_between(block, n, k, near, noise);
        (!creased).then_some(n)
    }

    fn add(&self, _: &[u8], r: &mut Region, block: usize) {
        let (c, row) = self.grid.cell_position(block);
        if r.depth == 0 {
            (r.lo, r.hi) = ((c, row), (c, row));
        }
        r.lo = (r.lo.0.min(c), r.lo.1.min(row));
        r.hi = (r.hi.0.max(c), r.hi.1.max(row));
        r.cols += c as u32;
        r.rows += row as u32;
        r.depth += self.grid.get(block) as u32;
        r.on_target += match self.target {
            TargetCells::None => 0,
            // Its own block outranks all eight neighbours together.
            TargetCells::Cell(t) if t == block => 9,
            TargetCells::Cell(t) => {
                let (tc, tr) = self.grid.cell_position(t);
                (tc.abs_diff(c) <= 1 && tr.abs_diff(row) <= 1) as u32
            }
            TargetCells::Cells(lo, hi) => {
                (lo.0 <= c && c <= hi.0 && lo.1 <= row && row <= hi.1) as u32
            }
        };
    }

    fn candidate(&self, r: &Region, size: u32) -> bool {
        let extent = self.extent(r, size);
        extent >= self.config.min_object_size && extent <= self.config.max_object_size
    }

    /// With a target, the blocks it covers; without (candidates only), first the regions whose
    /// block box holds the principal point, the largest first (an object seen around the
    /// optical axis, not a part of it nearer the axis: a container's inside), then the others
    /// by the nearness of their centre to the principal point.
    fn rank(&self, r: &Region, size: u32) -> u32 {
        if self.target != TargetCells::None {
            return r.on_target;
        }
        if !self.candidate(r, size) {
            return 0;
        }
        let k = &self.scene.intrinsics;
        let block = self.grid.block() as f32;
        let (axis_c, axis_r) = (k.cx / block, k.cy / block);
        let holds = |lo: u16, hi: u16, at: f32| lo as f32 <= at && at < hi as f32 + 1.0;
        if holds(r.lo.0, r.hi.0, axis_c) && holds(r.lo.1, r.hi.1, axis_r) {
            return HOLDS_AXIS | size.min(HOLDS_AXIS - 1);
        }
        let n = size.max(1) as f32;
        let (u, v) = (
            (r.cols as f32 / n + 0.5) * block,
            (r.rows as f32 / n + 0.5) * block,
        );
        let d2 = (u - k.cx) * (u - k.cx) + (v - k.cy) * (v - k.cy);
        // Pixel distances squared stay far below 2e9 for images up to 30 000 pixels a side.
        (HOLDS_AXIS - 1) - (d2.min(2.0e9) as u32)
    }
}

/// The cores of the chosen region as a graph: its blocks at least [`CORE_DEPTH`] from its
/// outline ([`DISTANCE`]), joined to their 4-neighbours that are too. Two touching objects the
/// block graph could not part (coplanar can lids meeting at a point) make a region with a
/// neck, a passage narrower than either object: each object's blocks deeper than the neck
/// form a core of their own. A convex object's distance map has a single summit and one core;
/// so does an object whose narrower part is no thicker than its junction with the rest (a
/// handle on a body). One object with a waist (a tool's handle between its body and its
/// battery, a curved fruit's middle) has two cores too: its parts rejoin unless their summits
/// are [`apart`] and the segment between them crosses a gap ([`at_gap`], [`Step::Split`]).
/// Ranked by the nearness of their nearest block to `aim` (block units): the core the target
/// names, or the one nearest the principal point, is marked.
struct Cores<'a, const C: usize> {
    grid: &'a DepthGrid<C>,
    aim: (f32, f32),
}

impl<const C: usize> Graph for Cores<'_, C> {
    const SEEDS_PER_UNIT: u32 = BLOCK_SEEDS_PER_UNIT;
    /// The nearness of the core's nearest block to the aim: `CLOSE - d²`, `d` in blocks.
    type Summary = u32;

    fn seeds(&self) -> u32 {
        self.grid.len() as u32
    }

    fn seed(&self, s: u32) -> usize {
        s as usize
    }

    fn can_seed(&self, flags: &[u8], block: usize) -> bool {
        distance(flags[block]) >= CORE_DEPTH
    }

    fn joined(&self, flags: &[u8], block: usize, k: usize) -> Option<usize> {
        let n = self.grid.side_neighbour(block, k)?;
        (distance(flags[n]) >= CORE_DEPTH).then_some(n)
    }

    fn add(&self, _: &[u8], nearest: &mut u32, block: usize) {
        let (c, r) = self.grid.cell_position(block);
        let (dc, dr) = (c as f32 + 0.5 - self.aim.0, r as f32 + 0.5 - self.aim.1);
        // Squared distances in blocks stay far below CLOSE for grids under 20 000 blocks a side.
        let d2 = (dc * dc + dr * dr).min(CLOSE as f32 - 1.0) as u32;
        *nearest = (*nearest).max(CLOSE - d2);
    }

    fn candidate(&self, _: &u32, _: u32) -> bool {
        true
    }

    fn rank(&self, nearest: &u32, _: u32) -> u32 {
        *nearest
    }
}

/// The least distance from the outline of a core's blocks ([`Cores`]). The distance map
/// resolves a block: at depths 1 and 2 a block is on the outline or next to it, where one
/// block read or dropped (a straddling edge, a pixel of noise) opens or closes a passage;
/// from 3 on, a core is at least five blocks across and the passage parting it from another
/// at most four.
const CORE_DEPTH: u8 = 3;

/// Points of the segment between two cores' summits tested for a gap ([`Step::Split`]),
/// its ends left out: at a 16th of the distance between two touching objects' summits (about
/// their radius), the gap between them, wider than a block, is not stepped over.
const SEGMENT_POINTS: u32 = 16;

/// The point seen at block `i`'s centre pixel (at its sample's depth when that pixel has no
/// reading): a reading like those it is compared with, not the nearest of nine.
fn block_point<const C: usize>(scene: &Scene<'_>, grid: &DepthGrid<C>, i: usize) -> Vec3 {
    let (u, v) = block_centre(scene, grid, i);
    let k = &scene.intrinsics;
    let raw = match scene.depth[v as usize * k.width as usize + u as usize] {
        0 => grid.get(i),
        raw => raw,
    };
    k.unproject(u as f32, v as f32, raw as f32 * scene.depth_scale)
}

/// Block `i`'s sample (the nearest candidate reading among its pixels) as a point at its
/// centre pixel: within a block of where it was read, on the block's own surface whatever its
/// centre pixel reads (a thin part's block may see the support past it there).
fn block_sample<const C: usize>(scene: &Scene<'_>, grid: &DepthGrid<C>, i: usize) -> Vec3 {
    let (u, v) = block_centre(scene, grid, i);
    let z = grid.get(i) as f32 * scene.depth_scale;
    scene.intrinsics.unproject(u as f32, v as f32, z)
}

/// The centre pixel of block `i` (within the image).
fn block_centre<const C: usize>(scene: &Scene<'_>, grid: &DepthGrid<C>, i: usize) -> (u16, u16) {
    let (c, r) = grid.cell_position(i);
    let b = grid.block();
    let k = &scene.intrinsics;
    (
        (c * b + b / 2).min(k.width - 1),
        (r * b + b / 2).min(k.height - 1),
    )
}

/// Whether `p`, a point of the segment between two summits ([`Step::Split`]), lies in the gap
/// where two touching convex objects meet:
/// - in free space: in front of the reading on its line of sight by more than [`CHORD_SIGMAS`]
///   σ of the sensor's noise (outside the image or without a reading: not known to be free);
/// - that reading deeper than both summits' (`beyond`, metres): from each object's summit its
///   surface recedes toward their contact, while a single object's narrower part between two
///   wider ones (a tool's handle between its body and its battery) is read between them;
/// - its block, or one of the eight around it, in each part (`flags`, after the flood): the gap
///   lies on the seam between the parts, not across a bay of one object's outline (the inside
///   of a curved banana, the opening in front of a handle), where the table is seen.
fn at_gap<const C: usize>(
    scene: &Scene<'_>,
    sensor: &SensorConfig,
    grid: &DepthGrid<C>,
    flags: &[u8],
    p: Vec3,
    beyond: f32,
) -> bool {
    let k = &scene.intrinsics;
    let Some((u, v)) = k.project(p).and_then(|(u, v)| pixel_at(k, u, v)) else {
        return false;
    };
    let raw = scene.depth[v as usize * k.width as usize + u as usize];
    let z = raw as f32 * scene.depth_scale;
    if raw == 0 || p.z >= z - CHORD_SIGMAS * sensor.sigma(z) || z <= beyond {
        return false;
    }
    let cell = grid.cell_of(u, v);
    let part = |i: usize| (distance(flags[i]) > 0).then_some(flags[i] & OBJECT != 0);
    let around = (0..8).filter_map(|n| grid.neighbour(cell, n));
    let mut parts = core::iter::once(cell).chain(around).filter_map(part);
    let first = parts.next();
    first.is_some_and(|kept| parts.any(|is_kept| is_kept != kept))
}

/// The pixel holding image coordinates `(u, v)` (truncated), if they lie in the image. The
/// comparisons also reject NaN.
fn pixel_at(k: &Intrinsics, u: f32, v: f32) -> Option<(u16, u16)> {
    let inside = u >= 0.0 && v >= 0.0 && u < k.width as f32 && v < k.height as f32;
    inside.then_some((u as u16, v as u16))
}

/// Whether two cores' summits (each its distance from the region's outline and its block) are
/// far enough apart to be two convex objects': a summit `d` blocks deep has the square of
/// chessboard radius `d - 1` around it inside the region, and two touching convex objects' own
/// squares do not overlap (their junction is narrower than either), so the summits are at
/// least `d₁ + d₂ - 1` blocks apart. One object's summits on either side of a slight waist
/// are nearer (a curved banana's halves, 2 blocks apart at depth 3).
fn apart<const C: usize>(grid: &DepthGrid<C>, (da, a): (u8, u32), (db, b): (u8, u32)) -> bool {
    let (ac, ar) = grid.cell_position(a as usize);
    let (bc, br) = grid.cell_position(b as usize);
    let blocks = ac.abs_diff(bc).max(ar.abs_diff(br)) as u32;
    blocks + 1 >= da as u32 + db as u32
}

/// σ of the sensor's noise by which a point of the segment between two readings must lie in
/// front of the reading behind it to be in free space: on one flat surface the segment and the
/// reading differ by three readings' noise (the two ends', interpolated, and the reading's),
/// about 1.5 σ; at five σ each of [`SEGMENT_POINTS`] points passes by chance less than once in
/// 2 000 (a convex surface's segment lies behind it and never does).
const CHORD_SIGMAS: f32 = 5.0;

/// The nearness of a block at the aim itself ([`Cores`]).
const CLOSE: u32 = 1 << 30;

/// The rank of a region whose box holds the principal point starts here (see
/// [`Blocks::rank`]); every other's is below it.
const HOLDS_AXIS: u32 = 1 << 31;

/// A box of blocks: its first and last column and row.
type BlockBox = ((u16, u16), (u16, u16));

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
    Creases {
        next: u32,
    },
    Components(BestComponent<Region>),
    /// The chosen region's distance transform ([`DISTANCE`]): a forward and a backward raster
    /// pass over the cells; `peak`: the largest distance so far.
    Distances {
        backward: bool,
        next: u32,
        peak: u8,
        /// Cells the region encloses (neither its own nor reached by the enclosing flood).
        enclosed: u32,
    },
    /// The region's cores (blocks at least [`CORE_DEPTH`] from its outline, 4-connected): the
    /// one nearest the target, or the principal point, is marked.
    Cores {
        enclosed: u32,
        search: BestComponent<u32>,
    },
    /// Every block of the region joins the core nearest it (a flood from all cores at once); the
    /// marked core's blocks are the object.
    Split {
        phase: Splitting,
        next: u32,
        head: u32,
        tail: u32,
        /// The marked core's summit (its first block farthest from the outline) and the other
        /// cores' (its distance, 0 for none; the block).
        kept: (u8, u32),
        other: (u8, u32),
        enclosed: u32,
    },
    /// Cells enclosed by the object join it: flood from the grid's border around it.
    Enclosed {
        phase: Enclosing,
        next: u32,
        head: u32,
        tail: u32,
        /// The region was split: the flood runs around the part kept, and the split is not
        /// tried again.
        parted: bool,
    },
    /// With a region of interest: each candidate region wholly within it joins the object.
    Boxed(BestComponent<Region>),
    /// Without one, with `part_at_creases`, `join_hanging_parts` and a support: each candidate
    /// region that hangs from the object ([`Hanging`]) joins it; then, if one did, a scan of
    /// the cells for the object's box: the next cell and the box so far (`None` before an
    /// object block).
    Hanging {
        search: BestComponent<Hang>,
        grow: Option<(u32, Option<BlockBox>)>,
    },
    CountObject {
        next: u32,
        /// Pixel weights (`1 / per_unit` unit each) done but not yet charged: a pass's
        /// remainder, or a probed pixel's weight beyond what its poll had left.
        owed: u32,
    },
    Sample {
        next: u32,
        /// As [`Step::CountObject`]'s.
        owed: u32,
    },
    Observed {
        next: u32,
    },
    Spread {
        next: u32,
    },
    Voxels {
        next: u32,
    },
    /// The object's radius: the next point, and the squared distance below which points are
    /// on its surface ([`Shells::within2`]).
    Radius {
        next: u32,
        within2: f32,
    },
    Done,
}

impl Step {
    /// [`Step::Split`] at the start of `phase`.
    fn split(phase: Splitting, enclosed: u32) -> Self {
        Step::Split {
            phase,
            next: 0,
            head: 0,
            tail: 0,
            kept: (0, 0),
            other: (0, 0),
            enclosed,
        }
    }
}

/// The phases of [`Step::Split`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Splitting {
    /// Every core block starts the flood; the other cores' summit is found.
    Seed,
    /// The flood: each block joins the core nearest it.
    Flood,
    /// Whether the segment between the two summits crosses the gap between two objects
    /// ([`at_gap`]).
    Gap,
    /// It does not, or the summits are not [`apart`] (the parts are one object's), or the
    /// region is not split: every block of the region is the object's.
    Rejoin,
}

/// The phases of [`Step::Enclosed`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Enclosing {
    /// The region was split: the cells the flood around the whole region reached are cleared,
    /// so that it runs again around the part kept (the inside of a bowl the part left out is
    /// not the part's).
    Clear,
    /// Border cells not the object's start the flood.
    Seed,
    /// The flood through cells not the object's.
    Flood,
    /// Cells the flood did not reach are the object's; every cell's component-search flag is
    /// cleared (for [`Step::Boxed`]).
    Fill,
}

/// First and second moments of inlier points, about a reference point (for the plane fit).
/// The second moments are two vector sums (squares, cross products), not a
/// [`crate::math::OuterSum`]: that costs more instructions per inlier on the Cortex-M4F
/// (`ci/firmware.sh`, preparing), and the RANSAC refinement adds every inlier twice.
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
    sensor: SensorConfig,
    /// Sample the object's outline besides the lattice (step 3b).
    outline: bool,
    step: Step,
    /// The support plane, given or fitted, normal toward the camera.
    table: Option<Plane>,
    stats: ObjectStats,
    /// Pixel bounding box of the object.
    bounds: Rect,
    /// How the object was chosen, when segmented (its box filled in once counted).
    segmentation: Option<Segmentation>,
    /// The pixels the support plane is fitted to (see [`Preparation::plane_window`]).
    plane_window: Rect,
    /// The pixels that may be the object's: the whole image, or the chosen region's blocks
    /// and their neighbours.
    object_area: Rect,
    /// Inliers of the best RANSAC plane so far.
    best_inliers: u32,
    /// Which shells about the centroid hold a sampled point, for the object's radius.
    shells: Shells,
    /// Squared distance from the centroid of the farthest sampled point on the object's
    /// surface so far (step 6).
    radius2: f32,
    sum: Vec3,
    depth_sum: f32,
    rng: u32,
}

/// File half `half` of the sampled points into the voxel hash: point `half / 2`'s voxel (even
/// `half`) or its coarser ones (odd). Filing every half in order, from an empty table, builds
/// the same table every time.
pub(crate) fn file_half<const V: usize>(voxels: &mut VoxelMap<V>, points: &[Vec3], half: u32) {
    let i = (half / 2) as usize;
    // A full map only coarsens the nearest-point queries; a point out of range is far from the
    // object centre by 512 voxels and cannot match anything anyway.
    let _: Insert = match points.get(i) {
        Some(&p) if half.is_multiple_of(2) => voxels.insert(p, i as u16),
        Some(_) => voxels.insert_coarse(i as u16, points),
        None => Insert::OutOfRange,
    };
}

/// What preparation found, handed to the search and the completion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Prepared {
    /// The support plane, given or fitted, normal toward the camera.
    pub table: Option<Plane>,
    /// The object's size and sampling.
    pub stats: ObjectStats,
    /// How the object was chosen, when the engine segmented it.
    pub segmentation: Option<Segmentation>,
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

/// The row-major index within `b` of the first pixel at or after index `j` that sampling
/// visits at stride `s`: a lattice point (both coordinates multiples of `s`), or, with
/// `outline`, any pixel of a lattice row or column. At least `b`'s pixel count when none is
/// left. O(1).
fn next_visited(j: u32, b: Rect, s: u16, outline: bool) -> u32 {
    let (w, h, s) = (b.width as u32, b.height as u32, s as u32);
    let (u0, v0) = (b.u0 as u32, b.v0 as u32);
    let (u, v) = (u0 + j % w, v0 + j / w);
    if outline && v % s == 0 {
        return j;
    }
    // The next lattice column on this row, when the row is visited.
    let column = u.div_ceil(s) * s;
    if (outline || v % s == 0) && column < u0 + w {
        return (v - v0) * w + column - u0;
    }
    // The next visited row: from its first pixel on a lattice row with the outline, else from
    // its first lattice column (with none in the box, only lattice rows hold visited pixels).
    let first_column = u0.div_ceil(s) * s;
    let row = if outline {
        v + 1
    } else {
        (v + 1).div_ceil(s) * s
    };
    match (outline && row % s == 0, first_column < u0 + w) {
        (true, _) => (row - v0) * w,
        (false, true) => (row - v0) * w + first_column - u0,
        (false, false) if outline => ((v + 1).div_ceil(s) * s - v0) * w,
        (false, false) => w * h,
    }
}

/// Items to process now and the units they cost, given what is left and the budget.
fn chunk(left: u32, budget: u32, per_unit: u32) -> (u32, u32) {
    let items = left.min(budget.saturating_mul(per_unit)).max(1).min(left);
    (items, items.div_ceil(per_unit).max(1))
}

/// One poll of a pass whose items weigh unevenly, `per_unit` weights a unit: an object-pixel
/// test weighs 1 and its mask reads [`Weighed::mask`] more. The poll takes items while it has
/// budget left; what the last costs beyond is owed and paid first by the next polls
/// ([`Weighed::start`]), so that the pass costs its weights' sum, rounded up, however the work
/// is sliced.
struct Weighed {
    per_unit: u32,
    budget: u32,
    /// `budget` units' weights.
    most: u32,
    /// Weights done and not yet charged, the owed ones included.
    spent: u32,
}

impl Weighed {
    /// The poll's pass with `owed` weights carried in (at most `budget` units, at least one);
    /// `Err(units)`: it pays that many owed units and takes no item (after the pass's last
    /// item, `done`, one weight is left for the finishing poll).
    fn start(owed: u32, per_unit: u32, budget: u32, done: bool) -> Result<Self, u32> {
        let budget = budget.max(1);
        let payable = if done { owed.saturating_sub(1) } else { owed } / per_unit;
        if payable > 0 {
            return Err(payable.min(budget));
        }
        Ok(Self {
            per_unit,
            budget,
            most: budget.saturating_mul(per_unit),
            spent: owed,
        })
    }

    /// The weight of `reads` mask reads: each as a pixel of a whole-image pass
    /// ([`PIXELS_PER_UNIT`] a unit).
    fn mask(&self, reads: u32) -> u32 {
        (reads * self.per_unit).div_ceil(PIXELS_PER_UNIT)
    }

    /// Whether the poll has budget left for another item.
    fn has_room(&self) -> bool {
        self.spent < self.most
    }

    fn add(&mut self, weight: u32) {
        self.spent += weight;
    }

    /// The units this poll charges and the weights it leaves owed, when the pass goes on (not
    /// `done`) or its last items cost more than the poll had: whole units, at most the
    /// budget (after the last item, at least one weight owed). `None`: the pass is over
    /// within the budget ([`Weighed::finish`]).
    fn pending(&self, done: bool) -> Option<(u32, u32)> {
        (!done || self.spent > self.most).then(|| self.split(done))
    }

    /// The whole units done, at most the budget, and the weights left owed (with `keep_one`,
    /// at least one).
    fn split(&self, keep_one: bool) -> (u32, u32) {
        let whole = self.spent.saturating_sub(u32::from(keep_one)) / self.per_unit;
        let units = whole.min(self.budget);
        (units, self.spent - units * self.per_unit)
    }

    /// The units of the pass's finishing poll: its weights rounded up, at least one.
    fn finish(&self) -> u32 {
        self.spent.div_ceil(self.per_unit).max(1)
    }
}

impl Preparation {
    /// A preparation with these settings; `outline`: sample the object's outline besides the
    /// lattice (step 3b).
    pub const fn new(config: PrepareConfig, sensor: SensorConfig, outline: bool) -> Self {
        Self {
            config,
            sensor,
            outline,
            step: Step::Done,
            table: None,
            stats: ObjectStats {
                centroid: [0.0; 3],
                radius: 0.0,
                top: 0.0,
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
            segmentation: None,
            plane_window: Rect {
                u0: 0,
                v0: 0,
                width: 0,
                height: 0,
            },
            object_area: Rect {
                u0: 0,
                v0: 0,
                width: 0,
                height: 0,
            },
            best_inliers: 0,
            // Begun again with the object's gap at step 5, once the spacing is known.
            shells: Shells::new(f32::INFINITY),
            radius2: 0.0,
            sum: Vec3::ZERO,
            depth_sum: 0.0,
            rng: 0,
        }
    }

    /// Begin preparing `scene` (already validated).
    pub fn begin(&mut self, scene: &Scene<'_>) {
        *self = Self::new(self.config, self.sensor, self.outline);
        self.table = scene.table;
        self.plane_window = self.plane_window(scene);
        let k = &scene.intrinsics;
        self.object_area = Rect {
            u0: 0,
            v0: 0,
            width: k.width,
            height: k.height,
        };
        self.rng = 0x9E37_79B9;
        self.step = if scene.table.is_none() {
            Step::CollectPlaneSamples { next: 0 }
        } else {
            self.after_plane(scene)
        };
    }

    /// The pixels the support plane is fitted to: the whole image; with a target and no mask,
    /// the square around it (its region, grown) that reaches `max_object_size` from it at the
    /// target's depth: the support under the named object, not a larger surface elsewhere in
    /// the frame (a wall, a floor, another table). A target pixel without a reading leaves the
    /// whole image.
    fn plane_window(&self, scene: &Scene<'_>) -> Rect {
        let k = &scene.intrinsics;
        let whole = Rect {
            u0: 0,
            v0: 0,
            width: k.width,
            height: k.height,
        };
        let (Some(target), None) = (scene.target, scene.mask) else {
            return whole;
        };
        let (u, v, half_w, half_h) = match target {
            Target::Pixel { u, v } => (u, v, 0, 0),
            Target::Region(r) => (
                r.u0 + r.width / 2,
                r.v0 + r.height / 2,
                r.width / 2,
                r.height / 2,
            ),
        };
        let Some(z) = scene.metres(v as usize * k.width as usize + u as usize) else {
            return whole;
        };
        // At most the image's size: the conversion saturates, and so do the sums below.
        let reach = (self.config.max_object_size * k.fx.min(k.fy) / z).min(u16::MAX as f32) as u16;
        let (u0, v0) = (
            u.saturating_sub(half_w.saturating_add(reach)),
            v.saturating_sub(half_h.saturating_add(reach)),
        );
        let (u1, v1) = (
            (u.saturating_add(half_w).saturating_add(reach)).min(k.width - 1),
            (v.saturating_add(half_h).saturating_add(reach)).min(k.height - 1),
        );
        Rect {
            u0,
            v0,
            width: u1 - u0 + 1,
            height: v1 - v0 + 1,
        }
    }

    fn after_plane(&self, scene: &Scene<'_>) -> Step {
        if scene.mask.is_some() {
            Step::CountObject { next: 0, owed: 0 }
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
                segmentation: self.segmentation,
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
            Step::Candidates { next } => {
                self.candidates(scene, store.grid, store.scratch, next, budget)?
            }
            Step::Creases { next } => self.creases(scene, store.grid, store.scratch, next, budget),
            Step::Components(_) => self.components(scene, store.grid, store.scratch, budget)?,
            Step::Distances { .. } => self.distances(store.grid, store.scratch, budget),
            Step::Cores { .. } => self.cores(scene, store.grid, store.scratch, budget),
            Step::Split { .. } => self.split(scene, store.grid, store.scratch, budget),
            Step::Enclosed { .. } => self.enclosed(scene, store.grid, store.scratch, budget),
            Step::Boxed(_) => self.boxed(scene, store.grid, store.scratch, budget),
            Step::Hanging { .. } => self.hanging(scene, store.grid, store.scratch, budget),
            Step::CountObject { next, owed } => {
                self.count_object(scene, store, (next, owed), budget)?
            }
            Step::Sample { next, owed } => self.sample(scene, store, (next, owed), budget)?,
            Step::Observed { next } => self.observed(scene, store.grid, next, budget),
            Step::Spread { next } => {
                let (_, around, _) = store.scratch.split(P);
                self.spread(store.grid, around, next, budget)
            }
            Step::Voxels { next } => {
                let marks = store.scratch.marks_mut(P);
                self.voxels(scene, store.points, (store.voxels, marks), next, budget)
            }
            Step::Radius { next, within2 } => self.radius(store.points, (next, within2), budget),
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
        let window = self.plane_window;
        let (ww, wh) = (window.width as u32, window.height as u32);
        let total = ww * wh;
        let w = scene.intrinsics.width as u32;
        let cap = P.min(RANSAC_SAMPLES) as u32;
        // Lattice stride so that the window gives about `cap` samples.
        let stride = ((ww * wh / cap.max(1)) as f32).max(1.0);
        let stride = (crate::math::sqrt(stride) as u32).max(1) + 1;
        if next == 0 {
            points.len = 0;
        }
        let (items, units) = chunk(total - next, budget, PIXELS_PER_UNIT);
        for j in next..next + items {
            let (u, v) = (window.u0 as u32 + j % ww, window.v0 as u32 + j / ww);
            let i = v * w + u;
            if u % stride != 0
                || v % stride != 0
                || (scene.mask.is_some() && scene.masked(i as usize))
            {
                continue;
            }
            if let Some(z) = scene
                .metres(i as usize)
                .filter(|&z| self.in_range(scene, z))
            {
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
        let Some(plane) = candidate.filter(|p| p.normal[1] < SUPPORT_FACING_DOWN) else {
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

    /// Whether a reading at depth `z` is within the working range (always, with a mask).
    #[inline]
    fn in_range(&self, scene: &Scene<'_>, z: f32) -> bool {
        scene.mask.is_some() || z <= self.config.max_range
    }

    /// Whether pixel `i` (valid, at `p`, column `u`, row `v`) may belong to the object. With a
    /// mask, a masked reading of what lies past the object's outline does not, with
    /// `trim_past_outline` ([`past_outline`]), and one within `min_height` of the support
    /// counts only inside the mask ([`inside_mask`]) and above the support's noise band (three
    /// σ of the sensor's noise below it: no surface lies lower); both tests' mask reads are
    /// counted in `mask_reads`.
    #[inline]
    fn is_candidate(
        &self,
        scene: &Scene<'_>,
        (i, u, v): (usize, u16, u16),
        p: Vec3,
        mask_reads: &mut u32,
    ) -> bool {
        if scene.mask.is_some() {
            // With a mask, only readings past the outline (on request) and the support's are
            // trimmed.
            if !scene.masked(i) {
                return false;
            }
            let trim = self.config.trim_past_outline;
            if trim && past_outline(scene, &self.sensor, i, (u, v), mask_reads) {
                return false;
            }
            let Some(h) = self.table.map(|t| t.signed_distance(p)) else {
                return true;
            };
            if h > self.config.min_height {
                return true;
            }
            if h <= -3.0 * self.sensor.sigma(p.z) {
                return false;
            }
            *mask_reads += MASK_PROBES;
            return inside_mask(scene, (u, v));
        }
        // The support's own readings scatter by the sensor's noise about its plane; the cheap
        // tests first (most pixels are the support's, below `min_height`).
        let h = self.table.map_or(f32::INFINITY, |t| t.signed_distance(p));
        h > self.config.min_height
            && h < self.config.max_height
            && p.z <= self.config.max_range
            && h > 3.0 * self.sensor.sigma(p.z)
    }

    /// Pixel `(u, v)` as a point, if it has a reading and may belong to the object (the mask's,
    /// or above the support plane within the working range): the completion's test of the
    /// pixels around each sample. Its mask reads ([`inside_mask`], at most [`MASK_PROBES`])
    /// are within the completion's unit for a pixel tried.
    #[inline]
    pub(crate) fn object_pixel(&self, scene: &Scene<'_>, (u, v): (u16, u16)) -> Option<Vec3> {
        let k = &scene.intrinsics;
        if u >= k.width || v >= k.height {
            return None;
        }
        let i = v as u32 * k.width as u32 + u as u32;
        self.candidate_at(scene, i, (u, v), &mut 0)
            .map(|(_, _, p)| p)
    }

    /// Pixel `i` as a point, if it has a reading and may belong to the object; the mask reads
    /// that took are added to `mask_reads`.
    #[inline]
    fn candidate_point(
        &self,
        scene: &Scene<'_>,
        i: u32,
        mask_reads: &mut u32,
    ) -> Option<(u16, u16, Vec3)> {
        let w = scene.intrinsics.width as u32;
        self.candidate_at(scene, i, ((i % w) as u16, (i / w) as u16), mask_reads)
    }

    /// [`Preparation::candidate_point`] of pixel `i` at column `u`, row `v`.
    #[inline]
    fn candidate_at(
        &self,
        scene: &Scene<'_>,
        i: u32,
        (u, v): (u16, u16),
        mask_reads: &mut u32,
    ) -> Option<(u16, u16, Vec3)> {
        let z = scene.metres(i as usize)?;
        let p = scene.intrinsics.unproject(u as f32, v as f32, z);
        self.is_candidate(scene, (i as usize, u, v), p, mask_reads)
            .then_some((u, v, p))
    }

    /// Step 2a: nearest candidate depth per block over the whole image, leaving out pixels on a
    /// depth discontinuity (a flying pixel reads a depth between two surfaces).
    fn candidates<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &mut DepthGrid<C>,
        scratch: &mut Scratch<C>,
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
            scratch.lend(C).flags.fill(0);
        }
        let jump_per_unit = EDGE_SLOPE / scene.intrinsics.fx.min(scene.intrinsics.fy);
        let block = grid.block();
        // The block's central pixels: `block / 2` and its neighbours within `CORE`.
        let core = |c: u16| (c % block).abs_diff(block / 2) <= CORE;
        let flags = scratch.lend(C).flags;
        let (items, units) = chunk(total - next, budget, CANDIDATE_PIXELS_PER_UNIT);
        for i in next..next + items {
            // No mask here: the candidate test reads none.
            if let Some((u, v, _)) = self.candidate_point(scene, i, &mut 0) {
                if on_edge(scene, i, (u, v), jump_per_unit) {
                    flags[grid.cell_of(u, v)] |= STRADDLES;
                } else if core(u) && core(v) {
                    grid.add(u, v, scene.depth[i as usize]);
                }
            }
        }
        self.step = if next + items < total {
            Step::Candidates { next: next + items }
        } else if self.config.part_at_creases {
            Step::Creases { next: 0 }
        } else {
            Step::Components(BestComponent::starting(Region::default()))
        };
        Ok(units)
    }

    /// Step 2b: flag the blocks on a concave crease ([`CREASE`]); skipped without
    /// [`PrepareConfig::part_at_creases`].
    fn creases<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        next: u32,
        budget: u32,
    ) -> u32 {
        let cells = grid.len() as u32;
        let flags = scratch.lend(C).flags;
        let blocks = self.blocks(scene, grid);
        let (items, units) = chunk(cells - next, budget, CREASE_BLOCKS_PER_UNIT);
        for i in next..next + items {
            if blocks.on_crease(i as usize) {
                flags[i as usize] |= CREASE;
            }
        }
        self.step = if next + items >= cells {
            Step::Components(BestComponent::starting(Region::default()))
        } else {
            Step::Creases { next: next + items }
        };
        units
    }

    /// The segmentation's graph over `grid`.
    fn blocks<'g, 's, const C: usize>(
        &'g self,
        scene: &'g Scene<'s>,
        grid: &'g DepthGrid<C>,
    ) -> Blocks<'g, 's, C> {
        let block = grid.block();
        let cell = |u: u16, v: u16| (u / block, v / block);
        let target = match scene.target {
            None => TargetCells::None,
            Some(Target::Pixel { u, v }) => TargetCells::Cell(grid.cell_of(u, v)),
            Some(Target::Region(r)) => TargetCells::Cells(
                cell(r.u0, r.v0),
                cell(r.u0 + (r.width - 1), r.v0 + (r.height - 1)),
            ),
        };
        Blocks {
            scene,
            grid,
            config: &self.config,
            sensor: self.sensor,
            block_per_z: block as f32 / scene.intrinsics.fx.min(scene.intrinsics.fy),
            target,
        }
    }

    /// Step 2c: the candidate regions; the chosen one is marked as the object.
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
        let blocks = self.blocks(scene, grid);
        let mut used = 0;
        while used < budget {
            used += 1;
            let lent = scratch.lend(C);
            match search.step(&blocks, &mut lent.flags[..cells], lent.queue) {
                component::Progress::Searching => {}
                component::Progress::Marking => break,
                component::Progress::Marked => {
                    let clamp = |n: u32| n.min(u16::MAX as u32) as u16;
                    self.segmentation = Some(Segmentation {
                        candidates: clamp(search.candidates()),
                        chosen: search.chosen().map(clamp),
                        object_box: Rect::default(),
                    });
                    let r = search.chosen_summary();
                    self.object_area = r.area(grid.block(), &scene.intrinsics, None);
                    self.step = Step::Enclosed {
                        phase: Enclosing::Seed,
                        next: 0,
                        head: 0,
                        tail: 0,
                        parted: false,
                    };
                    return Ok(used);
                }
                component::Progress::Empty if scene.target.is_some() => {
                    return Err(Error::TargetOnNoObject);
                }
                component::Progress::Empty => return Err(Error::NoObject),
            }
        }
        self.step = Step::Components(search);
        Ok(used)
    }

    /// Step 2e: the chosen region's distance transform ([`DISTANCE`], chessboard, capped at
    /// [`DISTANCE_MAX`]): a forward raster pass (the left and the three upper neighbours), then a
    /// backward one (the right and the three lower), which also clears the region's search
    /// flags, its blocks now known by their distance. Bounded work: [`DISTANCE_CELLS_PER_UNIT`]
    /// cells a unit.
    fn distances<const C: usize>(
        &mut self,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let Step::Distances {
            mut backward,
            mut next,
            mut peak,
            mut enclosed,
        } = self.step
        else {
            return 0;
        };
        let cells = grid.len() as u32;
        let (cols, rows) = (grid.cols() as usize, grid.rows() as usize);
        let flags = scratch.lend(C).flags;
        let mut used = 0;
        while used < budget {
            used += 1;
            let end = (next + DISTANCE_CELLS_PER_UNIT).min(cells);
            for j in next..end {
                // Forward in raster order, backward in reverse.
                let i = if backward { cells - 1 - j } else { j } as usize;
                if !backward && flags[i] & (OBJECT | OUTSIDE) == 0 {
                    enclosed += 1;
                }
                if !backward && flags[i] & OBJECT == 0 || backward && distance(flags[i]) == 0 {
                    continue;
                }
                let (c, r) = grid.cell_position(i);
                let (c, r) = (c as usize, r as usize);
                // The four neighbours already passed: `(dc, dr)` with `dr` toward the pass's
                // start, a cell off the grid counting as off the object.
                let sign: isize = if backward { 1 } else { -1 };
                let near = [(sign, 0), (-1, sign), (0, sign), (1, sign)]
                    .into_iter()
                    .map(|(dc, dr)| {
                        let (nc, nr) = (c as isize + dc, r as isize + dr);
                        if nc < 0 || nr < 0 || nc >= cols as isize || nr >= rows as isize {
                            0
                        } else {
                            distance(flags[nr as usize * cols + nc as usize])
                        }
                    });
                let through = near.min().unwrap_or(0).saturating_add(1);
                let d = if backward {
                    through.min(distance(flags[i]))
                } else {
                    through.min(DISTANCE_MAX)
                };
                peak = peak.max(d);
                let cleared = if backward {
                    flags[i] & !(DISTANCE | component::VISITED | OBJECT)
                } else {
                    flags[i] & !DISTANCE
                };
                flags[i] = cleared | d << DISTANCE_SHIFT;
            }
            next = end;
            if next == cells {
                if backward {
                    self.step = if peak < CORE_DEPTH {
                        Step::split(Splitting::Rejoin, enclosed)
                    } else {
                        Step::Cores {
                            enclosed,
                            search: BestComponent::starting(0),
                        }
                    };
                    return used;
                }
                (backward, next) = (true, 0);
            }
        }
        self.step = Step::Distances {
            backward,
            next,
            peak,
            enclosed,
        };
        used
    }

    /// Step 2f: the region's cores (see [`Cores`]); the one nearest the target, or else the
    /// principal point, is marked. One component search step a unit.
    fn cores<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let Step::Cores {
            enclosed,
            mut search,
        } = self.step
        else {
            return 0;
        };
        let k = &scene.intrinsics;
        let aim = match scene.target {
            Some(Target::Pixel { u, v }) => (u as f32, v as f32),
            Some(Target::Region(r)) => (
                r.u0 as f32 + r.width as f32 / 2.0,
                r.v0 as f32 + r.height as f32 / 2.0,
            ),
            None => (k.cx, k.cy),
        };
        let block = grid.block().max(1) as f32;
        let graph = Cores {
            grid,
            aim: (aim.0 / block, aim.1 / block),
        };
        let cells = grid.len();
        let mut used = 0;
        while used < budget {
            used += 1;
            let lent = scratch.lend(C);
            match search.step(&graph, &mut lent.flags[..cells], lent.queue) {
                component::Progress::Searching | component::Progress::Marking => {}
                component::Progress::Marked => {
                    self.step = Step::split(Splitting::Seed, enclosed);
                    return used;
                }
                // A region that reaches CORE_DEPTH has a core, so `Empty` does not happen;
                // were it to, the region is kept whole.
                component::Progress::Empty => {
                    self.step = Step::split(Splitting::Rejoin, enclosed);
                    return used;
                }
            }
        }
        self.step = Step::Cores { enclosed, search };
        used
    }

    /// Step 2g: each block of the region joins the core nearest it, in blocks along the region
    /// (a flood from every core block at once, in raster order: ties go to the core met first);
    /// those that join the marked core are the object's, unless the marked core's summit and
    /// the other cores' highest are not [`apart`], or the straight segment between them never
    /// crosses a gap ([`at_gap`]): one object's parts (a box's faces met at a partly read edge,
    /// a tool's handle between its body and its battery), which rejoin. Two touching convex
    /// objects leave a gap on their seam that the segment crosses in front of the surfaces
    /// seen behind it.
    /// Bounded work: [`BLOCK_SEEDS_PER_UNIT`] cells a unit while seeding and rejoining, one block
    /// (four neighbours) a unit while flooding, one point of the segment a unit.
    fn split<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let Step::Split {
            mut phase,
            mut next,
            mut head,
            mut tail,
            mut kept,
            mut other,
            enclosed,
        } = self.step
        else {
            return 0;
        };
        let cells = grid.len() as u32;
        let lent = scratch.lend(C);
        let (flags, queue) = (lent.flags, lent.queue);
        let (mut used, mut done, mut parted) = (0, false, false);
        while used < budget && !done {
            used += 1;
            match phase {
                Splitting::Seed => {
                    let end = (next + BLOCK_SEEDS_PER_UNIT).min(cells);
                    for i in next..end {
                        let f = &mut flags[i as usize];
                        let d = distance(*f);
                        if d >= CORE_DEPTH {
                            *f |= component::VISITED;
                            let summit = if *f & OBJECT != 0 {
                                &mut kept
                            } else {
                                &mut other
                            };
                            if d > summit.0 {
                                *summit = (d, i);
                            }
                            queue[tail as usize] = i as u16;
                            tail += 1;
                        }
                    }
                    next = end;
                    if next == cells {
                        // The region encloses more cells than its cores hold (`tail`): a
                        // container seen over its rim (a bowl, a mug from above), whose chords
                        // cross its own inside, or a loop (a handle); not two objects. It stays
                        // whole.
                        (phase, next) = if enclosed > tail {
                            (Splitting::Rejoin, 0)
                        } else {
                            (Splitting::Flood, next)
                        };
                    }
                }
                Splitting::Flood if head < tail => {
                    let i = queue[head as usize] as usize;
                    head += 1;
                    let label = flags[i] & OBJECT;
                    for n in grid.four_neighbours(i).into_iter().flatten() {
                        if distance(flags[n]) > 0 && flags[n] & component::VISITED == 0 {
                            flags[n] |= component::VISITED | label;
                            queue[tail as usize] = n as u16;
                            tail += 1;
                        }
                    }
                }
                Splitting::Flood if other.0 == 0 => done = true,
                Splitting::Flood if !apart(grid, kept, other) => {
                    (phase, next) = (Splitting::Rejoin, 0);
                }
                Splitting::Flood => (phase, next) = (Splitting::Gap, 1),
                Splitting::Gap if next < SEGMENT_POINTS => {
                    let (a, b) = (
                        block_point(scene, grid, kept.1 as usize),
                        block_point(scene, grid, other.1 as usize),
                    );
                    let t = next as f32 / SEGMENT_POINTS as f32;
                    let p = a + (b - a) * t;
                    parted = at_gap(scene, &self.sensor, grid, flags, p, a.z.max(b.z));
                    done = parted;
                    next += 1;
                }
                Splitting::Gap => (phase, next) = (Splitting::Rejoin, 0),
                Splitting::Rejoin => {
                    let end = (next + BLOCK_SEEDS_PER_UNIT).min(cells);
                    for f in &mut flags[next as usize..end as usize] {
                        if distance(*f) > 0 {
                            *f |= OBJECT;
                        }
                    }
                    next = end;
                    done = next == cells;
                }
            }
        }
        self.step = if done {
            Step::Enclosed {
                phase: if parted {
                    Enclosing::Clear
                } else {
                    Enclosing::Fill
                },
                next: 0,
                head: 0,
                tail: 0,
                parted,
            }
        } else {
            Step::Split {
                phase,
                next,
                head,
                tail,
                kept,
                other,
                enclosed,
            }
        };
        used
    }

    /// Steps 2d and 2h: the cells the chosen region encloses in the image join it (a
    /// container's inside, parted from its rim by the rim's own edge and from its walls by the
    /// crease at its bottom): a flood from the grid's border through the cells not the object's
    /// (2d; with `split_necks` the region is then split, 2e to 2g, and when the split stands the
    /// flood runs again around the part kept: a bowl's inside is not the can's beside it); those
    /// it did not reach, other than blocks the split left out, are marked the object's (2h).
    /// Bounded work: [`BLOCK_SEEDS_PER_UNIT`] cells a unit while clearing, seeding and filling,
    /// one cell (four neighbours) a unit while flooding.
    fn enclosed<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let Step::Enclosed {
            mut phase,
            mut next,
            mut head,
            mut tail,
            parted,
        } = self.step
        else {
            return 0;
        };
        let cells = grid.len() as u32;
        let (cols, rows) = (grid.cols() as u32, grid.rows() as u32);
        if cells == 0 {
            self.step = Step::CountObject { next: 0, owed: 0 };
            return 1;
        }
        let lent = scratch.lend(C);
        let (flags, queue) = (lent.flags, lent.queue);
        let free = |f: u8| f & (OBJECT | OUTSIDE) == 0;
        let mut used = 0;
        while used < budget {
            used += 1;
            match phase {
                Enclosing::Clear => {
                    let end = (next + BLOCK_SEEDS_PER_UNIT).min(cells);
                    for f in &mut flags[next as usize..end as usize] {
                        *f &= !OUTSIDE;
                    }
                    next = end;
                    if next == cells {
                        (phase, next) = (Enclosing::Seed, 0);
                    }
                }
                Enclosing::Seed => {
                    // The border cells: top row, bottom row, left column, right column.
                    let border = 2 * cols + 2 * rows;
                    let end = (next + BLOCK_SEEDS_PER_UNIT).min(border);
                    for j in next..end {
                        let i = if j < cols {
                            j
                        } else if j < 2 * cols {
                            (rows - 1) * cols + (j - cols)
                        } else if j < 2 * cols + rows {
                            (j - 2 * cols) * cols
                        } else {
                            (j - 2 * cols - rows) * cols + cols - 1
                        };
                        if free(flags[i as usize]) {
                            flags[i as usize] |= OUTSIDE;
                            queue[tail as usize] = i as u16;
                            tail += 1;
                        }
                    }
                    next = end;
                    if next == border {
                        (phase, next) = (Enclosing::Flood, 0);
                    }
                }
                Enclosing::Fill => {
                    let end = (next + BLOCK_SEEDS_PER_UNIT).min(cells);
                    for f in &mut flags[next as usize..end as usize] {
                        // Not the blocks of another object the split parted from it.
                        if free(*f) && distance(*f) == 0 {
                            *f |= OBJECT;
                        }
                        *f &= !component::VISITED;
                    }
                    next = end;
                    if next == cells {
                        self.step = match scene.target {
                            Some(Target::Region(_)) => {
                                Step::Boxed(BestComponent::every(Region::default()))
                            }
                            _ if self.config.part_at_creases
                                && self.config.join_hanging_parts
                                && self.table.is_some() =>
                            {
                                Step::Hanging {
                                    search: BestComponent::every(Hang::default()),
                                    grow: None,
                                }
                            }
                            _ => Step::CountObject { next: 0, owed: 0 },
                        };
                        return used;
                    }
                }
                Enclosing::Flood if head < tail => {
                    let i = queue[head as usize] as usize;
                    head += 1;
                    for n in grid.four_neighbours(i).into_iter().flatten() {
                        if free(flags[n]) {
                            flags[n] |= OUTSIDE;
                            queue[tail as usize] = n as u16;
                            tail += 1;
                        }
                    }
                }
                Enclosing::Flood if self.config.split_necks && !parted => {
                    // The region is split at its necks before the cells it encloses join it.
                    self.step = Step::Distances {
                        backward: false,
                        next: 0,
                        peak: 0,
                        enclosed: 0,
                    };
                    return used;
                }
                Enclosing::Flood => (phase, next) = (Enclosing::Fill, 0),
            }
        }
        self.step = Step::Enclosed {
            phase,
            next,
            head,
            tail,
            parted,
        };
        used
    }

    /// Step 2i, with a region of interest ([`Target::Region`]): every candidate region that lies
    /// wholly within it (its blocks within the region's blocks) joins the object. The caller's
    /// region bounds one object, so a region inside it that the graph parted from the chosen one
    /// is a piece of it: a chair's seat parted from its back by the crease where they meet, a
    /// bowl's outer wall parted from its inside by the rim's edge. Regions the neck split parted
    /// from the object stay out. Bounded work: one component search (its flags cleared by step
    /// 2h), which marks each such region as it is complete ([`BestComponent::every`]).
    fn boxed<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let Step::Boxed(mut search) = self.step else {
            return 0;
        };
        let cells = grid.len();
        let blocks = self.blocks(scene, grid);
        let TargetCells::Cells(lo, hi) = blocks.target else {
            self.step = Step::CountObject { next: 0, owed: 0 };
            return 1;
        };
        let graph = Boxed {
            blocks: &blocks,
            lo,
            hi,
        };
        let lent = scratch.lend(C);
        let (mut used, mut done, mut joined) = (0, false, false);
        while used < budget && !done {
            used += 1;
            match search.step(&graph, &mut lent.flags[..cells], lent.queue) {
                component::Progress::Searching | component::Progress::Marking => {}
                component::Progress::Marked => (done, joined) = (true, true),
                component::Progress::Empty => done = true,
            }
        }
        if joined {
            // The regions that joined lie within the target's blocks.
            let within = Region {
                lo,
                hi,
                ..Region::default()
            };
            let area = Some(self.object_area);
            self.object_area = within.area(grid.block(), &scene.intrinsics, area);
        }
        self.step = if done {
            Step::CountObject { next: 0, owed: 0 }
        } else {
            Step::Boxed(search)
        };
        used
    }

    /// Step 2i without a region of interest (with one: [`Preparation::boxed`]), with
    /// [`PrepareConfig::part_at_creases`] and [`PrepareConfig::join_hanging_parts`], when the
    /// support is known: every candidate region that hangs from the object ([`Hanging`]) joins
    /// it. Creases part touching objects, and with them a part of one object that meets its
    /// body at creases (a mug's handle); what tells the two apart is what holds each up. Then,
    /// if a region joined, the object's box grows over its blocks. Bounded work: one component
    /// search over the blocks not the object's, each region marked as it is complete
    /// ([`BestComponent::every`]), [`HANGING_SEEDS_PER_UNIT`] seeds tested a unit (its flags
    /// cleared by step 2h); the box a scan of [`BLOCK_SEEDS_PER_UNIT`] cells a unit.
    fn hanging<const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &mut Scratch<C>,
        budget: u32,
    ) -> u32 {
        let (
            Step::Hanging {
                mut search,
                mut grow,
            },
            Some(support),
        ) = (self.step, self.table)
        else {
            self.step = Step::CountObject { next: 0, owed: 0 };
            return 1;
        };
        let cells = grid.len();
        let blocks = self.blocks(scene, grid);
        let graph = Hanging {
            blocks: &blocks,
            support,
        };
        let lent = scratch.lend(C);
        let mut used = 0;
        while used < budget {
            used += 1;
            let Some((next, mut bounds)) = grow else {
                match search.step(&graph, &mut lent.flags[..cells], lent.queue) {
                    component::Progress::Searching | component::Progress::Marking => {}
                    component::Progress::Marked => grow = Some((0, None)),
                    component::Progress::Empty => {
                        self.step = Step::CountObject { next: 0, owed: 0 };
                        return used;
                    }
                }
                continue;
            };
            let end = (next + BLOCK_SEEDS_PER_UNIT).min(cells as u32);
            for i in next..end {
                if lent.flags[i as usize] & OBJECT != 0 {
                    let (c, r) = grid.cell_position(i as usize);
                    let (lo, hi) = bounds.unwrap_or(((c, r), (c, r)));
                    bounds = Some(((lo.0.min(c), lo.1.min(r)), (hi.0.max(c), hi.1.max(r))));
                }
            }
            grow = Some((end, bounds));
            if end == cells as u32 {
                if let Some((lo, hi)) = bounds {
                    let object = Region {
                        lo,
                        hi,
                        ..Region::default()
                    };
                    let area = Some(self.object_area);
                    self.object_area = object.area(grid.block(), &scene.intrinsics, area);
                }
                self.step = Step::CountObject { next: 0, owed: 0 };
                return used;
            }
        }
        self.step = Step::Hanging { search, grow };
        used
    }

    /// Whether pixel `i` is an object pixel, and its point; the mask reads that took are added
    /// to `mask_reads`.
    #[inline]
    fn object_point<const C: usize>(
        &self,
        scene: &Scene<'_>,
        grid: &DepthGrid<C>,
        scratch: &Scratch<C>,
        i: u32,
        mask_reads: &mut u32,
    ) -> Option<(u16, u16, Vec3)> {
        if scene.mask.is_some() {
            return self.candidate_point(scene, i, mask_reads);
        }
        if scene.depth[i as usize] == 0 {
            return None;
        }
        let w = scene.intrinsics.width as u32;
        let (u, v) = ((i % w) as u16, (i / w) as u16);
        // A region of interest bounds the object too.
        if let Some(Target::Region(r)) = scene.target {
            if !r.contains(u, v) {
                return None;
            }
        }
        // The flags first: most pixels are far from the object, and need no point.
        match near_object(grid, scratch.flags(), (u, v)) {
            Near::None => None,
            Near::Own => self.candidate_at(scene, i, (u, v), mask_reads),
            Near::Straddling { cell } => {
                self.candidate_at(scene, i, (u, v), mask_reads)
                    .filter(|&(_, _, p)| {
                        on_block_surface(scene, grid, cell, (u, v), p.z, &self.sensor) || {
                            let neighbours = object_neighbours(grid, scratch.flags(), cell);
                            on_object_surface(scene, grid, cell, neighbours, p.z, &self.sensor)
                        }
                    })
            }
            Near::Beside { cell, neighbours } => self
                .candidate_at(scene, i, (u, v), mask_reads)
                .filter(|&(_, _, p)| {
                    on_object_surface(scene, grid, cell, neighbours, p.z, &self.sensor)
                }),
        }
    }

    /// Step 3a: count the object pixels and find their bounding box; choose the sampling stride
    /// that should keep the lattice within `P` points (7/8 of it, for aliasing and the outline
    /// points; should they overflow, step 3b starts again at the next stride). Cost: a pixel
    /// of the area weighs `1 / per_unit` unit; one whose mask was probed ([`inside_mask`]) its
    /// [`MASK_PROBES`] reads as that many pixels. A pixel is taken while the poll has some of
    /// its budget left; what it costs beyond is owed and paid by the next polls before any
    /// other pixel, so the total is the weights' sum, rounded up, however the work is sliced.
    fn count_object<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        (next, owed): (u32, u32),
        budget: u32,
    ) -> Result<u32, Error> {
        let area = self.object_area;
        let total = area.width as u32 * area.height as u32;
        let w = scene.intrinsics.width as u32;
        if next == 0 {
            self.stats.object_pixels = 0;
            self.bounds = Rect {
                u0: u16::MAX,
                v0: u16::MAX,
                width: 0,
                height: 0,
            };
        }
        let per_unit = if scene.mask.is_some() {
            PIXELS_PER_UNIT
        } else {
            OBJECT_AREA_PIXELS_PER_UNIT
        };
        let mut pass = match Weighed::start(owed, per_unit, budget, next == total) {
            Ok(pass) => pass,
            Err(paid) => {
                let owed = owed - paid * per_unit;
                self.step = Step::CountObject { next, owed };
                return Ok(paid);
            }
        };
        let mut j = next;
        while j < total && pass.has_room() {
            let (u, v) = (
                area.u0 as u32 + j % area.width as u32,
                area.v0 as u32 + j / area.width as u32,
            );
            let (i, mut reads) = (v * w + u, 0);
            if let Some((u, v, _)) =
                self.object_point(scene, store.grid, store.scratch, i, &mut reads)
            {
                self.stats.object_pixels += 1;
                self.grow_bounds(u, v);
            }
            pass.add(1 + pass.mask(reads));
            j += 1;
        }
        if let Some((units, owed)) = pass.pending(j == total) {
            self.step = Step::CountObject { next: j, owed };
            return Ok(units);
        }
        let units = pass.finish();
        let found = self.stats.object_pixels as u64;
        if found == 0 {
            return Err(Error::NoObject);
        }
        if let Some(s) = &mut self.segmentation {
            s.object_box = self.bounds;
        }
        let target = (P as u64 * 7 / 8).max(1);
        let mut stride = 1u16;
        while stride < MAX_STRIDE && found > (stride as u64).pow(2) * target {
            stride += 1;
        }
        self.begin_sampling(store.points, stride, 0);
        Ok(units)
    }

    /// Whether the object pixel `(u, v)` is an outline point on its lattice row (`on_row`) or
    /// column: a neighbour along the line is not an object pixel.; the mask reads that took are
    /// added to `mask_reads`.
    fn on_outline<const P: usize, const V: usize, const C: usize>(
        &self,
        scene: &Scene<'_>,
        store: &Storage<'_, P, V, C>,
        (u, v): (u16, u16),
        on_row: bool,
        mask_reads: &mut u32,
    ) -> bool {
        let k = &scene.intrinsics;
        let mut is_object = |d: i32| {
            let (x, y) = if on_row {
                (u as i32 + d, v as i32)
            } else {
                (u as i32, v as i32 + d)
            };
            match (u16::try_from(x), u16::try_from(y)) {
                (Ok(x), Ok(y)) if x < k.width && y < k.height => {
                    let i = y as u32 * k.width as u32 + x as u32;
                    self.object_point(scene, store.grid, store.scratch, i, mask_reads)
                        .is_some()
                }
                _ => false,
            }
        };
        !is_object(-1) || !is_object(1)
    }

    /// Start sampling at `stride`, `owed` weights of the sampling pass carried in.
    fn begin_sampling<const P: usize>(&mut self, points: &mut Points<P>, stride: u16, owed: u32) {
        self.stats.stride = stride;
        points.len = 0;
        self.sum = Vec3::ZERO;
        self.depth_sum = 0.0;
        self.step = Step::Sample { next: 0, owed };
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

    /// Step 3b: the sampled points, in raster order: the object pixels at the lattice points of
    /// the chosen stride (multiples of the stride, within the object's box) and, with the
    /// outline sampled, the object pixels where a lattice row or column leaves the object (a
    /// neighbour along it is not an object pixel): the outline, about a stride apart along it.
    /// The lattice alone ends on average half a stride inside the outline, and a mirror plane
    /// with one side of the object ending on a silhouette sits a quarter stride toward the
    /// other side (the search matches the sampled extent, not the object's). Should the points
    /// overflow `P`, sampling starts again with the next stride (at [`MAX_STRIDE`], the first
    /// `P` are kept). Cost: with the outline, one unit per [`LINE_PIXELS_PER_UNIT`] pixels of
    /// the lattice lines; without, per [`LATTICE_POINTS_PER_UNIT`] lattice points (fewer with
    /// `drop_edge_pixels` or no mask); the pixels between are skipped in O(1); the mask reads
    /// of the object-pixel tests on top ([`Weighed`]).
    fn sample<const P: usize, const V: usize, const C: usize>(
        &mut self,
        scene: &Scene<'_>,
        store: &mut Storage<'_, P, V, C>,
        (next, owed): (u32, u32),
        budget: u32,
    ) -> Result<u32, Error> {
        let (s, b, outline) = (self.stats.stride, self.bounds, self.outline);
        let total = b.width as u32 * b.height as u32;
        let drop_edges = self.config.drop_edge_pixels;
        let per_unit = if outline {
            LINE_PIXELS_PER_UNIT
        } else if drop_edges {
            LATTICE_POINTS_WITH_EDGES_PER_UNIT
        } else if scene.mask.is_none() {
            // Each also looks up its block's flags (and its neighbours').
            OBJECT_AREA_PIXELS_PER_UNIT
        } else {
            LATTICE_POINTS_PER_UNIT
        };
        let mut j = next_visited(next, b, s, outline);
        let mut pass = match Weighed::start(owed, per_unit, budget, j >= total) {
            Ok(pass) => pass,
            Err(paid) => {
                let owed = owed - paid * per_unit;
                self.step = Step::Sample { next, owed };
                return Ok(paid);
            }
        };
        let w = scene.intrinsics.width as u32;
        let jump_per_unit = EDGE_SLOPE / scene.intrinsics.fx.min(scene.intrinsics.fy);
        while j < total && pass.has_room() {
            let (u, v) = (
                b.u0 + (j % b.width as u32) as u16,
                b.v0 + (j / b.width as u32) as u16,
            );
            j = next_visited(j + 1, b, s, outline);
            let (i, mut reads) = (v as u32 * w + u as u32, 0);
            let kept = self.object_point(scene, store.grid, store.scratch, i, &mut reads);
            let kept = kept.filter(|&(u, v, _)| {
                let lattice_point = u % s == 0 && v % s == 0;
                (lattice_point || self.on_outline(scene, store, (u, v), v % s == 0, &mut reads))
                    && !(drop_edges && on_edge(scene, i, (u, v), jump_per_unit))
            });
            pass.add(1 + pass.mask(reads));
            let Some((u, v, p)) = kept else {
                continue;
            };
            if store.points.len == P && s < MAX_STRIDE {
                // Whole units now, the rest carried into the next stride's pass.
                let (units, owed) = pass.split(false);
                self.begin_sampling(store.points, s + 1, owed);
                return Ok(units);
            }
            if store.points.push(p, u, v) {
                self.sum += p;
                self.depth_sum += p.z;
            }
        }
        if let Some((units, owed)) = pass.pending(j >= total) {
            self.step = Step::Sample { next: j, owed };
            return Ok(units);
        }
        let units = pass.finish();
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
        self.step = if next + items < total {
            Step::Observed { next: next + items }
        } else if self.sensor.lateral_noise {
            Step::Spread { next: 0 }
        } else {
            Step::Voxels { next: 0 }
        };
        units
    }

    /// Step 4b, with lateral sensor noise ([`crate::SensorConfig::lateral_noise`]): each cell's
    /// neighbourhood minimum into `around` ([`DepthGrid::spread_into`]), when it has room for
    /// all of them (else the search computes those it needs).
    fn spread<const C: usize>(
        &mut self,
        grid: &DepthGrid<C>,
        around: &mut [u16],
        next: u32,
        budget: u32,
    ) -> u32 {
        let total = if around.len() >= grid.len() {
            grid.len() as u32
        } else {
            0
        };
        let (items, units) = chunk(total - next, budget, CELLS_SPREAD_PER_UNIT);
        grid.spread_into(around, next as usize, items as usize);
        self.step = if next + items < total {
            Step::Spread { next: next + items }
        } else {
            Step::Voxels { next: 0 }
        };
        units
    }

    /// Step 5: the sampled points into the voxel hash (voxel edge = sample spacing), their
    /// shells about the centroid ([`Shells`]), the object's top, and a mark per point in `mixed`
    /// (1: a mixed reading, [`between_surfaces`]; the points beyond `mixed` are not marked).
    fn voxels<const P: usize, const V: usize>(
        &mut self,
        scene: &Scene<'_>,
        points: &Points<P>,
        (voxels, mixed): (&mut VoxelMap<V>, &mut [u8]),
        next: u32,
        budget: u32,
    ) -> u32 {
        let centroid = Vec3::from_array(self.stats.centroid);
        if next == 0 {
            voxels.reset(centroid, self.stats.spacing);
            self.shells = Shells::new(self.stats.surface_gap(&self.sensor));
        }
        // Two units a point: `next` counts halves, its voxel (even) then its coarser ones (odd).
        let halves = 2 * points.len as u32;
        let (items, units) = chunk(halves - next, budget, 1);
        for half in next..next + items {
            if half.is_multiple_of(2) {
                let i = (half / 2) as usize;
                let p = points.pos[i];
                self.shells.add((p - centroid).length_squared());
                let height = self.table.map_or(0.0, |t| t.signed_distance(p));
                self.stats.top = self.stats.top.max(height);
                if let Some(mark) = mixed.get_mut(i) {
                    *mark = between_surfaces(scene, points.pixel[i]) as u8;
                }
            }
            file_half(voxels, points.positions(), half);
        }
        self.step = if next + items < halves {
            Step::Voxels { next: next + items }
        } else {
            Step::Radius {
                next: 0,
                within2: self.shells.within2(),
            }
        };
        units
    }

    /// Step 6: the object's radius, the farthest sampled point on its surface ([`Shells`]):
    /// `SAMPLES_PER_UNIT` points a unit.
    fn radius<const P: usize>(
        &mut self,
        points: &Points<P>,
        (next, within2): (u32, f32),
        budget: u32,
    ) -> u32 {
        let centroid = Vec3::from_array(self.stats.centroid);
        let (items, units) = chunk(points.len as u32 - next, budget, SAMPLES_PER_UNIT);
        let range = next as usize..(next + items) as usize;
        let d2s = points.pos[range]
            .iter()
            .map(|&p| (p - centroid).length_squared());
        self.radius2 = Shells::farthest2(within2, d2s, self.radius2);
        self.step = if next + items < points.len as u32 {
            Step::Radius {
                next: next + items,
                within2,
            }
        } else {
            self.stats.radius = crate::math::sqrt(self.radius2);
            Step::Done
        };
        units
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reading_between_a_nearer_and_a_farther_neighbour_is_mixed() {
        let k = Intrinsics {
            width: 6,
            height: 3,
            fx: 285.0,
            fy: 285.0,
            cx: 2.5,
            cy: 1.0,
        };
        // Millimetres, each row alike: beyond 24 mm (at 600 mm; 28 at 700) neighbours are
        // apart (`EDGE_SLOPE`).
        let mixed = |row: [u16; 6]| {
            let depth: [u16; 18] = core::array::from_fn(|i| row[i % 6]);
            let scene = Scene::new(&depth, 1e-3, k);
            core::array::from_fn::<bool, 6, _>(|u| between_surfaces(&scene, [u as u16, 1]))
        };
        // A silhouette over a background, a blended reading between them: only it is mixed.
        let edge = [600, 600, 600, 700, 900, 900];
        assert_eq!(mixed(edge), [false, false, false, true, false, false]);
        // A surface at 80° to the line of sight steps 14 mm a pixel at 700 mm: not mixed.
        let steep = [658, 672, 686, 700, 714, 728];
        assert_eq!(mixed(steep), [false; 6]);
        // A pixel without a reading beside it is no farther surface.
        let hole = [600, 600, 600, 700, 0, 0];
        assert_eq!(mixed(hole), [false; 6]);
        // Two blended pixels side by side: the far surface two pixels out.
        let pair = [600, 600, 700, 690, 900, 900];
        assert_eq!(mixed(pair), [false, false, true, false, false, false]);
        // A surface at 80° two pixels out is no far surface.
        let ramp = [600, 600, 700, 714, 728, 742];
        assert_eq!(mixed(ramp), [false; 6]);
    }

    #[test]
    fn a_masked_reading_past_the_outline_is_not_the_objects() {
        let k = Intrinsics {
            width: 5,
            height: 3,
            fx: 285.0,
            fy: 285.0,
            cx: 2.0,
            cy: 1.0,
        };
        // Millimetres: rows 0 and 2 `around`, row 1 `row`, the middle pixel tested; beyond
        // 21 mm (at 600 mm; 33 at 950) neighbours are apart (`EDGE_SLOPE`).
        let past = |around: [u16; 5], row: [u16; 5], masked: usize| {
            let depth: [u16; 15] = core::array::from_fn(|i| {
                if i / 5 == 1 {
                    row[i % 5]
                } else {
                    around[i % 5]
                }
            });
            let mask: [u8; 15] = core::array::from_fn(|i| if i % 5 < masked { 255 } else { 0 });
            let scene = Scene {
                mask: Some(&mask),
                ..Scene::new(&depth, 1e-3, k)
            };
            let mut reads = 0;
            let past = past_outline(&scene, &SensorConfig::DEFAULT, 7, (2, 1), &mut reads);
            (past, reads)
        };
        let object = [600, 600, 600, 1000, 1000];
        // At the mask's outline (three columns masked), blended toward the background behind
        // the object: behind it, sharing no surface with it; each neighbour read.
        assert_eq!(past(object, [600, 600, 950, 1000, 1000], 3), (true, 4));
        // Read as the background itself, the same.
        assert!(past(object, [600, 600, 1000, 1000, 1000], 3).0);
        // The object's surface, however steep: its first neighbour, within a step, ends it.
        assert_eq!(past(object, [600, 600, 615, 1000, 1000], 3), (false, 1));
        // One masked neighbour read, the others dropped out: one step is no evidence.
        let dropped = [600, 600, 0, 1000, 1000];
        assert!(!past(dropped, [600, 600, 950, 1000, 1000], 3).0);
        // In front of its neighbours (a nearer part of the object): kept.
        let far = [900, 900, 900, 1000, 1000];
        assert!(!past(far, [900, 900, 600, 1000, 1000], 3).0);
        // Inside the mask, not at its outline (a speck the mask encloses): kept.
        assert!(!past(object, [600, 600, 950, 600, 600], 5).0);
    }

    /// An empty grid over a whole `width` x `height` image.
    fn grid_over<const C: usize>(width: u16, height: u16) -> DepthGrid<C> {
        let mut grid = DepthGrid::<C>::new();
        grid.reset(Rect {
            u0: 0,
            v0: 0,
            width,
            height,
        });
        grid
    }

    /// The radius [`Shells`] of `gap` read for points every millimetre from `from` to `to`,
    /// and at `more`.
    fn radius_of(gap: f32, (from, to): (f32, f32), more: &[f32]) -> f32 {
        let body = (0..)
            .map(|k| from + 0.001 * k as f32)
            .take_while(|&d| d <= to);
        let d2s = body.chain(more.iter().copied()).map(|d| d * d);
        let mut shells = Shells::new(gap);
        d2s.clone().for_each(|d2| shells.add(d2));
        shells.radius(d2s)
    }

    #[test]
    fn a_surfaces_step_is_a_diagonal_stride_at_the_steepest_slope_read() {
        let steps = SQRT_2 * crate::math::sqrt(1.0 + EDGE_SLOPE * EDGE_SLOPE);
        let stats = ObjectStats {
            spacing: 1.0,
            ..Default::default()
        };
        let sensor = SensorConfig {
            noise_floor: 0.0,
            noise_growth: 0.0,
            ..SensorConfig::DEFAULT
        };
        assert!((stats.surface_gap(&sensor) - steps).abs() < 0.01, "{steps}");
    }

    #[test]
    fn the_radius_is_the_surfaces_without_the_readings_apart_from_it() {
        let (gap, body) = (0.06, (0.0, 0.1));
        let near = |r: f32, d: f32| (r - d).abs() < 1e-3;
        // A surface out to 10 cm, and readings past the outline 20-30 cm out.
        let r = radius_of(gap, body, &[0.2, 0.25, 0.3]);
        assert!(near(r, 0.1), "{r}");
        // A step under a gap between samples is one surface; a few steps of it reach out.
        let r = radius_of(gap, body, &[0.1 + 0.99 * gap]);
        assert!(near(r, 0.1 + 0.99 * gap), "{r}");
        let chain: [f32; 5] = core::array::from_fn(|k| 0.1 + 0.9 * gap * (k + 1) as f32);
        let r = radius_of(gap, body, &chain);
        assert!(near(r, 0.1 + 4.5 * gap), "{r}");
        // A step of 1.125 gaps parts two surfaces.
        let r = radius_of(gap, body, &[0.1 + 1.13 * gap]);
        assert!(near(r, 0.1), "{r}");
        // Hollow about its centre (a bowl's rim): the walk starts at the mean distance.
        let r = radius_of(gap, (0.08, 0.1), &[0.3]);
        assert!(near(r, 0.1), "{r}");
        // Beyond 16 gaps (a rod 1.2 m long) the shells end: no gap is seen there.
        let r = radius_of(gap, (0.0, 1.2), &[3.0]);
        assert!(near(r, 3.0), "{r}");
        assert_eq!(radius_of(gap, (1.0, 0.0), &[]), 0.0);
    }

    /// A 16 x 8 image of one-pixel blocks.
    fn pixel_grid() -> DepthGrid<128> {
        grid_over(16, 8)
    }

    #[test]
    fn a_straddling_blocks_pixels_behind_its_surface_are_left_out() {
        // The real frames' camera (f = 1067 px) at 0.75 m, 0.1 mm units: 7-pixel blocks.
        let k = Intrinsics {
            width: 77,
            height: 77,
            fx: 1067.0,
            fy: 1067.0,
            cx: 38.0,
            cy: 38.0,
        };
        let depth = [0u16; 77 * 77];
        let scene = Scene::new(&depth, 1e-4, k);
        let mut grid = grid_over::<128>(77, 77);
        assert_eq!(grid.block(), 7);
        // A can's top sampled at 752 mm in the core (pixels 9-11) of the block of columns and
        // rows 7-13; row 7 is 4 pixels from the core's far side: a surface the camera reads
        // steps up to 32 mm over them, 37 mm with the noise.
        grid.add(10, 10, 7520);
        let cell = grid.cell_of(10, 10);
        let sensor = SensorConfig::DEFAULT;
        let at = |cell, (u, v), mm: f32| {
            on_block_surface(&scene, &grid, cell, (u, v), mm * 1e-3, &sensor)
        };
        // An object 6 cm behind the can's rim, seen in the block's top rows: not the can's.
        assert!(!at(cell, (10, 7), 814.0));
        // The can's own surface receding 2 cm over those pixels (its rim seen steeply), and a
        // part standing out in front of it: the can's.
        assert!(at(cell, (10, 7), 772.0));
        assert!(at(cell, (10, 7), 700.0));
        // In the core, two pixels' step (to its far side) and the noise: 20 mm.
        assert!(at(cell, (10, 10), 770.0) && !at(cell, (10, 10), 775.0));
        // A block without a sample keeps every pixel.
        assert!(at(grid.cell_of(30, 30), (30, 30), 2000.0));
    }

    #[test]
    fn summits_nearer_than_their_depths_are_one_objects() {
        let grid = pixel_grid();
        let at = |c: u32, r: u32| r * 16 + c;
        // Two summits 3 deep are two objects' from 5 blocks apart on (chessboard).
        assert!(!apart(&grid, (3, at(4, 4)), (3, at(8, 4))));
        assert!(apart(&grid, (3, at(4, 4)), (3, at(9, 4))));
        assert!(apart(&grid, (3, at(4, 1)), (3, at(9, 6))));
        assert!(!apart(&grid, (4, at(4, 1)), (3, at(9, 6))));
        assert!(apart(&grid, (1, at(4, 4)), (1, at(5, 4))));
    }

    #[test]
    fn a_gap_is_free_space_on_the_seam_read_beyond_both_summits() {
        let k = crate::Intrinsics {
            width: 16,
            height: 8,
            fx: 500.0,
            fy: 500.0,
            cx: 8.0,
            cy: 4.0,
        };
        // Every reading 1 m away (0.1 mm units).
        let depth = [10_000u16; 128];
        let scene = Scene::new(&depth, 1e-4, k);
        let grid = pixel_grid();
        // The left half of the region the kept part, the right half the other.
        let flags: [u8; 128] = core::array::from_fn(|i| {
            let kept = if i % 16 < 8 { OBJECT } else { 0 };
            kept | 1 << DISTANCE_SHIFT
        });
        let sensor = SensorConfig::DEFAULT;
        let gap = |u: f32, z: f32, beyond: f32| {
            let p = k.unproject(u, 4.5, z);
            at_gap(&scene, &sensor, &grid, &flags, p, beyond)
        };
        // On the seam, 10 cm in front of a reading beyond both summits.
        assert!(gap(8.5, 0.9, 0.95));
        assert!(gap(7.5, 0.9, 0.95));
        // The reading between the summits' depths: a single object's waist.
        assert!(!gap(8.5, 0.9, 1.0));
        // Within the sensor's noise of the reading: not free space.
        assert!(!gap(8.5, 0.999, 0.95));
        // Off the seam: across a bay of one part.
        assert!(!gap(12.5, 0.9, 0.95));
        assert!(!gap(3.5, 0.9, 0.95));
    }

    #[test]
    fn sampling_visits_every_lattice_point_or_line_pixel_in_raster_order() {
        // Boxes whose sides start and end on and off the lattice, and one narrower than a
        // stride (no lattice column in it).
        for (u0, v0, width, height) in [(0, 0, 9, 7), (5, 3, 11, 13), (7, 2, 2, 9), (4, 4, 1, 1)] {
            let b = Rect {
                u0,
                v0,
                width,
                height,
            };
            for s in 1..=4u16 {
                for outline in [false, true] {
                    let total = width as u32 * height as u32;
                    let wanted = (0..total).filter(|j| {
                        let (u, v) = (
                            u0 + (j % width as u32) as u16,
                            v0 + (j / width as u32) as u16,
                        );
                        let (column, row) = (u % s == 0, v % s == 0);
                        (column && row) || (outline && (column || row))
                    });
                    let mut visited = heapless::Vec::<u32, 256>::new();
                    let mut j = next_visited(0, b, s, outline);
                    while j < total {
                        visited.push(j).unwrap();
                        j = next_visited(j + 1, b, s, outline);
                    }
                    assert!(
                        visited.iter().copied().eq(wanted),
                        "{b:?} stride {s} outline {outline}: {visited:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_crease_turns_by_more_than_45_degrees() {
        // Two faces at 30° each (tan 30° = 0.577 over a unit step): 60° in all.
        assert!(concave_turn(0.577, 0.577, 1.0));
        // 20° and 20°: 40°; a face at 45° meeting a level one: 45°, not more.
        assert!(!concave_turn(0.364, 0.364, 1.0));
        assert!(!concave_turn(0.999, 0.0, 1.0));
        // A right angle seen square on: each face at 45°.
        assert!(concave_turn(1.0, 1.0, 1.0));
        // Scale free: the same turn over a step of 7 mm.
        assert!(concave_turn(0.577 * 0.007, 0.577 * 0.007, 0.007));
    }

    /// A row of eight one-pixel blocks, 1 mm wide at 0.5 m, whose depths follow `profile`
    /// (mm behind 0.5 m, by column); whether the block test flags columns 3 and 4 as on a
    /// crease, and whether the edge between them is cut.
    fn crease_tests(profile: impl Fn(f32) -> f32) -> (bool, bool, bool) {
        let k = crate::Intrinsics {
            width: 8,
            height: 3,
            fx: 500.0,
            fy: 500.0,
            cx: 4.0,
            cy: 1.0,
        };
        // 0.1 mm units.
        let depth: [u16; 24] =
            core::array::from_fn(|i| 5000 + (10.0 * profile((i % 8) as f32)) as u16);
        let scene = Scene::new(&depth, 1e-4, k);
        let mut grid = grid_over::<24>(8, 3);
        for (i, &z) in depth.iter().enumerate() {
            grid.add((i % 8) as u16, (i / 8) as u16, z);
        }
        let blocks = Blocks {
            scene: &scene,
            grid: &grid,
            config: &PrepareConfig::DEFAULT,
            sensor: SensorConfig::DEFAULT,
            block_per_z: 1.0 / 500.0,
            target: TargetCells::None,
        };
        // Middle row: blocks 11 and 12; neighbour 4 is the one to the right.
        let right = 4;
        let near = blocks.depth(11).min(blocks.depth(12));
        let noise = 3.0 * SensorConfig::DEFAULT.sigma(near);
        let cut = |a, b, k| blocks.crease_between(a, b, k, near, noise);
        (
            blocks.on_crease(11),
            blocks.on_crease(12),
            cut(11, 12, right) && cut(12, 11, 7 - right),
        )
    }

    #[test]
    fn a_crease_between_two_samples_cuts_their_edge() {
        // A right angle seen square on, its line midway between columns 3 and 4: each face
        // rises 1 mm a block into it. Each block sees 45° (one face only); the edge, 90°.
        assert_eq!(
            crease_tests(|x| 3.5 - (x - 3.5).abs()),
            (false, false, true)
        );
        // A tilted plane and a convex ridge are not creases.
        assert_eq!(crease_tests(|x| x), (false, false, false));
        assert_eq!(
            crease_tests(|x| 4.0 + (x - 3.5).abs()),
            (false, false, false)
        );
        // Faces at 20° each (rising 0.36 mm a block): 40°, no crease.
        assert_eq!(
            crease_tests(|x| 0.364 * (3.5 - (x - 3.5).abs())),
            (false, false, false)
        );
    }
}
