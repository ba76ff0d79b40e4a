//! Completion: the visible points plus the points each symmetry predicts in occluded space, as
//! densely as the output has room for (see [`Completion`]).

/// Where a completed point comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Provenance {
    /// A visible point of the object: an object pixel (one per sampling cell, or each one when
    /// the output has room for the completion's dense pass).
    Visible = 0,
    /// A point a symmetry predicts in space the camera could not see.
    Generated = 1,
}

/// One point of the completed object, in caller storage.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub struct CompletedPoint {
    /// Camera frame, metres.
    pub position: [f32; 3],
    /// How plausible the point is, in `[0, 1]`: 1 for visible points; for generated points the
    /// margin of its symmetry's score under the acceptance threshold.
    pub plausibility: f32,
    /// Seen by the camera, or predicted by a symmetry.
    pub provenance: Provenance,
    /// Index into [`crate::Report::symmetries`] of the symmetry whose domain holds the point
    /// (visible) or that generated it; `u8::MAX` for a visible point no symmetry explains.
    pub symmetry: u8,
}

impl CompletedPoint {
    /// All zero: the initial value of an output buffer.
    pub const ZERO: Self = Self {
        position: [0.0; 3],
        plausibility: 0.0,
        provenance: Provenance::Visible,
        symmetry: u8::MAX,
    };
}

use crate::Scene;
use crate::engine::Found;
use crate::math::Vec3;
use crate::prepare::{EDGE_SLOPE, ObjectStats, Preparation, file_half};
use crate::score::{Evidence, View};
use crate::search::domains::Owner;
use crate::symmetry::{MapSet, Sampling, Symmetry};
use crate::voxel::{GENERATED, Insert, SPARSE_PROBES, VoxelMap};
use crate::work::{Meter, PROBES_PER_UNIT, Poll, SLOTS_CLEARED_PER_UNIT};

/// Counts of what a completion wrote.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Written {
    pub visible: u32,
    pub generated: u32,
    /// Points that had to be left out: the output or the deduplication table was full.
    pub dropped: u32,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Step {
    #[default]
    Visible,
    /// Waiting for the next symmetry (or the end).
    Between,
    Generated,
    /// The pixels around the sample whose image was just kept, through the same map (dense
    /// pass only).
    Patch,
    /// Rebuilding the voxel hash of the visible points before the dense pass.
    Refile,
    /// Every symmetry's points are generated.
    Done,
}

/// The density of the dense pass: within each sample's `stride x stride` lattice cell, the
/// pixels `step` apart, `side x side` of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Dense {
    step: u16,
    side: u16,
}

impl Dense {
    /// The densest pass whose output, at most `side²` points for each of the `written` points of
    /// the sampled pass, fits `capacity`; `None` when no step finer than the sampling fits.
    fn fitting(stride: u16, written: u32, capacity: usize) -> Option<Self> {
        (1..stride)
            .map(|step| Dense {
                step,
                side: stride.div_ceil(step),
            })
            .find(|d| written as u64 * (d.side as u64).pow(2) <= capacity as u64)
    }

    fn cell(&self) -> u16 {
        self.side * self.side
    }
}

/// What the dense pass reads besides the points: the depth image, the object-pixel test and the
/// sampling lattice.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pixels<'s> {
    pub scene: &'s Scene<'s>,
    pub preparation: &'s Preparation,
    /// Each sampled point's pixel.
    pub pixels: &'s [[u16; 2]],
    pub stats: &'s ObjectStats,
}

impl Pixels<'_> {
    /// How many pixels sample `i` stands for in the `dense` pass: its lattice cell's, or only
    /// itself for an outline point (off the lattice: the pixels around it are in a lattice
    /// point's cell).
    fn cell(&self, i: usize, dense: Dense) -> u16 {
        let s = self.stats.stride;
        match self.pixels.get(i) {
            Some([u, v]) if u % s != 0 || v % s != 0 => 1,
            _ => dense.cell(),
        }
    }

    /// Pixel `k` (row-major) of the `dense` sub-lattice of sample `i`'s cell, as a point, when it
    /// is an object pixel on the sample's surface: its depth differs from the sample's by at
    /// most what a surface the sensor still reads steps between pixels that far apart
    /// ([`EDGE_SLOPE`]). Pixel 0 is the sample itself.
    fn point(&self, i: usize, k: u16, dense: Dense, points: &[Vec3]) -> Option<Vec3> {
        let ([u, v], &sample) = (*self.pixels.get(i)?, points.get(i)?);
        let (a, b) = (k % dense.side * dense.step, k / dense.side * dense.step);
        let p = self
            .preparation
            .object_pixel(self.scene, (u.checked_add(a)?, v.checked_add(b)?))?;
        let focal = self.scene.intrinsics.fx.min(self.scene.intrinsics.fy);
        let reach = EDGE_SLOPE * a.max(b) as f32 * sample.z / focal;
        ((p.z - sample.z).abs() <= reach).then_some(p)
    }
}

