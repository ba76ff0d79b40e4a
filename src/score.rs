//! The measurement model (paper section 4, eqs. 5-11): how well the visible points support a
//! hypothesised symmetry.
//!
//! Each transformed point `Q` has three possible causes, and costs the negative log-likelihood of
//! the most likely one (the "max-mixture" form of eq. 8; no logarithm or exponential is evaluated
//! per point, the constants below are already logarithms):
//! - **match**: `Q` lies on the visible surface: `d² / 2σ²`, `d` the distance to the nearest
//!   visible point (voxel hash, at most eight probes); when that is at most `c_occluded` (a
//!   confirmed match), less `e / 2σ²`, `e` the variance of a reading at the object's depth
//!   beyond what the finest σ allows for it ([`ModelConfig::excess2`]): a true image then costs
//!   on average what it costs at the sensor's best range, while the match's reach stays that of
//!   σ, so the extra noise turns no farther image into a match (a σ widened with the noise
//!   would, and a wrong hypothesis would pass more easily: `docs/figures.md`, the synthetic
//!   objects at range);
//! - **occluded**: `Q` lies where the camera could not see (behind the observed surface along its
//!   ray, in a block with no reading, or outside the image): `c_occluded + v² / 2σ_free²`, `v` the
//!   distance by which `Q` is in front of the observed depth or below the support plane (0 inside
//!   occluded space); with lateral sensor noise (`SensorConfig::lateral_noise`), also
//!   `c_occluded + c_lateral + v'² / 2σ_free²`, `v'` measured against the nearest reading of the
//!   3 x 3 cells around `Q`'s (the surface a neighbouring pixel saw may be the one at `Q`'s: a
//!   depth edge lands about a pixel off), `c_lateral` ([`LATERAL_COST`]) that displacement's
//!   cost;
//! - **stray**: anything else, `c_stray`, the heavy tail that makes a false symmetry pay for every
//!   point it puts where the camera would have seen it; beyond the observed crop (the box of
//!   the object's points and a margin, [`crate::prepare`]) no reading is kept, and an image
//!   there counts as seen in free space, also where the camera read nothing (the far half of a
//!   can's glossy lid; [`ImageCost::reading`] tells such an image);
//! - **obstructed**: `Q` lies behind a reading nearer than any point of the object can be (the
//!   object's points lie within its radius of their centroid, [`View::front`]): another object
//!   stands in front of where `Q` would be seen. The camera could not look there whatever the
//!   symmetry, so `Q` tells nothing and, like a self-map, is left out of the score. Hidden
//!   behind the object's own surface, it is occluded as above: that the object hides part of
//!   itself is what every hypothesis' images of a one-sided view share, and what an element must
//!   be confirmed despite. (A bowl with a bottle in front of it: its rotations send a third of
//!   their images behind the bottle, which would otherwise cost it `c_occluded` each.)
//! - **mixed source**: `Q`'s seen point is a mixed reading, a depth between a nearer and a
//!   farther surface beside it ([`crate::prepare::between_surfaces`]; the "flying" pixels a
//!   camera reads across a depth discontinuity): it samples neither surface, so where a
//!   hypothesis maps it tells nothing, and its images are left out of the score. It stays a
//!   seen point, which other images may match.
//! - **contact** (scene context, when the object rests on a known support plane,
//!   [`ModelConfig::resting`]): `Q` is the image under a map that turns the object upside down (a
//!   reflection that sends the support's up direction to down: a mirror plane level within the
//!   library's 5°, within which two elements are one, or a point reflection; with
//!   [`ModelConfig::tilted_contact`], also a mirror tilted so little further that it sends the
//!   object's top onto the support, [`turns_over`]) and lies in occluded space at signed height
//!   `h` from the support: `h² / 2σ²`, as a match. An object at rest touches its support; a
//!   true level mirror maps its seen top onto its underside, whose lowest points lie on the
//!   support (all of a flat base, a line of a round one). The images carry the seen points'
//!   noise, so they scatter about the support on both sides, as a match scatters about the
//!   surface: one just below it is contact as much as one just above. A mirror too high leaves
//!   those images floating (no credit), one too low sinks them beyond a match's reach (the
//!   free-space term below the support, cheaper there), so the term pins a level plane's height
//!   and confirms it where the view cannot. A mirror tilted further earns none: it sends the top
//!   sideways, not onto the underside, and what it puts near the support is no contact. (The
//!   tilted mirrors are opt-in: they also let a near-symmetric object's second, nearly true
//!   plane pass, a banana's cross plane beside the mirror it rests on, `docs/figures.md`.)
//!   Rotations earn no contact: a half-turn about any level axis through the object sends its
//!   top under it too, right or wrong.
//!
//! A hypothesis' score is the mean cost over its informative points (eq. 11). A composite
//! symmetry is scored per element (each plane; the rotations about an axis) and is a conjunction:
//! it holds only if each element holds, so each element must pass the acceptance test on the
//! points it maps itself. When every element passes, the score is the mean of the element means
//! (the composite's likelihood, which each element's parameters move); otherwise it is the worst
//! element mean, at or above the threshold. So an accepted
//! composite always scores below a rejected one, accepted composites are compared, climbed and
//! refined by how well all their elements fit (a maximum only of the worst would leave the
//! others' parameters free within its plateau: a box's plane several millimetres off), and a
//! rejected one by how far its least confirmed element is from passing. A single element's score
//! is its plain mean. An element whose images mostly land in occluded space (confirmed by few
//! matches, contradicted by nothing) keeps the composite out, and the weaker type made of the
//! confirmed elements is reported instead (Table 1 reaches it first). The maps a composite derives
//! from its elements are not scored (they hold when the elements do). A
//! transformed point within `self_radius` of its source tells nothing (a plane through a point
//! maps it onto itself) and is left out; a hypothesis with too few informative points is
//! rejected.
//!
//! Each element's test is the likelihood-ratio test of the element against no symmetry, whose
//! images cost `accept` on average. A BIC-like penalty for its free parameters, `(k / 2) ln N`
//! nats over its `N` seen points, would add `k ln N / 2N` a point: 0.016 for a plane over 600
//! points, 0.034 for a line over 342, within the margin by which `accept` lies below
//! `c_occluded` (an element must be confirmed, not merely uncontradicted); it is not added.
//! A composite's element is also held to its siblings' evidence: the elements see one object
//! through one sensor, so a true element's images meet free space (strays, among the images a
//! match or a stray decides) no more often than its least contradicted sibling's. One whose
//! stray share exceeds that sibling's by more than three standard deviations of the difference
//! (a two-proportion test; for a few strays, also as unlikely by the exact test,
//! `stray_excess`) holds on a part of the object only (a plane across a mug's body
//! sends the handle into the free space beside it), and fails whatever its mean: a stronger
//! type is reported only when its extra element is confirmed as well as the ones the weaker
//! type already has.
//!
//! The converse of contact (the **foot test**): under a map that turns a resting object over,
//! the seen points at the support are its foot (within a match's reach of the least height
//! preparation keeps, [`View::lowest`]: the readings below it are left out, the support's among
//! them), and a true level mirror maps them onto its top, which the camera sees or which is
//! hidden, as it does the rest. So an element's foot images stray no more often than its other
//! decided images; by the same two-proportion test, an element whose foot strays more fails
//! whatever its mean. A level plane halfway up a composite object (a roll lying across a box)
//! maps the roll's top onto the support, which the contact term credits, and the box's foot
//! into the free space above the box.
//!
//! The **halves test** holds the whole object to the same evidence: under a map that turns a
//! resting object over, the seen points below the mirror map above it and those above it map
//! below it, and a true mirror maps both halves of one object seen through one sensor, so the
//! images of each half stray as often as the other's. By the same two-proportion test, either
//! way round, an element whose images stray more often from one half than from the other
//! holds on the other half only and fails whatever its mean. A cup's level mirror maps its
//! outer wall onto itself, but the floor seen through the opening into the air inside the cup,
//! where the camera looked through to the floor. On request
//! ([`Evaluation::halves_about_every_mirror`]) every mirror is held to it, each about its own
//! plane: the check of a pair the search found by a wider climb (see [`crate::search`]); a
//! near-symmetry fits one side of its mirror and not the other.
//!
//! [`crate::Engine::explain`] hands out what the test reads: each element's mean, its images
//! that confirm or contradict it, whether its strays fail it ([`ElementEvidence`]), and each
//! transformed point's cost with its likeliest cause ([`Cause`], read off the cost).
//!
//! Cost: one work unit per transformed point: one 3x3 transform, up to eight hash probes, and,
//! unless the match already costs less than `c_occluded`, one division (projection) and one depth
//! lookup; for a point in front of the reading that no cheaper cause explains, with lateral
//! noise, the nearest reading of the 3 x 3 cells around it (one read where preparation spread
//! them, nine otherwise); per source point, the look-up of its mark (a mixed reading: its
//! images cost nothing more); under a map that turns a resting object over, two dot products
//! per image that confirms or contradicts (the foot test's height, the halves test's side);
//! when asked for, for a stray, its seen point and the point's outer product added to the
//! stray tally ([`Strays`], nine additions: where a hypothesis fails, which the type search
//! reads). No square root, no transcendental.

use crate::config::ModelConfig;
use crate::depth::{DepthGrid, Observed};
use crate::math::{Mat3, OuterSum, Vec3, outer};
use crate::search::family::COS_5_DEG;
use crate::symmetry::{MAX_GROUPS, MapSet, Sampling, Symmetry};
use crate::voxel::VoxelMap;
use crate::work::{Meter, Poll};
use crate::{Intrinsics, Plane};

impl ModelConfig {
    /// The finest match σ for a sampling of the given spacing.
    pub fn sigma_fine(&self, spacing: f32) -> f32 {
        self.sigma_min.max(self.sigma_per_spacing * spacing)
    }

    /// The variance of a reading at the object's depth beyond what [`ModelConfig::sigma_min`]
    /// allows for it, metres²: `sensor_sigma`² − (`sigma_min`² − `sigma_object`²) / 2, at
    /// least 0, for a sensor of σ `sensor_sigma` there ([`crate::SensorConfig::sigma`]). The
    /// default floor allows each of two readings 1.17 mm; the default sensor reads 1.2 mm at
    /// its best range (a credit of 0.004 a match), 1.7 mm at 0.9 m (0.08). One reading's, not
    /// two: a true image carries its own reading's noise whole, but the reading it is matched
    /// with is the nearest of those around it, whose noise the nearest-point search largely
    /// selects away (with both taken off, the synthetic bar's scores at twice the Kinect's
    /// noise, -0.04 to 0.34, fall below those at its noise, 0.21 to 0.42).
    ///
    /// ```
    /// # use shape_from_symmetry::ModelConfig;
    /// let model = ModelConfig::DEFAULT; // 3 mm floor, 2.5 mm object: 1.375 mm² a reading
    /// let excess = model.excess2(0.0024); // 2.4² - 1.375 = 4.385 mm²
    /// assert!((excess - 4.385e-6).abs() < 1e-9);
    /// assert_eq!(model.excess2(0.0011), 0.0);
    /// ```
    pub fn excess2(&self, sensor_sigma: f32) -> f32 {
        let allowed = self.sigma_min * self.sigma_min - self.sigma_object * self.sigma_object;
        (sensor_sigma * sensor_sigma - 0.5 * allowed).max(0.0)
    }

