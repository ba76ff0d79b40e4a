//! Every setting of the engine in one place: [`Config`] and the settings of each part of it.
//! Each validates its own fields; a value out of range is reported as
//! [`Error::InvalidConfig`] naming the field (`"model.accept"`). The engine validates its
//! configuration at `start` and `set_config`, before anything changes.

use crate::Error;
use crate::symmetry::{Sampling, TypeSet};

/// Every setting of the engine. [`Config::DEFAULT`] is what the figures in `docs/` were measured
/// with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// The symmetry types wanted (the search still visits the weaker types on the way).
    pub types: TypeSet,
    /// How continuous symmetries are sampled into maps.
    pub sampling: Sampling,
    /// The depth camera's noise.
    pub sensor: SensorConfig,
    /// Support plane and segmentation.
    pub prepare: PrepareConfig,
    /// The measurement model.
    pub model: ModelConfig,
    /// The parameter search (the inner loop).
    pub search: SearchConfig,
    /// The domain search (the middle loop): part symmetries.
    pub domains: DomainConfig,
}

impl Config {
    /// The defaults.
    pub const DEFAULT: Config = Config {
        types: TypeSet::ALL,
        sampling: Sampling { axial_steps: 7 },
        sensor: SensorConfig::DEFAULT,
        prepare: PrepareConfig::DEFAULT,
        model: ModelConfig::DEFAULT,
        search: SearchConfig::DEFAULT,
        domains: DomainConfig::DEFAULT,
    };

    /// Check every value, each settings group by its own `validate`; the first value out of
    /// range is named in the error (`Error::InvalidConfig { field: "model.accept" }`).
    pub fn validate(&self) -> Result<(), Error> {
        check(!self.types.is_empty(), "types")?;
        check(
            (2..=7).contains(&self.sampling.axial_steps),
            "sampling.axial_steps",
        )?;
        self.sensor.validate()?;
        self.prepare.validate()?;
        self.model.validate()?;
        self.search.validate()?;
        self.domains.validate()
    }

    /// This configuration restricted to `types`.
    pub const fn with_types(self, types: TypeSet) -> Self {
        Self { types, ..self }
    }
}

impl Default for Config {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The depth camera's noise: a reading at depth `z` scatters along its ray with
/// σ(z) = `noise_floor` + `noise_growth` · (z − `best_range`)² (metres), the form Nguyen, Izadi
/// & Lovell (2012) measured on a structured-light camera: the triangulation's error grows with
/// z², on a floor that the projected pattern's blur sets. The segmentation allows three σ
/// wherever it compares readings of one surface.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorConfig {
    /// σ at `best_range`, metres. Default 1.2 mm (Kinect v1 / Asus Xtion: Nguyen et al. 2012,
    /// eq. 4, incidences of 10° to 60°).
    pub noise_floor: f32,
    /// Growth of σ per squared metre away from `best_range`, metres. Default 1.9 mm (the same).
    pub noise_growth: f32,
    /// Depth of the least noise, metres. Default 0.4 m (the same). An active-stereo camera
    /// has no floor to speak of: an Intel RealSense D435 at 848 x 480 (0.08 px subpixel
    /// error, 50 mm baseline, 640 px focal length) is about 0.0 / 0.0025 / 0.0.
    pub best_range: f32,
    /// Whether a reading may come from a neighbouring pixel's surface: a structured-light or
    /// time-of-flight camera places a depth edge within about a pixel of the true one (Kinect
    /// v1: σ 0.8 px, Nguyen et al. 2012, eq. 3, incidences below 60°). The free-space test then
    /// lets a transformed point lie behind a neighbouring cell's reading, at a cost (see
    /// `View::new`). Default on; off for a rendered image with no lateral noise.
    pub lateral_noise: bool,
}

impl SensorConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        noise_floor: 0.0012,
        noise_growth: 0.0019,
        best_range: 0.4,
        lateral_noise: true,
    };

    /// σ of a reading at depth `z` (metres).
    ///
    /// ```
    /// # use shape_from_symmetry::SensorConfig;
    /// let sigma = SensorConfig::DEFAULT.sigma(1.4); // 1.2 mm + 1.9 mm x (1 m)²
    /// assert!((sigma - 0.0031).abs() < 1e-6);
    /// ```
    #[inline]
    pub fn sigma(&self, z: f32) -> f32 {
        let dz = z - self.best_range;
        self.noise_floor + self.noise_growth * dz * dz
    }

    /// Check every value (field names prefixed `sensor.`).
    pub fn validate(&self) -> Result<(), Error> {
        check(non_negative(self.noise_floor), "sensor.noise_floor")?;
        check(non_negative(self.noise_growth), "sensor.noise_growth")?;
        check(non_negative(self.best_range), "sensor.best_range")
    }
}

