//! The C types: the engine handle, the scene description, points, results, symmetries; the
//! constants a C firmware sizes its buffers with.

use core::mem::{align_of, size_of};

use shape_from_symmetry::MAX_SYMMETRIES;
use shape_from_symmetry::{
    CompletedPoint, DefaultEngine, Found, Provenance, RECOMMENDED_BUDGET, Segmentation, TypeSet,
};

use crate::*;

/// A work budget for one `sfs_poll` per tick of a 1 kHz control loop on a 168 MHz Cortex-M4F:
/// every poll of the built-in scene stays under 100 000 instructions (measured under QEMU; CI
/// fails above; the figures are in docs/figures.md).
pub const SFS_RECOMMENDED_BUDGET: u32 = 120;
/// Most symmetries one search reports (`SfsResult.symmetries` is at most this).
pub const SFS_MAX_SYMMETRIES: u32 = 8;
/// The mask of `sfs_config_types` that selects every type (the default).
pub const SFS_TYPES_ALL: u32 = 0xFF;
/// Bytes of storage that suffice for an engine on every supported target (`sfs_engine_size()`
/// is the exact need of the build at hand, a little less on 32-bit targets): for a `static`
/// buffer whose size must be known at compile time. 117 KiB: the engine's inline memory on a
/// 64-bit host rounded up, with under 1 KiB to spare (the exact size is in docs/figures.md; a
/// compile-time check keeps it sufficient, and a version whose engine outgrows it raises it).
pub const SFS_ENGINE_STORAGE_BYTES: usize = 119_808;
/// An alignment that suffices for the engine's storage on every supported target
/// (`sfs_engine_align()` is the exact need).
pub const SFS_ENGINE_STORAGE_ALIGN: usize = 8;
/// `SfsScene.target_kind`: no target; without a mask the engine chooses the object (the
/// candidate region of plausible size at the optical axis, or else nearest it).
pub const SFS_TARGET_NONE: u32 = 0;
/// `SfsScene.target_kind`: the object is the candidate region holding pixel
/// (`target_u`, `target_v`).
pub const SFS_TARGET_PIXEL: u32 = 1;
/// `SfsScene.target_kind`: the object is the candidate region with the most of its pixel blocks
/// in the region `target_u`, `target_v` (first column and row), `target_width`, `target_height`.
pub const SFS_TARGET_REGION: u32 = 2;

/// The header's constants are literals (cbindgen copies them); these checks keep them true.
const _: () = {
    assert!(SFS_RECOMMENDED_BUDGET == RECOMMENDED_BUDGET);
    assert!(SFS_MAX_SYMMETRIES as usize == MAX_SYMMETRIES);
    assert!(SFS_TYPES_ALL == TypeSet::ALL.0 as u32);
    assert!(size_of::<SfsEngine>() <= SFS_ENGINE_STORAGE_BYTES);
    assert!(align_of::<SfsEngine>() <= SFS_ENGINE_STORAGE_ALIGN);
    assert!(SFS_ENGINE_STORAGE_BYTES.is_multiple_of(SFS_ENGINE_STORAGE_ALIGN));
    // SfsPoint: `float position[3]; float plausibility; uint8_t provenance; uint8_t symmetry;`
    // and two bytes of padding, on every target.
    assert!(size_of::<SfsPoint>() == 20 && align_of::<SfsPoint>() == 4);
};

/// Where a completed point comes from (`SfsPoint.provenance`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SfsProvenance {
    /// A visible point of the object: an object pixel (one per sampling cell, or each one when
    /// the output has room for the completion's dense pass).
    Visible = 0,
    /// A point a symmetry predicts in space the camera could not see.
    Generated = 1,
}

/// One point of the completed object, in the caller's output buffer. The C view of the
/// library's `CompletedPoint` (same layout, checked at compile time).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsPoint {
    /// Camera frame, metres.
    pub position: [f32; 3],
    /// How plausible the point is, in [0, 1]: 1 for visible points; for generated points the
    /// support of the symmetry that made them.
    pub plausibility: f32,
    /// Visible or generated.
    pub provenance: SfsProvenance,
    /// Index (for `sfs_symmetry`) of the symmetry whose domain holds the point (visible) or
    /// that generated it; 255 for a visible point no symmetry explains.
    pub symmetry: u8,
}

const _: () = {
    use core::mem::offset_of;
    assert!(size_of::<SfsPoint>() == size_of::<CompletedPoint>());
    assert!(align_of::<SfsPoint>() == align_of::<CompletedPoint>());
    assert!(offset_of!(SfsPoint, position) == offset_of!(CompletedPoint, position));
    assert!(offset_of!(SfsPoint, plausibility) == offset_of!(CompletedPoint, plausibility));
    assert!(offset_of!(SfsPoint, provenance) == offset_of!(CompletedPoint, provenance));
    assert!(offset_of!(SfsPoint, symmetry) == offset_of!(CompletedPoint, symmetry));
    assert!(SfsProvenance::Visible as u8 == Provenance::Visible as u8);
    assert!(SfsProvenance::Generated as u8 == Provenance::Generated as u8);
};