/// The completion state machine: first every visible point, tagged with the symmetry whose
/// domain holds it; then, symmetry by symmetry, for each point of its domain (for the whole
/// object's symmetry, also each point of no domain) and each of its maps, the transformed point
/// if it lands in occluded space (within the free-space tolerance), is not already seen (farther
/// than the match σ from every visible point) and its voxel holds no point yet.
///
/// **Dense pass.** That sampled pass writes the search's sampled points and their images, `W`
/// points. When it left nothing out and the output has room for `W side²` points, `side =
/// ⌈stride / step⌉` for some `step` finer than the sampling stride, the completion starts over
/// at the finest such `step` (the voxel hash rebuilt as preparation built it, so the same images
/// are kept): each sample stands for the object pixels of its `stride x stride` lattice cell,
/// `step` apart, on its surface ([`EDGE_SLOPE`]), and each kept image for their images through
/// the same map that land hidden and unseen. The output then holds every object pixel (at
/// `step` 1) and the images of each, instead of one point a cell: the completed surface as dense
/// as the camera saw it. An output too small for it gets the sampled pass.
///
/// Cost: one work unit per point written, transformed point tested, pixel of a cell tried, or
/// point of another domain passed over; one per [`SLOTS_CLEARED_PER_UNIT`] slots cleared and per
/// half point filed when the hash is rebuilt; and one more for every [`PROBES_PER_UNIT`] hash
/// slots the tests' nearest-point lookups read beyond their first [`SPARSE_PROBES`] each (the
/// lookups grow long as the voxel table fills). A test costing more than a poll has left is paid
/// off by the next polls before anything else is done, so no poll exceeds its budget and the
/// total does not depend on how the work is sliced. The dense pass costs the sampled pass again
/// plus about `side²` units per written point.
#[derive(Clone, Debug)]
pub struct Completion {
    step: Step,
    /// Units of work done but not yet charged to a poll.
    owed: u32,
    /// Slots read beyond eight per lookup, not yet charged as a unit (< [`PROBES_PER_UNIT`]).
    probes: u32,
    next: usize,
    map: usize,
    maps: MapSet,
    /// The symmetry being completed, and the index of the next one.
    symmetry: Owner,
    next_symmetry: u8,
    /// The symmetry the points of no domain are completed through.
    unclaimed: Owner,
    plausibility: f32,
    tolerance: f32,
    seen2: f32,
    written: Written,
    /// `Some` in the dense pass.
    dense: Option<Dense>,
    /// The next pixel of the current cell (dense pass); 0 between cells.
    sub: u16,
    /// The sample and map of the image whose cell [`Step::Patch`] maps.
    patch: (usize, usize),
}

impl Default for Completion {
    fn default() -> Self {
        Self::new()
    }
}

impl Completion {
    pub const fn new() -> Self {
        Self {
            step: Step::Visible,
            owed: 0,
            probes: 0,
            next: 0,
            map: 0,
            maps: MapSet::new(),
            symmetry: Owner::UNCLAIMED,
            next_symmetry: 0,
            unclaimed: Owner::UNCLAIMED,
            plausibility: 0.0,
            tolerance: 0.0,
            seen2: 0.0,
            written: Written {
                visible: 0,
                generated: 0,
                dropped: 0,
            },
            dense: None,
            sub: 0,
            patch: (0, 0),
        }
    }

    /// Begin completing: generated points are accepted up to `tolerance` in front of the
    /// observed surface and farther than `seen` from any visible point; the points of no domain
    /// are completed through symmetry `unclaimed` ([`Owner::UNCLAIMED`]: none).
    pub(crate) fn begin(&mut self, tolerance: f32, seen: f32, unclaimed: Owner) {
        *self = Self::new().with(tolerance, seen * seen, unclaimed);
    }