    /// The per-point constants at match σ `sigma`, for readings of excess variance `excess2`
    /// ([`ModelConfig::excess2`], taken off a confirmed match's squared distance); nearest
    /// points are looked up at the voxel level `voxels` gives for that width.
    pub fn level<const V: usize>(&self, sigma: f32, excess2: f32, voxels: &VoxelMap<V>) -> Level {
        let free = sigma * self.free_per_match;
        let k_match = 0.5 / (sigma * sigma);
        Level {
            k_match,
            k_free: 0.5 / (free * free),
            credit: excess2 * k_match,
            cost_occluded: self.cost_occluded,
            cost_stray: self.cost_stray,
            self_radius2: (self.self_radius * sigma) * (self.self_radius * sigma),
            voxel_level: voxels.level_for(sigma),
            resting: self.resting,
        }
    }
}

/// Per-point constants of one resolution of the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    k_match: f32,
    k_free: f32,
    /// What a confirmed match's cost is lowered by: the readings' excess variance
    /// ([`ModelConfig::excess2`]) times `k_match`.
    credit: f32,
    cost_occluded: f32,
    cost_stray: f32,
    self_radius2: f32,
    /// The voxel level nearest points are looked up at (see [`VoxelMap::level_for`]).
    voxel_level: u8,
    /// [`ModelConfig::resting`]: the contact term applies.
    resting: bool,
}

impl Level {
    /// Whether `q`, the image of `p`, is too close to `p` to tell anything.
    #[inline]
    pub fn is_self_map(&self, p: Vec3, q: Vec3) -> bool {
        (q - p).length_squared() < self.self_radius2
    }

    /// The squared distance within which a match is the likelier cause of a transformed point
    /// than occlusion: `d² k_match <= cost_occluded`.
    pub fn match_gate2(&self) -> f32 {
        self.cost_occluded / self.k_match
    }

    /// Whether an image of cost `cost` is a stray: it contradicts its element.
    #[inline(always)]
    fn strays(&self, cost: f32) -> bool {
        cost >= self.cost_stray
    }

    /// Whether an image of cost `cost` confirms its element: a match explains it better than
    /// occlusion.
    #[inline(always)]
    fn confirms(&self, cost: f32) -> bool {
        cost < self.cost_occluded
    }

    /// The likeliest cause of an informative transformed point of cost `cost`, read off the
    /// cost as the scoring loop reads it ([`Level::confirms`], [`Level::strays`]).
    pub fn cause(&self, cost: f32) -> Cause {
        if self.strays(cost) {
            Cause::Stray
        } else if self.confirms(cost) {
            Cause::Confirmed
        } else if cost > self.cost_occluded {
            Cause::FreeSpace
        } else {
            Cause::Unseen
        }
    }
}

/// The likeliest cause of a transformed point under the measurement model (see the module
/// docs), as [`crate::Engine::explain`] reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cause {
    /// Within `ModelConfig::self_radius` σ of its source: it tells nothing and is left out of
    /// the score.
    SelfMap,
    /// Hidden behind a reading nearer than any point of the object (another object in front
    /// of where it would be seen): the camera could not look there whatever the symmetry, so it
    /// tells nothing and is left out of the score.
    Obstructed,
    /// Its source is a mixed ("flying") reading: a depth between a nearer and a farther
    /// neighbour's, each farther off than one surface steps between pixels, a sample of
    /// neither surface. Its images tell nothing and are left out of the score.
    Mixed,
    /// A visible point explains it better than occlusion does (or, under a map that turns a
    /// resting object over, its contact with the support): it confirms its element.
    Confirmed,
    /// It lies where the camera could not see (hidden, no reading, outside the image): it
    /// neither confirms nor contradicts, at `ModelConfig::cost_occluded`.
    Unseen,
    /// It lies a little way into space the camera saw empty (or below the support), within
    /// the free-space term's reach: dearer than unseen, cheaper than a stray.
    FreeSpace,
    /// It lies in space the camera saw empty, matching nothing: it contradicts its element, at
    /// `ModelConfig::cost_stray`.
    Stray,
}

/// One transformed point of an explained score ([`crate::Engine::explain`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImageCost {
    /// The element of the symmetry whose map made it: its plane's index for mirror planes, `0`
    /// for an axis' rotations and a single map's symmetry, `1` for an axial + plane's plane.
    pub element: u8,
    /// The seen point, camera frame, metres.
    pub source: [f32; 3],
    /// Its image under the map.
    pub image: [f32; 3],
    /// Its cost, a negative log-likelihood (0 for a self-map or an obstructed image, which are
    /// not scored).
    pub cost: f32,
    /// Its likeliest cause.
    pub cause: Cause,
    /// What the camera saw along its ray, as the free-space test reads it: the nearest depth
    /// of its pixel's block of the observed crop, metres along the optical axis; infinite
    /// outside the crop (the box of the object's points and a margin), where the model takes
    /// the camera to have seen no object; `None` where it saw nothing (no reading in the
    /// block, outside the image, behind the camera). An image is in free space by how far it
    /// lies in front of this.
    pub reading: Option<f32>,
}

impl ImageCost {
    /// Whether it is a stray beyond the observed crop (its `reading` infinite): counted as seen
    /// in free space whatever the camera read there.
    pub fn stray_beyond_crop(&self) -> bool {
        self.cause == Cause::Stray && self.reading == Some(f32::INFINITY)
    }
}

/// How one element of a symmetry fared in the acceptance test (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElementEvidence {
    /// Its informative images.
    pub images: u32,
    /// Their mean cost: the element passes when it is below `ModelConfig::accept` and it is
    /// not `contradicted` (infinite without informative images).
    pub mean: f32,
    /// The images that confirm or contradict it...
    pub decided: u32,
    /// ... and of those, the strays.
    pub strays: u32,
    /// Its images stray more often than its least contradicted sibling's, at the object's foot
    /// than elsewhere, or from one half of the object than from the other (the two-proportion
    /// tests): it fails whatever its mean.
    pub contradicted: bool,
}

/// A symmetry's score and how each of its elements reached it ([`crate::Engine::explain`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Explanation {
    /// The score, as [`crate::Engine::score`] gives it (infinite: too few informative images).
    pub score: f32,
    /// The images left out of the score: self-maps, obstructed images and those of mixed
    /// readings.
    pub uninformative: u32,
    /// Each element's evidence, in element order ([`ImageCost::element`]).
    pub elements: heapless::Vec<ElementEvidence, MAX_GROUPS>,
}

/// What the scoring loop does with each transformed point besides scoring it.
pub(crate) trait Watch {
    /// `q`, the image of seen point `p` under a map of element `group`, costs `cost`
    /// (`Err(cause)`: left out of the score, a [`Cause::SelfMap`] or [`Cause::Obstructed`]).
    fn image(&mut self, p: Vec3, q: Vec3, group: u8, cost: Result<f32, Cause>);
}

/// The search's scoring: nothing more.
impl Watch for () {
    #[inline(always)]
    fn image(&mut self, _: Vec3, _: Vec3, _: u8, _: Result<f32, Cause>) {}
}

/// The appendage check's scoring: where the images stray ([`Evaluation::tally_strays`]).
struct StrayTally {
    strays: Strays,
    level: Level,
}

impl Watch for StrayTally {
    #[inline(always)]
    fn image(&mut self, p: Vec3, _: Vec3, _: u8, cost: Result<f32, Cause>) {
        if cost.is_ok_and(|c| self.level.strays(c)) {
            self.strays.add_source(p);
        }
    }
}

/// An explained scoring: each transformed point handed to `visit` with its cause and the
/// reading it was judged against.
pub(crate) struct Visit<'s, F, const C: usize> {
    pub level: Level,
    pub view: View<'s, C>,
    pub visit: F,
}

impl<F: FnMut(&ImageCost), const C: usize> Watch for Visit<'_, F, C> {
    fn image(&mut self, p: Vec3, q: Vec3, group: u8, cost: Result<f32, Cause>) {
        let observed = self
            .view
            .pixel(q)
            .map(|(u, v)| self.view.observed.lookup(u, v));
        (self.visit)(&ImageCost {
            element: group,
            source: p.to_array(),
            image: q.to_array(),
            cost: cost.unwrap_or(0.0),
            cause: cost.map_or_else(|cause| cause, |c| self.level.cause(c)),
            reading: self.view.depth_seen(observed),
        });
    }
}

/// What the camera saw: the free-space test of the measurement model.
#[derive(Clone, Copy, Debug)]
pub struct View<'s, const C: usize> {
    pub intrinsics: &'s Intrinsics,
    pub depth_scale: f32,
    pub observed: &'s DepthGrid<C>,
    /// `observed`'s neighbourhood minima by cell index, read when it holds every cell
    /// ([`DepthGrid::spread_into`]); shorter (e.g. empty), they are computed where needed.
    pub around: &'s [u16],
    pub table: Option<Plane>,
    /// The least height above `table` of an object point ([`crate::PrepareConfig::min_height`]:
    /// preparation leaves lower readings out, the support's own among them, but for those a
    /// mask encloses): where the seen foot of a resting object begins (the foot test, see the
    /// module docs).
    pub lowest: f32,
    /// The cost of taking a neighbouring cell's reading for the one at a transformed point
    /// (lateral sensor noise, see [`View::new`]); infinite: never.
    pub lateral_cost: f32,
    /// Depth (metres, along the camera's `z`) in front of which a reading is not the object's:
    /// the object's points lie within its radius of their centroid
    /// ([`crate::prepare::ObjectStats`]), none nearer than the centroid's depth less the
    /// radius. What such a reading hides is obstructed (see the module docs); 0: nothing is.
    pub front: f32,
    /// The greatest height of an object point above `table` ([`crate::prepare::ObjectStats`]):
    /// which mirrors tilted beyond 5° of level turn a resting object over ([`contact_maps`]);
    /// infinite (none do) unless [`crate::ModelConfig::tilted_contact`].
    pub top: f32,
}

impl<'s, const C: usize> View<'s, C> {
    /// The view of `scene` through `observed` (and its neighbourhood minima `around`, see
    /// [`View::around`]), resting on `table` if given, the object's points kept from
    /// `config.prepare.min_height` up. With `config.sensor.lateral_noise`, a transformed point may
    /// lie behind the nearest reading of its cell's 3 x 3 neighbourhood instead of its own
    /// cell's, at [`LATERAL_COST`].
    pub fn new(
        scene: &'s crate::Scene<'_>,
        observed: &'s DepthGrid<C>,
        around: &'s [u16],
        table: Option<Plane>,
        stats: &crate::prepare::ObjectStats,
        config: &crate::Config,
    ) -> Self {
        Self {
            front: stats.centroid[2] - stats.radius,
            top: if config.model.tilted_contact {
                stats.top
            } else {
                f32::INFINITY
            },
            intrinsics: &scene.intrinsics,
            depth_scale: scene.depth_scale,
            observed,
            around,
            table,
            lowest: config.prepare.min_height,
            lateral_cost: if config.sensor.lateral_noise {
                LATERAL_COST
            } else {
                f32::INFINITY
            },
        }
    }

