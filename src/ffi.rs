//! The C API (cargo feature `ffi`): the only module of the crate with `unsafe` code.
//!
//! The header `include/shape_from_symmetry.h` is generated from this file by cbindgen
//! (`cbindgen.toml`; `ci/c_api.sh` fails when the committed header is stale), so the doc comments
//! below are also the C documentation. The README's "C API" section shows a poll loop.
//!
//! # Design
//!
//! - **Storage.** The caller provides the engine's memory: [`sfs_engine_size`] bytes aligned to
//!   [`sfs_engine_align`] (both at most [`SFS_ENGINE_STORAGE_BYTES`] and
//!   [`SFS_ENGINE_STORAGE_ALIGN`], compile-time constants for a `static` buffer). [`sfs_init`]
//!   checks pointer, size and alignment and copies a fresh [`DefaultEngine`] there behind a
//!   magic number (from a constant image in flash: no stack, no allocation), and hands out the
//!   same address as the opaque `SfsEngine *` handle. Every
//!   other call checks the handle (null, alignment, magic) before it touches the engine, so a
//!   handle to storage that was never initialised is an error, not undefined behaviour — as
//!   long as the storage's bytes are defined (static storage is zeroed; see [`sfs_init`]).
//! - **Lifetime contract.** [`sfs_set_input`] copies the [`SfsScene`] description (the struct
//!   itself may be reused at once) but *borrows* the buffers it points to: depth, mask and output
//!   must stay valid, and depth and mask unchanged, until the next `sfs_set_input` or `sfs_init`
//!   on the same storage (or until the storage is no longer used). This is the one promise Rust
//!   cannot check; it is where the engine's `'static` borrows of depth and mask come from (see
//!   the `SAFETY` comments in `sfs_set_input`). The output is not borrowed across calls: the
//!   handle keeps a raw pointer, and each `sfs_poll` makes the only reference to the buffer
//!   for that call alone (`Engine::poll_into`), so C may read it between polls.
//! - **Points.** The completed points are written into the caller's output buffer as the search
//!   completes; [`sfs_points_written`] tells how many are valid. No copy and no second buffer
//!   (an output of 3 072 points is 60 KiB on the M4), and the buffer is the caller's own
//!   `SfsPoint` array, read directly. The caller reads it between calls and never writes it
//!   while a search owns it.
//! - **Misuse** is reported with a status code: null pointers, misaligned pointers, storage too
//!   small, an uninitialised handle, buffers that overlap each other or the engine, lengths that
//!   do not match `width * height` or that overflow, polling before input, an unknown symmetry
//!   index. Results may be read at any time: before the search ends they hold the best result so
//!   far.
//! - **Panics.** The library is written not to panic (every input error is a status), but a bug
//!   could. A panic must never unwind into C: on the host the staticlib links `std`, and a panic
//!   that reaches an `extern "C"` function aborts the process. On bare-metal targets the feature
//!   `ffi-panic-handler` adds the `#[panic_handler]` a C firmware cannot write: it calls the C
//!   hook `sfs_panic_hook(file, file_len, line)` (a weak default on ARM does nothing; the
//!   firmware overrides it to log, reset or stop the actuators) and then spins forever, for the
//!   watchdog. It is a separate feature because a Rust firmware has its own panic handler.
//! - **Threads.** An engine is not reentrant: one caller at a time per handle (a control loop and
//!   an interrupt must not both use it). Different handles are independent.
//!
//! Input structures read from C contain only integers, floats and pointers (no `bool`, no
//! enum), so that every bit pattern C can write is a valid value; flags are "non-zero = yes".

// A staticlib for a hosted target needs a panic handler and unwinding support: linking `std`
// provides both (and a panic that reaches an `extern "C"` function aborts the process).
// Bare-metal builds never link it (see `panic` below).
#[cfg(not(target_os = "none"))]
extern crate std;

use core::ffi::{c_char, c_void};
use core::mem::{align_of, size_of};
use core::ptr::NonNull;

use crate::engine::{MAX_SYMMETRIES, Stage};
use crate::{
    CompletedPoint, Config, DefaultEngine, Error, Intrinsics, Plane, Provenance,
    RECOMMENDED_BUDGET, Scene, Status, Symmetry, SymmetryType, TypeSet,
};

/// What every `sfs_*` call returns: `SFS_STATUS_OK` (0), the two progress codes of
/// [`sfs_poll`] (positive), or an error (negative): one per library error, then the API's own.
/// (The function docs name them without the `SFS_STATUS_` prefix.)
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SfsStatus {
    /// The call succeeded.
    Ok = 0,
    /// `sfs_poll`: more work remains; poll again (the results hold the best so far).
    Working = 1,
    /// `sfs_poll`: the search and the completion are finished; the results are final.
    Done = 2,
    /// The image width or height is zero.
    ErrEmptyImage = -1,
    /// A focal length is not positive and finite, or the principal point is not finite.
    ErrInvalidIntrinsics = -2,
    /// `depth_len` is not `width * height`.
    ErrDepthSizeMismatch = -3,
    /// `mask_len` is not `width * height` (with a non-null mask).
    ErrMaskSizeMismatch = -4,
    /// The depth scale is not in (0, 1] metres per unit.
    ErrInvalidDepthScale = -5,
    /// The table normal is not a finite unit vector, or its offset is not finite.
    ErrInvalidTablePlane = -6,
    /// The depth image holds no valid reading.
    ErrNoValidDepth = -7,
    /// No support plane could be fitted (give a mask or a table plane).
    ErrNoSupportPlane = -8,
    /// Nothing of the object is left after segmentation (or the mask selects no valid pixel).
    ErrNoObject = -9,
    /// Too few object points for a symmetry search.
    ErrTooFewPoints = -10,
    /// A configuration value is out of range (`sfs_config_types`: an empty or unknown mask;
    /// `sfs_config_parts`: not 0 or 1).
    ErrInvalidConfig = -11,
    /// `sfs_poll` before a successful `sfs_set_input`.
    ErrNotStarted = -12,
    /// A pointer that must not be null is null (or null with a non-zero length).
    ErrNullPointer = -100,
    /// A pointer is not aligned for its type (storage: `sfs_engine_align()`; depth: 2; output: 4).
    ErrBadAlignment = -101,
    /// The storage is smaller than `sfs_engine_size()`.
    ErrTooSmall = -102,
    /// The handle does not point to storage initialised by `sfs_init` (wrong magic number).
    ErrBadHandle = -103,
    /// `sfs_symmetry`: the index is not below `SfsResult.symmetries`.
    ErrOutOfRange = -104,
    /// A size does not fit: width or height above 65 535, or a buffer length whose size in bytes
    /// overflows the address space.
    ErrTooLarge = -105,
    /// Two buffers overlap that must not: the output with depth, mask or the engine's storage,
    /// or depth or mask with the engine's storage.
    ErrOverlap = -106,
}

impl From<Error> for SfsStatus {
    fn from(e: Error) -> Self {
        match e {
            Error::EmptyImage => SfsStatus::ErrEmptyImage,
            Error::InvalidIntrinsics => SfsStatus::ErrInvalidIntrinsics,
            Error::DepthSizeMismatch { .. } => SfsStatus::ErrDepthSizeMismatch,
            Error::MaskSizeMismatch { .. } => SfsStatus::ErrMaskSizeMismatch,
            Error::InvalidDepthScale => SfsStatus::ErrInvalidDepthScale,
            Error::InvalidTablePlane => SfsStatus::ErrInvalidTablePlane,
            Error::NoValidDepth => SfsStatus::ErrNoValidDepth,
            Error::NoSupportPlane => SfsStatus::ErrNoSupportPlane,
            Error::NoObject => SfsStatus::ErrNoObject,
            Error::TooFewPoints { .. } => SfsStatus::ErrTooFewPoints,
            Error::InvalidConfig => SfsStatus::ErrInvalidConfig,
            Error::NotStarted => SfsStatus::ErrNotStarted,
        }
    }
}

