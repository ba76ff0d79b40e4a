//! Synthetic clutter: several ready-made objects touching on a table, a floor below and a wall
//! behind, seen by the Kinect-like camera of [`synth`], with each object's true mask (issue 24,
//! "real clutter").
//!
//! A *clutter scene* ([`ClutterScene`]) is 1 to [`MAX_OBJECTS`] objects of [`OBJECTS`] standing
//! on the table (the plane `z = 0` of the object frame, `table_half_size` as in
//! [`SynthScene::table_half_size`]), some of them touching (a gap of 0 to a few millimetres
//! between their surfaces), with a *room* around the table: a floor, a large slab
//! [`ClutterScene::floor_drop`] below the table top, and optionally a wall, a large vertical slab
//! behind the table as the camera sees it. Floor and wall are solids like the objects, so they
//! give readings beyond the table's edge, as a real room does; the table itself has no legs and
//! no thickness (the renderer's table is a rectangle of the plane `z = 0`). A *small support*
//! ([`SMALL_SUPPORT_HALF_SIZE`]) is a table of 0.5 x 0.4 m with the floor 1 m below it.
//!
//! [`render_clutter`] renders the depth image once (Kinect noise and flying pixels as
//! [`synth::render`] draws them) and, for each object, its *true mask*: the pixels whose nearest
//! hit, noise-free, is that object. The cases the tests use are [`CLUTTER_CASES`].
//!
//! # Frames
//! *Object frame* ([`synth`]): z up, the table top is `z = 0`, its centre the origin, the camera
//! placed by [`View`] about [`ClutterLayout::target`]. *Arrangement frame*:
//! the object frame turned about z by the view's azimuth, so that its x axis points
//! horizontally toward the camera and its y axis to the image's right (without roll), origin the
//! table centre. Objects are placed in it ([`Place`], [`ClutterObject::yaw_deg`]), so that an
//! arrangement looks the same in the image from every azimuth: "in front of" is `+x`, "to the
//! right of" is `+y`. The table and the floor stay fixed in the object frame; the wall turns with
//! the camera (it is always behind the table as seen from the camera).
//!
//! # How the masks are made
//! [`synth::render`] tells only "the object" from "the rest" ([`SynthScene::occluders`]), so
//! `render_clutter` renders the scene once per object: that object as `parts`, every other
//! object, the floor and the wall as `occluders`. The geometry, the noise seed and the
//! artefacts' seed are the same in every render, and the renderer draws a pixel's noise from the
//! seed, the pixel index and the surface hit only, so the depth images agree bit for bit; the
//! first render's depth is the output, every other render is compared with it and the pixels
//! that differ are counted ([`ClutterRendered::depth_mismatches`], 0 on every case). A pixel
//! whose nearest hits on two objects tie exactly would be claimed by both renders; it is kept in
//! the lower-numbered object's mask only and counted ([`ClutterRendered::contested_pixels`], 0 on
//! every case). Holes ([`synth::Artefacts::holes`]) are not offered: the renderer draws their
//! centres among the mask's pixels, which differ between the renders.
//!
//! Like [`synth`], nothing here allocates except [`ClutterFrame`] (owned buffers for tests),
//! nothing panics on any input, and the numbers are the same on every target (sines and cosines
//! through [`shape_from_symmetry::math`]); the module needs `std` only for [`ClutterFrame`] and
//! `std::error::Error`, and is built with the feature `std` as [`synth`] is.
//!
//! # Cost
//! One [`synth::render`] per object: a clutter scene of `n` objects costs `n` renders of a scene
//! with all its solids (0.1 to 1 s per Xtion frame in a release build with debug info, the
//! floor and the wall being two more solids every ray tests).

use shape_from_symmetry::math::{Isometry, Mat3, Vec3, sin_cos};
use shape_from_symmetry::{Intrinsics, Plane, Rect};

use crate::synth::{
    self, Artefacts, BUILTIN_INTRINSICS, Noise, OBJECTS, Part, ReadyObject, Shape, SynthError,
    SynthScene, TABLE_HALF_SIZE, View, XTION_DEPTH_SCALE, XTION_INTRINSICS,
};

// ------------------------------------------------------------------------------------------------
// Constants
// ------------------------------------------------------------------------------------------------

/// Most objects in a scene: the clutter is 2 to 5 objects; the bound keeps the layout on
/// the stack and the renders (one per object) few.
pub const MAX_OBJECTS: usize = 5;
/// Most parts of one object: the largest ready-made object, the figure of
/// [`synth::PART_OBJECTS`], has 6.
pub const MAX_OBJECT_PARTS: usize = 6;
/// Most occluders of one render: every other object's parts, the floor and the wall.
const MAX_OCCLUDERS: usize = (MAX_OBJECTS - 1) * MAX_OBJECT_PARTS + 2;

/// The small support: a side table or a stool top of 0.5 x 0.4 m, about the smallest surface a
/// few household objects stand on; the floor around it fills much of the image.
pub const SMALL_SUPPORT_HALF_SIZE: [f32; 2] = [0.25, 0.2];
/// Table top above the floor (metres) for the dev scenes' table: 0.75 m, a dining or office
/// table's height.
pub const TABLE_HEIGHT: f32 = 0.75;
/// The small support's top above the floor (metres): 1 m, a high counter or a shelf, so that the
/// floor's readings reach about 2 m from the camera (see [`SMALL_SUPPORT_FLOOR_HALF`]).
pub const SMALL_SUPPORT_HEIGHT: f32 = 1.0;
/// Half side (metres) of the square floor slab around the dev scenes' table: 2 m, a room of
/// 4 x 4 m; the rays that miss it read nothing (as a doorway or a far corner would, or the
/// sensor's range).
pub const FLOOR_HALF: f32 = 2.0;
/// Half side (metres) of the floor slab around the small support: 1 m, so that, from the
/// cases' views, the floor's farthest readings lie about 2 m from the camera (1.8 to 2.6 m).
pub const SMALL_SUPPORT_FLOOR_HALF: f32 = 1.0;
/// Thickness (metres) of the floor and wall slabs: any positive value would do (only their
/// faces are seen); 5 cm keeps them well clear of the renderer's dimension limits.
const SLAB_THICKNESS: f32 = 0.05;
/// Height (metres) of the wall's top above the table top: 1.5 m, beyond the top of the image
/// from every case's view.
const WALL_TOP: f32 = 1.5;

