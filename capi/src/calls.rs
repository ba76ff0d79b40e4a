//! The `sfs_*` calls.

use core::ffi::{c_char, c_void};
use core::mem::{align_of, size_of};
use core::ptr::NonNull;

use shape_from_symmetry::{
    CompletedPoint, Config, Found, Intrinsics, Plane, Report, Scene, Status, TypeSet,
};

use crate::checks::*;
use crate::*;

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
/// keeping the other settings, `sfs_config_parts`' and `sfs_config_one_object`'s), so any
/// search in progress and its input are discarded: call it before `sfs_set_input`.
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
/// naming its domain's) or the whole object only (0, the default after `sfs_init`). See
/// docs/algorithm.md, "Part symmetries": it costs more work. Re-initialises the engine like
/// `sfs_config_types` (keeping its mask and `sfs_config_one_object`'s setting).
///
/// Errors: the handle's, and `ERR_INVALID_CONFIG` for `enable` other than 0 or 1.
///
/// # Safety
/// As `sfs_config_types`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_config_parts(engine: *mut SfsEngine, enable: u32) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract, `reconfigure_flag`'s.
    unsafe { reconfigure_flag(engine, enable, |config, parts| config.domains.parts = parts) }
}

/// Tell the engine that nothing touches the object (`enable` 1: one object in view, as on a
/// clear table or under a wrist camera over the item to grasp) or not (0, the default after
/// `sfs_init`). Without a mask the engine then neither parts regions at concave creases nor
/// splits them at necks, as by default it must where two objects touch, so a part that meets
/// its body at a crease or a neck (a mug's handle, a bottle's neck) stays with it
/// (`PrepareConfig::with_one_object`; docs/algorithm.md, "Segmentation"). With a mask it
/// changes nothing. Re-initialises the engine like
/// `sfs_config_types` (keeping its mask and `sfs_config_parts`' setting).
///
/// Errors: the handle's, and `ERR_INVALID_CONFIG` for `enable` other than 0 or 1.
///
/// # Safety
/// As `sfs_config_types`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_config_one_object(engine: *mut SfsEngine, enable: u32) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract, `reconfigure_flag`'s.
    unsafe {
        reconfigure_flag(engine, enable, |config, one_object| {
            config.prepare = config.prepare.with_one_object(one_object)
        })
    }
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
/// `ERR_INVALID_TABLE_PLANE`; then the target's: `ERR_UNKNOWN_TARGET_KIND`,
/// `ERR_TARGET_OUTSIDE_IMAGE`. Content errors (no object, no object at the target, ...) come
/// from `sfs_poll`.
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
pub(crate) unsafe fn set_input(
    handle: NonNull<SfsEngine>,
    scene: *const SfsScene,
) -> Result<(), SfsStatus> {
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
    let target = target(&s);
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
        target: target.unwrap_or(None),
    };
    // The same checks `start` makes, before the output is cleared: a rejected input changes
    // nothing. The scene's own fields first, then the target's kind and range.
    scene.validate()?;
    target?;

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
/// `ERR_TARGET_ON_NO_OBJECT`, `ERR_TOO_FEW_POINTS`), which further polls repeat.
/// `SFS_RECOMMENDED_BUDGET` keeps a poll under 100 000 instructions on a Cortex-M4F.
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
        let (segmented, candidates, chosen, object_box) =
            SfsResult::segmentation(report.segmentation);
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
            segmented,
            candidates,
            chosen,
            object_box,
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
    let pick = |report: &Report| {
        let i = usize::try_from(index).ok()?;
        report.symmetries.get(i).copied()
    };
    // SAFETY: this function's contract is `write_found`'s.
    unsafe { write_found(engine, out, pick) }
}

/// Copy the whole object's runner-up (the best-scoring other hypothesis its search met that
/// the strongest symmetry does not entail; accepted or not, its `confidence` 0 when not) into
/// `*out`, once `sfs_poll` has returned `DONE`.
///
/// Errors: the handle's; `ERR_OUT_OF_RANGE` when there is none (yet); `ERR_NULL_POINTER`,
/// `ERR_BAD_ALIGNMENT` or `ERR_OVERLAP` for `out`.
///
/// # Safety
/// As `sfs_symmetry`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sfs_runner_up(
    engine: *const SfsEngine,
    out: *mut SfsSymmetry,
) -> SfsStatus {
    // SAFETY: this function's contract is `write_found`'s.
    unsafe { write_found(engine, out, |report: &Report| report.runner_up) }
}

/// Write the symmetry `pick` chooses from the engine's report into `*out`
/// (`ERR_OUT_OF_RANGE` when it chooses none).
///
/// # Safety
/// As `sfs_symmetry`.
unsafe fn write_found(
    engine: *const SfsEngine,
    out: *mut SfsSymmetry,
    pick: impl Fn(&Report) -> Option<Found>,
) -> SfsStatus {
    // SAFETY: the handle contract is this function's own safety contract.
    let handle = match unsafe { checked_with_slot(engine, out) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let found = {
        // SAFETY: as in `sfs_result`.
        let engine = unsafe { &(*handle.as_ptr()).engine };
        match pick(engine.report()) {
            Some(f) => SfsSymmetry::new(&f),
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
        -13 => c"err_target_outside_image",
        -14 => c"err_target_on_no_object",
        -100 => c"err_null_pointer",
        -101 => c"err_bad_alignment",
        -102 => c"err_too_small",
        -103 => c"err_bad_handle",
        -104 => c"err_out_of_range",
        -105 => c"err_too_large",
        -106 => c"err_overlap",
        -107 => c"err_unknown_target_kind",
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

unsafe extern "C" {
    /// Panic hook, for bare-metal builds with the feature `panic-handler` only: the library
    /// calls it if it panics (a bug), with the source location: `file` (`file_len` bytes, not
    /// NUL-terminated) and `line`. On ARM a weak default that returns is linked; define this
    /// function to log, stop the actuators or reset the part. If it returns, the library spins
    /// forever (for the watchdog). Never called in other builds (a host aborts on a panic).
    pub fn sfs_panic_hook(file: *const c_char, file_len: usize, line: u32);
}