    /// What was written so far.
    pub(crate) fn written(&self) -> Written {
        self.written
    }

    /// Complete, spending what is left on `meter`; once every symmetry's points are generated,
    /// what was written. `owners[i]` names the symmetry (of `found`) whose domain holds point
    /// `i`; each symmetry's plausibility is its [`Found::confidence`]. Starting each
    /// symmetry, and ending, cost one unit.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn advance<const V: usize, const C: usize>(
        &mut self,
        view: &View<'_, C>,
        pixels: &Pixels<'_>,
        voxels: &mut VoxelMap<V>,
        points: &[Vec3],
        owners: &[Owner],
        found: &[Found],
        sampling: Sampling,
        output: &mut [CompletedPoint],
        meter: &mut Meter,
    ) -> Poll<Written> {
        let (budget, mut used) = (meter.left(), 0);
        while used < budget && self.step != Step::Done {
            if self.step == Step::Between && self.owed == 0 {
                match found.get(self.next_symmetry as usize) {
                    Some(f) => self.begin_symmetry(&f.symmetry, sampling, f.confidence),
                    None => self.end_pass(pixels.stats.stride, output.len()),
                }
                used += 1;
                continue;
            }
            let context = (view, pixels);
            used += self.advance_symmetry(context, voxels, points, owners, output, budget - used);
        }
        meter.spend(used);
        if self.step == Step::Done {
            Poll::Ready(self.written)
        } else {
            Poll::Pending
        }
    }

    /// Generate the points of the next symmetry, whose domain is the points it owns, with
    /// `plausibility`.
    fn begin_symmetry(&mut self, symmetry: &Symmetry, sampling: Sampling, plausibility: f32) {
        (self.symmetry, self.maps, self.plausibility) = (
            Owner(self.next_symmetry),
            symmetry.maps(sampling),
            plausibility,
        );
        self.next_symmetry += 1;
        (self.step, self.next, self.map) = (Step::Generated, 0, 0);
    }

    /// Every symmetry is done: the end, or, after a sampled pass that left nothing out, the dense
    /// pass when its output fits (see [`Completion`]).
    fn end_pass(&mut self, stride: u16, capacity: usize) {
        let written = self.written.visible + self.written.generated;
        let dense = match self.dense {
            None if self.written.dropped == 0 => Dense::fitting(stride, written, capacity),
            _ => None,
        };
        let Some(dense) = dense else {
            self.step = Step::Done;
            return;
        };
        *self = Self {
            step: Step::Refile,
            dense: Some(dense),
            ..Self::new()
        }
        .with(self.tolerance, self.seen2, self.unclaimed);
    }

    /// `self` with the settings [`Completion::begin`] gave.
    fn with(self, tolerance: f32, seen2: f32, unclaimed: Owner) -> Self {
        Self {
            tolerance,
            seen2,
            unclaimed,
            ..self
        }
    }

    /// Do at most `budget` units of the visible points or of the current symmetry; returns the
    /// units used.
    fn advance_symmetry<const V: usize, const C: usize>(
        &mut self,
        (view, pixels): (&View<'_, C>, &Pixels<'_>),
        voxels: &mut VoxelMap<V>,
        points: &[Vec3],
        owners: &[Owner],
        output: &mut [CompletedPoint],
        budget: u32,
    ) -> u32 {
        let mut used = 0;
        loop {
            let paid = self.owed.min(budget - used);
            (used, self.owed) = (used + paid, self.owed - paid);
            if used == budget || self.step == Step::Between {
                return used;
            }
            self.owed = self.step((view, pixels), voxels, points, owners, output);
        }
    }

    /// One step of the state machine; returns its cost in units.
    fn step<const V: usize, const C: usize>(
        &mut self,
        (view, pixels): (&View<'_, C>, &Pixels<'_>),
        voxels: &mut VoxelMap<V>,
        points: &[Vec3],
        owners: &[Owner],
        output: &mut [CompletedPoint],
    ) -> u32 {
        let probes = match self.step {
            Step::Visible => {
                self.visible(pixels, points, owners, output);
                0
            }
            // A full table would refuse every new point, after long probe runs: count the rest
            // as dropped at once.
            Step::Generated if voxels.is_full() => {
                self.drop_rest(owners);
                0
            }
            Step::Generated => {
                let evidence = Evidence {
                    view: *view,
                    voxels,
                    points,
                };
                let (candidate, probes) = self.next_candidate(&evidence, owners);
                if let Some(image) = candidate {
                    self.keep(image, voxels, output);
                }
                probes
            }
            Step::Patch => {
                let evidence = Evidence {
                    view: *view,
                    voxels,
                    points,
                };
                self.patch_point(&evidence, pixels, output)
            }
            Step::Refile => {
                self.refile(voxels, points, pixels.stats);
                0
            }
            Step::Between | Step::Done => 0,
        };
        self.probes += probes.saturating_sub(SPARSE_PROBES);
        let extra = self.probes / PROBES_PER_UNIT;
        self.probes %= PROBES_PER_UNIT;
        1 + extra
    }

    /// One step of rebuilding the visible points' voxel hash as preparation built it (the
    /// sampled pass's images removed), so that the dense pass keeps the same images:
    /// [`SLOTS_CLEARED_PER_UNIT`] slots cleared, then one half of a point filed.
    fn refile<const V: usize>(
        &mut self,
        voxels: &mut VoxelMap<V>,
        points: &[Vec3],
        stats: &ObjectStats,
    ) {
        let chunks = V.div_ceil(SLOTS_CLEARED_PER_UNIT as usize);
        let halves = 2 * points.len();
        if self.next < chunks {
            let per = SLOTS_CLEARED_PER_UNIT as usize;
            voxels.clear_slots(self.next * per, per);
        } else if self.next - chunks < halves {
            if self.next == chunks {
                voxels.set_grid(Vec3::from_array(stats.centroid), stats.spacing);
            }
            file_half(voxels, points, (self.next - chunks) as u32);
        }
        self.next += 1;
        if self.next >= chunks + halves {
            (self.step, self.next) = (Step::Visible, 0);
        }
    }

    /// End this symmetry's completion, counting every transformed point of its domain not yet
    /// tested as dropped (one pass over the owners: at most `POINTS` byte compares).
    fn drop_rest(&mut self, owners: &[Owner]) {
        let maps = self.maps.maps.len();
        let points = owners
            .get(self.next..)
            .unwrap_or_default()
            .iter()
            .filter(|&&o| o == self.symmetry)
            .count();
        let rest = (points * maps).saturating_sub(self.map);
        self.written.dropped = self
            .written
            .dropped
            .saturating_add(u32::try_from(rest).unwrap_or(u32::MAX));
        self.step = Step::Between;
    }

    fn write(&mut self, output: &mut [CompletedPoint], point: CompletedPoint) -> bool {
        let at = (self.written.visible + self.written.generated) as usize;
        match output.get_mut(at) {
            Some(slot) => {
                *slot = point;
                true
            }
            None => {
                self.written.dropped += 1;
                false
            }
        }
    }

    /// The next visible point: the next sample, or in the dense pass the next pixel of its cell.
    fn visible(
        &mut self,
        pixels: &Pixels<'_>,
        points: &[Vec3],
        owners: &[Owner],
        output: &mut [CompletedPoint],
    ) {
        let i = self.next;
        let Some(&sample) = points.get(i) else {
            (self.step, self.next) = (Step::Between, 0);
            return;
        };
        let p = match self.dense {
            None => {
                self.next += 1;
                Some(sample)
            }
            Some(dense) => {
                let (k, last) = self.take_pixel(pixels.cell(i, dense));
                if last {
                    self.next = i + 1;
                }
                pixels.point(i, k, dense, points)
            }
        };
        let Some(p) = p else {
            return;
        };
        let point = CompletedPoint {
            position: p.to_array(),
            plausibility: 1.0,
            provenance: Provenance::Visible,
            symmetry: owners.get(i).map_or(u8::MAX, |o| o.0),
        };
        if self.write(output, point) {
            self.written.visible += 1;
        }
    }

    /// The index of the current cell's next pixel, of `cell` in all, and whether it is the
    /// cell's last (the next call starts a new cell).
    fn take_pixel(&mut self, cell: u16) -> (u16, bool) {
        let k = self.sub;
        self.sub = (k + 1) % cell.max(1);
        (k, self.sub == 0)
    }

    /// The next pixel of the kept image's cell through its map, written when it lands hidden
    /// and unseen; returns the slots its nearest-point lookup read.
    fn patch_point<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        pixels: &Pixels<'_>,
        output: &mut [CompletedPoint],
    ) -> u32 {
        let (Some(dense), (i, map)) = (self.dense, self.patch) else {
            self.step = Step::Generated;
            return 0;
        };
        let (k, last) = self.take_pixel(pixels.cell(i, dense));
        if last {
            self.step = Step::Generated;
        }
        let Some((p, (m, _))) = pixels
            .point(i, k, dense, evidence.points)
            .zip(self.maps.maps.get(map))
        else {
            return 0;
        };
        let q = m.apply(p);
        if evidence.view.free_space_violation(q) > self.tolerance {
            return 0;
        }
        let (nearest2, probes) = evidence.nearest_visible2(q);
        if nearest2 > self.seen2 {
            self.write_generated(q, output);
        }
        probes
    }

    /// The next transformed point of the symmetry's domain, if it lands hidden and unseen, and
    /// the slots its nearest-point lookup read.
    fn next_candidate<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        owners: &[Owner],
    ) -> (Option<Image>, u32) {
        let Some(&owner) = owners.get(self.next) else {
            self.step = Step::Between;
            return (None, 0);
        };
        let through = if owner == Owner::UNCLAIMED {
            self.unclaimed
        } else {
            owner
        };
        if through != self.symmetry || self.maps.maps.is_empty() {
            self.next += 1;
            return (None, 0);
        }
        let image = Image {
            q: self.maps.maps[self.map].0.apply(evidence.points[self.next]),
            sample: self.next,
            map: self.map,
        };
        self.map += 1;
        if self.map == self.maps.maps.len() {
            (self.map, self.next) = (0, self.next + 1);
        }
        if evidence.view.free_space_violation(image.q) > self.tolerance {
            return (None, 0);
        }
        let (nearest2, probes) = evidence.nearest_visible2(image.q);
        ((nearest2 > self.seen2).then_some(image), probes)
    }

    /// Keep `image` unless its voxel already holds a point: write it, or in the dense pass map
    /// its sample's cell ([`Step::Patch`]).
    fn keep<const V: usize>(
        &mut self,
        image: Image,
        voxels: &mut VoxelMap<V>,
        output: &mut [CompletedPoint],
    ) {
        match voxels.insert(image.q, GENERATED) {
            Insert::New if self.dense.is_some() => {
                (self.step, self.patch) = (Step::Patch, (image.sample, image.map));
            }
            Insert::New => self.write_generated(image.q, output),
            Insert::Taken(_) => {}
            Insert::Full | Insert::OutOfRange => self.written.dropped += 1,
        }
    }

    fn write_generated(&mut self, q: Vec3, output: &mut [CompletedPoint]) {
        let point = CompletedPoint {
            position: q.to_array(),
            plausibility: self.plausibility,
            provenance: Provenance::Generated,
            symmetry: self.symmetry.0,
        };
        if self.write(output, point) {
            self.written.generated += 1;
        }
    }
}