/// The random stream of the flying pixels, XORed into [`ClutterScene::seed`]: any constant
/// other than 0 keeps them independent of the noise, whose seed is the scene's seed itself.
const FLYING_SEED: u32 = 0x2c1a_77e5;

// ------------------------------------------------------------------------------------------------
// Scene description
// ------------------------------------------------------------------------------------------------

/// Where an object stands on the table (arrangement frame, see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Place {
    /// Its object-frame origin (the ready object's, on the table) at `(x, y)` metres from the
    /// table centre: `x` toward the camera, `y` to the image's right.
    At { x: f32, y: f32 },
    /// Touching the earlier object `of` (an index into [`ClutterScene::objects`], lower than this
    /// one's): placed from `of`'s origin in the horizontal direction `bearing_deg` (0: toward the
    /// camera, this object in front of `of`; 90: to the image's right; 180: behind) so that the
    /// two objects' supporting planes across that direction lie `gap` metres apart (`gap >= 0`).
    /// That is the distance between their surfaces when their outermost points in that direction
    /// face each other at the same height (a vertical side against any other object, two balls;
    /// not a ball against a cone or a bowl, whose outermost points lie at other heights): the
    /// cases keep to such pairs, and the tests measure the true gaps.
    Beside {
        of: usize,
        bearing_deg: f32,
        gap: f32,
    },
}

/// One object of a clutter scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClutterObject {
    pub object: &'static ReadyObject,
    pub place: Place,
    /// Turn about the vertical through its origin, degrees, counter-clockwise seen from above,
    /// in the arrangement frame: at 0 its object-frame x axis points toward the camera (a
    /// cereal box shows its broad face, a mug's handle points at the camera); at 90 toward the
    /// image's right.
    pub yaw_deg: f32,
}

/// A clutter scene (see the module docs). Render it with [`render_clutter`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClutterScene<'a> {
    /// A name for messages.
    pub name: &'static str,
    /// 1 to [`MAX_OBJECTS`] objects, each of at most [`MAX_OBJECT_PARTS`] parts.
    pub objects: &'a [ClutterObject],
    /// The camera, looking at [`ClutterLayout::target`]. Its azimuth also turns the arrangement.
    pub view: View,
    /// The table top, as [`SynthScene::table_half_size`] ([`TABLE_HALF_SIZE`] or
    /// [`SMALL_SUPPORT_HALF_SIZE`]).
    pub table_half_size: [f32; 2],
    /// The floor's top lies this far (metres, `> 0`) below the table top.
    pub floor_drop: f32,
    /// Half side (metres, `> 0`) of the square floor slab, centred under the table.
    pub floor_half: f32,
    /// The wall's face lies this far (metres, `>= 0`) behind the table's far edge as seen from
    /// the camera (horizontally, along the view's azimuth); `None`: no wall. It reaches from the
    /// floor to 1.5 m above the table and `floor_half` to either side.
    pub wall_gap: Option<f32>,
    /// Kinect noise ([`Noise::kinect`] with `seed`) or none ([`Noise::OFF`]).
    pub noise: bool,
    /// Probability of a flying pixel per discontinuity pixel ([`Artefacts::flying`]), in
    /// `[0, 1]`; 0: none.
    pub flying_pixels: f32,
    /// Seed of the noise and of the flying pixels.
    pub seed: u32,
    /// Metres per depth unit (as [`SynthScene::depth_scale`]).
    pub depth_scale: f32,
}

/// A scene of [`CLUTTER_CASES`] and the camera it is rendered with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClutterCase {
    pub scene: ClutterScene<'static>,
    pub intrinsics: Intrinsics,
}

/// Two objects placed touching ([`Place::Beside`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    /// The object placed against ...
    pub object: usize,
    /// ... this earlier one.
    pub of: usize,
    pub bearing_deg: f32,
    /// The nominal gap between the surfaces (metres).
    pub gap: f32,
}

impl Touch {
    /// `true` when the later object stands in front of or behind the earlier one (bearing within
    /// 45° of 0° or 180°): seen from the camera one hides part of the other, and their masks
    /// meet at a depth discontinuity. `false`: side by side, at similar depths where they meet.
    pub fn in_depth(&self) -> bool {
        let b = libm::fabsf(libm::remainderf(self.bearing_deg, 180.0));
        b < 45.0
    }
}

/// Why a clutter scene could not be rendered. Checked before any pixel is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClutterError {
    /// The renderer refused the scene (a view, intrinsics or depth scale error).
    Synth(SynthError),
    /// No object, or more than [`MAX_OBJECTS`].
    ObjectCount,
    /// Object `index` has more than [`MAX_OBJECT_PARTS`] parts, a non-finite position or yaw,
    /// a negative or non-finite gap, or is placed beside itself or a later object.
    InvalidObject { index: u32 },
    /// The floor's drop or half side is not finite and positive, the wall's gap not finite and
    /// `>= 0`, or the flying-pixel probability not in `[0, 1]`.
    InvalidRoom,
    /// `depth` or `scratch` does not hold `width * height` values, or `masks` does not hold
    /// that times the number of objects.
    BufferSize,
}

impl From<SynthError> for ClutterError {
    fn from(e: SynthError) -> Self {
        ClutterError::Synth(e)
    }
}

impl core::fmt::Display for ClutterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ClutterError::Synth(e) => write!(f, "{e}"),
            ClutterError::ObjectCount => {
                write!(f, "a clutter scene holds 1 to {MAX_OBJECTS} objects")
            }
            ClutterError::InvalidObject { index } => {
                write!(
                    f,
                    "object {index} has too many parts or an invalid placement"
                )
            }
            ClutterError::InvalidRoom => write!(
                f,
                "floor drop and size must be finite and positive, wall gap finite and >= 0, \
                 flying pixels in [0, 1]"
            ),
            ClutterError::BufferSize => write!(
                f,
                "depth and scratch must hold width * height values, masks that times the objects"
            ),
        }
    }
}

impl std::error::Error for ClutterError {}