/// The eight symmetry types (paper Fig. 5). Bit `1 << type` selects a type in the mask of
/// [`sfs_config_types`].
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SfsSymmetryType {
    PlaneReflection = 0,
    LineReflection = 1,
    PointReflection = 2,
    /// Continuous rotation about an axis.
    Axial = 3,
    Spherical = 4,
    /// Two orthogonal mirror planes.
    DualPlane = 5,
    /// Three mutually orthogonal mirror planes.
    TriplePlane = 6,
    /// An axis and a mirror plane orthogonal to it.
    AxialPlane = 7,
}

impl From<SymmetryType> for SfsSymmetryType {
    fn from(t: SymmetryType) -> Self {
        match t {
            SymmetryType::PlaneReflection => SfsSymmetryType::PlaneReflection,
            SymmetryType::LineReflection => SfsSymmetryType::LineReflection,
            SymmetryType::PointReflection => SfsSymmetryType::PointReflection,
            SymmetryType::Axial => SfsSymmetryType::Axial,
            SymmetryType::Spherical => SfsSymmetryType::Spherical,
            SymmetryType::DualPlane => SfsSymmetryType::DualPlane,
            SymmetryType::TriplePlane => SfsSymmetryType::TriplePlane,
            SymmetryType::AxialPlane => SfsSymmetryType::AxialPlane,
        }
    }
}

/// A work budget for one `sfs_poll` per tick of a 1 kHz control loop on a 168 MHz Cortex-M4F
/// (at most 91 280 instructions in a poll of the built-in scene, measured under QEMU; CI fails
/// above 100 000).
pub const SFS_RECOMMENDED_BUDGET: u32 = 140;
/// Most symmetries one search reports (`SfsResult.symmetries` is at most this).
pub const SFS_MAX_SYMMETRIES: u32 = 8;
/// The mask of `sfs_config_types` that selects every type (the default).
pub const SFS_TYPES_ALL: u32 = 0xFF;
/// Bytes of storage that suffice for an engine on every supported target (`sfs_engine_size()`
/// is the exact need of the build at hand, a little less on 32-bit targets): for a `static`
/// buffer whose size must be known at compile time.
pub const SFS_ENGINE_STORAGE_BYTES: usize = 95_232;
/// An alignment that suffices for the engine's storage on every supported target
/// (`sfs_engine_align()` is the exact need).
pub const SFS_ENGINE_STORAGE_ALIGN: usize = 8;

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
    /// A visible (sampled) point of the object.
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
const MAGIC: u32 = 0x5346_5331;

/// The engine in caller storage: opaque to C. Obtain one with [`sfs_init`].
#[derive(Debug)]
pub struct SfsEngine {
    magic: u32,
    engine: DefaultEngine<'static>,
    /// The caller's output buffer. The engine does not hold it: the C caller reads it between
    /// calls, which a Rust `&mut` kept from one call to the next would forbid, so `sfs_poll`
    /// lends it to the engine for that call alone.
    output: Output,
}

/// The output buffer of the last `sfs_set_input`: null and 0, or a range `set_input` checked
/// (non-null, aligned, not wrapping, overlapping neither depth, mask nor the engine's storage)
/// and initialised with valid points.
#[derive(Clone, Copy, Debug)]
struct Output {
    points: *mut CompletedPoint,
    capacity: usize,
}

// SAFETY: `Sync` is needed only so that `FRESH` (which holds a null `Output`) can be a `static`.
// A shared `&Output` gives nothing but the pointer's value; dereferencing it is `sfs_poll`'s
// `unsafe`, on an engine used by one caller at a time (the API's thread contract).
unsafe impl Sync for Output {}

impl Output {
    const NONE: Self = Self {
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
    pub height: u32,
    /// Pinhole intrinsics in pixels; pixel (u, v) has its centre at (u, v).
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
    /// Non-zero: the table plane `table_normal · X = table_offset` (camera frame, metres; unit
    /// normal pointing away from the table, toward the camera's side) is given. Zero: the
    /// engine fits it (unless a mask is given).
    pub has_table: u32,
    pub table_normal: [f32; 3],
    pub table_offset: f32,
    /// Optional object mask, row-major, non-zero = object pixel. NULL (with `mask_len` 0): the
    /// engine segments the object itself.
    pub mask: *const u8,
    /// Number of mask values; `width * height` with a mask.
    pub mask_len: usize,
    /// Where the completed points go (visible, then generated). Aligned to 4 bytes. NULL with
    /// capacity 0 runs the search without completion output (every point is counted dropped).
    pub output: *mut SfsPoint,
    /// Number of `SfsPoint`s `output` holds. Three times the engine's 1 024 sampled points is
    /// ample for one object (the built-in can needs 2 276).
    pub output_capacity: usize,
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
    pub points_generated: u32,
    /// Points left out because the output (or the engine's deduplication table) was full;
    /// non-zero means the output is incomplete.
    pub points_dropped: u32,
    /// Object pixels with a reading, and the object points sampled for the search.
    pub object_pixels: u32,
    pub sampled_points: u32,
    /// Polls so far, and the work units they did.
    pub polls: u32,
    pub work_units: u64,
}

/// A mirror plane `normal · X = offset` (camera frame, metres; unit normal).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsPlane {
    pub normal: [f32; 3],
    pub offset: f32,
}

/// One symmetry found: [`sfs_symmetry`]'s output. Geometry in the camera frame (metres).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SfsSymmetry {
    /// The symmetry type.
    pub kind: SfsSymmetryType,
    /// The measurement model's mean cost over the transformed points (lower is better).
    pub score: f32,
    /// Visible (sampled) points this symmetry explains.
    pub domain_points: u32,
    /// Mirror planes: 1 for plane reflection and axial + plane, 2 for dual plane, 3 for triple
    /// plane, else 0. Entries past `plane_count` are zero.
    pub plane_count: u32,
    pub planes: [SfsPlane; 3],
    /// Non-zero for line reflection, axial and axial + plane: the axis through `axis_point`
    /// along the unit vector `axis_direction` (zero otherwise).
    pub has_axis: u32,
    pub axis_direction: [f32; 3],
    pub axis_point: [f32; 3],
    /// Non-zero for point reflection and spherical: the centre (zero otherwise).
    pub has_centre: u32,
    pub centre: [f32; 3],
}