    /// The support and the object's top, when the object rests on a support plane.
    pub fn rest(&self) -> Option<Rest> {
        (self.table).map(|support| Rest {
            support,
            top: self.top,
        })
    }

    /// The support raised to [`View::lowest`]: a seen point of a resting object is of its foot
    /// (the foot test) when it lies at most a match's reach above this plane, or below it
    /// ([`at_foot`]).
    pub fn foot(&self) -> Option<Plane> {
        (self.table).map(|t| Plane {
            offset: t.offset + self.lowest,
            ..t
        })
    }

    /// How far `q` lies in space the camera saw to be empty: in front of the observed depth along
    /// its ray, or below the support plane. 0 in occluded space; infinite in the image outside the
    /// observed crop (where nothing of the object was seen).
    #[inline]
    pub fn free_space_violation(&self, q: Vec3) -> f32 {
        let observed = self.pixel(q).map(|(u, v)| self.observed.lookup(u, v));
        let clearance = self.clearance(q, observed);
        clearance.max(self.below_table(q)).max(0.0)
    }

    /// How far `q` lies below the support plane (negative above it; 0 without one).
    #[inline]
    fn below_table(&self, q: Vec3) -> f32 {
        self.table.map_or(0.0, |t| -t.signed_distance(q))
    }

    /// The continuous pixel coordinates of `q`, if it projects into the image.
    #[inline]
    fn pixel(&self, q: Vec3) -> Option<(f32, f32)> {
        let (u, v) = self.intrinsics.project(q)?;
        let k = self.intrinsics;
        let in_image =
            u >= -0.5 && v >= -0.5 && u < k.width as f32 - 0.5 && v < k.height as f32 - 0.5;
        in_image.then_some((u, v))
    }

    /// How far in front of `q` the camera saw a surface along `q`'s ray, given what it
    /// observed at `q`'s pixel (`None`: outside the image or behind the camera): positive when
    /// `q` lies in front of it (in free space), negative when hidden behind it; `-∞` where the
    /// camera saw nothing (no reading, outside the image, behind the camera), `+∞` in the image
    /// outside the observed crop.
    #[inline]
    fn clearance(&self, q: Vec3, observed: Option<Observed>) -> f32 {
        self.depth_seen(observed)
            .map_or(f32::NEG_INFINITY, |depth| depth - q.z)
    }

    /// The depth the camera saw, metres, given what it observed at a pixel (`None`: outside
    /// the image or behind the camera): infinite in the image outside the observed crop,
    /// `None` where it saw nothing ([`ImageCost::reading`]).
    #[inline]
    fn depth_seen(&self, observed: Option<Observed>) -> Option<f32> {
        match observed {
            None | Some(Observed::Unknown) => None,
            Some(Observed::Outside) => Some(f32::INFINITY),
            Some(Observed::Depth(raw)) => Some(raw as f32 * self.depth_scale),
        }
    }
}

/// The cost of taking a neighbouring cell's reading for a transformed point's own: the mean
/// negative log-likelihood of a displacement drawn from the sensor's lateral noise, an
/// isotropic 2-D Gaussian of any σ: `E|ε|² / 2σ² = 2σ² / 2σ² = 1`. (Reaching a neighbouring
/// cell takes a displacement of up to a cell's width; the sensor's σ, about a pixel, is of that
/// order for the one- and two-pixel cells of an object's crop at the default capacity.)
pub const LATERAL_COST: f32 = 1.0;

/// Everything the cost of a transformed point needs: the view and the visible points.
#[derive(Clone, Copy, Debug)]
pub struct Evidence<'s, const V: usize, const C: usize> {
    pub view: View<'s, C>,
    pub voxels: &'s VoxelMap<V>,
    pub points: &'s [Vec3],
}

impl<'s, const V: usize, const C: usize> Evidence<'s, V, C> {
    /// The evidence of `view` and the visible `points`, filed in `voxels`.
    pub fn new(view: View<'s, C>, voxels: &'s VoxelMap<V>, points: &'s [Vec3]) -> Self {
        Self {
            view,
            voxels,
            points,
        }
    }

    /// Squared distance from `q` to the nearest visible point (within the voxel block), and the
    /// hash slots the lookup read.
    #[inline]
    pub fn nearest_visible2(&self, q: Vec3) -> (f32, u32) {
        self.voxels.nearest_probed(q, self.points, 0)
    }

    /// The index of the visible point nearest `q` (within the voxel block of the finest level)
    /// and its squared distance.
    pub fn nearest_visible(&self, q: Vec3) -> Option<(f32, usize)> {
        self.voxels.nearest_point(q, self.points, 0)
    }

    /// The cost of transformed point `q` (see the module docs), with the contact term when
    /// `upside_down` (`q` is the image under a map that turns the object upside down,
    /// [`contact_maps`]); `None` when `q` is obstructed (it tells nothing). Always inlined,
    /// like the voxel lookup it makes: the scoring loop runs it once per work unit, and called
    /// out of line (as the compiler may choose once it has several callers) it costs 15 % more
    /// instructions. Its callers leave out self-maps first, and both kinds of image that tell
    /// nothing alike (the score, the domain growth): written out at each, as one shared helper
    /// costs the scoring loop 4 more instructions a unit on the Cortex-M4F (`ci/firmware.sh`).
    #[inline(always)]
    pub fn image_cost(&self, q: Vec3, level: &Level, upside_down: bool) -> Option<f32> {
        let matched = self.voxels.nearest(q, self.points, level.voxel_level) * level.k_match;
        // An unseen point costs at least `cost_occluded`: a closer match needs no free-space test.
        // A confirmed match, its reading's expected excess noise credited (see `Level`).
        if matched <= level.cost_occluded {
            return Some(matched - level.credit);
        }
        let view = &self.view;
        // `None`: outside the image; `Some(None)`: in it, outside the observed crop.
        let cell = view.pixel(q).map(|(u, v)| view.observed.locate(u, v));
        let own = cell.map(|c| c.map_or(Observed::Outside, |c| view.observed.at(c)));
        let clearance = view.clearance(q, own);
        let below_table = view.below_table(q);
        // Hidden by a reading nearer than any point of the object: another object's.
        let reading = clearance + q.z;
        if clearance < 0.0 && reading > 0.0 && reading < view.front && below_table <= 0.0 {
            return None;
        }
        let v = clearance.max(below_table).max(0.0);
        let mut unseen = level.cost_occluded + v * v * level.k_free;
        // Lateral noise: the surface seen at a neighbouring cell may be the one at `q`'s pixel.
        // That alternative costs at least `cost_occluded + lateral_cost`: looked up only when
        // `q` is in front of its own cell's reading and both the match and the free-space term
        // cost more.
        let floor = level.cost_occluded + view.lateral_cost;
        let dearer = v * v * level.k_free > view.lateral_cost && matched > floor;
        if let Some(Some(c)) =
            cell.filter(|_| clearance > 0.0 && dearer && floor < level.cost_stray)
        {
            let nearest = view.observed.nearest_around_in(view.around, c);
            let around = view.clearance(q, Some(nearest));
            let v = around.max(below_table).max(0.0);
            unseen = unseen.min(floor + v * v * level.k_free);
        }
        let unseen = unseen.min(level.cost_stray);
        // The contact term (see the module docs): under a map that turns the object over, an
        // image hidden behind what the camera saw by more than a match's reach, near the support
        // (either side of it: below, it costs the cheaper of contact and free space).
        let hidden = || clearance < 0.0 && clearance * clearance > level.match_gate2();
        Some(match self.view.table {
            Some(support) if upside_down && hidden() => {
                let h = support.signed_distance(q);
                matched.min(unseen).min(h * h * level.k_match)
            }
            _ => matched.min(unseen),
        })
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
    /// Per element: images a match explains better than occlusion, or nothing but a stray
    /// (the images that confirm or contradict it; occluded ones do neither)...
    decided: [u32; MAX_GROUPS],
    /// ... and of those, the strays.
    strays: [u32; MAX_GROUPS],
    /// Per element, of `decided` and `strays`: the images of the foot (seen points within a
    /// match's reach of [`View::lowest`]) under maps that turn the object over (the foot test).
    foot_decided: [u32; MAX_GROUPS],
    foot_strays: [u32; MAX_GROUPS],
    /// Per element, of `decided` and `strays`: the images of the seen points below the mirror
    /// (their images lie higher up) under maps that turn the object over (the halves test).
    lower_decided: [u32; MAX_GROUPS],
    lower_strays: [u32; MAX_GROUPS],
    /// Whether to tally where the images stray ([`Evaluation::tally_strays`])...
    tally: bool,
    /// Whether every mirror is held to the halves test about its own plane
    /// ([`Evaluation::halves_about_every_mirror`]).
    every_mirror: bool,
    /// ... and if so, the seen points whose images are strays, over every element (their sum
    /// and second moments; the counts are `strays` and `decided`).
    stray_tally: Strays,
    uninformative: u32,
    /// Bit `i` set: map `i` turns the object upside down, and its images may rest on the
    /// support (the contact term); found at the first `advance`, from the view's support plane.
    upside_down: Option<u16>,
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
            decided: [0; MAX_GROUPS],
            strays: [0; MAX_GROUPS],
            foot_decided: [0; MAX_GROUPS],
            foot_strays: [0; MAX_GROUPS],
            lower_decided: [0; MAX_GROUPS],
            lower_strays: [0; MAX_GROUPS],
            tally: false,
            every_mirror: false,
            stray_tally: Strays::NONE,
            uninformative: 0,
            upside_down: None,
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

    /// Also tally where the images stray (the seen points whose images do, in
    /// [`Evaluation::scored`]'s [`Strays`]), from the next point scored on; call after
    /// [`Evaluation::begin`]. Nine more additions per stray image.
    pub(crate) fn tally_strays(&mut self) {
        self.tally = true;
    }

    /// The halves test's tally of a decided image of element `g` under a map of linear part
    /// `linear`, `moved` from its seen point, when every mirror is held to it: the side of its
    /// mirror the seen point lies on (rotations left out). Out of line and cold: only a retry's
    /// check asks for it, and inlined it costs the scoring loop every other evaluation's
    /// instructions on the M4F.
    #[cold]
    #[inline(never)]
    fn tally_side(&mut self, g: usize, linear: &Mat3, moved: Vec3, stray: bool) {
        if linear.determinant() >= 0.0 {
            return;
        }
        // `I - L` is `2 n nᵀ` for a mirror of normal `n`: its column of largest diagonal entry
        // is along `n`, one orientation for every image.
        let m = Mat3::IDENTITY - *linear;
        let (x, y, z) = (m.x_axis.x, m.y_axis.y, m.z_axis.z);
        let n = if x >= y && x >= z {
            m.x_axis
        } else if y >= z {
            m.y_axis
        } else {
            m.z_axis
        };
        let lower = (n.dot(moved) > 0.0) as u32;
        self.lower_decided[g] += lower;
        self.lower_strays[g] += lower & stray as u32;
    }

    /// Also hold every mirror (a map of determinant -1 whose linear part is a reflection) to
    /// the halves test about its own plane, not only those that turn a resting object over
    /// (see the module docs); call after [`Evaluation::begin`]. Per decided image of a mirror:
    /// its plane's normal from the map's linear part (three comparisons) and a dot product.
    pub(crate) fn halves_about_every_mirror(&mut self) {
        self.every_mirror = true;
    }

    /// Score transformed points, one unit each, spending what is left on `meter`; once every
    /// point is scored, the score (see the module docs; again at every later call, at no cost).
    /// `point(j)` is the index of the `j`-th active point (`j` below the count given to
    /// [`Evaluation::begin`]) and whether its reading is mixed ([`Cause::Mixed`]: its images
    /// are left out).
    pub(crate) fn advance<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        point: impl Fn(usize) -> (usize, bool),
        meter: &mut Meter,
    ) -> Poll<()> {
        // Two loops from one source: the stray tally's branch and call, even never taken, cost
        // the scoring loop of every other evaluation registers (more instructions a unit on the
        // Cortex-M4F, `ci/firmware.sh`).
        match self.level.filter(|_| self.tally) {
            Some(level) => {
                let mut tally = StrayTally {
                    strays: self.stray_tally,
                    level,
                };
                let poll = self.advance_watched(evidence, point, meter, &mut tally);
                self.stray_tally = tally.strays;
                poll
            }
            None => self.advance_watched(evidence, point, meter, &mut ()),
        }
    }