/// A [`Part`] used only to fill unused slots of fixed arrays.
const UNUSED: Part = Part {
    shape: Shape::Sphere { radius: 1.0 },
    pose: Isometry::IDENTITY,
};

/// The solids of a clutter scene, in the object frame ([`ClutterScene::layout`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClutterLayout {
    parts: [Part; MAX_OBJECTS * MAX_OBJECT_PARTS],
    /// First part and part count of each object.
    spans: [(usize, usize); MAX_OBJECTS],
    count: usize,
    /// Each object's origin (the ready object's origin), object frame.
    pub origins: [[f32; 3]; MAX_OBJECTS],
    /// The floor slab.
    pub floor: Part,
    /// The wall slab, if any.
    pub wall: Option<Part>,
    /// The point the camera looks at: the centre of the objects' joint bounding box.
    pub target: [f32; 3],
}

impl ClutterLayout {
    /// The number of objects.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there is no object (never, for a layout [`ClutterScene::layout`] returns).
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Object `i`'s parts, placed (object frame); empty beyond the last object.
    pub fn object(&self, i: usize) -> &[Part] {
        match self.spans.get(i) {
            Some(&(start, n)) if i < self.count => &self.parts[start..start + n],
            _ => &[],
        }
    }

    /// Every object's parts, placed.
    pub fn all_objects(&self) -> &[Part] {
        let end = self.spans[..self.count]
            .last()
            .map_or(0, |&(start, n)| start + n);
        &self.parts[..end]
    }

    /// The room: the floor and, if any, the wall.
    pub fn room(&self) -> ([Part; 2], usize) {
        match self.wall {
            Some(wall) => ([self.floor, wall], 2),
            None => ([self.floor, UNUSED], 1),
        }
    }

    /// Fills `out` with the occluders of object `i`'s render (every other object, the floor,
    /// the wall) and returns how many.
    fn occluders_of(&self, i: usize, out: &mut [Part; MAX_OCCLUDERS]) -> usize {
        let mut n = 0;
        for j in (0..self.count).filter(|&j| j != i) {
            for part in self.object(j) {
                out[n] = *part;
                n += 1;
            }
        }
        let (room, rooms) = self.room();
        for part in &room[..rooms] {
            out[n] = *part;
            n += 1;
        }
        n
    }
}

/// Rotation by `deg` degrees about the object frame's z axis.
fn turn_z(deg: f32) -> Mat3 {
    let (s, c) = sin_cos(deg.to_radians());
    Mat3::from_cols(Vec3::new(c, s, 0.0), Vec3::new(-s, c, 0.0), Vec3::Z)
}

/// `part` turned by `r` about the origin, then moved by `t`.
fn moved(part: &Part, r: Mat3, t: Vec3) -> Part {
    Part {
        shape: part.shape,
        pose: Isometry {
            linear: r * part.pose.linear,
            translation: r * part.pose.translation + t,
        },
    }
}

/// How far `parts` (turned by `yaw_deg` about their origin) reach from the origin in the
/// horizontal direction at `bearing_deg` (both about z, degrees): their support function.
fn reach(parts: &[Part], yaw_deg: f32, bearing_deg: f32) -> f32 {
    // Turn the direction onto +x and read the bounding box (exact for the convex hull).
    let r = turn_z(yaw_deg - bearing_deg);
    let mut turned = [UNUSED; MAX_OBJECT_PARTS];
    for (slot, part) in turned.iter_mut().zip(parts) {
        *slot = moved(part, r, Vec3::ZERO);
    }
    let (_, hi) = synth::bounds(&turned[..parts.len().min(MAX_OBJECT_PARTS)]);
    hi[0]
}

