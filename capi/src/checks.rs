//! Checks shared by the calls: buffers, overlaps, handles.

use core::mem::size_of;
use core::ptr::NonNull;

use shape_from_symmetry::{Config, DefaultEngine, Error};
use shape_from_symmetry::{Rect, Stage, Target};

use crate::*;

/// The byte range `[start, start + len * size_of::<T>())` of a buffer of `len` `T`s at `ptr`,
/// after the checks `slice::from_raw_parts` needs and a caller cannot be trusted with: not
/// null (unless `len` is 0 and `optional`), aligned, and a size in bytes that neither exceeds
/// `isize::MAX` nor wraps around the address space. `Ok(None)`: an absent optional buffer.
pub(crate) fn buffer<T>(
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

/// The target a scene names (`None`: `SFS_TARGET_NONE`): `ERR_UNKNOWN_TARGET_KIND` for another
/// kind, `ERR_TARGET_OUTSIDE_IMAGE` for a coordinate or size above 65 535 (outside any image;
/// the library checks the rest against the image).
pub(crate) fn target(s: &SfsScene) -> Result<Option<Target>, SfsStatus> {
    let pixels = |value: u32| u16::try_from(value).map_err(|_| SfsStatus::ErrTargetOutsideImage);
    match s.target_kind {
        SFS_TARGET_NONE => Ok(None),
        SFS_TARGET_PIXEL => Ok(Some(Target::Pixel {
            u: pixels(s.target_u)?,
            v: pixels(s.target_v)?,
        })),
        SFS_TARGET_REGION => Ok(Some(Target::Region(Rect {
            u0: pixels(s.target_u)?,
            v0: pixels(s.target_v)?,
            width: pixels(s.target_width)?,
            height: pixels(s.target_height)?,
        }))),
        _ => Err(SfsStatus::ErrUnknownTargetKind),
    }
}

/// Whether two byte ranges share a byte (empty ranges share none).
pub(crate) fn overlap(a: Option<(usize, usize)>, b: Option<(usize, usize)>) -> bool {
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
pub(crate) unsafe fn checked(handle: *const SfsEngine) -> Result<NonNull<SfsEngine>, SfsStatus> {
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
pub(crate) fn storage_range(handle: NonNull<SfsEngine>) -> Option<(usize, usize)> {
    let start = handle.as_ptr() as usize;
    Some((start, start.saturating_add(size_of::<SfsEngine>())))
}

/// A checked handle (see [`checked`]) and a result slot `out` for one `T`: not null, aligned,
/// and outside the handle's storage.
///
/// # Safety
/// As for [`checked`].
pub(crate) unsafe fn checked_with_slot<T>(
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
pub(crate) unsafe fn write_fresh(storage: NonNull<SfsEngine>, config: Config) -> Result<(), Error> {
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
pub(crate) unsafe fn reconfigure(
    handle: NonNull<SfsEngine>,
    change: impl FnOnce(&mut Config),
) -> SfsStatus {
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

/// Re-initialise the engine at `engine` with an on/off setting: `enable` 0 or 1 handed to
/// `set` as `false` or `true`; `ERR_INVALID_CONFIG` for any other value, the handle's errors
/// for a bad handle (the engine unchanged either way).
///
/// # Safety
/// As `checked`: `engine` is a handle from `sfs_init` (or any pointer to at least
/// `sfs_engine_size()` bytes of defined, writable storage), and no reference to it is live.
pub(crate) unsafe fn reconfigure_flag(
    engine: *mut SfsEngine,
    enable: u32,
    set: impl FnOnce(&mut Config, bool),
) -> SfsStatus {
    // SAFETY: the caller's promise is `checked`'s contract.
    let handle = match unsafe { checked(engine) } {
        Ok(handle) => handle,
        Err(status) => return status,
    };
    let on = match enable {
        0 => false,
        1 => true,
        _ => return SfsStatus::ErrInvalidConfig,
    };
    // SAFETY: a checked handle holds a valid engine in writable storage; no reference to it
    // is live (the caller's promise, none made above).
    unsafe { reconfigure(handle, |config| set(config, on)) }
}

/// The status of an engine as `sfs_poll` would report it without working.
pub(crate) fn state(engine: &DefaultEngine<'static>) -> SfsStatus {
    match engine.stage() {
        Stage::Idle => SfsStatus::ErrNotStarted,
        Stage::Preparing | Stage::Searching | Stage::Completing => SfsStatus::Working,
        Stage::Done => SfsStatus::Done,
        Stage::Failed(e) => e.into(),
    }
}