    /// [`Evaluation::advance`], handing each transformed point to `watch` (and without the
    /// stray tally).
    pub(crate) fn advance_watched<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        point: impl Fn(usize) -> (usize, bool),
        meter: &mut Meter,
        watch: &mut impl Watch,
    ) -> Poll<()> {
        let Some(level) = self.level else {
            return Poll::Ready(());
        };
        let (maps, foot) = (&self.maps, evidence.view.foot());
        let upside_down = *self
            .upside_down
            .get_or_insert_with(|| contact_maps(maps, evidence.view.rest(), &level));
        let (budget, mut used) = (meter.left(), 0);
        // The source at hand, looked up once for all its maps.
        let mut source = (self.next < self.end).then(|| point(self.next as usize));
        while let Some((i, mixed)) = source.filter(|_| used < budget) {
            let p = evidence.points[i];
            let (map, group) = self.maps.maps[self.map as usize];
            if let Some(sum) = self.sums.get_mut(group as usize) {
                let q = map.apply(p);
                let over = upside_down & (1 << self.map) != 0;
                let cost = if mixed {
                    Err(Cause::Mixed)
                } else if level.is_self_map(p, q) {
                    Err(Cause::SelfMap)
                } else {
                    evidence
                        .image_cost(q, &level, over)
                        .ok_or(Cause::Obstructed)
                };
                watch.image(p, q, group, cost);
                self.uninformative += cost.is_err() as u32;
                if let Ok(cost) = cost {
                    *sum += cost;
                    let g = group as usize;
                    self.counts[g] += 1;
                    let stray = level.strays(cost);
                    let decided = stray || level.confirms(cost);
                    self.decided[g] += decided as u32;
                    self.strays[g] += stray as u32;
                    // The foot and halves tests' tallies (see the module docs): `over` implies a
                    // support.
                    if let Some(raised) = foot.filter(|_| over && decided) {
                        let at_foot = at_foot(raised, p, &level) as u32;
                        self.foot_decided[g] += at_foot;
                        self.foot_strays[g] += at_foot & stray as u32;
                        let lower = (raised.n().dot(q - p) > 0.0) as u32;
                        self.lower_decided[g] += lower;
                        self.lower_strays[g] += lower & stray as u32;
                    } else if self.every_mirror && decided {
                        self.tally_side(g, &map.linear, q - p, stray);
                    }
                }
                used += 1;
            }
            self.map += 1;
            if self.map as usize == self.maps.maps.len() {
                self.map = 0;
                self.next = self.next.saturating_add(self.stride);
                source = (self.next < self.end).then(|| point(self.next as usize));
            }
        }
        meter.spend(used);
        if self.next < self.end {
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }

    /// The score once finished (see the module docs), or infinity when no transformed point, or
    /// fewer than `min_informative` of them, were informative.
    pub(crate) fn score(&self, model: &ModelConfig) -> f32 {
        let informative: u32 = self.counts.iter().sum();
        let total = informative + self.uninformative;
        if informative == 0 || (informative as f32) < model.min_informative * total as f32 {
            return f32::INFINITY;
        }
        let (groups, least) = (self.groups(), self.least());
        let (mut sum, mut worst, mut elements) = (0.0f32, 0.0f32, 0);
        for g in groups {
            let element = self.element(g, least);
            let mut mean = element.mean;
            if element.contradicted {
                mean = mean.max(model.accept);
            }
            (sum, worst, elements) = (sum + mean, worst.max(mean), elements + 1);
        }
        // Accepted: the likelihood of all elements (their mean, at most the worst); rejected:
        // the least confirmed element's.
        if worst < model.accept {
            sum / elements as f32
        } else {
            worst
        }
    }
}

impl Evaluation {
    /// The score once finished ([`Evaluation::score`]), with where its images met free space.
    pub(crate) fn scored(&self, model: &ModelConfig) -> Scored {
        let n = self.maps.groups as usize;
        Scored {
            score: self.score(model),
            strays: Strays {
                strays: self.strays[..n].iter().sum(),
                decided: self.decided[..n].iter().sum(),
                ..self.stray_tally
            },
            every_point: self.stride == 1,
        }
    }

    /// The elements with informative images.
    fn groups(&self) -> impl Iterator<Item = usize> + Clone + '_ {
        (0..self.maps.groups as usize).filter(|&g| self.counts[g] > 0)
    }

    /// The least contradicted element that any image confirms or contradicts: what its
    /// siblings' stray shares are held to.
    fn least(&self) -> Option<usize> {
        (self.groups())
            .filter(|&g| self.decided[g] > 0)
            .min_by(|&a, &b| self.share(a).total_cmp(&self.share(b)))
    }

    /// Element `g`'s evidence, held to its least contradicted sibling `least`.
    fn element(&self, g: usize, least: Option<usize>) -> ElementEvidence {
        ElementEvidence {
            images: self.counts[g],
            mean: match self.counts[g] {
                0 => f32::INFINITY,
                n => self.sums[g] / n as f32,
            },
            decided: self.decided[g],
            strays: self.strays[g],
            contradicted: self.contradicted(g, least)
                || self.foot_contradicts(g)
                || self.halves_contradict(g),
        }
    }

    /// The score once finished and each element's evidence (see [`Evaluation::score`]).
    pub(crate) fn explain(&self, model: &ModelConfig) -> Explanation {
        let least = self.least();
        Explanation {
            score: self.score(model),
            uninformative: self.uninformative,
            elements: (0..self.maps.groups as usize)
                .map(|g| self.element(g, least))
                .collect(),
        }
    }

    /// Element `g`'s stray share: strays per image that confirms or contradicts it.
    fn share(&self, g: usize) -> f32 {
        self.strays[g] as f32 / self.decided[g].max(1) as f32
    }

    /// Whether element `g` of a composite meets free space more often than its least
    /// contradicted sibling `least`, by more than [`STRAY_SIGMAS`] standard deviations of the
    /// difference (a two-proportion test). The elements see one object with one sensor's
    /// noise, so a true element's images stray no more often than its sibling's; one that
    /// strays more holds on a part of the object, not on all of it (a plane across a mug's
    /// body sends the handle into the free space beside it), and fails its test whatever its
    /// mean.
    fn contradicted(&self, g: usize, least: Option<usize>) -> bool {
        least.filter(|&l| l != g).is_some_and(|l| {
            let (own, other) = (
                (self.strays[g], self.decided[g]),
                (self.strays[l], self.decided[l]),
            );
            stray_excess(own, other) > 0.0
        })
    }

    /// Whether element `g`'s foot images stray more often than its other decided images, by the
    /// same two-proportion test (the foot test, see the module docs).
    fn foot_contradicts(&self, g: usize) -> bool {
        let (foot, rest) = self.split(g, (self.foot_strays[g], self.foot_decided[g]));
        stray_excess(foot, rest) > 0.0
    }

    /// Whether element `g`'s images stray more often from the seen points on one side of its
    /// mirror than from those on the other, by the same two-proportion test either way round
    /// (the halves test, see the module docs).
    fn halves_contradict(&self, g: usize) -> bool {
        let (lower, upper) = self.split(g, (self.lower_strays[g], self.lower_decided[g]));
        stray_excess(lower, upper) > 0.0 || stray_excess(upper, lower) > 0.0
    }

    /// Element `g`'s decided images as (strays, decided) of `part` of them and of the rest.
    fn split(&self, g: usize, part: (u32, u32)) -> ((u32, u32), (u32, u32)) {
        (part, (self.strays[g] - part.0, self.decided[g] - part.1))
    }
}

/// Whether the seen point `p` is of a resting object's foot: at most a match's reach above
/// `raised`, the support raised to the least height kept ([`View::foot`]), or below it.
#[inline]
fn at_foot(raised: Plane, p: Vec3, level: &Level) -> bool {
    let above = raised.signed_distance(p).max(0.0);
    above * above <= level.match_gate2()
}

/// A finished evaluation: its score, its strays, and whether it scored every point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scored {
    pub score: f32,
    pub strays: Strays,
    /// Every active point was a source (stride 1): no image was left out of the score.
    pub every_point: bool,
}

/// Where a hypothesis' images met free space, over all its elements: of the images that
/// confirm or contradict it (`decided`), the strays, the sum of the seen points they are images
/// of (their centroid, times `strays`: the part of the object the hypothesis does not hold on)
/// and their second moments (these two zero unless asked for, [`Evaluation::tally_strays`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strays {
    pub strays: u32,
    pub decided: u32,
    pub sources: Vec3,
    /// The sum of the outer products of those points.
    pub moments: OuterSum,
}

impl Strays {
    /// No images.
    pub const NONE: Self = Self {
        strays: 0,
        decided: 0,
        sources: Vec3::ZERO,
        moments: OuterSum::ZERO,
    };

    /// Add seen point `p`, one whose image strayed, to `sources` and `moments`. Out of line
    /// and cold: only the two evaluations of the appendage check ask for it.
    #[cold]
    #[inline(never)]
    pub(crate) fn add_source(&mut self, p: Vec3) {
        self.sources += p;
        self.moments.add(p);
    }

    /// `(strays, decided)`.
    pub fn counts(&self) -> (u32, u32) {
        (self.strays, self.decided)
    }

    /// The centroid of the seen points whose images strayed, if any did.
    pub fn centroid(&self) -> Option<Vec3> {
        (self.strays > 0).then(|| self.sources / self.strays as f32)
    }