impl SfsSymmetry {
    fn new(symmetry: &Symmetry, score: f32, domain_points: u32) -> Self {
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
            score,
            domain_points,
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

// ------------------------------------------------------------------------------------------------
// Checks shared by the calls (no unsafe here except where marked)
// ------------------------------------------------------------------------------------------------

/// The byte range `[start, start + len * size_of::<T>())` of a buffer of `len` `T`s at `ptr`,
/// after the checks `slice::from_raw_parts` needs and a caller cannot be trusted with: not
/// null (unless `len` is 0 and `optional`), aligned, and a size in bytes that neither exceeds
/// `isize::MAX` nor wraps around the address space. `Ok(None)`: an absent optional buffer.
fn buffer<T>(
    ptr: *const T,
    len: usize,
    optional: bool,
) -> Result<Option<(usize, usize)>, SfsStatus> {
    if ptr.is_null() {
        return if optional && len == 0 {
            Ok(None)
        } else {
            Err(SfsStatus::ErrNullPointer)
        };
    }
    if !ptr.is_aligned() {
        return Err(SfsStatus::ErrBadAlignment);
    }
    let start = ptr as usize;
    let bytes = len
        .checked_mul(size_of::<T>())
        .filter(|&b| b <= isize::MAX as usize)
        .ok_or(SfsStatus::ErrTooLarge)?;
    let end = start.checked_add(bytes).ok_or(SfsStatus::ErrTooLarge)?;
    Ok(Some((start, end)))
}

/// Whether two byte ranges share a byte (empty ranges share none).
fn overlap(a: Option<(usize, usize)>, b: Option<(usize, usize)>) -> bool {
    match (a, b) {
        (Some((a0, a1)), Some((b0, b1))) => a0 < a1 && b0 < b1 && a0 < b1 && b0 < a1,
        _ => false,
    }
}

/// A handle that passed the checks every call makes before it touches the engine: not null,
/// aligned, and the magic number `sfs_init` writes.
///
/// # Safety
/// `handle`, when not null and aligned, points to at least `sfs_engine_size()` bytes of storage
/// that the caller owns and whose bytes are defined (the API's contract for handles).
unsafe fn checked(handle: *const SfsEngine) -> Result<NonNull<SfsEngine>, SfsStatus> {
    let handle = NonNull::new(handle.cast_mut()).ok_or(SfsStatus::ErrNullPointer)?;
    if !handle.is_aligned() {
        return Err(SfsStatus::ErrBadAlignment);
    }
    // SAFETY: the pointer is non-null and aligned, and by the contract above it points to
    // `size_of::<SfsEngine>()` readable, defined bytes; the magic field lies within them and a
    // `u32` is valid for every bit pattern. No reference to the (possibly invalid) engine is made.
    let magic = unsafe { (&raw const (*handle.as_ptr()).magic).read() };
    if magic != MAGIC {
        return Err(SfsStatus::ErrBadHandle);
    }
    Ok(handle)
}

/// The byte range of the engine's storage, for the overlap checks.
fn storage_range(handle: NonNull<SfsEngine>) -> Option<(usize, usize)> {
    let start = handle.as_ptr() as usize;
    Some((start, start.saturating_add(size_of::<SfsEngine>())))
}

/// A checked handle (see [`checked`]) and a result slot `out` for one `T`: not null, aligned,
/// and outside the handle's storage.
///
/// # Safety
/// As for [`checked`].
unsafe fn checked_with_slot<T>(
    handle: *const SfsEngine,
    out: *mut T,
) -> Result<NonNull<SfsEngine>, SfsStatus> {
    // SAFETY: this function's contract is `checked`'s.
    let handle = unsafe { checked(handle) }?;
    let slot = buffer(out.cast_const(), 1, false)?;
    if overlap(slot, storage_range(handle)) {
        return Err(SfsStatus::ErrOverlap);
    }
    Ok(handle)
}

/// A fresh engine with the default configuration: the image `sfs_init` copies. Copying it
/// needs no stack. Writing `DefaultEngine::new(..)` through the pointer instead makes rustc
/// build the engine as a temporary first: measured, a 51 KiB stack frame in `sfs_init` on the
/// M4F, more than a firmware's stack. The price is this image in flash (`sfs_engine_size()`
/// bytes, as for the `.data` image of a Rust firmware's `static` engine).
static FRESH: SfsEngine = SfsEngine {
    magic: MAGIC,
    engine: DefaultEngine::new(Config::DEFAULT),
    output: Output::NONE,
};

/// Write a fresh engine with `config` into `storage`.
///
/// # Safety
/// `storage` is non-null, aligned for `SfsEngine`, valid for writes of `size_of::<SfsEngine>()`
/// bytes, and no reference to that memory is live.
unsafe fn write_fresh(storage: NonNull<SfsEngine>, config: Config) -> Result<(), Error> {
    // SAFETY: `FRESH` is a valid engine; `storage` is valid for the write (the caller's
    // promise) and is not `FRESH` (an immutable static the caller cannot name). A bitwise copy
    // is a valid, independent engine: an engine owns nothing to release, holds no reference
    // but an empty `&mut []` output, and the `Output` is null. The old contents, possibly
    // uninitialised bytes, are overwritten, not dropped.
    unsafe { core::ptr::copy_nonoverlapping(&raw const FRESH, storage.as_ptr(), 1) };
    if config == Config::DEFAULT {
        return Ok(());
    }
    // SAFETY: the storage now holds a valid engine (above), exclusively ours (the caller's
    // promise); the reference ends with this function.
    let engine = unsafe { &mut (*storage.as_ptr()).engine };
    engine.set_config(config)
}

/// Re-initialise the engine at a checked handle with its configuration changed by `change`.
///
/// # Safety
/// `handle` comes from `checked` (non-null, aligned, a whole engine's writable storage holding
/// a valid engine) and no reference to it is live.
unsafe fn reconfigure(handle: NonNull<SfsEngine>, change: impl FnOnce(&mut Config)) -> SfsStatus {
    // SAFETY: the handle holds a valid engine (the caller's promise); the configuration is
    // copied out and the reference ends here.
    let mut config = *unsafe { (*handle.as_ptr()).engine.config() };
    change(&mut config);
    // SAFETY: as for `handle` above; no reference to it is live.
    match unsafe { write_fresh(handle, config) } {
        Ok(()) => SfsStatus::Ok,
        Err(e) => e.into(),
    }
}

/// The status of an engine as `sfs_poll` would report it without working.
fn state(engine: &DefaultEngine<'static>) -> SfsStatus {
    match engine.stage() {
        Stage::Idle => SfsStatus::ErrNotStarted,
        Stage::Preparing | Stage::Searching | Stage::Completing => SfsStatus::Working,
        Stage::Done => SfsStatus::Done,
        Stage::Failed(e) => e.into(),
    }
}

// ------------------------------------------------------------------------------------------------
// The calls
// ------------------------------------------------------------------------------------------------

/// Bytes of storage an engine needs (the exact figure for this build; at most
/// `SFS_ENGINE_STORAGE_BYTES`).
#[unsafe(no_mangle)]
pub extern "C" fn sfs_engine_size() -> usize {
    size_of::<SfsEngine>()
}

/// Alignment in bytes the engine's storage needs (a power of two, at most
/// `SFS_ENGINE_STORAGE_ALIGN`).
#[unsafe(no_mangle)]
pub extern "C" fn sfs_engine_align() -> usize {
    align_of::<SfsEngine>()
}

/// Write a fresh engine (default configuration, no input) into `storage` and store the handle
/// in `*engine` (it is `storage` itself). `size` is the storage's size in bytes, at least
/// `sfs_engine_size()`; `storage` is aligned to `sfs_engine_align()`. Any earlier engine in the
/// same storage is discarded, and with it the buffers of its `sfs_set_input`. Writes
/// `sfs_engine_size()` bytes, allocates nothing. `*engine` is left untouched on error.
///
/// Errors: `ERR_NULL_POINTER` (storage or engine), `ERR_TOO_SMALL`, `ERR_BAD_ALIGNMENT`,
/// `ERR_OVERLAP` (`engine` points into the storage).
///
/// The handle check of the other calls (a magic number) tells storage that was never
/// initialised from an engine if the storage's bytes are defined: `static` storage (zeroed) or
/// storage the firmware cleared. Reading never-written stack or heap memory is undefined in C
/// and in Rust alike.
///
/// # Safety
/// `storage` is valid for writes of `size` bytes, and `engine` for the write of a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_init(
    storage: *mut c_void,
    size: usize,
    engine: *mut *mut SfsEngine,
) -> SfsStatus {
    let (Some(storage), false) = (NonNull::new(storage.cast::<SfsEngine>()), engine.is_null())
    else {
        return SfsStatus::ErrNullPointer;
    };
    if size < size_of::<SfsEngine>() {
        return SfsStatus::ErrTooSmall;
    }
    if !storage.is_aligned() || !engine.is_aligned() {
        return SfsStatus::ErrBadAlignment;
    }
    if overlap(
        storage_range(storage),
        buffer(engine.cast_const(), 1, false).ok().flatten(),
    ) {
        return SfsStatus::ErrOverlap;
    }
    // SAFETY: `storage` is non-null and aligned (checked), and valid for writes of `size >=
    // size_of::<SfsEngine>()` bytes (checked size, and the caller's promise). The API holds no
    // reference into it: every other call makes its reference from the handle and drops it
    // before returning, and calls do not overlap (one caller per engine). The default
    // configuration needs no change (cannot fail).
    let _ = unsafe { write_fresh(storage, Config::DEFAULT) };
    // SAFETY: `engine` is non-null and aligned (checked), valid for writes (caller's promise),
    // and outside the storage just written (checked).
    unsafe { engine.write(storage.as_ptr()) };
    SfsStatus::Ok
}

/// Restrict the search to the symmetry types in `mask` (bit `1 << SfsSymmetryType`;
/// `SFS_TYPES_ALL` for all, the default after `sfs_init`). The search still visits the weaker
/// types on the way to the wanted ones. This re-initialises the engine (like `sfs_init`, but
/// keeping the other settings, `sfs_config_parts`'), so any search in progress and its input
/// are discarded: call it before `sfs_set_input`.
///
/// Errors: the handle's, and `ERR_INVALID_CONFIG` for an empty mask or bits above bit 7.
///
/// # Safety
/// `engine` is a handle from `sfs_init` (or any pointer to at least `sfs_engine_size()` bytes
/// of defined, writable storage; see `sfs_init`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_config_types(engine: *mut SfsEngine, mask: u32) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked(engine) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let Ok(bits) = u8::try_from(mask) else {
        return SfsStatus::ErrInvalidConfig;
    };
    if bits == 0 {
        return SfsStatus::ErrInvalidConfig;
    }
    // SAFETY: a checked handle holds a valid engine in writable storage (the contract); no
    // reference to it is live (none is made above).
    unsafe { reconfigure(handle, |config| config.types = TypeSet(bits)) }
}