impl ClutterScene<'_> {
    /// The renderer's noise of this scene.
    pub fn synth_noise(&self) -> Noise {
        if self.noise {
            Noise::kinect(self.seed)
        } else {
            Noise::OFF
        }
    }

    /// The renderer's artefacts of this scene (flying pixels only).
    pub fn synth_artefacts(&self) -> Artefacts {
        Artefacts::flying(self.seed ^ FLYING_SEED, self.flying_pixels)
    }

    /// The objects placed touching, in the order of [`ClutterScene::objects`].
    pub fn touching(&self) -> impl Iterator<Item = Touch> + '_ {
        self.objects
            .iter()
            .enumerate()
            .filter_map(|(object, o)| match o.place {
                Place::Beside {
                    of,
                    bearing_deg,
                    gap,
                } => Some(Touch {
                    object,
                    of,
                    bearing_deg,
                    gap,
                }),
                Place::At { .. } => None,
            })
    }

    /// The scene's solids in the object frame: places the objects, the floor and the wall.
    pub fn layout(&self) -> Result<ClutterLayout, ClutterError> {
        let count = self.objects.len();
        if count == 0 || count > MAX_OBJECTS {
            return Err(ClutterError::ObjectCount);
        }
        let positive = |x: f32| x.is_finite() && x > 0.0;
        let room_ok = positive(self.floor_drop)
            && positive(self.floor_half)
            && self.wall_gap.is_none_or(|g| g.is_finite() && g >= 0.0)
            && (0.0..=1.0).contains(&self.flying_pixels);
        if !room_ok {
            return Err(ClutterError::InvalidRoom);
        }
        if !self.view.azimuth_deg.is_finite() {
            return Err(SynthError::InvalidView.into());
        }
        let azimuth = self.view.azimuth_deg;
        let to_object = turn_z(azimuth);

        let mut layout = ClutterLayout {
            parts: [UNUSED; MAX_OBJECTS * MAX_OBJECT_PARTS],
            spans: [(0, 0); MAX_OBJECTS],
            count,
            origins: [[0.0; 3]; MAX_OBJECTS],
            floor: UNUSED,
            wall: None,
            target: [0.0; 3],
        };
        // Arrangement-frame origins (x, y).
        let mut at = [[0.0f32; 2]; MAX_OBJECTS];
        for (i, o) in self.objects.iter().enumerate() {
            let invalid = ClutterError::InvalidObject { index: i as u32 };
            let parts = o.object.parts;
            if parts.is_empty() || parts.len() > MAX_OBJECT_PARTS || !o.yaw_deg.is_finite() {
                return Err(invalid);
            }
            at[i] = match o.place {
                Place::At { x, y } => {
                    if !(x.is_finite() && y.is_finite()) {
                        return Err(invalid);
                    }
                    [x, y]
                }
                Place::Beside {
                    of,
                    bearing_deg,
                    gap,
                } => {
                    if of >= i || !bearing_deg.is_finite() || !(gap.is_finite() && gap >= 0.0) {
                        return Err(invalid);
                    }
                    let other = &self.objects[of];
                    let distance = reach(other.object.parts, other.yaw_deg, bearing_deg)
                        + reach(parts, o.yaw_deg, bearing_deg + 180.0)
                        + gap;
                    let (s, c) = sin_cos(bearing_deg.to_radians());
                    [at[of][0] + distance * c, at[of][1] + distance * s]
                }
            };
            let origin = to_object * Vec3::new(at[i][0], at[i][1], 0.0);
            if !origin.is_finite() {
                return Err(invalid);
            }
            let turn = turn_z(azimuth + o.yaw_deg);
            let start = i * MAX_OBJECT_PARTS;
            for (slot, part) in layout.parts[start..].iter_mut().zip(parts) {
                *slot = moved(part, turn, origin);
            }
            layout.spans[i] = (start, parts.len());
            layout.origins[i] = origin.to_array();
        }
        // Compact the parts so that `all_objects` is one slice.
        let mut next = 0;
        for i in 0..count {
            let (start, n) = layout.spans[i];
            layout.parts.copy_within(start..start + n, next);
            layout.spans[i] = (next, n);
            next += n;
        }
        let (lo, hi) = synth::bounds(layout.all_objects());
        layout.target = [
            0.5 * (lo[0] + hi[0]),
            0.5 * (lo[1] + hi[1]),
            0.5 * (lo[2] + hi[2]),
        ];

        let half = 0.5 * SLAB_THICKNESS;
        layout.floor = Part {
            shape: Shape::Box {
                half: [self.floor_half, self.floor_half, half],
            },
            pose: Isometry {
                linear: Mat3::IDENTITY,
                translation: Vec3::new(0.0, 0.0, -self.floor_drop - half),
            },
        };
        layout.wall = self.wall_gap.map(|gap| {
            // The table's far edge seen from the camera: its support in the direction away from
            // the camera, |cos az| hx + |sin az| hy.
            let (s, c) = sin_cos(azimuth.to_radians());
            let [hx, hy] = self.table_half_size;
            let far_edge = libm::fabsf(c) * hx + libm::fabsf(s) * hy;
            let behind = far_edge + gap + half;
            let bottom = -self.floor_drop;
            Part {
                shape: Shape::Box {
                    half: [half, self.floor_half, 0.5 * (WALL_TOP - bottom)],
                },
                pose: Isometry {
                    linear: to_object,
                    translation: Vec3::new(-behind * c, -behind * s, 0.5 * (WALL_TOP + bottom)),
                },
            }
        });
        Ok(layout)
    }

    /// The renderer's scene for object `i` of `layout` (this scene's): that object as `parts`,
    /// the rest as `occluders` (filled into `occluders`).
    fn synth_scene<'p>(
        &self,
        layout: &'p ClutterLayout,
        i: usize,
        occluders: &'p mut [Part; MAX_OCCLUDERS],
    ) -> SynthScene<'p> {
        let n = layout.occluders_of(i, occluders);
        SynthScene {
            parts: layout.object(i),
            occluders: &occluders[..n],
            artefacts: self.synth_artefacts(),
            target: layout.target,
            view: self.view,
            noise: self.synth_noise(),
            depth_scale: self.depth_scale,
            table_half_size: self.table_half_size,
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Rendering
// ------------------------------------------------------------------------------------------------

/// What [`render_clutter`] reports about one object.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ObjectInView {
    /// Pixels of its true mask.
    pub pixels: u32,
    /// Of them, pixels with a depth reading.
    pub valid_pixels: u32,
    /// The mask's bounding box (a hint as a region).
    pub pixel_box: Rect,
    /// The mask's centroid `(u, v)` (pixels; it need not lie on the object: a bowl's or a mug's
    /// centroid may fall on the far inner wall, an L-shaped mask's outside it).
    pub centroid: [f32; 2],
    /// A pixel on the object for a hint: the pixel nearest the centroid among the mask's
    /// pixels with a reading whose eight neighbours are all in the mask (away from the
    /// silhouette, where flying pixels sit); if there is none, the mask pixel nearest the
    /// centroid. `None` for an empty mask.
    pub hint: Option<[u16; 2]>,
}

/// What [`render_clutter`] reports besides the images.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClutterRendered {
    objects: [ObjectInView; MAX_OBJECTS],
    count: usize,
    /// Object frame -> camera frame.
    pub object_to_camera: Isometry,
    /// The table plane in the camera frame ([`synth::Rendered::table`]).
    pub table: Plane,
    /// Pixels made flying pixels.
    pub flying_pixels: u32,
    /// Pixels where a later object's render read another depth than the first (see the module
    /// docs; 0 on every case).
    pub depth_mismatches: u32,
    /// Pixels two objects' renders both claimed, left to the lower-numbered one (0 on every
    /// case).
    pub contested_pixels: u32,
}

impl ClutterRendered {
    /// Per object, in the order of [`ClutterScene::objects`].
    pub fn objects(&self) -> &[ObjectInView] {
        &self.objects[..self.count]
    }
}