/// "SFS1": written by `sfs_init` in front of a valid engine.
pub(crate) const MAGIC: u32 = 0x5346_5331;

/// The engine in caller storage: opaque to C. Obtain one with [`sfs_init`].
#[derive(Debug)]
pub struct SfsEngine {
    pub(crate) magic: u32,
    pub(crate) engine: DefaultEngine<'static>,
    /// The caller's output buffer. The engine does not hold it: the C caller reads it between
    /// calls, which a Rust `&mut` kept from one call to the next would forbid, so `sfs_poll`
    /// lends it to the engine for that call alone.
    pub(crate) output: Output,
}

/// The output buffer of the last `sfs_set_input`: null and 0, or a range `set_input` checked
/// (non-null, aligned, not wrapping, overlapping neither depth, mask nor the engine's storage)
/// and initialised with valid points.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Output {
    pub(crate) points: *mut CompletedPoint,
    pub(crate) capacity: usize,
}

// SAFETY: `Sync` is needed only so that `FRESH` (which holds a null `Output`) can be a `static`.
// A shared `&Output` gives nothing but the pointer's value; dereferencing it is `sfs_poll`'s
// `unsafe`, on an engine used by one caller at a time (the API's thread contract).
unsafe impl Sync for Output {}

impl Output {
    pub(crate) const NONE: Self = Self {
        points: core::ptr::null_mut(),
        capacity: 0,
    };
}

/// One depth image with its camera, optional table plane and mask, and the output buffer: the
/// argument of [`sfs_set_input`].
///
/// Lifetime: `sfs_set_input` copies this struct, but `depth`, `mask` and `output` must stay
/// valid, and `depth` and `mask` unchanged, until the next `sfs_set_input` or `sfs_init` on the
/// same engine storage. The engine writes `output` during `sfs_poll`; read it between calls, and
/// do not write it while the engine owns it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SfsScene {
    /// Row-major depth values, `width * height` of them; 0 = no reading. Aligned to 2 bytes.
    pub depth: *const u16,
    /// Number of depth values (not bytes).
    pub depth_len: usize,
    /// Metres per depth unit (0.001 for millimetres); depth is along the optical axis.
    pub depth_scale: f32,
    /// Image size in pixels (each at most 65 535).
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Pinhole intrinsics in pixels (focal length along x); pixel (u, v) has its centre at
    /// (u, v).
    pub fx: f32,
    /// Focal length along y, pixels.
    pub fy: f32,
    /// Principal point x, pixels.
    pub cx: f32,
    /// Principal point y, pixels.
    pub cy: f32,
    /// Non-zero: the table plane `table_normal · X = table_offset` (camera frame, metres; unit
    /// normal pointing away from the table, toward the camera's side) is given. Zero: the
    /// engine fits it (unless a mask is given).
    pub has_table: u32,
    /// The table plane's unit normal (with `has_table`).
    pub table_normal: [f32; 3],
    /// The table plane's offset, metres (with `has_table`).
    pub table_offset: f32,
    /// Optional object mask, row-major, non-zero = object pixel. NULL (with `mask_len` 0): the
    /// engine segments the object itself.
    pub mask: *const u8,
    /// Number of mask values; `width * height` with a mask.
    pub mask_len: usize,
    /// Where the completed points go (visible, then generated). Aligned to 4 bytes. NULL with
    /// capacity 0 runs the search without completion output (every point is counted dropped).
    pub output: *mut SfsPoint,
    /// Number of `SfsPoint`s `output` holds: each point is visible or the image of one under a
    /// map; what does not fit is counted in `points_dropped`. An output with room for several
    /// times the sampled completion gets the dense one (every object pixel and its images).
    pub output_capacity: usize,
    /// Which object to segment when no mask is given (ignored with a mask, but still checked):
    /// `SFS_TARGET_NONE` (0: the engine chooses; the other target fields are then ignored),
    /// `SFS_TARGET_PIXEL` or `SFS_TARGET_REGION`; another value is `ERR_UNKNOWN_TARGET_KIND`.
    /// A pixel outside the image, or a region that is empty or not wholly inside it, is
    /// `ERR_TARGET_OUTSIDE_IMAGE` (values above 65 535 included); no candidate region there
    /// makes `sfs_poll` return `ERR_TARGET_ON_NO_OBJECT`. A zeroed scene has no target.
    pub target_kind: u32,
    /// The target pixel's column, or the region's first column.
    pub target_u: u32,
    /// The target pixel's row, or the region's first row.
    pub target_v: u32,
    /// The region's width in pixels (`SFS_TARGET_REGION` only).
    pub target_width: u32,
    /// The region's height in pixels (`SFS_TARGET_REGION` only).
    pub target_height: u32,
}