/// Search part symmetries (`enable` 1: a symmetry per domain, up to 8, each point's `symmetry`
/// naming its domain's) or the whole object only (0, the default after `sfs_init`). See the
/// README, "Part symmetries": it costs more work, and objects symmetric as a whole can get a
/// wrong stronger type. Re-initialises the engine like `sfs_config_types` (keeping its mask).
///
/// Errors: the handle's, and `ERR_INVALID_CONFIG` for `enable` other than 0 or 1.
///
/// # Safety
/// As `sfs_config_types`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_config_parts(engine: *mut SfsEngine, enable: u32) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked(engine) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let parts = match enable {
        0 => false,
        1 => true,
        _ => return SfsStatus::ErrInvalidConfig,
    };
    // SAFETY: as in `sfs_config_types`.
    unsafe { reconfigure(handle, |config| config.domains.parts = parts) }
}

/// Give the engine a scene and an output buffer, and begin the search (the first `sfs_poll`
/// starts working). Checks every pointer, length and value in O(1) before it changes anything,
/// then clears the output buffer (`output_capacity * sizeof(SfsPoint)` bytes written).
/// On error the engine is left as it was (a search in progress goes on with its old input).
///
/// Errors: the handle's; `ERR_NULL_POINTER` (scene, depth, or mask/output null with a non-zero
/// length); `ERR_BAD_ALIGNMENT` (scene, depth, output); `ERR_TOO_LARGE` (width or height above
/// 65 535, or a length too large for the address space); `ERR_OVERLAP` (output overlapping
/// depth, mask or the engine storage; depth or mask overlapping the engine storage); then the
/// library's input errors: `ERR_EMPTY_IMAGE`, `ERR_INVALID_INTRINSICS`,
/// `ERR_DEPTH_SIZE_MISMATCH`, `ERR_MASK_SIZE_MISMATCH`, `ERR_INVALID_DEPTH_SCALE`,
/// `ERR_INVALID_TABLE_PLANE`. Content errors (no object, ...) come from `sfs_poll`.
///
/// # Safety
/// `engine` as in `sfs_config_types`; `scene` points to a readable `SfsScene`; `depth` is valid
/// for reads of `depth_len` values, `mask` (if not null) of `mask_len` values, `output` (if not
/// null) for reads and writes of `output_capacity` points. **These three buffers must stay valid,
/// and depth and mask unchanged, until the next `sfs_set_input` or `sfs_init` on this storage;
/// the output buffer is written only by the engine meanwhile.**
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_set_input(
    engine: *mut SfsEngine,
    scene: *const SfsScene,
) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked(engine) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    // SAFETY: the handle is checked, the rest is this function's own safety contract.
    match unsafe { set_input(handle, scene) } {
        Ok(()) => SfsStatus::Ok,
        Err(status) => status,
    }
}

/// The body of [`sfs_set_input`], with `?`.
///
/// # Safety
/// As [`sfs_set_input`], with a checked handle.
unsafe fn set_input(handle: NonNull<SfsEngine>, scene: *const SfsScene) -> Result<(), SfsStatus> {
    if scene.is_null() {
        return Err(SfsStatus::ErrNullPointer);
    }
    if !scene.is_aligned() {
        return Err(SfsStatus::ErrBadAlignment);
    }
    // SAFETY: non-null and aligned (checked), readable (caller's promise); every field is an
    // integer, a float or a raw pointer, valid for any bits. Copied before any reference to the
    // engine exists, so a scene inside the engine's storage would be harmless too.
    let s = unsafe { scene.read() };

    let (Ok(width), Ok(height)) = (u16::try_from(s.width), u16::try_from(s.height)) else {
        return Err(SfsStatus::ErrTooLarge);
    };
    let intrinsics = Intrinsics {
        width,
        height,
        fx: s.fx,
        fy: s.fy,
        cx: s.cx,
        cy: s.cy,
    };
    let depth_range = buffer(s.depth, s.depth_len, false)?;
    let mask_range = buffer(s.mask, s.mask_len, true)?;
    let output_range = buffer(s.output.cast_const(), s.output_capacity, true)?;
    let storage = storage_range(handle);
    if overlap(output_range, depth_range)
        || overlap(output_range, mask_range)
        || overlap(output_range, storage)
        || overlap(depth_range, storage)
        || overlap(mask_range, storage)
    {
        return Err(SfsStatus::ErrOverlap);
    }

    // SAFETY (depth and mask): `buffer` checked non-null, alignment and a byte size within
    // `isize::MAX` that does not wrap; the caller promises the memory is readable and
    // initialised for `len` values. The `'static` lifetime is the API's lifetime contract: the
    // caller keeps these buffers valid and unchanged until the next `sfs_set_input` or `sfs_init`
    // on this storage, and both of those replace the engine's copy of the slices (or the whole
    // engine) before the old buffers may go away; the engine reads them only during calls.
    // Neither overlaps the output or the engine's storage (checked), the only memory written
    // through Rust references while they are alive.
    let depth: &'static [u16] = unsafe { core::slice::from_raw_parts(s.depth, s.depth_len) };
    let mask: Option<&'static [u8]> = match mask_range {
        Some(_) => Some(unsafe { core::slice::from_raw_parts(s.mask, s.mask_len) }),
        None => None,
    };
    let table = (s.has_table != 0).then_some(Plane {
        normal: s.table_normal,
        offset: s.table_offset,
    });
    let scene = Scene {
        depth,
        depth_scale: s.depth_scale,
        intrinsics,
        table,
        mask,
    };
    // The same checks `start` makes, before the output is cleared: a rejected input changes
    // nothing.
    scene.validate()?;

    let output = match output_range {
        None => Output::NONE,
        Some(_) => {
            // The same memory as the library's point type (layout checked at compile time).
            let points = s.output.cast::<CompletedPoint>();
            for i in 0..s.output_capacity {
                // SAFETY: `i < output_capacity`, so the element lies within the range checked
                // above (aligned, not wrapping) and valid for writes (caller's promise). Writing
                // through the raw pointer makes every element a valid `CompletedPoint` (the
                // buffer may hold any bytes before, e.g. an invalid `provenance`), which the
                // slice `sfs_poll` makes of it requires.
                unsafe { points.add(i).write(CompletedPoint::ZERO) };
            }
            Output {
                points,
                capacity: s.output_capacity,
            }
        }
    };
    // SAFETY: a checked handle points to an engine written by `write_fresh` (the magic is only
    // ever written together with one), in storage the caller lends to this call alone; no other
    // reference to it is live. The reference ends with this function.
    let handle = unsafe { &mut *handle.as_ptr() };
    // The engine gets no output here: `sfs_poll` lends it one poll at a time.
    handle.engine.start(scene, &mut [])?;
    handle.output = output;
    Ok(())
}