impl Default for SensorConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Segmentation and support-plane settings (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PrepareConfig {
    /// Largest distance from the plane of a support-plane inlier. Default 1 cm: three σ of the
    /// default sensor's noise at 1.4 m (3.1 mm, [`SensorConfig::sigma`]), toward the far end
    /// of the working range (`max_range`), where much of a table is seen.
    pub plane_tolerance: f32,
    /// Object pixels lie at least this high above the support plane (default 4 mm: with a
    /// mask, it trims the background readings at the silhouette; a lower masked reading counts
    /// only 4 pixels or more inside the mask, a container's floor); without a mask, also above
    /// three σ of the sensor's noise at their depth, within which the support's own readings
    /// scatter ([`SensorConfig`]; 4.1 mm at 0.7 m, 5.6 mm at 1 m by default).
    pub min_height: f32,
    /// ... and at most this high. Default 0.6 m: the top of the largest object
    /// ([`PrepareConfig::max_object_size`], 0.4 m) standing on the support, with half as much
    /// again for one standing on another object (a box on a box); readings higher are shelves,
    /// walls or the arm above the workspace.
    pub max_height: f32,
    /// Leave out of the sampled points every pixel next to a depth jump (a neighbour's depth
    /// differs by more than a surface seen at 85° incidence steps between pixels): the mixed
    /// ("flying") pixels that time-of-flight and some structured-light cameras put between an
    /// object's silhouette and the background. Off by default: a narrow part (a handle) loses
    /// its rim pixels with them.
    pub drop_edge_pixels: bool,
    /// With a mask, leave out the masked pixels at its outline that read what lies past it:
    /// behind the object's pixels beside them and sharing a surface with none of them (at
    /// least two of them read). A mask drawn in a registered colour camera, or one pixel too
    /// wide, takes in readings past the silhouette, and a time-of-flight or structured-light
    /// camera blends the object into the background there by any weight (mixed pixels that
    /// [`PrepareConfig::drop_edge_pixels`] drops with every pixel next to a depth jump; this
    /// keeps the object's own edge pixels). Off by default: a pixel at a round silhouette
    /// seen edge-on, steeper than the camera reads, is left out with them, and the search's
    /// result can turn on a pixel where a symmetry barely beats its rival.
    pub trim_past_outline: bool,
    /// Sample the object's outline besides the sampling lattice: the object pixels where a
    /// lattice row or column leaves the object. On by default: the lattice alone ends on
    /// average half a stride inside the outline, and a mirror plane with one side of the object
    /// ending on a silhouette then sits about a quarter stride toward the other side. Not with
    /// [`DomainConfig::parts`] (the part search grows its domains over the lattice's
    /// 8-neighbours, which outline points are not on).
    pub outline: bool,
    /// Working range (m): without a mask, readings farther than this take no part in the
    /// support plane or the object candidates. Default 1.5 m: a manipulator reaches about
    /// 0.85 m from its base, and a head or wrist camera sits within about 0.65 m of the base,
    /// so nothing the gripper can take is farther; floors and walls behind usually are.
    pub max_range: f32,
    /// Smallest extent (m) of a candidate object region (the larger side of its pixel box at
    /// its mean depth) chosen without a target. Default 2 cm: a two-finger gripper's
    /// fingertips are about that wide, and a smaller region is noise or a fragment.
    pub min_object_size: f32,
    /// Largest such extent (m). Default 0.4 m: about the largest object a one-arm gripper
    /// lifts (the longest YCB objects are about 0.3 m); a larger region is furniture or a
    /// group of objects.
    pub max_object_size: f32,
    /// Without a mask, split the chosen region where it narrows to a neck between two parts
    /// whose connecting segment crosses the gap between two objects on their seam (two touching
    /// objects the block graph could not part, such as two cans whose lids meet). On by default;
    /// a region that encloses more than its cores (a container seen over its rim) is never
    /// split.
    pub split_necks: bool,
    /// Without a mask, part the candidate regions at concave creases, where two objects that
    /// touch meet (a can against a box). On by default. Off for a caller who knows that
    /// nothing touches the object (one object on the table; [`PrepareConfig::with_one_object`]
    /// turns [`PrepareConfig::split_necks`] off with it): a part that meets its body at a
    /// crease (a mug's handle, a bottle's neck, a drill's chuck) then stays with it, and
    /// touching objects are taken for one.
    pub part_at_creases: bool,
    /// With [`PrepareConfig::part_at_creases`] and a support plane (given or found), a region
    /// the creases parted from the object joins it again when nothing but the object holds it
    /// up: it meets the object above and below, and the camera sees the air below it down to
    /// the support (a mug's handle seen from the side; not a second object standing or lying
    /// on the support, leaning on the object, or resting on another region). On by default.
    pub join_hanging_parts: bool,
}

impl PrepareConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        plane_tolerance: 0.01,
        min_height: 0.004,
        max_height: 0.6,
        drop_edge_pixels: false,
        trim_past_outline: false,
        outline: true,
        max_range: 1.5,
        min_object_size: 0.02,
        max_object_size: 0.4,
        split_necks: true,
        part_at_creases: true,
        join_hanging_parts: true,
    };

    /// These settings for a caller who knows whether anything touches the object. With
    /// `one_object` (one object on the table, a wrist camera over the item to grasp), without a
    /// mask no region is parted at a concave crease nor split at a neck: both part touching
    /// objects, and with none touching each could only cut the object itself (a mug's handle
    /// at its junctions, its front wall from its inside). Sets
    /// [`PrepareConfig::part_at_creases`] and [`PrepareConfig::split_necks`] to `!one_object`.
    ///
    /// ```
    /// # use shape_from_symmetry::PrepareConfig;
    /// let one = PrepareConfig::DEFAULT.with_one_object(true);
    /// assert!(!one.part_at_creases && !one.split_necks);
    /// assert_eq!(one.with_one_object(false), PrepareConfig::DEFAULT);
    /// ```
    pub const fn with_one_object(self, one_object: bool) -> Self {
        Self {
            part_at_creases: !one_object,
            split_necks: !one_object,
            ..self
        }
    }

    /// Check every value (field names prefixed `prepare.`).
    pub fn validate(&self) -> Result<(), Error> {
        check(positive(self.plane_tolerance), "prepare.plane_tolerance")?;
        check(self.min_height.is_finite(), "prepare.min_height")?;
        check(self.max_height > self.min_height, "prepare.max_height")?;
        check(self.max_range > 0.0, "prepare.max_range")?;
        check(
            non_negative(self.min_object_size),
            "prepare.min_object_size",
        )?;
        check(
            self.max_object_size.is_finite() && self.max_object_size > self.min_object_size,
            "prepare.max_object_size",
        )
    }
}