/// Render `scene` with camera `k`: `depth` as [`synth::render`] writes it (`width * height`
/// values, row-major), and in `masks` object `i`'s true mask (255: the nearest hit is object
/// `i`, noise-free; else 0) at `masks[i * n .. (i + 1) * n]` for `n = width * height`. `scratch`
/// (`n` values) holds the depth of the second and later renders (see the module docs).
///
/// Everything is validated before the first pixel is written; on error the buffers are untouched.
pub fn render_clutter(
    scene: &ClutterScene,
    k: &Intrinsics,
    depth: &mut [u16],
    masks: &mut [u8],
    scratch: &mut [u16],
) -> Result<ClutterRendered, ClutterError> {
    let layout = scene.layout()?;
    let count = layout.len();
    k.validate()
        .map_err(|_| ClutterError::Synth(SynthError::InvalidIntrinsics))?;
    let n = k.pixel_count();
    if depth.len() != n || scratch.len() != n || masks.len() != n * count {
        return Err(ClutterError::BufferSize);
    }
    let mut occluders = [UNUSED; MAX_OCCLUDERS];
    let mut objects = [ObjectInView::default(); MAX_OBJECTS];
    let mut mismatches = 0u32;
    let mut first: Option<synth::Rendered> = None;
    for (i, mask) in masks.chunks_exact_mut(n).enumerate() {
        let synth_scene = scene.synth_scene(&layout, i, &mut occluders);
        if let Some(first) = &first {
            let r = synth::render(&synth_scene, k, scratch, mask)?;
            debug_assert_eq!(r.flying_pixels, first.flying_pixels);
            mismatches += depth.iter().zip(&*scratch).filter(|(a, b)| a != b).count() as u32;
        } else {
            // The first render validates every solid (the others are the same solids).
            first = Some(synth::render(&synth_scene, k, depth, mask)?);
        }
    }
    let Some(first) = first else {
        return Err(ClutterError::ObjectCount);
    };

    // Exact ties: keep each pixel in the first mask that claims it.
    let mut contested = 0u32;
    for p in 0..n {
        let mut claimed = false;
        for i in 0..count {
            let m = &mut masks[i * n + p];
            if *m != 0 {
                if claimed {
                    *m = 0;
                    contested += 1;
                }
                claimed = true;
            }
        }
    }
    for (i, info) in objects.iter_mut().take(count).enumerate() {
        *info = describe(&masks[i * n..(i + 1) * n], depth, k.width as usize);
    }
    Ok(ClutterRendered {
        objects,
        count,
        object_to_camera: first.object_to_camera,
        table: first.table,
        flying_pixels: first.flying_pixels,
        depth_mismatches: mismatches,
        contested_pixels: contested,
    })
}

/// Pixel count, box, centroid and hint of one mask (image `width` pixels wide).
fn describe(mask: &[u8], depth: &[u16], width: usize) -> ObjectInView {
    let height = mask.len() / width.max(1);
    let (mut pixels, mut valid) = (0u32, 0u32);
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    let (mut su, mut sv) = (0.0f64, 0.0f64);
    for (p, _) in mask.iter().enumerate().filter(|(_, m)| **m != 0) {
        let (u, v) = (p % width, p / width);
        pixels += 1;
        valid += u32::from(depth[p] != 0);
        lo = [lo[0].min(u), lo[1].min(v)];
        hi = [hi[0].max(u), hi[1].max(v)];
        su += u as f64;
        sv += v as f64;
    }
    if pixels == 0 {
        return ObjectInView::default();
    }
    let centroid = [
        (su / f64::from(pixels)) as f32,
        (sv / f64::from(pixels)) as f32,
    ];
    let inside = |u: usize, v: usize| mask[v * width + u] != 0;
    let interior = |p: usize| {
        let (u, v) = (p % width, p / width);
        depth[p] != 0
            && u > 0
            && v > 0
            && u + 1 < width
            && v + 1 < height
            && (v - 1..=v + 1).all(|y| (u - 1..=u + 1).all(|x| inside(x, y)))
    };
    let nearest = |want_interior: bool| {
        let mut best: Option<(f32, usize)> = None;
        for (p, _) in mask.iter().enumerate().filter(|(_, m)| **m != 0) {
            if want_interior && !interior(p) {
                continue;
            }
            let du = (p % width) as f32 - centroid[0];
            let dv = (p / width) as f32 - centroid[1];
            let d2 = du * du + dv * dv;
            if best.is_none_or(|(b, _)| d2 < b) {
                best = Some((d2, p));
            }
        }
        best.map(|(_, p)| p)
    };
    let hint = nearest(true)
        .or_else(|| nearest(false))
        .map(|p| [(p % width) as u16, (p / width) as u16]);
    ObjectInView {
        pixels,
        valid_pixels: valid,
        pixel_box: Rect {
            u0: lo[0] as u16,
            v0: lo[1] as u16,
            width: (hi[0] - lo[0] + 1) as u16,
            height: (hi[1] - lo[1] + 1) as u16,
        },
        centroid,
        hint,
    }
}

/// A rendered clutter scene in owned buffers (for tests).
#[derive(Clone, Debug, PartialEq)]
pub struct ClutterFrame {
    pub depth: Vec<u16>,
    /// Every object's mask, one after the other (see [`render_clutter`]).
    pub masks: Vec<u8>,
    pub rendered: ClutterRendered,
}

impl ClutterFrame {
    /// Renders `scene` with camera `k` ([`render_clutter`]).
    pub fn render(scene: &ClutterScene, k: &Intrinsics) -> Result<ClutterFrame, ClutterError> {
        let count = scene.objects.len();
        if count == 0 || count > MAX_OBJECTS {
            return Err(ClutterError::ObjectCount);
        }
        k.validate()
            .map_err(|_| ClutterError::Synth(SynthError::InvalidIntrinsics))?;
        let n = k.pixel_count();
        let mut depth = vec![0u16; n];
        let mut masks = vec![0u8; n * count];
        let mut scratch = vec![0u16; n];
        let rendered = render_clutter(scene, k, &mut depth, &mut masks, &mut scratch)?;
        Ok(ClutterFrame {
            depth,
            masks,
            rendered,
        })
    }

    /// Object `i`'s true mask (empty beyond the last object).
    pub fn mask(&self, i: usize) -> &[u8] {
        let n = self.depth.len();
        self.masks.get(i * n..(i + 1) * n).unwrap_or(&[])
    }

    /// The pixels of any object (255) or of none (0).
    pub fn union_mask(&self) -> Vec<u8> {
        let n = self.depth.len();
        (0..n)
            .map(|p| {
                if self.masks[p..].iter().step_by(n).any(|m| *m != 0) {
                    255
                } else {
                    0
                }
            })
            .collect()
    }
}

// ------------------------------------------------------------------------------------------------
// The cases
// ------------------------------------------------------------------------------------------------

const CAN: &ReadyObject = &OBJECTS[0];
const CEREAL_BOX: &ReadyObject = &OBJECTS[1];
const BOWL: &ReadyObject = &OBJECTS[2];
const BALL: &ReadyObject = &OBJECTS[3];
const CONE: &ReadyObject = &OBJECTS[4];
const TWO_PLANE: &ReadyObject = &OBJECTS[5];
const CHAIR: &ReadyObject = &OBJECTS[6];
const MUG: &ReadyObject = &OBJECTS[9];
const LUMP: &ReadyObject = &OBJECTS[10];