/// What the search has found so far and what it cost: [`sfs_result`]'s output.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsResult {
    /// Where the engine is, as `sfs_poll` would say without doing any work: `SFS_STATUS_WORKING`,
    /// `SFS_STATUS_DONE`, the error that ended the search, or `SFS_STATUS_ERR_NOT_STARTED`
    /// before any input.
    pub state: SfsStatus,
    /// Symmetries found so far (strongest first; query each with `sfs_symmetry`).
    pub symmetries: u32,
    /// Visible and generated points written to the output; `points_visible + points_generated`
    /// equals `sfs_points_written()`.
    pub points_visible: u32,
    /// Generated points written to the output.
    pub points_generated: u32,
    /// Points left out because the output (or the engine's deduplication table) was full;
    /// non-zero means the output is incomplete.
    pub points_dropped: u32,
    /// Object pixels with a reading.
    pub object_pixels: u32,
    /// Object points sampled for the search.
    pub sampled_points: u32,
    /// Polls so far.
    pub polls: u32,
    /// Work units the polls did.
    pub work_units: u64,
    /// Non-zero once the engine has segmented the object (no mask given; set when the
    /// preparation is over): `candidates`, `chosen` and `object_box` are then valid (zero, -1
    /// and zeros otherwise).
    pub segmented: u32,
    /// Candidate object regions: connected regions above the support plane, within the working
    /// range, of a plausible object size.
    pub candidates: u32,
    /// The chosen region's index among the candidates (raster order of their first pixel block,
    /// from 0); -1 when the target named a region of implausible size, or without segmentation.
    pub chosen: i32,
    /// The object's pixel box: first column, first row, width, height.
    pub object_box: [u32; 4],
}

impl SfsResult {
    /// The segmentation fields of a report's segmentation.
    pub(crate) fn segmentation(segmentation: Option<Segmentation>) -> (u32, u32, i32, [u32; 4]) {
        match segmentation {
            None => (0, 0, -1, [0; 4]),
            Some(s) => {
                let b = s.object_box;
                (
                    1,
                    s.candidates.into(),
                    s.chosen.map_or(-1, i32::from),
                    [b.u0.into(), b.v0.into(), b.width.into(), b.height.into()],
                )
            }
        }
    }
}

/// A mirror plane `normal · X = offset` (camera frame, metres; unit normal).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsPlane {
    /// Unit normal.
    pub normal: [f32; 3],
    /// Signed distance of the plane from the camera's origin along `normal`, metres.
    pub offset: f32,
}

/// One symmetry found: [`sfs_symmetry`]'s output. Geometry in the camera frame (metres).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsSymmetry {
    /// The symmetry type.
    pub kind: SfsSymmetryType,
    /// The measurement model's score (lower is better): the mean cost of the transformed points;
    /// for a composite, the mean of its elements' means when each passes, else the least confirmed
    /// element's.
    pub score: f32,
    /// `1 - score / accept` within 0..=1: the share of the acceptance margin left (0: at the
    /// threshold or above it). How often a symmetry of a given confidence is true: docs/figures.md.
    pub confidence: f32,
    /// Visible (sampled) points this symmetry explains.
    pub domain_points: u32,
    /// Mirror planes: 1 for plane reflection and axial + plane, 2 for dual plane, 3 for triple
    /// plane, else 0. Entries past `plane_count` are zero.
    pub plane_count: u32,
    /// The planes, `plane_count` of them first.
    pub planes: [SfsPlane; 3],
    /// Non-zero for line reflection, axial and axial + plane: the axis through `axis_point`
    /// along the unit vector `axis_direction` (zero otherwise).
    pub has_axis: u32,
    /// The axis's unit direction (with `has_axis`).
    pub axis_direction: [f32; 3],
    /// A point on the axis (with `has_axis`), metres.
    pub axis_point: [f32; 3],
    /// Non-zero for point reflection and spherical: the centre (zero otherwise).
    pub has_centre: u32,
    /// The centre (with `has_centre`), metres.
    pub centre: [f32; 3],
}

impl SfsSymmetry {
    pub(crate) fn new(found: &Found) -> Self {
        let symmetry = &found.symmetry;
        let mut planes = [SfsPlane {
            normal: [0.0; 3],
            offset: 0.0,
        }; 3];
        let listed = symmetry.planes();
        for (slot, plane) in planes.iter_mut().zip(listed) {
            *slot = SfsPlane {
                normal: plane.normal,
                offset: plane.offset,
            };
        }
        let axis = symmetry.axis();
        let centre = symmetry.center();
        Self {
            kind: symmetry.kind().into(),
            score: found.score,
            confidence: found.confidence,
            domain_points: found.domain_points,
            plane_count: listed.len() as u32,
            planes,
            has_axis: axis.is_some() as u32,
            axis_direction: axis.map_or([0.0; 3], |a| a.direction),
            axis_point: axis.map_or([0.0; 3], |a| a.point),
            has_centre: centre.is_some() as u32,
            centre: centre.unwrap_or([0.0; 3]),
        }
    }
}