/// Constants of the measurement model (costs are negative log-likelihoods, lengths in metres).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelConfig {
    /// Cost of a point in occluded space, relative to a perfect match (0). Default 1 nat: a
    /// match and occlusion are then equally likely √2 σ from a seen point (`d² / 2σ² = 1`, the
    /// match gate: 4.2 mm at the 3 mm floor), a distance that holds 84 % of a Gaussian's errors
    /// along one axis, the axis a reading's noise lies along (its ray).
    pub cost_occluded: f32,
    /// Cost of a stray point (in free space, matching nothing). Default 4 nats: the paper's
    /// uniform density over a range `R` (eq. 7) against a match's peak, `ln(R / (√(2π) σ))`, is
    /// 3.97 for `R` the largest object (`PrepareConfig::max_object_size`, 0.4 m) at the 3 mm
    /// floor. A match costs as much 2√2 σ away (beyond which 0.5 % of a Gaussian's errors lie
    /// along one axis), the free-space term √6 σ in front of the surface seen; and a stray costs
    /// as much as four hidden images.
    pub cost_stray: f32,
    /// Smallest match σ, metres: a transformed point carries its reading's noise and the
    /// object's own deviation from its symmetry, and the reading it is matched with its own
    /// noise. Default 3 mm: √(2 × (1.2 mm)² + `sigma_object`²), two readings at the default
    /// sensor's best range (`SensorConfig::noise_floor`) and the object's deviation. Where the
    /// sensor is noisier (at range, or a noisier camera) σ stays and a confirmed match is
    /// credited its reading's extra variance instead ([`ModelConfig::excess2`]): a wider σ
    /// would let farther images match too, and under a fixed [`ModelConfig::accept`] stronger
    /// types would pass on weaker evidence.
    pub sigma_min: f32,
    /// σ of the object's own deviation from its symmetry, metres, per axis: a 3-D Gaussian
    /// offset of this σ has mean length 2√(2/π) σ = 1.60 σ, and 2.5 mm (the default) makes it
    /// the 4 mm within which a symmetry of the whole object counts as valid (`SCENES.md`).
    pub sigma_object: f32,
    /// Match σ per sample spacing: the finest σ is at least this many spacings of the sampling
    /// lattice (a sparser sampling needs a wider match). Default 0.6: an image on a frontal
    /// surface lies at most 0.71 spacings from a sample (at a lattice cell's centre), where it
    /// costs 0.71² / (2 × 0.6²) = 0.69, inside the match gate (at 0.5 it would lie on it).
    pub sigma_per_spacing: f32,
    /// σ of the free-space term per match σ. Default 1: an image's depth is set against a
    /// reading's, whose error is the same sensor noise and object deviation a match allows for.
    pub free_per_match: f32,
    /// A transformed point closer than this many σ to its source is uninformative (a plane
    /// through a point maps it onto itself). Default 1.5: just beyond the match gate (√2 σ,
    /// [`ModelConfig::cost_occluded`]), so that no image is confirmed by its own source.
    pub self_radius: f32,
    /// Least share of informative transformed points. Default 0.2: a hypothesis that maps most
    /// points within the self radius (a plane through a thin object's middle) is judged on the
    /// others; a fifth of the 1 200 images a polishing climb scores is 240, whose mean cost
    /// has a standard error of about 0.03 (an image's cost spreads by about 0.5), a fifth of
    /// the margin between `accept` and `cost_occluded`.
    pub min_informative: f32,
    /// A hypothesis is accepted when its score is below this. Default 0.85, 0.15 below
    /// `cost_occluded`, the score of an element whose images are all hidden: it must be
    /// confirmed, not merely uncontradicted. A confirmed match costs 0.2 to 0.4 on average
    /// (its reading's noise within σ; `examples/explain` prints the costs), so an element passes
    /// with about a fifth to a quarter of its images confirmed and none contradicted, and
    /// needs four or five more confirmed for every stray.
    pub accept: f32,
    /// The object rests on the support plane (when one is given or found): a mirror image that
    /// turns the object upside down and lies on the plane, hidden under the object, is its
    /// underside touching it (the contact term of the measurement model, `docs/algorithm.md`),
    /// and the search also tries axes along the plane's normal. `false` for an object held or
    /// hanging.
    pub resting: bool,
    /// With `resting`, the contact term also credits a mirror tilted beyond 5° of level that,
    /// halfway up the object, sends its top within a match's reach of the support (a curved
    /// object resting on its side, its mirror a few degrees off level; `docs/algorithm.md`).
    /// Off by default: it completes such an object's underside, but a near-symmetric one's
    /// second, nearly true plane then passes too (a banana's cross plane, its stem aside), and
    /// the search does more work (`docs/figures.md`).
    pub tilted_contact: bool,
}