/// Do at most `budget` work units of the search (0 counts as 1: every poll makes progress) and
/// return `SFS_STATUS_WORKING` (poll again), `SFS_STATUS_DONE` (finished; further polls return
/// `DONE` at no cost) or an error: the handle's, `ERR_NOT_STARTED` before `sfs_set_input`,
/// or a content error (`ERR_NO_VALID_DEPTH`, `ERR_NO_SUPPORT_PLANE`, `ERR_NO_OBJECT`,
/// `ERR_TOO_FEW_POINTS`), which further polls repeat. `SFS_RECOMMENDED_BUDGET` keeps a poll
/// under 100 000 instructions on a Cortex-M4F.
///
/// # Safety
/// `engine` as in `sfs_config_types`; the buffers of the last `sfs_set_input` are still valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_poll(engine: *mut SfsEngine, budget: u32) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked(engine) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    // SAFETY: a checked handle points to a valid engine (see `set_input`), lent to this call
    // alone; the reference ends with this function. The engine's borrowed depth and mask are
    // valid by the lifetime contract.
    let SfsEngine { engine, output, .. } = unsafe { &mut *handle.as_ptr() };
    let output: &mut [CompletedPoint] = if output.capacity == 0 {
        &mut []
    } else {
        // SAFETY: `set_input` checked the range (non-null, aligned, not wrapping, overlapping
        // neither depth, mask nor this storage) and made every element a valid point; the
        // engine writes only valid points. By the lifetime contract the buffer is still valid
        // and C does not touch it during this call. This slice is the only reference to it and
        // ends with this call, so C may read the buffer between polls.
        unsafe { core::slice::from_raw_parts_mut(output.points, output.capacity) }
    };
    match engine.poll_into(budget, output) {
        Ok(Status::Working) => SfsStatus::Working,
        Ok(Status::Done) => SfsStatus::Done,
        Err(e) => e.into(),
    }
}

/// Copy the result so far into `*out` (any time after `sfs_init`: before the search is done it
/// holds the best result so far; before any input, zeros and state `ERR_NOT_STARTED`).
///
/// Errors: the handle's; `ERR_NULL_POINTER`, `ERR_BAD_ALIGNMENT` or `ERR_OVERLAP` for `out`.
///
/// # Safety
/// `engine` as in `sfs_config_types` (it is only read); `out` is valid for the write of an
/// `SfsResult`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_result(engine: *const SfsEngine, out: *mut SfsResult) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked_with_slot(engine, out) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let result = {
        // SAFETY: a checked handle points to a valid engine (see `set_input`); the shared
        // reference ends with this block, before `out` is written.
        let engine = unsafe { &(*handle.as_ptr()).engine };
        let report = engine.report();
        SfsResult {
            state: state(engine),
            symmetries: report.symmetries.len() as u32,
            points_visible: report.points_visible,
            points_generated: report.points_generated,
            points_dropped: report.points_dropped,
            object_pixels: report.object_pixels,
            sampled_points: report.sampled_points,
            polls: report.polls,
            work_units: report.work_units,
        }
    };
    // SAFETY: non-null and aligned (checked), writable (caller's promise), outside the engine's
    // storage (checked).
    unsafe { out.write(result) };
    SfsStatus::Ok
}

/// Copy symmetry number `index` (0 = strongest, below `SfsResult.symmetries`) into `*out`.
///
/// Errors: the handle's; `ERR_OUT_OF_RANGE`; `ERR_NULL_POINTER`, `ERR_BAD_ALIGNMENT` or
/// `ERR_OVERLAP` for `out`.
///
/// # Safety
/// `engine` as in `sfs_config_types` (it is only read); `out` is valid for the write of an
/// `SfsSymmetry`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_symmetry(
    engine: *const SfsEngine,
    index: u32,
    out: *mut SfsSymmetry,
) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked_with_slot(engine, out) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let found = {
        // SAFETY: as in `sfs_result`.
        let engine = unsafe { &(*handle.as_ptr()).engine };
        let symmetries = &engine.report().symmetries;
        match usize::try_from(index).ok().and_then(|i| symmetries.get(i)) {
            Some(f) => SfsSymmetry::new(&f.symmetry, f.score, f.domain_points),
            None => return SfsStatus::ErrOutOfRange,
        }
    };
    // SAFETY: as in `sfs_result`.
    unsafe { out.write(found) };
    SfsStatus::Ok
}

/// Number of completed points at the start of the output buffer given to `sfs_set_input`
/// (visible points first, then generated ones); 0 before the completion stage, and 0 for an
/// invalid handle. Read them between calls.
///
/// # Safety
/// `engine` as in `sfs_config_types` (it is only read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_points_written(engine: *const SfsEngine) -> usize {
    // SAFETY: the handle contract is this function's own safety contract.
    match unsafe { checked(engine) } {
        Ok(handle) => {
            // SAFETY: as in `sfs_result`; only the report is read, not the output buffer.
            let report = unsafe { (*handle.as_ptr()).engine.report() };
            // Never more than the output's capacity (the completion writes only what fits).
            report.points_visible as usize + report.points_generated as usize
        }
        Err(_) => 0,
    }
}

/// A static, NUL-terminated name for a status code ("ok", "working", "done",
/// "err_no_object", ...; "unknown" for a value that is no status).
#[unsafe(no_mangle)]
pub extern "C" fn sfs_status_name(status: i32) -> *const c_char {
    let name = match status {
        0 => c"ok",
        1 => c"working",
        2 => c"done",
        -1 => c"err_empty_image",
        -2 => c"err_invalid_intrinsics",
        -3 => c"err_depth_size_mismatch",
        -4 => c"err_mask_size_mismatch",
        -5 => c"err_invalid_depth_scale",
        -6 => c"err_invalid_table_plane",
        -7 => c"err_no_valid_depth",
        -8 => c"err_no_support_plane",
        -9 => c"err_no_object",
        -10 => c"err_too_few_points",
        -11 => c"err_invalid_config",
        -12 => c"err_not_started",
        -100 => c"err_null_pointer",
        -101 => c"err_bad_alignment",
        -102 => c"err_too_small",
        -103 => c"err_bad_handle",
        -104 => c"err_out_of_range",
        -105 => c"err_too_large",
        -106 => c"err_overlap",
        _ => c"unknown",
    };
    name.as_ptr()
}

/// The binding name of a symmetry type ("plane_reflection", ..., "axial_plane", as in the
/// scene and result files), static and NUL-terminated; "unknown" for another value.
#[unsafe(no_mangle)]
pub extern "C" fn sfs_symmetry_type_name(kind: u32) -> *const c_char {
    let name = match kind {
        0 => c"plane_reflection",
        1 => c"line_reflection",
        2 => c"point_reflection",
        3 => c"axial",
        4 => c"spherical",
        5 => c"dual_plane",
        6 => c"triple_plane",
        7 => c"axial_plane",
        _ => c"unknown",
    };
    name.as_ptr()
}

// ------------------------------------------------------------------------------------------------
// Panic handler for C firmware (feature `ffi-panic-handler`, bare-metal targets only)
// ------------------------------------------------------------------------------------------------

unsafe extern "C" {
    /// Panic hook, for bare-metal builds with the feature `ffi-panic-handler` only: the library
    /// calls it if it panics (a bug), with the source location: `file` (`file_len` bytes, not
    /// NUL-terminated) and `line`. On ARM a weak default that returns is linked; define this
    /// function to log, stop the actuators or reset the part. If it returns, the library spins
    /// forever (for the watchdog). Never called in other builds (a host aborts on a panic).
    pub fn sfs_panic_hook(file: *const c_char, file_len: usize, line: u32);
}