const fn at(object: &'static ReadyObject, x: f32, y: f32, yaw_deg: f32) -> ClutterObject {
    ClutterObject {
        object,
        place: Place::At { x, y },
        yaw_deg,
    }
}

const fn beside(
    object: &'static ReadyObject,
    of: usize,
    bearing_deg: f32,
    gap: f32,
    yaw_deg: f32,
) -> ClutterObject {
    ClutterObject {
        object,
        place: Place::Beside {
            of,
            bearing_deg,
            gap,
        },
        yaw_deg,
    }
}

// Gaps: objects side by side touch with a gap of 0 (a can against a can) or 0.3 mm, less than
// a pixel's footprint (0.9 mm at 0.5 m on the Xtion), so that their masks meet as a real
// contact's do; objects one in front of the other leave 2-3 mm (a box set down next to a can),
// which the front one's silhouette hides. The arrangements on the dev table stand 0.2-0.25 m
// behind its centre, toward the wall, so that the wall and the floor beyond the table's far edge
// show in the image from most views.

/// A cereal box (broad face to the camera), a can in front of it, a ball against its side.
const BOX_CAN_BALL: [ClutterObject; 3] = [
    at(CEREAL_BOX, -0.25, 0.0, 0.0),
    beside(CAN, 0, 0.0, 0.002, 0.0),
    beside(BALL, 0, 90.0, 0.0, 0.0),
];
/// Two cans side by side, a mug in front of the left one, its handle to the right.
const CANS_MUG: [ClutterObject; 3] = [
    at(CAN, -0.25, -0.04, 0.0),
    beside(CAN, 0, 90.0, 0.0, 0.0),
    beside(MUG, 0, 0.0, 0.003, 90.0),
];
/// A bowl with a can against its left side, a ball apart.
const BOWL_CAN_BALL: [ClutterObject; 3] = [
    at(BOWL, -0.2, 0.03, 0.0),
    beside(CAN, 0, -90.0, 0.0, 0.0),
    at(BALL, -0.08, 0.16, 0.0),
];
/// A cereal box, a mug in front of it (handle to the left), a can against its left side.
const MUG_BOX_CAN: [ClutterObject; 3] = [
    at(CEREAL_BOX, -0.25, 0.0, 0.0),
    beside(MUG, 0, 0.0, 0.003, -90.0),
    beside(CAN, 0, -90.0, 0.0, 0.0),
];
/// Five: a cereal box, a can in front of it, a ball and a bowl against its sides, a cone
/// against the can's front right (its base, wider than the can, clear of the box).
const FIVE: [ClutterObject; 5] = [
    at(CEREAL_BOX, -0.25, 0.0, 0.0),
    beside(CAN, 0, 0.0, 0.002, 0.0),
    beside(BALL, 0, 90.0, 0.0, 0.0),
    beside(BOWL, 0, -90.0, 0.0, 0.0),
    beside(CONE, 1, 60.0, 0.0, 0.0),
];
/// The two-plane object, the chair against its right side, a can in front of it.
const TWO_PLANE_CHAIR_CAN: [ClutterObject; 3] = [
    at(TWO_PLANE, -0.2, -0.05, 0.0),
    beside(CHAIR, 0, 90.0, 0.0, 0.0),
    beside(CAN, 0, 0.0, 0.003, 0.0),
];
/// A cereal box, the asymmetric lump in front of it, a can against its left side.
const LUMP_BOX_CAN: [ClutterObject; 3] = [
    at(CEREAL_BOX, -0.25, 0.05, 0.0),
    beside(LUMP, 0, 0.0, 0.002, 0.0),
    beside(CAN, 0, -90.0, 0.0, 0.0),
];
/// A can, a ball in front of it, a second ball against the first's right side.
const BALLS_CAN: [ClutterObject; 3] = [
    at(CAN, -0.25, 0.0, 0.0),
    beside(BALL, 0, 0.0, 0.002, 0.0),
    beside(BALL, 1, 90.0, 0.0, 0.0),
];
/// A can, a mug against its left side with the handle touching it, a cone in front of the can.
const MUG_HANDLE_CAN_CONE: [ClutterObject; 3] = [
    at(CAN, -0.22, 0.04, 0.0),
    beside(MUG, 0, -90.0, 0.0, 90.0),
    beside(CONE, 0, 0.0, 0.002, 0.0),
];
/// Two cans side by side.
const PAIR_OF_CANS: [ClutterObject; 2] =
    [at(CAN, -0.2, -0.035, 0.0), beside(CAN, 0, 90.0, 0.0, 0.0)];
/// A cereal box and the two-plane object side by side, a ball apart in front.
const BOX_TWO_PLANE_BALL: [ClutterObject; 3] = [
    at(CEREAL_BOX, -0.25, -0.05, 0.0),
    beside(TWO_PLANE, 0, 90.0, 0.0003, 0.0),
    at(BALL, -0.05, 0.0, 0.0),
];

// On the small support (within about 0.13 m of its centre, so on it from every azimuth).

/// A can and a ball side by side.
const SMALL_CAN_BALL: [ClutterObject; 2] =
    [at(CAN, -0.03, -0.04, 0.0), beside(BALL, 0, 90.0, 0.0, 0.0)];
/// A can, a bowl in front of it (its rim against the can), a mug against the can's left side.
const SMALL_CAN_BOWL_MUG: [ClutterObject; 3] = [
    at(CAN, -0.06, 0.02, 0.0),
    beside(BOWL, 0, 0.0, 0.003, 0.0),
    beside(MUG, 0, -90.0, 0.0, 180.0),
];
/// A cereal box, a can in front of it, a can against its right side.
const SMALL_BOX_CANS: [ClutterObject; 3] = [
    at(CEREAL_BOX, -0.04, -0.03, 0.0),
    beside(CAN, 0, 0.0, 0.002, 0.0),
    beside(CAN, 0, 90.0, 0.0, 0.0),
];
/// Two balls side by side, a can against the left one's left side.
const SMALL_BALLS_CAN: [ClutterObject; 3] = [
    at(BALL, 0.0, -0.02, 0.0),
    beside(BALL, 0, 90.0, 0.0, 0.0),
    beside(CAN, 0, -90.0, 0.0, 0.0),
];