impl ModelConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        cost_occluded: 1.0,
        cost_stray: 4.0,
        sigma_min: 0.003,
        sigma_object: 0.0025,
        sigma_per_spacing: 0.6,
        free_per_match: 1.0,
        self_radius: 1.5,
        min_informative: 0.2,
        accept: 0.85,
        resting: true,
        tilted_contact: false,
    };

    /// Check every value (field names prefixed `model.`).
    pub fn validate(&self) -> Result<(), Error> {
        check(positive(self.cost_occluded), "model.cost_occluded")?;
        check(positive(self.cost_stray), "model.cost_stray")?;
        check(positive(self.sigma_min), "model.sigma_min")?;
        check(non_negative(self.sigma_object), "model.sigma_object")?;
        check(
            self.sigma_per_spacing.is_finite(),
            "model.sigma_per_spacing",
        )?;
        check(positive(self.free_per_match), "model.free_per_match")?;
        check(self.self_radius.is_finite(), "model.self_radius")?;
        check(share(self.min_informative), "model.min_informative")?;
        check(positive(self.accept), "model.accept")
    }
}

/// Parameter-search settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SearchConfig {
    /// The grid each family is searched on first.
    pub grid: GridConfig,
    /// Local minima of the grid refined by hill climbing, best first; each family's best grid
    /// point that is not among them is refined too (as many as the parameter search holds,
    /// `MAX_CANDIDATES`). Default 4: with 3, the extra views lose exact-class scenes; with 6,
    /// the search does more work for no more valid ones (both measured with `examples/evaluate`
    /// on the development scenes and the extra views).
    pub candidates: u8,
    /// Transformed points scored per grid hypothesis, one work unit each. Default 160: their
    /// mean cost has a standard error of about 0.04 (at the spread of an image's cost
    /// [`ModelConfig::min_informative`] states); the grid only ranks starting points for the
    /// climb.
    pub grid_transformed: u32,
    /// Transformed points scored per hill-climbing hypothesis while the step is coarser than the
    /// finest match σ (default 640: a standard error of about 0.02)...
    pub climb_transformed: u32,
    /// ... and once it is finer (default 1 200: about 0.014; the last levels decide the
    /// precision).
    pub polish_transformed: u32,
    /// The climber stops when its step falls below this fraction of the finest match σ.
    /// Default 0.25: 0.75 mm at the 3 mm floor, a step that moves a mirror's images by 1.5 mm,
    /// about one reading's noise at the sensor's best range (1.2 mm); the refinement from
    /// matched point pairs (`refine_rounds`) takes the parameters further.
    pub finest_step: f32,
    /// Improvement rounds per resolution of the hill climber, each two evaluations per
    /// parameter. Default 3: with 2 or with 4, the extra views lose exact-class scenes
    /// (measured as `candidates` is).
    pub rounds_per_level: u8,
    /// Rounds of refinement of each symmetry found with a continuous rotation or mirror planes,
    /// from the point pairs it matches (`refine`; 0: none). The climb leaves the parameters
    /// within a fraction of σ of the optimum, where the pairs barely change after the second
    /// round.
    pub refine_rounds: u8,
}