/// A transformed sample: where it lands, the sample and the map.
#[derive(Clone, Copy, Debug)]
struct Image {
    q: Vec3,
    sample: usize,
    map: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{ModelConfig, PrepareConfig, SensorConfig};
    use crate::geometry::Plane;
    use crate::prepare::Points;
    use crate::score::plate::Plate;

    const MODEL: ModelConfig = ModelConfig::DEFAULT;
    const PREPARE: PrepareConfig = PrepareConfig::DEFAULT;
    const SENSOR: SensorConfig = SensorConfig::DEFAULT;
    /// Room for the square plate's 400 points and all their images.
    const OUT: usize = 1024;

    /// The plate's mirror image through the plane `z = at`, scored `score`.
    fn depth_mirror(at: f32, score: f32) -> Found {
        let symmetry = Symmetry::PlaneReflection(Plane::new(Vec3::Z, at).unwrap());
        Found::new(symmetry, score, 0, MODEL.accept)
    }

    /// Five symmetries of the plate at 0.5 m, whose images land: 0.1 m behind it (occluded, the
    /// only ones to write); onto it (its columns swapped: seen); 0.1 m in front of it (free);
    /// half a σ behind it, and half a σ in front of it (within σ of their sources: seen; one of
    /// the two in a voxel of no plate point, wherever rounding puts the plate's).
    fn symmetries(sigma: f32) -> [Found; 5] {
        let symmetry = Symmetry::PlaneReflection(Plane::new(Vec3::X, 0.0).unwrap());
        let across = Found::new(symmetry, 0.3, 0, MODEL.accept);
        [
            depth_mirror(0.55, 0.2),
            across,
            depth_mirror(0.45, 0.1),
            depth_mirror(0.5 + sigma / 4.0, 0.1),
            depth_mirror(0.5 - sigma / 4.0, 0.1),
        ]
    }