const fn view(distance: f32, elevation_deg: f32, azimuth_deg: f32) -> View {
    View {
        distance,
        elevation_deg,
        azimuth_deg,
        roll_deg: 0.0,
    }
}

/// A case on the dev scenes' table ([`TABLE_HALF_SIZE`], [`TABLE_HEIGHT`] above the floor of
/// [`FLOOR_HALF`]), with a wall `wall_gap` behind it, Kinect noise.
#[allow(clippy::too_many_arguments)]
const fn on_table(
    name: &'static str,
    objects: &'static [ClutterObject],
    view: View,
    wall_gap: Option<f32>,
    flying_pixels: f32,
    seed: u32,
    xtion: bool,
) -> ClutterCase {
    ClutterCase {
        scene: ClutterScene {
            name,
            objects,
            view,
            table_half_size: TABLE_HALF_SIZE,
            floor_drop: TABLE_HEIGHT,
            floor_half: FLOOR_HALF,
            wall_gap,
            noise: true,
            flying_pixels,
            seed,
            depth_scale: if xtion { XTION_DEPTH_SCALE } else { 0.001 },
        },
        intrinsics: if xtion {
            XTION_INTRINSICS
        } else {
            BUILTIN_INTRINSICS
        },
    }
}

/// A case on the small support ([`SMALL_SUPPORT_HALF_SIZE`], [`SMALL_SUPPORT_HEIGHT`] above the
/// floor of [`SMALL_SUPPORT_FLOOR_HALF`]).
const fn on_small_support(
    name: &'static str,
    objects: &'static [ClutterObject],
    view: View,
    wall_gap: Option<f32>,
    flying_pixels: f32,
    seed: u32,
    xtion: bool,
) -> ClutterCase {
    let case = on_table(name, objects, view, wall_gap, flying_pixels, seed, xtion);
    ClutterCase {
        scene: ClutterScene {
            table_half_size: SMALL_SUPPORT_HALF_SIZE,
            floor_drop: SMALL_SUPPORT_HEIGHT,
            floor_half: SMALL_SUPPORT_FLOOR_HALF,
            ..case.scene
        },
        ..case
    }
}

/// The clutter cases: 24 scenes of 2 to 5 objects, Kinect noise, each its own seed; views 0.5 to
/// 1 m away, 30° to 60° above the table, from all around; 16 on the Xtion (640 x 480, 0.1 mm
/// units), 8 on the built-in camera (320 x 240, mm); 6 on the small support (one of them with a
/// wall); 12 with flying pixels (30 %, 50 % or every discontinuity pixel).
pub const CLUTTER_CASES: [ClutterCase; 24] = [
    // The Xtion, the dev table, a wall.
    on_table(
        "box_can_ball",
        &BOX_CAN_BALL,
        view(0.8, 45.0, 30.0),
        Some(0.1),
        0.0,
        1,
        true,
    ),
    on_table(
        "cans_mug",
        &CANS_MUG,
        view(0.7, 35.0, 120.0),
        Some(0.2),
        0.5,
        2,
        true,
    ),
    on_table(
        "bowl_can_ball",
        &BOWL_CAN_BALL,
        view(0.9, 55.0, -60.0),
        Some(0.05),
        0.0,
        3,
        true,
    ),
    on_table(
        "mug_box_can",
        &MUG_BOX_CAN,
        view(1.0, 40.0, 200.0),
        Some(0.3),
        1.0,
        4,
        true,
    ),
    on_table(
        "five",
        &FIVE,
        view(0.9, 50.0, 75.0),
        Some(0.15),
        0.5,
        5,
        true,
    ),
    on_table(
        "two_plane_chair_can",
        &TWO_PLANE_CHAIR_CAN,
        view(0.75, 30.0, 10.0),
        Some(0.1),
        0.0,
        6,
        true,
    ),
    on_table(
        "lump_box_can",
        &LUMP_BOX_CAN,
        view(0.85, 60.0, 250.0),
        Some(0.2),
        0.3,
        7,
        true,
    ),
    on_table(
        "balls_can",
        &BALLS_CAN,
        view(0.6, 45.0, 300.0),
        Some(0.1),
        0.0,
        8,
        true,
    ),
    on_table(
        "mug_handle_can_cone",
        &MUG_HANDLE_CAN_CONE,
        view(0.65, 35.0, 160.0),
        Some(0.25),
        1.0,
        9,
        true,
    ),
    on_table(
        "pair_of_cans",
        &PAIR_OF_CANS,
        view(0.5, 50.0, 45.0),
        Some(0.1),
        0.0,
        10,
        true,
    ),
    on_table(
        "box_two_plane_ball",
        &BOX_TWO_PLANE_BALL,
        view(0.7, 40.0, -20.0),
        Some(0.15),
        0.5,
        11,
        true,
    ),
    on_table(
        "five_far",
        &FIVE,
        view(1.0, 35.0, 220.0),
        Some(0.05),
        0.0,
        12,
        true,
    ),
    // The built-in camera.
    on_table(
        "box_can_ball_320",
        &BOX_CAN_BALL,
        view(0.7, 50.0, 100.0),
        Some(0.2),
        0.5,
        13,
        false,
    ),
    on_table(
        "cans_mug_320",
        &CANS_MUG,
        view(0.55, 40.0, 20.0),
        Some(0.1),
        0.0,
        14,
        false,
    ),
    on_table(
        "bowl_can_ball_320",
        &BOWL_CAN_BALL,
        view(0.8, 45.0, 270.0),
        Some(0.1),
        1.0,
        15,
        false,
    ),
    on_table(
        "lump_box_can_320",
        &LUMP_BOX_CAN,
        view(0.9, 35.0, 60.0),
        Some(0.2),
        0.0,
        16,
        false,
    ),
    on_table(
        "two_plane_chair_can_320",
        &TWO_PLANE_CHAIR_CAN,
        view(0.6, 55.0, 140.0),
        Some(0.15),
        0.3,
        17,
        false,
    ),
    on_table(
        "mug_handle_can_cone_320",
        &MUG_HANDLE_CAN_CONE,
        view(0.75, 45.0, 330.0),
        None,
        0.0,
        18,
        false,
    ),
    // The small support.
    on_small_support(
        "small_can_ball",
        &SMALL_CAN_BALL,
        view(0.7, 45.0, 30.0),
        None,
        0.5,
        19,
        true,
    ),
    on_small_support(
        "small_can_bowl_mug",
        &SMALL_CAN_BOWL_MUG,
        view(0.8, 55.0, 150.0),
        None,
        0.0,
        20,
        true,
    ),
    on_small_support(
        "small_box_cans_320",
        &SMALL_BOX_CANS,
        view(0.6, 40.0, 240.0),
        None,
        1.0,
        21,
        false,
    ),
    on_small_support(
        "small_balls_can_320",
        &SMALL_BALLS_CAN,
        view(1.0, 60.0, 300.0),
        None,
        0.0,
        22,
        false,
    ),
    on_small_support(
        "small_box_cans_wall",
        &SMALL_BOX_CANS,
        view(0.9, 35.0, 90.0),
        Some(0.3),
        0.5,
        23,
        true,
    ),
    on_small_support(
        "small_can_ball_near",
        &SMALL_CAN_BALL,
        view(0.5, 30.0, 180.0),
        None,
        0.0,
        24,
        true,
    ),
];