impl SearchConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        grid: GridConfig::DEFAULT,
        candidates: 4,
        grid_transformed: 160,
        climb_transformed: 640,
        polish_transformed: 1200,
        finest_step: 0.25,
        rounds_per_level: 3,
        refine_rounds: 3,
    };

    /// Check every value (field names prefixed `search.`).
    pub fn validate(&self) -> Result<(), Error> {
        self.grid.validate()?;
        check(self.candidates >= 1, "search.candidates")?;
        check(self.grid_transformed >= 1, "search.grid_transformed")?;
        check(self.climb_transformed >= 1, "search.climb_transformed")?;
        check(self.polish_transformed >= 1, "search.polish_transformed")?;
        let finest = self.finest_step;
        check(finest > 0.0 && finest <= 1.0, "search.finest_step")
    }
}

/// Grid resolutions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GridConfig {
    /// Plane normals on the hemisphere. Default 96: one per 0.065 sr, about 15° apart.
    pub plane_normals: u16,
    /// Line directions on the hemisphere. Default 24: one per 0.26 sr, about 29° apart.
    pub line_directions: u16,
    /// Steps of an angle over half a turn. Default 12: 15° apart, as the plane normals are.
    pub angle_steps: u16,
    /// Steps of a position across the object's diameter. Default 9: an eighth of it apart.
    pub offset_steps: u16,
    /// Steps per axis of the 2-D and 3-D position lattices (axis through a plane, point and
    /// line positions), across the object's diameter. Default 7: a sixth of it apart.
    pub lattice_steps: u16,
}

impl GridConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        plane_normals: 96,
        line_directions: 24,
        angle_steps: 12,
        offset_steps: 9,
        lattice_steps: 7,
    };

    /// Check every value (field names prefixed `search.grid.`).
    pub fn validate(&self) -> Result<(), Error> {
        check(self.plane_normals >= 1, "search.grid.plane_normals")?;
        check(self.line_directions >= 1, "search.grid.line_directions")?;
        check(self.angle_steps >= 1, "search.grid.angle_steps")?;
        check(
            (2..=64).contains(&self.offset_steps),
            "search.grid.offset_steps",
        )?;
        check(
            (2..=64).contains(&self.lattice_steps),
            "search.grid.lattice_steps",
        )
    }
}