/// The `#[panic_handler]` for C firmware.
/// cbindgen:ignore
#[cfg(all(feature = "ffi-panic-handler", target_os = "none"))]
mod panic {
    use super::sfs_panic_hook;

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
        let (file, line) = info.location().map_or(("", 0), |l| (l.file(), l.line()));
        // SAFETY: the hook's C signature is the one declared above (documented in the header);
        // `file` points to `file.len()` bytes of static, immutable data.
        unsafe { sfs_panic_hook(file.as_ptr().cast(), file.len(), line) };
        // The hook returned: stop here for good (a watchdog, if any, resets the part).
        loop {
            core::hint::spin_loop();
        }
    }

    // The weak default hook: returns at once. A strong definition in the firmware replaces it.
    #[cfg(target_arch = "arm")]
    core::arch::global_asm!(
        ".section .text.sfs_panic_hook,\"ax\",%progbits",
        ".weak sfs_panic_hook",
        ".type sfs_panic_hook,%function",
        ".thumb_func",
        "sfs_panic_hook:",
        "bx lr",
        ".size sfs_panic_hook, . - sfs_panic_hook",
    );
}

// ------------------------------------------------------------------------------------------------
// Tests: the misuse paths through the extern functions (Miri runs these), and one whole search
// ------------------------------------------------------------------------------------------------

#[cfg(test)]
mod tests {
    extern crate std;

    use core::ptr;
    use std::vec;
    use std::vec::Vec;

    use super::*;
    use crate::synth;

    /// Engine storage on the heap, aligned to 8 (and zeroed: defined bytes, no magic).
    struct Storage(Vec<u64>);

    impl Storage {
        fn new() -> Self {
            Storage(vec![0u64; SFS_ENGINE_STORAGE_BYTES / 8])
        }
        fn ptr(&mut self) -> *mut c_void {
            self.0.as_mut_ptr().cast()
        }
        fn bytes(&self) -> usize {
            self.0.len() * 8
        }
    }

    fn init(storage: &mut Storage) -> *mut SfsEngine {
        let mut engine = ptr::null_mut();
        let size = storage.bytes();
        assert_eq!(
            unsafe { sfs_init(storage.ptr(), size, &mut engine) },
            SfsStatus::Ok
        );
        assert_eq!(engine.cast::<c_void>(), storage.ptr());
        engine
    }

    /// A scene over the given buffers: the built-in camera, no table, no mask.
    fn scene(depth: &[u16], output: &mut [CompletedPoint]) -> SfsScene {
        let k = synth::BUILTIN_INTRINSICS;
        SfsScene {
            depth: depth.as_ptr(),
            depth_len: depth.len(),
            depth_scale: 0.001,
            width: k.width as u32,
            height: k.height as u32,
            fx: k.fx,
            fy: k.fy,
            cx: k.cx,
            cy: k.cy,
            has_table: 0,
            table_normal: [0.0; 3],
            table_offset: 0.0,
            mask: ptr::null(),
            mask_len: 0,
            output: output.as_mut_ptr().cast(),
            output_capacity: output.len(),
        }
    }

    const PIXELS: usize = 320 * 240;

    #[test]
    fn sizes_fit_the_header_constants() {
        assert!(sfs_engine_size() <= SFS_ENGINE_STORAGE_BYTES);
        assert!(sfs_engine_align().is_power_of_two());
        assert!(sfs_engine_align() <= SFS_ENGINE_STORAGE_ALIGN);
        assert_eq!(sfs_engine_size(), size_of::<SfsEngine>());
    }

    #[test]
    fn init_rejects_bad_storage() {
        let mut storage = Storage::new();
        let mut engine = ptr::null_mut();
        let size = storage.bytes();
        unsafe {
            assert_eq!(
                sfs_init(ptr::null_mut(), size, &mut engine),
                SfsStatus::ErrNullPointer
            );
            assert_eq!(
                sfs_init(storage.ptr(), size, ptr::null_mut()),
                SfsStatus::ErrNullPointer
            );
            assert_eq!(
                sfs_init(storage.ptr(), sfs_engine_size() - 1, &mut engine),
                SfsStatus::ErrTooSmall
            );
            let misaligned = storage.ptr().cast::<u8>().add(1).cast::<c_void>();
            assert_eq!(
                sfs_init(misaligned, size - 1, &mut engine),
                SfsStatus::ErrBadAlignment
            );
            // The handle's own slot inside the storage it is about to receive.
            let inside = storage.ptr().cast::<*mut SfsEngine>();
            assert_eq!(sfs_init(storage.ptr(), size, inside), SfsStatus::ErrOverlap);
        }
        assert!(engine.is_null(), "no handle on error");
        assert!(
            storage.0.iter().all(|&w| w == 0),
            "storage untouched on error"
        );
    }

    #[test]
    fn handles_are_checked() {
        let mut storage = Storage::new();
        let depth = vec![0u16; PIXELS];
        let mut output = vec![CompletedPoint::ZERO; 8];
        let s = scene(&depth, &mut output);
        let uninitialised = storage.ptr().cast::<SfsEngine>();
        let misaligned = storage
            .ptr()
            .cast::<u8>()
            .wrapping_add(4)
            .cast::<SfsEngine>();
        let mut result = SfsResult {
            state: SfsStatus::Ok,
            symmetries: 7,
            points_visible: 0,
            points_generated: 0,
            points_dropped: 0,
            object_pixels: 0,
            sampled_points: 0,
            polls: 0,
            work_units: 0,
        };
        let mut symmetry = SfsSymmetry::new(&Symmetry::Spherical([0.0; 3]), 0.0, 0);
        for (handle, expected) in [
            (ptr::null_mut(), SfsStatus::ErrNullPointer),
            (misaligned, SfsStatus::ErrBadAlignment),
            (uninitialised, SfsStatus::ErrBadHandle),
        ] {
            unsafe {
                assert_eq!(sfs_poll(handle, 100), expected);
                assert_eq!(sfs_set_input(handle, &s), expected);
                assert_eq!(sfs_result(handle, &mut result), expected);
                assert_eq!(sfs_symmetry(handle, 0, &mut symmetry), expected);
                assert_eq!(sfs_config_types(handle, SFS_TYPES_ALL), expected);
                assert_eq!(sfs_config_parts(handle, 1), expected);
                assert_eq!(sfs_points_written(handle), 0);
            }
        }
        assert_eq!(result.symmetries, 7, "out untouched on error");
        assert!(storage.0.iter().all(|&w| w == 0), "storage untouched");
    }

    #[test]
    fn before_input() {
        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let mut result = core::mem::MaybeUninit::<SfsResult>::uninit();
        let mut symmetry = core::mem::MaybeUninit::<SfsSymmetry>::uninit();
        unsafe {
            assert_eq!(sfs_poll(engine, 100), SfsStatus::ErrNotStarted);
            assert_eq!(sfs_result(engine, result.as_mut_ptr()), SfsStatus::Ok);
            let result = result.assume_init();
            assert_eq!(result.state, SfsStatus::ErrNotStarted);
            assert_eq!(
                (result.symmetries, result.polls, result.work_units),
                (0, 0, 0)
            );
            assert_eq!(
                sfs_symmetry(engine, 0, symmetry.as_mut_ptr()),
                SfsStatus::ErrOutOfRange
            );
            assert_eq!(sfs_points_written(engine), 0);
            assert_eq!(
                sfs_result(engine, ptr::null_mut()),
                SfsStatus::ErrNullPointer
            );
            assert_eq!(
                sfs_symmetry(engine, 0, ptr::null_mut()),
                SfsStatus::ErrNullPointer
            );
            // An output struct inside the engine's storage would corrupt it.
            let inside = storage.ptr().cast::<SfsResult>().wrapping_add(1);
            assert_eq!(sfs_result(engine, inside), SfsStatus::ErrOverlap);
            assert_eq!(sfs_config_types(engine, 0), SfsStatus::ErrInvalidConfig);
            assert_eq!(sfs_config_types(engine, 0x100), SfsStatus::ErrInvalidConfig);
            assert_eq!(sfs_config_types(engine, 1 << 3), SfsStatus::Ok);
            assert_eq!(sfs_poll(engine, 100), SfsStatus::ErrNotStarted);
        }
    }