    /// Every sixth point in no domain, the others in those of symmetries 0 to 4 in turn.
    fn owners(n: usize) -> heapless::Vec<Owner, OUT> {
        let of = |i: usize| match i % 6 {
            5 => Owner::UNCLAIMED,
            k => Owner(k as u8),
        };
        (0..n).map(of).collect()
    }

    /// Complete the plate (its voxel table copied) into `output` as the engine does, `slice`
    /// units a call: what was written and the units spent.
    fn complete<const V: usize>(
        plate: &Plate<1024, V>,
        (owners, found, unclaimed): (&[Owner], &[Found], Owner),
        output: &mut [CompletedPoint],
        slice: u32,
    ) -> (Written, u32) {
        let mut voxels = plate.voxels.clone();
        let sigma = plate.sigma();
        let mut completion = Completion::new();
        completion.begin(sigma * MODEL.free_per_match, sigma, unclaimed);
        let (scene, preparation) = (plate.scene(), Preparation::new(PREPARE, SENSOR, true));
        let [first, second] = [0, 1].map(|i| plate.points.pixel[i][0]);
        let stats = ObjectStats {
            centroid: centroid(plate.points.positions()).to_array(),
            spacing: plate.spacing,
            stride: second - first,
            ..ObjectStats::default()
        };
        let pixels = Pixels {
            scene: &scene,
            preparation: &preparation,
            pixels: plate.points.pixels(),
            stats: &stats,
        };
        let mut units = 0;
        loop {
            let mut meter = Meter::new(slice);
            let poll = completion.advance(
                &plate.view(),
                &pixels,
                &mut voxels,
                plate.points.positions(),
                owners,
                found,
                Sampling::default(),
                output,
                &mut meter,
            );
            // `Meter::spend` asserts that no call spends more than it holds.
            let spent = slice - meter.left();
            units += spent;
            if let Poll::Ready(written) = poll {
                assert_eq!(written, completion.written());
                return (written, units);
            }
            assert!(spent >= 1, "every call makes progress");
        }
    }