    /// How far to one side of `axis` the points whose images strayed lie: the squared
    /// distance of their centroid from the axis over their mean squared distance from it, in
    /// `[0, 1]` (1: all at one point; 0: spread evenly around it); `None` without strays. The
    /// mean squared distance is the centroid's plus the points' spread about the centroid (both
    /// across the axis), so over 1/2 the centroid lies farther from the axis than the points'
    /// root-mean-square spread about it: they lie to one side. Three dot products and no root.
    pub fn sidedness(&self, axis: &crate::Axis) -> Option<f32> {
        let m = self.centroid()?;
        let (a, d) = (axis.p(), axis.d());
        let second = self.moments.over(self.strays as f32).matrix();
        // The second moments about `a`: E[(p - a)(p - a)ᵀ] = E[p pᵀ] - m aᵀ - a mᵀ + a aᵀ.
        let c = second - outer(m, a) - outer(a, m) + outer(a, a);
        let spread = c.x_axis.x + c.y_axis.y + c.z_axis.z - d.dot(c * d);
        let off = m - a;
        let radial = off - d * off.dot(d);
        (spread > 0.0).then(|| (radial.length_squared() / spread).min(1.0))
    }
}

/// Standard deviations beyond which an element's strays contradict it: at 3, a true element is
/// rejected by chance about once in 740 tests (the normal distribution's one-sided tail).
const STRAY_SIGMAS: f32 = 3.0;
/// That chance, the one-sided normal tail beyond [`STRAY_SIGMAS`]: what the exact tail of a
/// few strays is held to ([`stray_excess`]).
const STRAY_CHANCE: f32 = 0.00135;

/// By how much the stray share of `own` = (strays, images) exceeds that of `other`, beyond
/// [`STRAY_SIGMAS`] standard deviations of the difference of two shares drawn from their
/// pooled share (positive: `own` is contradicted). The deviation is at least half an image of
/// `own` (the binomial's continuity correction), so that no stray at all on either side decides
/// nothing. No images of its own: never contradicted.
///
/// The normal approximation holds for many strays, not for the few a true element's images
/// meet at a small part of the object (a box's foot, where the sensor's mixed and displaced
/// readings lie): there, two strays among 31 foot images against 2 among 661 others lie 3.8
/// deviations out, yet a 1.1 % chance. So an excess is kept only when it is also that unlikely
/// by the exact test (Fisher's): with every stray of the two equally likely to be any of their
/// images, the chance that at least `own`'s strays fall among `own`'s images (its binomial
/// form, the strays being few against the images) must be at most [`STRAY_CHANCE`];
/// otherwise the excess is 0. Per test, not per image: two `ln`, three `ln_gamma`, one `exp`.
pub(crate) fn stray_excess(own: (u32, u32), other: (u32, u32)) -> f32 {
    if own.1 == 0 || other.1 == 0 {
        return -1.0;
    }
    let (s, n) = (own.0 as f32, own.1 as f32);
    let (t, m) = (other.0 as f32, other.1 as f32);
    let pooled = (s + t) / (n + m);
    let deviation = crate::math::sqrt(pooled * (1.0 - pooled) * (1.0 / n + 1.0 / m));
    let excess = s / n - t / m - STRAY_SIGMAS * deviation.max(0.5 / n);
    if excess <= 0.0 || binomial_tail(own.0, own.0 + other.0, n / (n + m)) <= STRAY_CHANCE {
        excess
    } else {
        0.0
    }
}

/// An upper bound on the chance of at least `k` successes in `trials` draws of chance `f` in
/// `(0, 1)` (1 when `k` is not beyond the mode): the first term,
/// `C(trials, k) f^k (1 - f)^(trials - k)`, over one less the ratio of the next term to it, the
/// ratios falling from there on.
fn binomial_tail(k: u32, trials: u32, f: f32) -> f32 {
    let (kf, nf) = (k as f32, trials as f32);
    let ratio = (nf - kf) / (kf + 1.0) * f / (1.0 - f);
    if ratio >= 1.0 || !(0.0..1.0).contains(&f) {
        return 1.0;
    }
    use crate::math::{exp, ln, ln_gamma};
    let choose = ln_gamma(nf + 1.0) - ln_gamma(kf + 1.0) - ln_gamma(nf - kf + 1.0);
    let ln_first = choose + kf * ln(f) + (nf - kf) * ln(1.0 - f);
    (exp(ln_first) / (1.0 - ratio)).min(1.0)
}

/// Where a resting object rests: the support plane and the greatest height above it of the
/// object's seen points ([`View::rest`]), what tells which maps turn it over ([`contact_maps`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rest {
    /// The support plane, its normal toward the camera (up, on the object's side).
    pub support: Plane,
    /// The greatest height of a seen point above it, or infinite: only level mirrors turn the
    /// object over ([`View::top`]).
    pub top: f32,
}

/// The maps of `maps` whose images may earn the contact term (see the module docs): those that
/// turn the object resting as `rest` says over ([`turns_over`], a match's reach at `level`);
/// none without a support plane, or when `level`'s model does not take the object to rest on
/// it ([`ModelConfig::resting`]). Bit `i` for map `i` ([`crate::symmetry::MAX_MAPS`] is 16).
pub(crate) fn contact_maps(maps: &MapSet, rest: Option<Rest>, level: &Level) -> u16 {
    upside_down(maps, rest.filter(|_| level.resting), level.match_gate2())
}

/// [`contact_maps`] on `rest`, a match reaching `sqrt(reach2)`. Out of line and given the
/// reach alone: inlined into the scoring loop's function, or handed the loop's `Level` by
/// reference, it costs the loop 12 % more instructions on the M4F (535 against 476 a work
/// unit, `ci/firmware.sh`).
#[inline(never)]
fn upside_down(maps: &MapSet, rest: Option<Rest>, reach2: f32) -> u16 {
    const _: () = assert!(crate::symmetry::MAX_MAPS <= u16::BITS as usize);
    let Some(rest) = rest else {
        return 0;
    };
    let up = rest.support.n();
    maps.maps
        .iter()
        .enumerate()
        .filter(|(_, (map, _))| turns_over(&map.linear, up, rest.top, reach2))
        .fold(0, |bits, (i, _)| bits | 1 << i)
}

/// Whether the map of linear part `linear` turns over an object resting on a support of up
/// direction `up`, its seen points up to height `top`: a reflection (determinant -1) that
/// - sends `up` within 10° of down: a mirror within 5° of level (within which two elements are
///   one), or a point reflection; or
/// - is a mirror tilted θ further from level that sends the object's top within a match's reach
///   (`reach2`, squared) of the support; never for `top` infinite. A mirror halfway up an
///   object of height `H` (where a mirror that turns the object over lies) sends its top to
///   `H sin²θ` above the support, `H` at least `top`. Within the reach, a true mirror maps the
///   seen top onto the underside, whose lowest points lie on the support, as a level one does
///   (a curved object resting on its side, its mirror a few degrees off level); beyond it, it
///   sends the top sideways, not onto the underside, and what it puts near the support is no
///   contact.
///
/// Cost: a determinant, a matrix-vector product, two dot products; no root.
fn turns_over(linear: &Mat3, up: Vec3, top: f32, reach2: f32) -> bool {
    // A mirror within 5° of level sends `up` within 10° of `-up`: `1 - 2 cos² 5° = -cos 10°`.
    const LEVEL: f32 = 1.0 - 2.0 * COS_5_DEG * COS_5_DEG;
    if linear.determinant() >= 0.0 {
        return false;
    }
    // `(L up) · up = 1 - 2 cos²θ`: `sin²θ = (1 + down) / 2`.
    let down = (*linear * up).dot(up);
    let risen = top * (1.0 + down) * 0.5;
    down <= LEVEL || risen * risen <= reach2
}

/// A scene for the unit tests of the measurement model, the middle loop, the completion and the
/// engine: a flat plate facing the camera 0.5 m away, in front of a wall at 0.8 m, every plate
/// pixel a sampled point (stride 1), filed as preparation files them.
#[cfg(test)]
pub(crate) mod plate {
    use super::{Evidence, Level, View};
    use crate::config::ModelConfig;
    use crate::depth::{DepthGrid, Rect};
    use crate::math::Vec3;
    use crate::prepare::Points;
    use crate::voxel::VoxelMap;
    use crate::{Intrinsics, Plane, Scene};
    use core::ops::RangeInclusive;

    /// 64 x 48 pixels, focal length 60 px: neighbouring pixels 8.3 mm apart at 0.5 m.
    pub(crate) const K: Intrinsics = Intrinsics {
        width: 64,
        height: 48,
        fx: 60.0,
        fy: 60.0,
        cx: 31.5,
        cy: 23.5,
    };
    /// The image's pixels.
    pub(crate) const PIXELS: usize = 64 * 48;
    /// Depth in millimetres.
    pub(crate) const SCALE: f32 = 0.001;
    /// The plate's depth: points 8.3 mm apart, a finest match σ of 5 mm.
    pub(crate) const PLATE_MM: u16 = 500;
    /// The wall's depth, 0.3 m behind the plate: what lies between them was seen to be empty.
    pub(crate) const WALL_MM: u16 = 800;
    /// The wall as the support plane, its normal toward the camera (`z = 0.8`).
    pub(crate) const WALL: Plane = Plane {
        normal: [0.0, 0.0, -1.0],
        offset: -0.8,
    };
    /// 20 columns and rows centred on the principal point (31.5, 23.5): a square plate, mirror
    /// symmetric about the planes `x = 0` and `y = 0`.
    pub(crate) const COLUMNS: RangeInclusive<u16> = 22..=41;
    pub(crate) const ROWS: RangeInclusive<u16> = 14..=33;

    /// The plate's depth image and mask, its points (raster order), the observed depth of the
    /// whole image (one pixel a cell) and the points' voxels.
    pub(crate) struct Plate<const P: usize, const V: usize> {
        pub depth: [u16; PIXELS],
        pub mask: [u8; PIXELS],
        pub points: Points<P>,
        pub observed: DepthGrid<PIXELS>,
        pub voxels: VoxelMap<V>,
        /// Distance between neighbouring points (stride × mean depth / focal length), metres.
        pub spacing: f32,
    }

    impl<const P: usize, const V: usize> Plate<P, V> {
        /// The square plate (400 points).
        pub(crate) fn square() -> Self {
            Self::new(|u, v| (COLUMNS.contains(&u) && ROWS.contains(&v)).then_some(PLATE_MM))
        }