    #[test]
    fn the_two_settings_keep_each_other() {
        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let config = || unsafe { *(*engine).engine.config() };
        let axial = TypeSet(1 << 3);
        unsafe {
            assert_eq!(sfs_config_parts(engine, 2), SfsStatus::ErrInvalidConfig);
            assert_eq!(config(), Config::DEFAULT, "nothing changed on error");
            assert_eq!(sfs_config_types(engine, 1 << 3), SfsStatus::Ok);
            assert_eq!(sfs_config_parts(engine, 1), SfsStatus::Ok);
            assert_eq!((config().types, config().domains.parts), (axial, true));
            assert_eq!(sfs_config_types(engine, SFS_TYPES_ALL), SfsStatus::Ok);
            assert_eq!(
                (config().types, config().domains.parts),
                (TypeSet::ALL, true)
            );
            assert_eq!(sfs_config_parts(engine, 0), SfsStatus::Ok);
            assert_eq!(config(), Config::DEFAULT);
        }
    }

    #[test]
    fn set_input_checks_every_pointer_and_length() {
        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let depth = vec![0u16; PIXELS + 1];
        let mask = vec![0u8; PIXELS + 1];
        let mut output = vec![CompletedPoint::ZERO; 16];
        // The pointer may read all PIXELS + 1 values (the too-long case); the length is right.
        let good = SfsScene {
            depth_len: PIXELS,
            ..scene(&depth, &mut output)
        };
        let set = |s: SfsScene| unsafe { sfs_set_input(engine, &s) };
        // An output pointer into the depth image, aligned for SfsPoint.
        let at = depth.as_ptr().cast::<u8>().cast_mut();
        let aligned_in_depth = at.wrapping_add(at.align_offset(4)).cast::<SfsPoint>();
        let cases: [(SfsScene, SfsStatus); 22] = [
            (
                SfsScene {
                    depth: ptr::null(),
                    ..good
                },
                SfsStatus::ErrNullPointer,
            ),
            (
                SfsScene {
                    depth: ptr::null(),
                    depth_len: 0,
                    ..good
                },
                SfsStatus::ErrNullPointer,
            ),
            (
                SfsScene {
                    depth: depth.as_ptr().cast::<u8>().wrapping_add(1).cast(),
                    ..good
                },
                SfsStatus::ErrBadAlignment,
            ),
            (
                SfsScene {
                    depth_len: PIXELS - 1,
                    ..good
                },
                SfsStatus::ErrDepthSizeMismatch,
            ),
            (
                SfsScene {
                    depth_len: PIXELS + 1,
                    ..good
                },
                SfsStatus::ErrDepthSizeMismatch,
            ),
            (
                SfsScene {
                    depth_len: usize::MAX / 2,
                    ..good
                },
                SfsStatus::ErrTooLarge,
            ),
            (
                SfsScene {
                    mask: mask.as_ptr(),
                    mask_len: PIXELS + 1,
                    ..good
                },
                SfsStatus::ErrMaskSizeMismatch,
            ),
            (
                SfsScene {
                    mask: mask.as_ptr(),
                    mask_len: 0,
                    ..good
                },
                SfsStatus::ErrMaskSizeMismatch,
            ),
            (
                SfsScene {
                    mask_len: PIXELS,
                    ..good
                },
                SfsStatus::ErrNullPointer,
            ),
            (
                SfsScene {
                    output: ptr::null_mut(),
                    ..good
                },
                SfsStatus::ErrNullPointer,
            ),
            (
                SfsScene {
                    output: output.as_mut_ptr().cast::<u8>().wrapping_add(2).cast(),
                    ..good
                },
                SfsStatus::ErrBadAlignment,
            ),
            (
                SfsScene {
                    output_capacity: usize::MAX / 8,
                    ..good
                },
                SfsStatus::ErrTooLarge,
            ),
            (
                SfsScene {
                    width: 0,
                    depth_len: 0,
                    ..good
                },
                SfsStatus::ErrEmptyImage,
            ),
            (
                SfsScene {
                    width: 70_000,
                    ..good
                },
                SfsStatus::ErrTooLarge,
            ),
            (
                SfsScene {
                    height: u32::MAX,
                    ..good
                },
                SfsStatus::ErrTooLarge,
            ),
            (
                SfsScene {
                    fx: f32::NAN,
                    ..good
                },
                SfsStatus::ErrInvalidIntrinsics,
            ),
            (
                SfsScene {
                    depth_scale: 0.0,
                    ..good
                },
                SfsStatus::ErrInvalidDepthScale,
            ),
            (
                SfsScene {
                    has_table: 1,
                    table_normal: [0.0, 0.0, 2.0],
                    ..good
                },
                SfsStatus::ErrInvalidTablePlane,
            ),
            // The output over the depth image, or inside the engine's storage; the depth image
            // inside the engine's storage.
            (
                SfsScene {
                    output: aligned_in_depth,
                    output_capacity: 4,
                    ..good
                },
                SfsStatus::ErrOverlap,
            ),
            (
                SfsScene {
                    output: storage.ptr().cast(),
                    output_capacity: 4,
                    ..good
                },
                SfsStatus::ErrOverlap,
            ),
            (
                SfsScene {
                    depth: storage.ptr().cast(),
                    depth_len: PIXELS,
                    ..good
                },
                SfsStatus::ErrOverlap,
            ),
            (good, SfsStatus::Ok),
        ];
        for (i, (s, expected)) in cases.into_iter().enumerate() {
            assert_eq!(set(s), expected, "case {i}");
        }
        unsafe {
            assert_eq!(
                sfs_set_input(engine, ptr::null()),
                SfsStatus::ErrNullPointer
            );
            // The good input was taken: the search runs (and finds no valid depth).
            let mut result = core::mem::MaybeUninit::<SfsResult>::uninit();
            assert_eq!(sfs_result(engine, result.as_mut_ptr()), SfsStatus::Ok);
            assert_eq!(result.assume_init().state, SfsStatus::Working);
            let mut status = SfsStatus::Working;
            for _ in 0..100 {
                status = sfs_poll(engine, 1_000);
                if status != SfsStatus::Working {
                    break;
                }
            }
            assert_eq!(status, SfsStatus::ErrNoValidDepth);
            assert_eq!(sfs_poll(engine, 1_000), SfsStatus::ErrNoValidDepth);
            let mut result = core::mem::MaybeUninit::<SfsResult>::uninit();
            assert_eq!(sfs_result(engine, result.as_mut_ptr()), SfsStatus::Ok);
            assert_eq!(result.assume_init().state, SfsStatus::ErrNoValidDepth);
            // Output without capacity is allowed (the search alone).
            let empty = SfsScene {
                output: ptr::null_mut(),
                output_capacity: 0,
                ..good
            };
            assert_eq!(sfs_set_input(engine, &empty), SfsStatus::Ok);
        }
    }

    #[test]
    fn set_input_clears_the_output_and_accepts_any_bytes_there() {
        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let depth = vec![0u16; PIXELS];
        // Bytes that are no valid CompletedPoint (provenance 0xAB).
        let mut raw = vec![0xABAB_ABABu32; 5 * 5];
        let output = raw.as_mut_ptr().cast::<CompletedPoint>();
        let s = SfsScene {
            output: output.cast(),
            output_capacity: 4,
            ..scene(&depth, &mut [])
        };
        unsafe {
            assert_eq!(sfs_set_input(engine, &s), SfsStatus::Ok);
            for i in 0..4 {
                assert_eq!(*output.add(i), CompletedPoint::ZERO);
            }
        }
        assert_eq!(raw[20..], [0xABAB_ABAB; 5], "nothing past the capacity");
    }