    /// The image of `p` under `found`'s one map.
    fn image(found: &Found, p: Vec3) -> [f32; 3] {
        found.symmetry.maps(Sampling::default()).maps[0]
            .0
            .apply(p)
            .to_array()
    }

    #[test]
    fn visible_points_come_first_then_only_the_images_in_occluded_space() {
        let plate = Plate::<1024, 2048>::square();
        let (points, n) = (plate.points.positions(), plate.points.len);
        let (owners, found) = (owners(n), symmetries(plate.sigma()));
        let mut out = [CompletedPoint::ZERO; OUT];
        let input = (&owners[..], &found[..], Owner::UNCLAIMED);
        let (written, _) = complete(&plate, input, &mut out, u32::MAX);
        let hidden: heapless::Vec<usize, OUT> = (0..n).filter(|&i| owners[i].0 == 0).collect();
        assert_eq!(
            written,
            Written {
                visible: n as u32,
                generated: hidden.len() as u32,
                dropped: 0,
            }
        );
        for (i, point) in out[..n].iter().enumerate() {
            let visible = CompletedPoint {
                position: points[i].to_array(),
                plausibility: 1.0,
                provenance: Provenance::Visible,
                symmetry: owners[i].0,
            };
            assert_eq!(*point, visible, "point {i}");
        }
        // Only the first symmetry's, each image in a voxel of its own; plausibility is the
        // score's margin under the threshold.
        let plausibility = (MODEL.accept - found[0].score) / MODEL.accept;
        for (point, &i) in out[n..].iter().zip(&hidden) {
            let generated = CompletedPoint {
                position: image(&found[0], points[i]),
                plausibility,
                provenance: Provenance::Generated,
                symmetry: 0,
            };
            assert_eq!(*point, generated, "image of point {i}");
        }
        assert_eq!(out[n + hidden.len()], CompletedPoint::ZERO, "nothing more");
    }