/// The cases of [`CLUTTER_CASES`], in order.
pub fn clutter_cases() -> impl Iterator<Item = ClutterCase> {
    CLUTTER_CASES.into_iter()
}

/// The engine's choice on a clutter frame: its report and the pixels of its sampled points (the
/// chosen object's pixels on its sampling lattice, and on its outline).
pub struct Selection {
    pub report: shape_from_symmetry::Report,
    pub pixels: Vec<usize>,
}

/// Search `frame` (camera `k`, `depth_scale`) with neither mask nor table, naming the object by
/// `target`, with the host engine at its default configuration.
pub fn select(
    frame: &ClutterFrame,
    k: Intrinsics,
    depth_scale: f32,
    target: Option<shape_from_symmetry::Target>,
) -> Result<Selection, shape_from_symmetry::Error> {
    let config = shape_from_symmetry::Config::DEFAULT;
    select_in(&frame.depth, k, depth_scale, target, config)
}

/// [`select`] in any depth image (row-major, `k.width * k.height` values), with `config`.
pub fn select_in(
    depth: &[u16],
    k: Intrinsics,
    depth_scale: f32,
    target: Option<shape_from_symmetry::Target>,
    config: shape_from_symmetry::Config,
) -> Result<Selection, shape_from_symmetry::Error> {
    use shape_from_symmetry::{CompletedPoint, Scene, Status};
    let scene = Scene {
        target,
        ..Scene::new(depth, depth_scale, k)
    };
    let mut output = vec![CompletedPoint::ZERO; crate::search::OUTPUT_POINTS];
    let mut engine = Box::new(crate::search::HostEngine::new(config));
    engine.start(scene, &mut output)?;
    while engine.poll(crate::search::DEFAULT_BUDGET)? == Status::Working {}
    let w = k.width as usize;
    let pixels = engine
        .object_points()
        .iter()
        .map(|p| {
            let (u, v) = (
                (k.fx * p.x / p.z + k.cx).round(),
                (k.fy * p.y / p.z + k.cy).round(),
            );
            v as usize * w + u as usize
        })
        .collect();
    Ok(Selection {
        report: engine.report().clone(),
        pixels,
    })
}

/// IoU of `chosen` (the pixels of the sampled points) with `mask` restricted to pixels with a
/// reading (the engine cannot choose a pixel without one), both on the sampling lattice: the
/// largest stride (up to the engine's 16) whose lattice holds more than half of the chosen
/// pixels; the others are outline points, off it, and left out. An unbiased estimate of the
/// IoU over the whole image.
pub fn lattice_iou(chosen: &[usize], mask: &[u8], depth: &[u16], width: usize) -> f32 {
    let w = width.max(1);
    let on = |s: usize, p: usize| (p % w).is_multiple_of(s) && (p / w).is_multiple_of(s);
    let stride = (1..=16)
        .rev()
        .find(|&s| chosen.iter().filter(|&&p| on(s, p)).count() * 2 > chosen.len())
        .unwrap_or(1);
    let chosen: Vec<usize> = chosen.iter().copied().filter(|&p| on(stride, p)).collect();
    let truth = (0..mask.len().min(depth.len()))
        .filter(|&p| on(stride, p) && mask[p] != 0 && depth[p] != 0)
        .count();
    let both = chosen
        .iter()
        .filter(|&&p| mask.get(p).is_some_and(|&m| m != 0))
        .count();
    let union = truth + chosen.len() - both;
    if union == 0 {
        0.0
    } else {
        both as f32 / union as f32
    }
}

/// One object of one case, selected by a target.
#[derive(Clone, Debug)]
pub struct Hinted {
    pub scene: &'static str,
    pub object: usize,
    /// IoU of the chosen region with the object's true mask ([`lattice_iou`]); 0 on an error.
    pub iou: f32,
    pub error: Option<shape_from_symmetry::Error>,
}

/// Every object of every case of [`clutter_cases`] named by `hint(object)` (objects it gives no
/// target are skipped), and how well the engine's choice matches it.
pub fn hinted(
    hint: impl Fn(&ObjectInView) -> Option<shape_from_symmetry::Target>,
) -> Result<Vec<Hinted>, ClutterError> {
    let mut out = Vec::new();
    for case in clutter_cases() {
        let (scene, k) = (case.scene, case.intrinsics);
        let frame = ClutterFrame::render(&scene, &k)?;
        for (i, object) in frame.rendered.objects().iter().enumerate() {
            let Some(target) = hint(object) else { continue };
            let result = select(&frame, k, scene.depth_scale, Some(target));
            out.push(Hinted {
                scene: scene.name,
                object: i,
                iou: result.as_ref().map_or(0.0, |s| {
                    lattice_iou(&s.pixels, frame.mask(i), &frame.depth, k.width as usize)
                }),
                error: result.err(),
            });
        }
    }
    Ok(out)
}