        /// A plate whose pixel `(u, v)` lies `depth_mm(u, v)` away (`None`: the wall's pixel).
        pub(crate) fn new(depth_mm: impl Fn(u16, u16) -> Option<u16>) -> Self {
            let (mut depth, mut mask) = ([WALL_MM; PIXELS], [0u8; PIXELS]);
            let mut points = Points::new();
            let mut observed = DepthGrid::new();
            let (w, h) = (K.width, K.height);
            observed.reset(Rect {
                u0: 0,
                v0: 0,
                width: w,
                height: h,
            });
            let mut depth_sum = 0.0;
            for v in 0..h {
                for u in 0..w {
                    let i = Self::pixel(u, v);
                    if let Some(mm) = depth_mm(u, v) {
                        (depth[i], mask[i]) = (mm, 1);
                        let z = mm as f32 * SCALE;
                        points.pos[points.len] = K.unproject(u as f32, v as f32, z);
                        points.pixel[points.len] = [u, v];
                        points.len += 1;
                        depth_sum += z;
                    }
                    observed.add(u, v, depth[i]);
                }
            }
            let spacing = depth_sum / points.len as f32 / K.fx;
            // As preparation files them: voxels a sample spacing wide around the centroid, each
            // point at every level.
            let sum = points.positions().iter().fold(Vec3::ZERO, |s, p| s + *p);
            let mut voxels = VoxelMap::new();
            voxels.reset(sum / points.len as f32, spacing);
            for i in 0..points.len {
                voxels.insert(points.pos[i], i as u16);
                voxels.insert_coarse(i as u16, points.positions());
            }
            assert!(!voxels.is_full(), "the visible points fit the voxel table");
            Self {
                depth,
                mask,
                points,
                observed,
                voxels,
                spacing,
            }
        }

        /// Pixel `(u, v)`'s index in the image.
        fn pixel(u: u16, v: u16) -> usize {
            v as usize * K.width as usize + u as usize
        }

        /// The finest match σ of the default model at this sampling (5 mm on the square).
        pub(crate) fn sigma(&self) -> f32 {
            ModelConfig::DEFAULT.sigma_fine(self.spacing)
        }

        /// The default model's constants at the finest σ.
        pub(crate) fn level(&self) -> Level {
            ModelConfig::DEFAULT.level(self.sigma(), 0.0, &self.voxels)
        }

        /// What the camera saw (no support plane: the wall is seen, not given).
        pub(crate) fn view(&self) -> View<'_, PIXELS> {
            View {
                intrinsics: &K,
                depth_scale: SCALE,
                observed: &self.observed,
                around: &[],
                table: None,
                lowest: 0.0,
                lateral_cost: f32::INFINITY,
                front: 0.0,
                top: f32::INFINITY,
            }
        }