    #[test]
    fn the_points_of_no_domain_are_completed_through_the_whole_objects_symmetry() {
        let plate = Plate::<1024, 2048>::square();
        let (points, n) = (plate.points.positions(), plate.points.len);
        let (owners, found) = (owners(n), symmetries(plate.sigma()));
        let mut out = [CompletedPoint::ZERO; OUT];
        let input = (&owners[..], &found[..], Owner(0));
        let (written, _) = complete(&plate, input, &mut out, u32::MAX);
        // Symmetry 0's domain and no one's, in point order, all as symmetry 0's.
        let through: heapless::Vec<usize, OUT> = (0..n)
            .filter(|&i| owners[i] == Owner(0) || owners[i] == Owner::UNCLAIMED)
            .collect();
        assert_eq!(written.generated as usize, through.len());
        for (point, &i) in out[n..].iter().zip(&through) {
            assert_eq!(point.position, image(&found[0], points[i]), "point {i}");
            assert_eq!(point.symmetry, 0);
        }
        // A visible point of no domain stays tagged as such.
        assert_eq!(out[5].symmetry, u8::MAX);
    }

    #[test]
    fn a_full_output_counts_every_point_it_leaves_out() {
        let plate = Plate::<1024, 2048>::square();
        let n = plate.points.len;
        let (owners, found) = (owners(n), symmetries(plate.sigma()));
        let input = (&owners[..], &found[..], Owner::UNCLAIMED);
        let mut out = [CompletedPoint::ZERO; OUT];
        let (all, _) = complete(&plate, input, &mut out, u32::MAX);
        assert!(all.generated > 5);
        // Room for five images.
        let (five, _) = complete(&plate, input, &mut out[..n + 5], u32::MAX);
        let left_out = all.generated - 5;
        let expected = Written {
            visible: n as u32,
            generated: 5,
            dropped: left_out,
        };
        assert_eq!(five, expected);
        // Room for all but ten visible points: no image fits.
        let (short, _) = complete(&plate, input, &mut out[..n - 10], u32::MAX);
        let expected = Written {
            visible: n as u32 - 10,
            generated: 0,
            dropped: 10 + all.generated,
        };
        assert_eq!(short, expected);
    }

    #[test]
    fn a_full_voxel_table_counts_every_image_it_leaves_untested() {
        // 1024 slots: the 400 points and their coarser voxels fit under the load limit (3/4 of
        // the slots, 768), not all 400 images besides.
        let plate = Plate::<1024, 1024>::square();
        let n = plate.points.len;
        let owners = [Owner(0); OUT];
        let found = [depth_mirror(0.55, 0.2)];
        let mut out = [CompletedPoint::ZERO; OUT];
        let input = (&owners[..n], &found[..], Owner::UNCLAIMED);
        let (written, _) = complete(&plate, input, &mut out, u32::MAX);
        // Every image is hidden and unseen: written until the table is full, then counted.
        assert_eq!(written.generated as usize, 768 - plate.voxels.len());
        assert_eq!(written.generated + written.dropped, n as u32);
    }

    #[test]
    fn completion_spends_its_meter_and_any_slicing_gives_the_same_points() {
        let square = Plate::<1024, 2048>::square();
        // A table near its load limit: long probe runs, charged a unit per 64 slots.
        let crowded = Plate::<1024, 1024>::square();
        let n = square.points.len;
        let (owners, found) = (owners(n), symmetries(square.sigma()));
        let input = (&owners[..], &found[..], Owner(0));
        let runs = |slice: u32| {
            let mut outs = [[CompletedPoint::ZERO; OUT]; 2];
            let square = complete(&square, input, &mut outs[0], slice);
            let crowded = complete(&crowded, input, &mut outs[1], slice);
            ([square, crowded], outs.map(|out| out.map(bits)))
        };
        let whole = runs(u32::MAX);
        assert!(whole.0[1].1 > whole.0[0].1, "the crowded table costs more");
        // One unit a call (a lookup's extra probe units then span calls), an odd slice, a larger.
        for slice in [1, 7, 64] {
            assert!(runs(slice) == whole, "{slice} units a call");
        }
    }

    fn centroid(points: &[Vec3]) -> Vec3 {
        points.iter().fold(Vec3::ZERO, |s, p| s + *p) / points.len() as f32
    }