/// Domain-search settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DomainConfig {
    /// Search part symmetries at all (`false`: the whole object is the only domain). With
    /// parts, the object's outline is not sampled ([`PrepareConfig::outline`]).
    pub parts: bool,
    /// A grown domain holds at least this share of the domain it was grown in... Default 0.15:
    /// 90 points of a 600-point object, over which a part's mean cost has a standard error of
    /// about 0.05 (an image's cost spreads by about 0.5, [`ModelConfig::min_informative`]), a
    /// third of the margin between `accept` and `cost_occluded`; a smaller part cannot be told
    /// confirmed from uncontradicted.
    pub min_share: f32,
    /// ... and at most this share (a domain that is nearly all of it is searched as it is).
    /// Default 0.97: a symmetry of the whole domain leaves out of it only the points whose
    /// images stray or lie at its border, the sensor's few in a hundred (a true element's stray
    /// share, `examples/explain`).
    pub max_share: f32,
    /// Largest rim (members with a neighbour in the rest of the domain) per member. At 0.5 the
    /// rim is at most as large as the interior, the loosest reading of the paper's "small rim
    /// relative to its interior size"; a sliver of a surface that one axis happens to fit has
    /// a rim about as large as itself.
    pub max_rim: f32,
    /// The leftover points searched as a further domain hold at least this share of all points.
    /// Default 0.08: 48 points of a 600-point object (and never fewer than the search's least,
    /// 24), a standard error of about 0.07 on their mean cost, half the margin between `accept`
    /// and `cost_occluded`: the most a leftover's test may spread and still tell a confirmed
    /// symmetry from an unconfirmed one.
    pub min_leftover: f32,
}

impl DomainConfig {
    /// The defaults.
    pub const DEFAULT: Self = Self {
        parts: false,
        min_share: 0.15,
        max_share: 0.97,
        max_rim: 0.5,
        min_leftover: 0.08,
    };

    /// Check every value (field names prefixed `domains.`).
    pub fn validate(&self) -> Result<(), Error> {
        check(share(self.min_share), "domains.min_share")?;
        check(share(self.max_share), "domains.max_share")?;
        check(non_negative(self.max_rim), "domains.max_rim")?;
        check(share(self.min_leftover), "domains.min_leftover")
    }
}

/// `Ok` when `ok`, else the error naming `field`.
fn check(ok: bool, field: &'static str) -> Result<(), Error> {
    if ok {
        Ok(())
    } else {
        Err(Error::InvalidConfig { field })
    }
}

/// Finite and above zero (false for NaN).
fn positive(x: f32) -> bool {
    x.is_finite() && x > 0.0
}

/// Finite and at least zero (false for NaN).
fn non_negative(x: f32) -> bool {
    x.is_finite() && x >= 0.0
}

/// In `[0, 1]` (false for NaN).
fn share(x: f32) -> bool {
    (0.0..=1.0).contains(&x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_valid() {
        assert_eq!(Config::DEFAULT.validate(), Ok(()));
    }

    #[test]
    fn a_value_out_of_range_is_named() {
        let named = |change: fn(&mut Config)| {
            let mut config = Config::DEFAULT;
            change(&mut config);
            match config.validate() {
                Err(Error::InvalidConfig { field }) => field,
                other => panic!("{other:?}"),
            }
        };
        assert_eq!(named(|c| c.types = TypeSet::EMPTY), "types");
        assert_eq!(
            named(|c| c.sampling.axial_steps = 8),
            "sampling.axial_steps"
        );
        assert_eq!(named(|c| c.prepare.max_height = 0.0), "prepare.max_height");
        assert_eq!(
            named(|c| c.prepare.max_range = f32::NAN),
            "prepare.max_range"
        );
        assert_eq!(
            named(|c| c.prepare.max_object_size = 0.01),
            "prepare.max_object_size"
        );
        assert_eq!(named(|c| c.model.accept = f32::INFINITY), "model.accept");
        assert_eq!(
            named(|c| c.model.min_informative = 1.5),
            "model.min_informative"
        );
        assert_eq!(named(|c| c.search.finest_step = 0.0), "search.finest_step");
        assert_eq!(
            named(|c| c.search.grid.offset_steps = 65),
            "search.grid.offset_steps"
        );
        assert_eq!(named(|c| c.domains.max_rim = -1.0), "domains.max_rim");
    }
}