    #[test]
    fn names() {
        let name = |p: *const c_char| unsafe { core::ffi::CStr::from_ptr(p) }.to_str().unwrap();
        assert_eq!(name(sfs_status_name(SfsStatus::Done as i32)), "done");
        assert_eq!(
            name(sfs_status_name(SfsStatus::ErrOverlap as i32)),
            "err_overlap"
        );
        assert_eq!(name(sfs_status_name(12345)), "unknown");
        for t in SymmetryType::ALL {
            assert_eq!(name(sfs_symmetry_type_name(t as u32)), t.name());
            assert_eq!(SfsSymmetryType::from(t) as u32, t as u32);
        }
        assert_eq!(name(sfs_symmetry_type_name(8)), "unknown");
    }

    /// What a C caller does: poll, and between polls read the points written so far through its
    /// own pointer to the output. Under Miri (with `libm/force-soft-floats`, see
    /// ci/harden.sh) this checks that no Rust reference to the buffer outlives a call: a read
    /// between polls would invalidate one, and the next poll's write through it would be
    /// reported. A 24x16 image and a search shrunk to a few thousand units keep it fast.
    #[test]
    fn output_is_readable_between_polls() {
        const W: usize = 24;
        const H: usize = 16;
        // A wall at 1 m (the table) and a square block 10 cm in front of it, masked.
        let mut depth = vec![1000u16; W * H];
        let mut mask = vec![0u8; W * H];
        for y in 4..12 {
            for x in 8..16 {
                depth[y * W + x] = 900;
                mask[y * W + x] = 1;
            }
        }
        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let mut small = Config::DEFAULT;
        small.search.grid.plane_normals = 6;
        small.search.grid.offset_steps = 2;
        small.search.grid.line_directions = 3;
        small.search.grid.angle_steps = 2;
        small.search.grid.lattice_steps = 2;
        small.search.candidates = 1;
        (
            small.search.grid_transformed,
            small.search.climb_transformed,
        ) = (16, 16);
        small.search.polish_transformed = 16;
        small.search.finest_step = 1.0;
        // SAFETY (test): a valid engine from `init`, no other reference to it.
        unsafe { (*engine).engine.set_config(small).unwrap() };

        // The caller's buffer, owned through a raw pointer as C owns it.
        const CAPACITY: usize = 256;
        let buffer =
            std::boxed::Box::into_raw(std::boxed::Box::new([CompletedPoint::ZERO; CAPACITY]));
        let points = buffer.cast::<CompletedPoint>();
        let s = SfsScene {
            width: W as u32,
            height: H as u32,
            fx: 30.0,
            fy: 30.0,
            cx: W as f32 / 2.0,
            cy: H as f32 / 2.0,
            has_table: 1,
            table_normal: [0.0, 0.0, -1.0],
            table_offset: -1.0,
            mask: mask.as_ptr(),
            mask_len: mask.len(),
            output: points.cast(),
            output_capacity: CAPACITY,
            ..scene(&depth, &mut [])
        };
        let mut checksum = 0.0f32;
        let mut reads = 0;
        unsafe {
            assert_eq!(sfs_set_input(engine, &s), SfsStatus::Ok);
            loop {
                let status = sfs_poll(engine, 16);
                // Read (and once write back) what is there, as C may between polls.
                let written = sfs_points_written(engine);
                assert!(written <= CAPACITY);
                for i in 0..written {
                    checksum += (*points.add(i)).position[2];
                    reads += 1;
                }
                match status {
                    SfsStatus::Working => {}
                    SfsStatus::Done => break,
                    other => panic!("poll: {other:?}"),
                }
            }
            let written = sfs_points_written(engine);
            assert!(written >= 64, "the 64 block pixels at least: {written}");
            assert!(reads > written, "the points were read between polls too");
            for i in 0..written {
                let z = (*points.add(i)).position[2];
                assert!(z > 0.85 && z < 1.0, "point {i} at z = {z}");
            }
            assert!(checksum.is_finite());
            drop(std::boxed::Box::from_raw(buffer));
        }
    }

    /// The built-in scene through the C API gives what the Rust API gives. Too slow for Miri.
    #[test]
    #[cfg_attr(miri, ignore)]
    fn whole_search_matches_the_rust_api() {
        let k = synth::BUILTIN_INTRINSICS;
        let (mut depth, mut mask) = (vec![0u16; PIXELS], vec![0u8; PIXELS]);
        let rendered = synth::render(&synth::builtin_scene(), &k, &mut depth, &mut mask).unwrap();

        let mut rust_output = vec![CompletedPoint::ZERO; 3072];
        let mut rust = std::boxed::Box::new(DefaultEngine::new(Config::DEFAULT));
        let mut rust_scene = Scene::new(&depth, 0.001, k);
        rust_scene.table = Some(rendered.table);
        rust.start(rust_scene, &mut rust_output).unwrap();
        while rust.poll(5_000).unwrap() == Status::Working {}

        let mut storage = Storage::new();
        let engine = init(&mut storage);
        let mut output = vec![CompletedPoint::ZERO; 3072];
        let s = SfsScene {
            has_table: 1,
            table_normal: rendered.table.normal,
            table_offset: rendered.table.offset,
            ..scene(&depth, &mut output)
        };
        let mut result = core::mem::MaybeUninit::<SfsResult>::uninit();
        let mut symmetry = core::mem::MaybeUninit::<SfsSymmetry>::uninit();
        unsafe {
            assert_eq!(sfs_set_input(engine, &s), SfsStatus::Ok);
            let mut polls = 0;
            loop {
                match sfs_poll(engine, 5_000) {
                    SfsStatus::Working => polls += 1,
                    SfsStatus::Done => break,
                    other => panic!("poll: {other:?}"),
                }
                if polls == 3 {
                    // Best so far is readable mid-search.
                    assert_eq!(sfs_result(engine, result.as_mut_ptr()), SfsStatus::Ok);
                    assert_eq!(result.assume_init().state, SfsStatus::Working);
                }
            }
            assert_eq!(sfs_poll(engine, 5_000), SfsStatus::Done);
            assert_eq!(sfs_result(engine, result.as_mut_ptr()), SfsStatus::Ok);
            let result = result.assume_init();
            let report = rust.report();
            assert_eq!(result.state, SfsStatus::Done);
            assert_eq!(result.symmetries as usize, report.symmetries.len());
            assert_eq!(
                (
                    result.points_visible,
                    result.points_generated,
                    result.work_units
                ),
                (
                    report.points_visible,
                    report.points_generated,
                    report.work_units
                )
            );
            assert_eq!(result.symmetries, 1);
            assert_eq!(
                sfs_symmetry(engine, 0, symmetry.as_mut_ptr()),
                SfsStatus::Ok
            );
            let found = &report.symmetries[0];
            let expected = SfsSymmetry::new(&found.symmetry, found.score, found.domain_points);
            assert_eq!(symmetry.assume_init(), expected);
            assert_eq!(expected.kind, SfsSymmetryType::AxialPlane);
            assert_eq!((expected.plane_count, expected.has_axis), (1, 1));
            assert_eq!(
                sfs_symmetry(engine, 1, symmetry.as_mut_ptr()),
                SfsStatus::ErrOutOfRange
            );
            let written = sfs_points_written(engine);
            assert!(written > 1000);
            assert_eq!(written, rust.points().len());
            // Read the caller's buffer after the last call that wrote it.
            assert_eq!(&output[..written], rust.points());
            // sfs_init again: a fresh engine, the old buffers released.
            let engine = init(&mut storage);
            assert_eq!(sfs_points_written(engine), 0);
            assert_eq!(sfs_poll(engine, 1), SfsStatus::ErrNotStarted);
        }
    }
}