    /// The square plate sampled at stride 2 (its 100 even pixels of 400), its voxels a sample
    /// spacing wide, as preparation would sample and file it.
    fn strided() -> Plate<1024, 2048> {
        let mut plate = Plate::<1024, 2048>::square();
        let mut points = Points::new();
        for (&p, &[u, v]) in plate.points.positions().iter().zip(plate.points.pixels()) {
            if u % 2 == 0 && v % 2 == 0 {
                (points.pos[points.len], points.pixel[points.len]) = (p, [u, v]);
                points.len += 1;
            }
        }
        plate.spacing *= 2.0;
        plate
            .voxels
            .reset(centroid(points.positions()), plate.spacing);
        for half in 0..2 * points.len as u32 {
            file_half(&mut plate.voxels, points.positions(), half);
        }
        plate.points = points;
        plate
    }

    /// Complete `plate` through one mirror behind it (every point in its domain) into an output
    /// of `N` points.
    fn behind<const N: usize>(plate: &Plate<1024, 2048>) -> (Written, [CompletedPoint; N], Found) {
        let owners = [Owner(0); OUT];
        let found = [depth_mirror(0.55, 0.2)];
        let input = (&owners[..plate.points.len], &found[..], Owner::UNCLAIMED);
        let mut out = [CompletedPoint::ZERO; N];
        let (written, _) = complete(plate, input, &mut out, u32::MAX);
        (written, out, found[0])
    }

    #[test]
    fn an_output_with_room_gets_every_object_pixel_and_its_images() {
        let (plate, all) = (strided(), Plate::<1024, 2048>::square());
        let (n, every) = (plate.points.len, all.points.positions());
        assert_eq!((n, every.len()), (100, 400));
        // The sampled pass writes 100 + 100 points: the dense one fits 4 x 200.
        let (written, out, found) = behind::<800>(&plate);
        let counts = (written.visible, written.generated, written.dropped);
        assert_eq!(counts, (400, 400, 0));
        let sorted = |points: &mut [[f32; 3]]| {
            points.sort_by(|a, b| a.map(f32::to_bits).cmp(&b.map(f32::to_bits)));
        };
        let mut seen: [[f32; 3]; 400] = core::array::from_fn(|i| out[i].position);
        let mut generated: [[f32; 3]; 400] = core::array::from_fn(|i| out[400 + i].position);
        let mut pixels: [[f32; 3]; 400] = core::array::from_fn(|i| every[i].to_array());
        let mut images: [[f32; 3]; 400] = core::array::from_fn(|i| image(&found, every[i]));
        for points in [&mut seen, &mut generated, &mut pixels, &mut images] {
            sorted(points);
        }
        assert!(seen == pixels, "every plate pixel, once");
        assert!(generated == images, "the image of every plate pixel, once");
        assert!(
            out[..400]
                .iter()
                .all(|p| p.provenance == Provenance::Visible)
        );
        assert!(
            out[400..]
                .iter()
                .all(|p| p.provenance == Provenance::Generated)
        );
    }

    #[test]
    fn an_output_without_room_for_the_dense_pass_keeps_the_sampled_points() {
        let plate = strided();
        let n = plate.points.len;
        let (written, out, _) = behind::<799>(&plate);
        let counts = (written.visible, written.generated, written.dropped);
        assert_eq!(counts, (100, 100, 0));
        for (i, point) in out[..n].iter().enumerate() {
            assert_eq!(point.position, plate.points.pos[i].to_array());
        }
    }

    #[test]
    fn any_slicing_of_the_dense_pass_gives_the_same_points() {
        let plate = strided();
        let n = plate.points.len;
        let (owners, found) = (owners(n), symmetries(plate.sigma()));
        let input = (&owners[..], &found[..], Owner(0));
        let run = |slice: u32| {
            let mut out = [CompletedPoint::ZERO; OUT];
            let done = complete(&plate, input, &mut out, slice);
            (done, out.map(bits))
        };
        let whole = run(u32::MAX);
        assert!(whole.0.0.visible == 400, "the dense pass ran");
        for slice in [1, 7, 64] {
            assert!(run(slice) == whole, "{slice} units a call");
        }
    }

    /// A completed point's bits.
    fn bits(p: CompletedPoint) -> ([u32; 4], Provenance, u8) {
        let [x, y, z] = p.position.map(f32::to_bits);
        (
            [x, y, z, p.plausibility.to_bits()],
            p.provenance,
            p.symmetry,
        )
    }
}