        pub(crate) fn evidence(&self) -> Evidence<'_, V, PIXELS> {
            Evidence {
                view: self.view(),
                voxels: &self.voxels,
                points: self.points.positions(),
            }
        }

        /// The engine's input: the depth image, the plate's mask, the wall as support plane.
        pub(crate) fn scene(&self) -> Scene<'_> {
            Scene {
                depth: &self.depth,
                depth_scale: SCALE,
                intrinsics: K,
                table: Some(WALL),
                mask: Some(&self.mask),
                target: None,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::plate::{self, K};
    use super::*;
    use crate::math::rotation;
    use crate::work::Meter;

    type Plate = plate::Plate<1024, 2048>;
    const MODEL: ModelConfig = ModelConfig::DEFAULT;

    /// The strays of seen points `points`, as an evaluation tallies them.
    fn strays_of(points: &[Vec3]) -> Strays {
        let mut strays = Strays::NONE;
        for &p in points {
            strays.strays += 1;
            strays.add_source(p);
        }
        strays
    }

    #[test]
    fn strays_to_one_side_of_an_axis_are_told_from_strays_around_it() {
        // An axis along y, 0.6 m in front of the camera, as a mug's.
        let axis = crate::Axis::new(Vec3::Y, Vec3::new(0.0, 0.0, 0.6), Vec3::ZERO);
        let at = |angle: f32, radius: f32, height: f32| {
            let (s, c) = crate::math::sin_cos(angle);
            Vec3::new(radius * c, height, 0.6 + radius * s)
        };
        // A handle: 40 mm to 60 mm out, ±20° about one direction, at several heights.
        let handle: heapless::Vec<Vec3, 64> = (0..60)
            .map(|i| {
                at(
                    (i % 5) as f32 * 0.17 - 0.34,
                    0.04 + (i % 3) as f32 * 0.01,
                    i as f32 * 1e-3,
                )
            })
            .collect();
        let one_side = strays_of(&handle).sidedness(&axis).unwrap();
        assert!(one_side > 0.9, "{one_side}");
        // The same number at the silhouette's two rims, 40 mm out on either side.
        let rims: heapless::Vec<Vec3, 64> = (0..60)
            .map(|i| {
                at(
                    if i % 2 == 0 {
                        0.0
                    } else {
                        core::f32::consts::PI
                    },
                    0.04,
                    i as f32 * 1e-3,
                )
            })
            .collect();
        let around = strays_of(&rims).sidedness(&axis).unwrap();
        assert!(around < 0.05, "{around}");
        // No strays, no centroid; the handle's centroid lies among its points, 40-60 mm out.
        assert_eq!(Strays::NONE.sidedness(&axis), None);
        assert_eq!(Strays::NONE.centroid(), None);
        let m = strays_of(&handle).centroid().unwrap();
        assert!(
            (crate::math::sqrt(axis.distance_squared(m)) - 0.045).abs() < 0.005,
            "{m}"
        );
    }

    fn mirror(normal: Vec3, offset: f32) -> Symmetry {
        Symmetry::PlaneReflection(Plane::new(normal, offset).unwrap())
    }

    /// Score `symmetry` over every plate point at the finest σ, `slice` units a call: the score
    /// and the units spent.
    fn score(plate: &Plate, symmetry: &Symmetry, slice: u32) -> (f32, u32) {
        let mut evaluation = Evaluation::new();
        let n = plate.points.len;
        // No limit on the transformed points: every point is a source (stride 1).
        evaluation.begin(symmetry, Sampling::default(), plate.level(), n, u32::MAX);
        let mut units = 0;
        loop {
            let mut meter = Meter::new(slice);
            let poll = evaluation.advance(&plate.evidence(), |j| (j, false), &mut meter);
            let spent = slice - meter.left();
            units += spent;
            if poll.is_ready() {
                return (evaluation.score(&MODEL), units);
            }
            assert_eq!(spent, slice, "a pending evaluation spends what is left");
        }
    }

    #[test]
    fn the_images_of_mixed_readings_are_left_out() {
        let plate = Plate::square();
        let n = plate.points.len;
        let truth = mirror(Vec3::X, 0.0);
        let scored = |mixed: &dyn Fn(usize) -> bool| {
            let mut evaluation = Evaluation::new();
            evaluation.begin(&truth, Sampling::default(), plate.level(), n, u32::MAX);
            let mut meter = Meter::new(u32::MAX);
            let point = |j: usize| (j, mixed(j));
            assert!(
                evaluation
                    .advance(&plate.evidence(), point, &mut meter)
                    .is_ready()
            );
            (
                evaluation.score(&MODEL),
                evaluation.explain(&MODEL).uninformative,
            )
        };
        let (all, left_out) = scored(&|_| false);
        assert!(all < MODEL.accept, "{all}");
        // Half the points mixed: their images are left out (self-maps or not), the others
        // scored as before.
        let (half, half_left_out) = scored(&|j| j % 2 == 0);
        assert!(half_left_out as usize >= n.div_ceil(2) && half_left_out > left_out);
        assert!(half < MODEL.accept, "{half}");
        // Every point mixed: nothing is informative.
        assert_eq!(scored(&|_| true).0, f32::INFINITY);
    }

    #[test]
    fn a_true_mirror_scores_below_acceptance_and_wrong_ones_above() {
        let plate = Plate::square();
        let centre = Vec3::new(0.0, 0.0, 0.5);
        let (truth, _) = score(&plate, &mirror(Vec3::X, 0.0), u32::MAX);
        assert!(truth < MODEL.accept, "{truth}");
        // Every image is a plate point (the columns swap about the principal point).
        assert!(truth < 1e-3, "{truth}");
        // Five columns over (8σ): half the images land beyond the plate's edge, in front of the
        // wall, where the camera saw nothing.
        let beside = mirror(Vec3::X, 5.0 * plate.spacing);
        let (offset, _) = score(&plate, &beside, u32::MAX);
        assert!(offset > MODEL.accept, "{offset}");
        // Turned by 30° about the vertical through the centre: the images leave the plate's
        // surface, behind it (occluded) or in front of it (free).
        let normal = rotation(Vec3::Y, 0.52) * Vec3::X;
        let tilted = Symmetry::PlaneReflection(Plane::through(centre, normal));
        let (tilt, _) = score(&plate, &tilted, u32::MAX);
        assert!(tilt > MODEL.accept, "{tilt}");
    }

    #[test]
    fn a_point_beside_a_depth_edge_may_lie_behind_the_neighbouring_reading() {
        let plate = Plate::square();
        let cost = |lateral_cost, column: f32| {
            let evidence = Evidence {
                view: View {
                    lateral_cost,
                    ..plate.view()
                },
                ..plate.evidence()
            };
            // 0.6 m deep on the plate's middle row: behind the plate, in front of the wall.
            let q = K.unproject(column, 23.0, 0.6);
            // The plate's view has no front: nothing is obstructed.
            evidence
                .image_cost(q, &plate.level(), false)
                .unwrap_or(f32::NAN)
        };
        let last = *plate::COLUMNS.end() as f32;
        // One column beside the plate: the wall's pixel says free space (a stray point), but the
        // plate's reading next to it may be the surface at that pixel.
        assert_eq!(cost(f32::INFINITY, last + 1.0), MODEL.cost_stray);
        let lateral = cost(LATERAL_COST, last + 1.0);
        assert_eq!(lateral, MODEL.cost_occluded + LATERAL_COST);
        // Two columns beside it no neighbour saw anything but the wall.
        assert_eq!(cost(LATERAL_COST, last + 2.0), MODEL.cost_stray);
        // On the plate the point is hidden behind the plate's own reading.
        assert_eq!(cost(LATERAL_COST, last), MODEL.cost_occluded);
    }

    /// Score `symmetry` over every plate point at the finest σ, the wall given as the support
    /// plane the plate rests on (`resting`) or not.
    fn score_on_wall(plate: &Plate, symmetry: &Symmetry, resting: bool) -> f32 {
        score_on_wall_up_to(plate, symmetry, resting, plate.view().top)
    }

    /// [`score_on_wall`], the plate's points taken to reach `top` above the wall ([`View::top`]).
    fn score_on_wall_up_to(plate: &Plate, symmetry: &Symmetry, resting: bool, top: f32) -> f32 {
        let model = ModelConfig { resting, ..MODEL };
        let evidence = Evidence {
            view: View {
                table: Some(plate::WALL),
                top,
                ..plate.view()
            },
            ..plate.evidence()
        };
        let mut evaluation = Evaluation::new();
        let level = model.level(plate.sigma(), 0.0, &plate.voxels);
        let n = plate.points.len;
        evaluation.begin(symmetry, Sampling::default(), level, n, u32::MAX);
        let mut meter = Meter::new(u32::MAX);
        while evaluation
            .advance(&evidence, |j| (j, false), &mut meter)
            .is_pending()
        {}
        evaluation.score(&model)
    }

    #[test]
    fn every_mirror_is_held_to_the_halves_test_when_asked() {
        // An upright mirror a column right of the plate's: the two columns at its left edge map
        // beside the plate, in front of the wall (40 strays of 400 images, all from the left
        // of the mirror); every other image lands on the plate. The mean passes; the halves
        // test, about the mirror's own plane, fails it.
        let plate = Plate::square();
        let off_centre = mirror(Vec3::X, 0.5 / plate::K.fx);
        let score = |every_mirror: bool| {
            let evidence = plate.evidence();
            let mut evaluation = Evaluation::new();
            let level = MODEL.level(plate.sigma(), 0.0, &plate.voxels);
            let n = plate.points.len;
            evaluation.begin(&off_centre, Sampling::default(), level, n, u32::MAX);
            if every_mirror {
                evaluation.halves_about_every_mirror();
            }
            let mut meter = Meter::new(u32::MAX);
            while evaluation
                .advance(&evidence, |j| (j, false), &mut meter)
                .is_pending()
            {}
            (evaluation.score(&MODEL), evaluation.strays[0])
        };
        let (mean, strays) = score(false);
        assert!(mean < MODEL.accept, "{mean}");
        assert_eq!(strays, 40);
        assert_eq!(score(true).0, MODEL.accept);
    }

    #[test]
    fn a_level_mirror_that_rests_the_top_on_the_support_earns_the_contact_term() {
        let plate = Plate::square();
        // Halfway between the plate (z = 0.5) and the wall (0.8): the plate's images lie on the
        // wall, hidden behind the plate. No pixel sees them: unconfirmed, unless the object rests
        // on the wall and the images are its underside touching it.
        let level = mirror(Vec3::Z, 0.65);
        let resting = score_on_wall(&plate, &level, true);
        assert!(resting < 0.01, "{resting}");
        let held = score_on_wall(&plate, &level, false);
        assert_eq!(held, MODEL.cost_occluded);
        // 2 cm nearer the camera: the images float 4 cm above the wall (8σ), no contact.
        let floating = score_on_wall(&plate, &mirror(Vec3::Z, 0.63), true);
        assert_eq!(floating, MODEL.cost_occluded);
        // 2 cm farther: the images sink 4 cm below the wall, where the camera saw nothing.
        let sinking = score_on_wall(&plate, &mirror(Vec3::Z, 0.67), true);
        assert!(sinking > MODEL.accept, "{sinking}");
    }

    #[test]
    fn an_image_hidden_by_another_objects_reading_tells_nothing() {
        let plate = Plate::square();
        let level = plate.level();
        // Behind the plate's centre, beyond a match's reach of it: hidden, `c_occluded`.
        let q = Vec3::new(0.0, 0.0, 0.6);
        let mut evidence = plate.evidence();
        assert_eq!(
            evidence.image_cost(q, &level, false),
            Some(MODEL.cost_occluded)
        );
        // The plate's reading nearer than any point of the object could be: another object's,
        // in front of where the image would be seen.
        evidence.view.front = 0.55;
        assert_eq!(evidence.image_cost(q, &level, false), None);
        // In front of that reading, the image is in free space whoever's it is.
        let free = evidence.image_cost(Vec3::new(0.0, 0.0, 0.45), &level, false);
        assert!(free.is_some_and(|c| c > MODEL.cost_occluded), "{free:?}");
    }

    #[test]
    fn contact_is_credited_as_much_just_below_the_support_as_just_above() {
        let plate = Plate::square();
        // Half a σ off the height that rests the images on the wall: they lie σ above or below
        // it, and cost what a match σ away costs (1/2) either way.
        let half = plate.sigma() * 0.5;
        let above = score_on_wall(&plate, &mirror(Vec3::Z, 0.65 - half), true);
        let below = score_on_wall(&plate, &mirror(Vec3::Z, 0.65 + half), true);
        assert!((above - 0.5).abs() < 0.01, "{above}");
        assert!((below - above).abs() < 0.01, "{below} against {above}");
    }

    #[test]
    fn a_mirror_a_few_degrees_off_level_earns_contact_when_it_sends_the_top_onto_the_support() {
        let plate = Plate::square();
        // Tilted 6° about the point halfway between the plate and the wall: it sends the
        // plate's points (0.17 m wide) onto a line across the wall, from 14 mm below it to
        // 20 mm above it, hidden behind the plate.
        let (sin, cos) = crate::math::sin_cos(6.0 * core::f32::consts::PI / 180.0);
        let tilted = mirror(Vec3::new(sin, 0.0, cos), 0.65 * cos);
        let level = score_on_wall(&plate, &mirror(Vec3::Z, 0.65), true);
        let credited = score_on_wall_up_to(&plate, &tilted, true, 0.3);
        let uncredited = score_on_wall_up_to(&plate, &tilted, true, f32::INFINITY);
        // Level, every image rests on the wall; tilted, those within a match's reach of it are
        // contact, the others occluded (or below the wall) ...
        assert!(
            level < credited && credited < uncredited,
            "{level} {credited} {uncredited}"
        );
        // ... and without the object's height (`tilted_contact` off) none are.
        assert!(uncredited >= MODEL.cost_occluded, "{uncredited}");
    }

    #[test]
    fn only_maps_that_turn_the_object_over_earn_contact() {
        let wall = Some(plate::WALL);
        let level = Symmetry::PlaneReflection(Plane::new(Vec3::Z, 0.65).unwrap());
        let upright = Symmetry::PlaneReflection(Plane::new(Vec3::X, 0.0).unwrap());
        let point = Symmetry::PointReflection([0.0, 0.0, 0.65]);
        let about_level_axis = Symmetry::Axial(crate::Axis::new(
            Vec3::X,
            Vec3::new(0.0, 0.0, 0.65),
            Vec3::new(0.0, 0.0, 0.65),
        ));
        let resting = Plate::square().level();
        let rest = wall.map(|support| Rest { support, top: 0.3 });
        let bits = |s: &Symmetry| contact_maps(&s.maps(Sampling::default()), rest, &resting);
        assert_eq!(bits(&level), 1);
        assert_eq!(bits(&upright), 0);
        // Level within 5°, it is the level mirror. Tilted further, halfway up the plate's 0.3 m
        // it would send the top to `0.3 sin²θ` above the support: 3.3 mm at 6°, within a
        // match's reach (between 3.3 and 13 mm at the plate's σ); 13 mm at 12° and 75 mm at
        // 30°, beyond it.
        let tilted = |deg: f32| {
            let (sin, cos) = crate::math::sin_cos(deg * core::f32::consts::PI / 180.0);
            Symmetry::PlaneReflection(Plane::new(Vec3::new(sin, 0.0, cos), 0.65).unwrap())
        };
        assert_eq!(bits(&tilted(4.0)), 1);
        assert_eq!(bits(&tilted(30.0)), 0);
        let reach = crate::math::sqrt(resting.match_gate2());
        assert!(reach > 0.0033 && reach < 0.013, "{reach}");
        assert_eq!(bits(&tilted(6.0)), 1);
        assert_eq!(bits(&tilted(12.0)), 0);
        // Without `ModelConfig::tilted_contact` the view's top is infinite: level mirrors only.
        let level_only = rest.map(|r| Rest {
            top: f32::INFINITY,
            ..r
        });
        let tilted_6 = tilted(6.0).maps(Sampling::default());
        assert_eq!(contact_maps(&tilted_6, level_only, &resting), 0);
        assert_eq!(bits(&point), 1);
        // The half-turn about a level axis turns the object over too, but is a rotation.
        assert_eq!(bits(&about_level_axis), 0);
        assert_eq!(
            contact_maps(&level.maps(Sampling::default()), None, &resting),
            0
        );
        // Nor when the object is not known to rest on the support.
        let held = Level {
            resting: false,
            ..resting
        };
        assert_eq!(
            contact_maps(&level.maps(Sampling::default()), rest, &held),
            0
        );
    }

    /// The score of a dual plane whose element `g` has 400 informative images of mean cost
    /// `means[g]`, none of them a stray.
    fn dual_scored(means: [f32; 2]) -> f32 {
        dual_with_strays(means, [(0, 0); 2])
    }

    #[test]
    fn no_informative_image_is_no_score_at_any_share() {
        let lenient = ModelConfig {
            min_informative: 0.0,
            ..MODEL
        };
        let x = Plane::new(Vec3::X, 0.0).unwrap();
        let mut evaluation = Evaluation {
            maps: Symmetry::PlaneReflection(x).maps(Sampling::default()),
            level: None,
            ..Evaluation::new()
        };
        evaluation.uninformative = 10;
        assert_eq!(evaluation.score(&lenient), f32::INFINITY);
    }

    #[test]
    fn a_composite_passes_only_when_each_element_is_confirmed() {
        // Both elements matched: the composite holds.
        assert!(dual_scored([0.2, 0.3]) < MODEL.accept);
        // The second plane's images almost all unseen (cost_occluded each, a few matches): on
        // average the two elements would pass, but the second is not confirmed on its own.
        let unconfirmed = [0.2, 0.95];
        assert!((unconfirmed[0] + unconfirmed[1]) / 2.0 < MODEL.accept);
        assert!(dual_scored(unconfirmed) >= MODEL.accept);
        assert_eq!(dual_scored(unconfirmed), 0.95);
    }

    /// [`dual_scored`] with element `g`'s images confirming or contradicting it
    /// `decided[g].1` times, `decided[g].0` of them strays.
    fn dual_with_strays(means: [f32; 2], decided: [(u32, u32); 2]) -> f32 {
        let x = Plane::new(Vec3::X, 0.0).unwrap();
        let y = Plane::new(Vec3::Y, 0.0).unwrap();
        let mut evaluation = Evaluation {
            maps: Symmetry::DualPlane([x, y]).maps(Sampling::default()),
            level: None,
            ..Evaluation::new()
        };
        for (g, (mean, (strays, images))) in means.into_iter().zip(decided).enumerate() {
            (evaluation.sums[g], evaluation.counts[g]) = (mean * 400.0, 400);
            (evaluation.strays[g], evaluation.decided[g]) = (strays, images);
        }
        evaluation.score(&MODEL)
    }

    #[test]
    fn an_element_that_strays_more_than_its_sibling_is_contradicted() {
        // Both planes pass on their means; the second sends 5 % of the images that test it into
        // free space, the first none: it holds on a part only, and the dual is rejected.
        let means = [0.5, 0.6];
        assert!((dual_with_strays(means, [(0, 300), (0, 300)]) - 0.55).abs() < 1e-6);
        assert_eq!(dual_with_strays(means, [(0, 300), (15, 300)]), MODEL.accept);
        // Either order: the least contradicted element is the reference.
        assert_eq!(dual_with_strays(means, [(15, 300), (0, 300)]), MODEL.accept);
        // Shares that differ within their sampling noise decide nothing.
        assert!(dual_with_strays(means, [(3, 300), (6, 300)]) < MODEL.accept);
        assert!(dual_with_strays(means, [(0, 300), (1, 300)]) < MODEL.accept);
        // A sibling that no image tests (all occluded) is no reference.
        assert!(dual_with_strays(means, [(0, 0), (15, 300)]) < MODEL.accept);
    }

    /// A level plane's evaluation whose 400 informative images (mean cost 0.5) are decided
    /// `decided.1` times, `decided.0` of them strays; its tests' tallies left to the caller.
    fn level_plane(decided: (u32, u32)) -> Evaluation {
        let level = Plane::new(Vec3::Y, 0.0).unwrap();
        let mut evaluation = Evaluation {
            maps: Symmetry::PlaneReflection(level).maps(Sampling::default()),
            level: None,
            ..Evaluation::new()
        };
        (evaluation.sums[0], evaluation.counts[0]) = (0.5 * 400.0, 400);
        (evaluation.strays[0], evaluation.decided[0]) = decided;
        evaluation
    }

    /// The score of [`level_plane`] whose decided images are `rest` = (strays, decided) beyond
    /// the foot and `foot` at it.
    fn plane_with_foot(rest: (u32, u32), foot: (u32, u32)) -> f32 {
        let mut evaluation = level_plane((rest.0 + foot.0, rest.1 + foot.1));
        (evaluation.foot_strays[0], evaluation.foot_decided[0]) = foot;
        evaluation.score(&MODEL)
    }

    #[test]
    fn a_level_mirror_whose_foot_strays_more_than_the_rest_fails() {
        // The foot's images stray as often as the rest's: the mirror holds on its mean.
        assert!((plane_with_foot((5, 260), (1, 40)) - 0.5).abs() < 1e-6);
        assert!((plane_with_foot((0, 300), (0, 0)) - 0.5).abs() < 1e-6);
        // A third of the foot's images in free space, against 2 % of the rest's: the plane turns
        // the object over about a height it does not have (its foot is no top).
        assert_eq!(plane_with_foot((5, 260), (14, 40)), MODEL.accept);
    }

    /// The score of [`level_plane`] whose decided images are `lower` = (strays, decided) of the
    /// seen points below the mirror and `upper` of those above it.
    fn plane_with_halves(lower: (u32, u32), upper: (u32, u32)) -> f32 {
        let mut evaluation = level_plane((lower.0 + upper.0, lower.1 + upper.1));
        (evaluation.lower_strays[0], evaluation.lower_decided[0]) = lower;
        evaluation.score(&MODEL)
    }

    #[test]
    fn a_level_mirror_whose_images_stray_more_from_one_half_fails() {
        // Both halves' images stray alike (within their sampling noise): the mean decides.
        assert!((plane_with_halves((4, 150), (3, 150)) - 0.5).abs() < 1e-6);
        assert!((plane_with_halves((0, 0), (5, 300)) - 0.5).abs() < 1e-6);
        // A cup's floor, seen below the mirror, sent into the air inside it: 12 % of the lower
        // half's images stray, 1 % of the upper's.
        assert_eq!(plane_with_halves((18, 150), (2, 150)), MODEL.accept);
        // Either way round.
        assert_eq!(plane_with_halves((2, 150), (18, 150)), MODEL.accept);
    }

    #[test]
    fn the_foot_is_the_band_a_match_reaches_above_the_lowest_kept_height() {
        let plate = Plate::square();
        let level = plate.level();
        let view = View {
            table: Some(Plane::new(Vec3::Y, 0.0).unwrap()),
            lowest: 0.004,
            ..plate.view()
        };
        let reach = crate::math::sqrt(level.match_gate2());
        let raised = view.foot().unwrap();
        let at = |h: f32| at_foot(raised, Vec3::new(0.0, h, 0.5), &level);
        assert!(at(0.0) && at(0.004) && at(0.004 + 0.9 * reach));
        assert!(!at(0.004 + 1.1 * reach));
        assert_eq!(plate.view().foot(), None);
    }

    #[test]
    fn the_stray_test_is_a_two_proportion_test() {
        // 5 % against 0 % over 300 images each: pooled 2.5 %, deviation 1.27 %, 3 of them 3.8 %.
        assert!((stray_excess((15, 300), (0, 300)) - (0.05 - 3.0 * 0.012_747)).abs() < 1e-4);
        // With no stray on either side the continuity correction keeps it negative.
        assert!(stray_excess((0, 300), (0, 300)) < 0.0);
        assert!(stray_excess((10, 300), (0, 0)) < 0.0);
    }

    #[test]
    fn a_few_strays_contradict_only_when_their_exact_tail_is_as_unlikely() {
        // Two strays among 31 foot images against 2 among 661: 3.8 deviations, yet a chance of
        // 1.1 % that two of the four strays fall among the foot's 31 of 692 images.
        let tail = binomial_tail(2, 4, 31.0 / 692.0);
        assert!((tail - 0.0113).abs() < 2e-4, "{tail}");
        assert_eq!(stray_excess((2, 31), (2, 661)), 0.0);
        // Five of seven: a chance of 4e-6, contradicted.
        assert!(stray_excess((5, 31), (2, 661)) > 0.0);
        // Many strays: the exact tail agrees with the normal test (15 of 15 on one side of two
        // equal halves: 3e-5).
        let excess = stray_excess((15, 300), (0, 300));
        assert!((excess - (0.05 - 3.0 * 0.012_747)).abs() < 1e-4);
        assert!(binomial_tail(15, 15, 0.5) < STRAY_CHANCE);
        // Not beyond the mode: certain; at it, the bound is no more than certain.
        assert_eq!(binomial_tail(1, 4, 0.5), 1.0);
        assert_eq!(binomial_tail(2, 4, 0.5), 1.0);
    }

    #[test]
    fn an_accepted_composite_is_ranked_by_all_of_its_elements() {
        // The same least confirmed element (0.8): the better fit of the other one ranks first,
        // where a score of the worst element alone would tie them.
        let (loose, tight) = (dual_scored([0.6, 0.8]), dual_scored([0.2, 0.8]));
        assert!(tight < loose);
        assert!((tight - 0.5).abs() < 1e-6);
        // Any accepted composite ranks before any rejected one.
        assert!(loose < dual_scored([0.1, MODEL.accept]));
    }

    #[test]
    fn a_mirror_that_maps_every_point_onto_itself_is_rejected() {
        let plate = Plate::square();
        // The plate's own plane: every image is its source (within `self_radius`).
        let own = mirror(Vec3::Z, 0.5);
        assert_eq!(score(&plate, &own, u32::MAX).0, f32::INFINITY);
    }

    #[test]
    fn a_transformed_point_costs_its_likeliest_cause() {
        let plate = Plate::square();
        let (evidence, level) = (plate.evidence(), plate.level());
        // The plate's view has no front: nothing is obstructed.
        let cost = |u: f32, v: f32, z: f32| {
            (evidence.image_cost(K.unproject(u, v, z), &level, false)).unwrap_or(f32::NAN)
        };
        // On a visible point (any: the first): a perfect match.
        assert_eq!(
            evidence.image_cost(plate.points.pos[0], &level, false),
            Some(0.0)
        );
        // Pixel (5, 5) sees the wall at 0.8 m; 0.2 m in front of it nothing was seen: stray.
        assert_eq!(cost(5.0, 5.0, 0.6), MODEL.cost_stray);
        // Behind the wall, behind the plate (12 voxels from its points), or outside the image:
        // the camera could not see there.
        assert_eq!(cost(5.0, 5.0, 0.9), MODEL.cost_occluded);
        assert_eq!(cost(31.0, 23.0, 0.6), MODEL.cost_occluded);
        assert_eq!(cost(-10.0, 5.0, 0.6), MODEL.cost_occluded);
        // One free-space σ (σ_free = σ × free_per_match = σ) in front of the wall: occluded plus
        // half (v² / 2σ_free²).
        let near = cost(5.0, 5.0, 0.8 - plate.sigma());
        assert!((near - (MODEL.cost_occluded + 0.5)).abs() < 1e-3, "{near}");
    }

    #[test]
    fn a_confirmed_match_is_credited_the_readings_excess_noise_and_nothing_else_is() {
        let plate = Plate::square();
        let evidence = plate.evidence();
        // A noisier reading (sensor σ 2 mm): 4 - 1.375 = 2.625 mm² beyond what the floor allows.
        let excess2 = MODEL.excess2(0.002);
        assert!((excess2 - 2.625e-6).abs() < 1e-10, "{excess2}");
        let noisy = MODEL.level(plate.sigma(), excess2, &plate.voxels);
        let credit = excess2 * 0.5 / (plate.sigma() * plate.sigma());
        // The plate's view has no front: nothing is obstructed.
        let cost =
            |q: Vec3, level: &Level| evidence.image_cost(q, level, false).unwrap_or(f32::NAN);
        // A match within the gate: lowered by the credit (a perfect one below 0).
        let seen = plate.points.pos[0];
        let near = seen + Vec3::new(0.0, 0.0, plate.sigma());
        for q in [seen, near] {
            let (quiet, loud) = (cost(q, &plate.level()), cost(q, &noisy));
            assert!(quiet <= MODEL.cost_occluded);
            assert!((quiet - loud - credit).abs() < 1e-5, "{quiet} {loud}");
        }
        // Unseen and stray images cost what they did: the extra noise widens no match.
        for q in [K.unproject(5.0, 5.0, 0.9), K.unproject(5.0, 5.0, 0.6)] {
            assert_eq!(cost(q, &plate.level()), cost(q, &noisy));
        }
        // The default sensor at its best range is about what the floor allows a reading
        // (1.44 mm² against 1.375): a credit of 0.004 a match at the floor's σ.
        let best = crate::SensorConfig::DEFAULT.sigma(crate::SensorConfig::DEFAULT.best_range);
        let at_best = MODEL.excess2(best) * 0.5 / (MODEL.sigma_min * MODEL.sigma_min);
        assert!((at_best - 0.0036).abs() < 1e-4, "{at_best}");
    }

    #[test]
    fn scoring_spends_one_unit_per_scored_point_and_any_slicing_gives_the_same_bits() {
        let plate = Plate::square();
        let n = plate.points.len as u32;
        let dual = Symmetry::DualPlane([
            Plane::new(Vec3::X, 0.0).unwrap(),
            Plane::new(Vec3::Y, 0.0).unwrap(),
        ]);
        // One map for a plane; two for the two planes (their derived half-turn is not scored).
        for (symmetry, maps) in [(mirror(Vec3::X, 0.0), 1), (dual, 2)] {
            let (whole, units) = score(&plate, &symmetry, u32::MAX);
            assert_eq!(units, n * maps);
            assert!(whole < MODEL.accept, "{whole}");
            // One unit a call, and calls that end inside a source's maps (7 is odd).
            for slice in [1, 7] {
                let (sliced, sliced_units) = score(&plate, &symmetry, slice);
                assert_eq!(sliced.to_bits(), whole.to_bits(), "{slice} units a call");
                assert_eq!(sliced_units, units);
            }
        }
        // An empty meter buys nothing.
        let mut evaluation = Evaluation::new();
        evaluation.begin(&dual, Sampling::default(), plate.level(), n as usize, 1);
        let mut empty = Meter::new(0);
        assert!(
            evaluation
                .advance(&plate.evidence(), |j| (j, false), &mut empty)
                .is_pending()
        );
    }
}
