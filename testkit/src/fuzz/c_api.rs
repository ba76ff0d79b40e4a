//! Fuzz harness for the C API: an arbitrary sequence of calls (`sfs_init` at arbitrary offsets
//! and sizes into a zeroed buffer, `sfs_config_types` with arbitrary masks, `sfs_config_parts`,
//! `sfs_set_input` with arbitrary sizes, lengths, null / misaligned / overlapping pointers and
//! targets (none, a pixel, a region, inside or outside the image, an unknown kind),
//! `sfs_poll`, `sfs_result`,
//! `sfs_symmetry` with arbitrary indices, `sfs_points_written`, the name functions), each on the
//! current handle or on a null, misaligned or never-initialised one. The harness keeps the API's
//! contract (every buffer it passes is valid for the length it claims, or the claimed length
//! overflows the address space, which the API must reject; buffers stay alive and unwritten for
//! the whole run) and checks the API's promises: the documented status for each misuse, overlaps
//! rejected, results consistent with each other and with the output buffer.
//!
//! Shared by `fuzz/fuzz_targets/c_api.rs` and `capi/tests/fuzz_regressions.rs`.

use core::ffi::{CStr, c_void};
use core::mem::size_of;
use core::ptr;

use shape_from_symmetry_capi::*;

use super::bytes::Bytes;

/// Most calls in one input.
pub const MAX_CALLS: usize = 48;
/// Polls of one "poll until the end" call: with the budget used there (50 000) more than enough
/// for the images of at most 64x64 pixels made here (the engine target bounds a whole run at
/// 4 M units).
pub const MAX_POLLS: u32 = 200;

const SLACK: usize = 256;

/// What the harness knows about the engine at the current handle.
#[derive(Default)]
struct Model {
    /// An `sfs_init` succeeded: `handle` is valid.
    handle: Option<*mut SfsEngine>,
    /// Capacity of the output buffer of the accepted `sfs_set_input`, if any.
    started: Option<(*const SfsPoint, usize)>,
    /// The accepted input's image size.
    image: (u32, u32),
    /// The accepted input names a target the engine reads (no mask).
    targeted: bool,
}

fn overlaps(a: (usize, usize), b: (usize, usize)) -> bool {
    a.0 < a.1 && b.0 < b.1 && a.0 < b.1 && b.0 < a.1
}

pub fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let engine_size = sfs_engine_size();
    assert!(engine_size <= SFS_ENGINE_STORAGE_BYTES);
    assert!(sfs_engine_align() <= SFS_ENGINE_STORAGE_ALIGN);
    // Zeroed storage (defined bytes, as the API requires) with room to slide the engine.
    let mut arena = vec![0u64; (SFS_ENGINE_STORAGE_BYTES + SLACK) / 8];
    let arena_ptr = arena.as_mut_ptr().cast::<u8>();
    let arena_bytes = arena.len() * 8;
    // Storage never given to `sfs_init`.
    let mut blank = vec![0u64; SFS_ENGINE_STORAGE_BYTES / 8];
    let blank_ptr = blank.as_mut_ptr().cast::<SfsEngine>();
    // Buffers lent to `sfs_set_input`: alive until the end of the run, never written by us.
    let mut keep_u32: Vec<Vec<u32>> = Vec::new();
    let mut keep_u8: Vec<Vec<u8>> = Vec::new();
    let mut model = Model::default();

    for _ in 0..MAX_CALLS {
        if b.is_empty() {
            break;
        }
        // The handle this call gets.
        let which = b.u8();
        let valid = model.handle.is_some() && which % 8 < 5;
        let handle: *mut SfsEngine = match which % 8 {
            0..5 => model.handle.unwrap_or(ptr::null_mut()),
            5 => ptr::null_mut(),
            6 => blank_ptr,
            _ => model
                .handle
                .map_or(blank_ptr, |h| h.cast::<u8>().wrapping_add(1).cast()),
        };
        let initialised = model.handle.is_some();
        let handle_error = move |status: SfsStatus| {
            let expected = match which % 8 {
                0..5 if !initialised => SfsStatus::ErrNullPointer,
                5 => SfsStatus::ErrNullPointer,
                6 => SfsStatus::ErrBadHandle,
                7 if !initialised => SfsStatus::ErrBadHandle,
                7 => SfsStatus::ErrBadAlignment,
                _ => unreachable!(),
            };
            assert_eq!(status, expected, "handle choice {}", which % 8);
        };

        // The call. `sfs_config_parts` takes the four top byte values, so that the saved inputs
        // of earlier versions (calls 0 to 8, byte % 9) mostly keep their meaning.
        let call = match b.u8() {
            252.. => 9,
            byte => byte % 9,
        };
        match call {
            // sfs_init
            0 => {
                let offset = b.u8() as usize % SLACK;
                let room = arena_bytes - offset;
                let size = match b.u8() % 4 {
                    0 => engine_size,
                    1 => engine_size - 1 - b.u8() as usize % 64,
                    2 => b.u16() as usize,
                    _ => room,
                }
                .min(room);
                let storage = arena_ptr.wrapping_add(offset);
                let mut out: *mut SfsEngine = ptr::null_mut();
                let out_choice = b.u8() % 5;
                let out_ptr: *mut *mut SfsEngine = match out_choice {
                    0 => ptr::null_mut(),
                    // Inside the storage (8-aligned there when `offset` is).
                    1 => storage.wrapping_add(64).cast(),
                    _ => &mut out,
                };
                let null = out_choice == 0;
                let status = unsafe { sfs_init(storage.cast::<c_void>(), size, out_ptr) };
                let aligned = offset.is_multiple_of(sfs_engine_align());
                let expected = if null {
                    SfsStatus::ErrNullPointer
                } else if size < engine_size {
                    SfsStatus::ErrTooSmall
                } else if !aligned || (out_choice == 1 && !(offset + 64).is_multiple_of(8)) {
                    SfsStatus::ErrBadAlignment
                } else if out_choice == 1 {
                    SfsStatus::ErrOverlap
                } else {
                    SfsStatus::Ok
                };
                assert_eq!(status, expected, "sfs_init(+{offset}, {size})");
                if status == SfsStatus::Ok {
                    assert_eq!(out, storage.cast());
                    model = Model {
                        handle: Some(out),
                        ..Model::default()
                    };
                }
                // A failed init may still have overwritten nothing: the old handle stays.
            }
            // sfs_config_parts
            9 => {
                let enable = b.u8() as u32 % 3;
                let status = unsafe { sfs_config_parts(handle, enable) };
                if !valid {
                    handle_error(status);
                } else if enable > 1 {
                    assert_eq!(status, SfsStatus::ErrInvalidConfig);
                } else {
                    assert_eq!(status, SfsStatus::Ok);
                    model.started = None;
                }
            }
            // sfs_config_types
            1 => {
                let mask = match b.u8() % 4 {
                    0 => 0,
                    1 => 0xFF,
                    2 => b.u8() as u32,
                    _ => b.u32(),
                };
                let status = unsafe { sfs_config_types(handle, mask) };
                if !valid {
                    handle_error(status);
                } else if mask == 0 || mask > 0xFF {
                    assert_eq!(status, SfsStatus::ErrInvalidConfig);
                } else {
                    assert_eq!(status, SfsStatus::Ok);
                    model.started = None;
                }
            }
            // sfs_set_input
            2 => set_input(
                &mut b,
                handle,
                valid,
                &mut model,
                &mut keep_u32,
                &mut keep_u8,
                &handle_error,
            ),
            // sfs_poll, one call
            3 => {
                let budget = match b.u8() % 4 {
                    0 => 0,
                    1 => 1,
                    2 => b.u16() as u32,
                    _ => b.u32(),
                };
                let status = unsafe { sfs_poll(handle, budget) };
                check_poll(status, valid, &model, &handle_error);
            }
            // sfs_poll to the end (bounded)
            4 => {
                for _ in 0..MAX_POLLS {
                    let status = unsafe { sfs_poll(handle, 50_000) };
                    check_poll(status, valid, &model, &handle_error);
                    if status != SfsStatus::Working {
                        break;
                    }
                }
            }
            // sfs_result
            5 => {
                let mut result = core::mem::MaybeUninit::<SfsResult>::uninit();
                let mut bytes = [0u64; 1 + size_of::<SfsResult>() / 8];
                let out: *mut SfsResult = match b.u8() % 4 {
                    0 => ptr::null_mut(),
                    1 => bytes.as_mut_ptr().cast::<u8>().wrapping_add(4).cast(),
                    2 if model.handle.is_some() => handle.cast::<u8>().wrapping_add(128).cast(),
                    _ => result.as_mut_ptr(),
                };
                let status = unsafe { sfs_result(handle, out) };
                if !valid {
                    handle_error(status);
                } else if out.is_null() {
                    assert_eq!(status, SfsStatus::ErrNullPointer);
                } else if !out.is_aligned() {
                    assert_eq!(status, SfsStatus::ErrBadAlignment);
                } else if out != result.as_mut_ptr() {
                    assert_eq!(status, SfsStatus::ErrOverlap);
                } else {
                    assert_eq!(status, SfsStatus::Ok);
                    let r = unsafe { result.assume_init() };
                    check_result(&r, handle, &model);
                }
            }
            // sfs_symmetry
            6 => {
                let index = match b.u8() % 3 {
                    0 => b.u8() as u32 % 10,
                    1 => u32::MAX,
                    _ => b.u32(),
                };
                let mut sym = core::mem::MaybeUninit::<SfsSymmetry>::uninit();
                let null = b.u8().is_multiple_of(8);
                let out = if null {
                    ptr::null_mut()
                } else {
                    sym.as_mut_ptr()
                };
                let status = unsafe { sfs_symmetry(handle, index, out) };
                if !valid {
                    handle_error(status);
                } else if null {
                    assert_eq!(status, SfsStatus::ErrNullPointer);
                } else {
                    let mut r = core::mem::MaybeUninit::<SfsResult>::uninit();
                    assert_eq!(unsafe { sfs_result(handle, r.as_mut_ptr()) }, SfsStatus::Ok);
                    let count = unsafe { r.assume_init() }.symmetries;
                    if index < count {
                        assert_eq!(status, SfsStatus::Ok);
                        let s = unsafe { sym.assume_init() };
                        assert!(s.plane_count <= 3 && s.score.is_finite(), "{s:?}");
                        let name = unsafe { CStr::from_ptr(sfs_symmetry_type_name(s.kind as u32)) };
                        assert_ne!(name.to_bytes(), b"unknown");
                    } else {
                        assert_eq!(status, SfsStatus::ErrOutOfRange);
                    }
                }
            }
            // sfs_points_written, and read the points as C would (between calls)
            7 => {
                let n = unsafe { sfs_points_written(handle) };
                if !valid {
                    assert_eq!(n, 0);
                } else {
                    match model.started {
                        None => assert_eq!(n, 0),
                        Some((output, capacity)) => {
                            assert!(n <= capacity, "{n} points written into {capacity}");
                            for i in 0..n {
                                let p = unsafe { output.add(i).read() };
                                assert!(p.position.iter().all(|c| c.is_finite()), "{p:?}");
                                assert!((0.0..=1.0).contains(&p.plausibility), "{p:?}");
                            }
                        }
                    }
                }
            }
            // The name functions, on any value.
            _ => {
                let status = b.u32() as i32;
                let name = unsafe { CStr::from_ptr(sfs_status_name(status)) };
                assert!(!name.to_bytes().is_empty());
                let kind = b.u32();
                let name = unsafe { CStr::from_ptr(sfs_symmetry_type_name(kind)) };
                assert_eq!(kind > 7, name.to_bytes() == b"unknown");
            }
        }
    }
    drop(keep_u32);
    drop(keep_u8);
    drop(blank);
    drop(arena);
}

fn check_poll(status: SfsStatus, valid: bool, model: &Model, handle_error: &dyn Fn(SfsStatus)) {
    if !valid {
        return handle_error(status);
    }
    if model.started.is_none() {
        assert_eq!(status, SfsStatus::ErrNotStarted);
        return;
    }
    assert!(
        matches!(
            status,
            SfsStatus::Working
                | SfsStatus::Done
                | SfsStatus::ErrNoValidDepth
                | SfsStatus::ErrNoSupportPlane
                | SfsStatus::ErrNoObject
                | SfsStatus::ErrTooFewPoints
        ) || (model.targeted && status == SfsStatus::ErrTargetOnNoObject),
        "sfs_poll: {status:?}"
    );
}

fn check_result(r: &SfsResult, handle: *mut SfsEngine, model: &Model) {
    assert!(r.symmetries <= SFS_MAX_SYMMETRIES);
    let written = r.points_visible as usize + r.points_generated as usize;
    assert_eq!(written, unsafe { sfs_points_written(handle) });
    match model.started {
        None => {
            assert_eq!(r.state, SfsStatus::ErrNotStarted);
            assert_eq!((written, r.work_units, r.polls), (0, 0, 0));
        }
        Some((_, capacity)) => {
            assert!(written <= capacity);
            assert_ne!(r.state, SfsStatus::ErrNotStarted);
        }
    }
    let [u0, v0, width, height] = r.object_box.map(u64::from);
    if r.segmented == 0 {
        assert_eq!(
            (r.candidates, r.chosen, r.object_box),
            (0, -1, [0; 4]),
            "{r:?}"
        );
    } else {
        assert_eq!(r.segmented, 1, "{r:?}");
        assert!(
            r.chosen >= -1 && i64::from(r.chosen) < i64::from(r.candidates),
            "{r:?}"
        );
        let (image_width, image_height) = (u64::from(model.image.0), u64::from(model.image.1));
        assert!(
            u0 + width <= image_width && v0 + height <= image_height,
            "{r:?}"
        );
    }
}

/// The target fields of a scene of `width` x `height` pixels, from bytes the harness reads anyway
/// (so that the saved inputs of earlier versions keep their byte layout): `kind` 0 to 2 names
/// none, a pixel or a region, 3 an unknown kind; `wild` puts a coordinate or size beyond 16 bits.
/// Returns `[kind, u, v, width, height]` and whether the API must accept them (in the image).
fn target_fields(
    kind: u8,
    (width, height): (u32, u32),
    a: u16,
    b: u16,
    wild: bool,
) -> ([u32; 5], bool) {
    let (a, b) = (u32::from(a), u32::from(b));
    let (w, h) = (width.saturating_add(2), height.saturating_add(2));
    let inside = |u: u32, v: u32, du: u32, dv: u32| {
        du > 0
            && dv > 0
            && u64::from(u) + u64::from(du) <= u64::from(width)
            && u64::from(v) + u64::from(dv) <= u64::from(height)
    };
    match kind {
        0 => ([SFS_TARGET_NONE, a, b, a, b], true),
        1 => {
            let (u, v) = (a % w, if wild { u32::MAX - b } else { b % h });
            ([SFS_TARGET_PIXEL, u, v, 0, 0], inside(u, v, 1, 1))
        }
        2 => {
            let (u, v) = ((a & 0xFF) % w, (a >> 8) % h);
            let du = b % w;
            let dv = if wild {
                65_536 + (b >> 6)
            } else {
                (b >> 6) % h
            };
            ([SFS_TARGET_REGION, u, v, du, dv], inside(u, v, du, dv))
        }
        _ => ([3 + a, a, b, 1, 1], false),
    }
}

#[allow(clippy::too_many_arguments)]
fn set_input(
    b: &mut Bytes<'_>,
    handle: *mut SfsEngine,
    valid: bool,
    model: &mut Model,
    keep_u32: &mut Vec<Vec<u32>>,
    keep_u8: &mut Vec<Vec<u8>>,
    handle_error: &dyn Fn(SfsStatus),
) {
    let sizes = b.u8();
    let (width, height) = match sizes % 8 {
        0 => (b.u32(), b.u32()),
        1 => (65_536 + b.u8() as u32, 1),
        _ => (1 + b.u8() as u32 % 64, 1 + b.u8() as u32 % 64),
    };
    let pixels = (width as usize).saturating_mul(height as usize);
    let fx = b.f32_near(width as f32);
    let fy = b.f32_near(width as f32);
    let cx = b.f32_near(width as f32 / 2.0);
    let cy = b.f32_near(height as f32 / 2.0);
    let depth_scale = b.f32_near(0.001);
    let flags = b.u8();
    let table_normal = if flags & 2 != 0 {
        [0.0, -0.8, -0.6]
    } else {
        [b.f32_near(0.0), b.f32_near(-0.7), b.f32_near(-0.7)]
    };
    let table_offset = b.f32_near(0.4);

    // One u32 buffer holds depth (from word 0) and, unless the output has its own, the output
    // (from an arbitrary word): the two may overlap, which the API must reject.
    let depth_words_wanted = match b.u8() % 8 {
        0 => b.u16() as usize % 4200,
        _ => pixels.min(4096),
    };
    let depth_len_choice = b.u8() % 8;
    let output_choice = b.u8() % 8;
    let capacity_wanted = match b.u8() % 4 {
        0 => 0,
        1 => b.u8() as usize % 16,
        2 => b.u16() as usize % 4096,
        _ => 3072,
    };
    let output_word = b.u16() as usize % 8192;
    let fill = b.u16();
    let pattern = b.u8();

    let depth_words = depth_words_wanted.div_ceil(2);
    let shared_words = depth_words.max(output_word + capacity_wanted * 5) + 1;
    let mut shared: Vec<u32> = (0..shared_words)
        .map(|i| {
            let v = if (i as u8) & pattern == 0 { 0 } else { fill };
            (v as u32) | ((v as u32) << 16)
        })
        .collect();
    let base = shared.as_mut_ptr();
    let (depth, depth_len): (*const u16, usize) = match depth_len_choice {
        0 => (ptr::null(), depth_words_wanted),
        1 => (base.cast::<u8>().wrapping_add(1).cast(), depth_words_wanted),
        2 => (base.cast(), usize::MAX / 2 + 1), // byte size overflows
        // Inside the engine's storage (readable: the arena).
        3 if model.handle.is_some() => (handle.cast::<u8>().wrapping_add(256).cast(), 16),
        _ => (base.cast(), depth_words_wanted),
    };
    let (output, capacity): (*mut SfsPoint, usize) = match output_choice {
        0 => (ptr::null_mut(), capacity_wanted),
        1 => (ptr::null_mut(), 0),
        2 => (base.wrapping_add(output_word).cast(), usize::MAX / 8),
        3 if model.handle.is_some() => (handle.cast::<u8>().wrapping_add(512).cast(), 1),
        4 => {
            let mut own = vec![0u32; capacity_wanted * 5 + 1];
            let p = own.as_mut_ptr().cast::<u8>().wrapping_add(2).cast();
            keep_u32.push(own);
            (p, capacity_wanted)
        }
        _ => (base.wrapping_add(output_word).cast(), capacity_wanted),
    };
    let mask_choice = flags >> 4;
    let mask_buffer: Vec<u8> = (0..pixels.min(4096) + 8)
        .map(|i| ((i as u8) ^ pattern) & 1)
        .collect();
    let (mask, mask_len): (*const u8, usize) = match mask_choice % 8 {
        0 => (ptr::null(), 1),
        1 => (mask_buffer.as_ptr(), usize::MAX),
        2 => (mask_buffer.as_ptr(), pixels.min(4096) + 8),
        3 | 4 => (mask_buffer.as_ptr(), pixels.min(4096)),
        _ => (ptr::null(), 0),
    };
    // Bits 2 and 3 of `flags` choose the target; its values come from `fill` and `output_word`.
    let target_kind = (flags >> 2) & 3;
    let ([kind, target_u, target_v, target_width, target_height], target_ok) = target_fields(
        target_kind,
        (width, height),
        fill,
        output_word as u16,
        pattern & 0x80 != 0,
    );
    let scene = SfsScene {
        depth,
        depth_len,
        depth_scale,
        width,
        height,
        fx,
        fy,
        cx,
        cy,
        has_table: (flags & 1) as u32,
        table_normal,
        table_offset,
        mask,
        mask_len,
        output,
        output_capacity: capacity,
        target_kind: kind,
        target_u,
        target_v,
        target_width,
        target_height,
    };
    let scene_choice = b.u8() % 8;
    let mut scene_bytes = vec![0u64; 2 + size_of::<SfsScene>() / 8];
    let scene_ptr: *const SfsScene = match scene_choice {
        0 => ptr::null(),
        1 => {
            let p = scene_bytes.as_mut_ptr().cast::<u8>().wrapping_add(4);
            unsafe { ptr::write_unaligned(p.cast::<SfsScene>(), scene) };
            p.cast()
        }
        _ => &scene,
    };
    let status = unsafe { sfs_set_input(handle, scene_ptr) };
    if !valid {
        return handle_error(status);
    }
    // The harness's own view of the checks the API must make.
    let range = |p: usize, bytes: usize| (p, p.saturating_add(bytes));
    let depth_r = range(depth as usize, depth_len.saturating_mul(2));
    let out_r = range(
        output as usize,
        capacity.saturating_mul(size_of::<SfsPoint>()),
    );
    let mask_r = range(mask as usize, mask_len);
    let engine_r = range(handle as usize, sfs_engine_size());
    let mask_used = !mask.is_null();
    let out_used = !output.is_null() && capacity > 0;
    let overlap = (out_used && overlaps(out_r, depth_r))
        || (out_used && mask_used && overlaps(out_r, mask_r))
        || (out_used && overlaps(out_r, engine_r))
        || overlaps(depth_r, engine_r)
        || (mask_used && overlaps(mask_r, engine_r));
    let geometric_ok = width <= 65_535
        && height <= 65_535
        && !depth.is_null()
        && depth.is_aligned()
        && !(output.is_null() && capacity > 0)
        && !(mask.is_null() && mask_len > 0)
        && (output.is_null() || output.is_aligned())
        && depth_len
            .checked_mul(2)
            .is_some_and(|n| n <= isize::MAX as usize)
        && mask_len <= isize::MAX as usize
        && capacity
            .checked_mul(size_of::<SfsPoint>())
            .is_some_and(|n| n <= isize::MAX as usize);
    if scene_ptr.is_null() {
        assert_eq!(status, SfsStatus::ErrNullPointer);
    } else if !scene_ptr.is_aligned() {
        assert_eq!(status, SfsStatus::ErrBadAlignment);
    } else if overlap && geometric_ok {
        assert_eq!(status, SfsStatus::ErrOverlap, "{scene:?}");
    }
    match status {
        SfsStatus::ErrUnknownTargetKind => assert_eq!(target_kind, 3, "{scene:?}"),
        SfsStatus::ErrTargetOutsideImage => {
            assert!(matches!(target_kind, 1 | 2) && !target_ok, "{scene:?}")
        }
        _ => {}
    }
    if status == SfsStatus::Ok {
        assert!(!overlap && geometric_ok && target_ok, "accepted: {scene:?}");
        assert_eq!(depth_len, pixels);
        model.started = Some((
            output.cast_const(),
            if output.is_null() { 0 } else { capacity },
        ));
        model.image = (width, height);
        model.targeted = target_kind != 0 && mask.is_null();
        keep_u32.push(shared);
        keep_u8.push(mask_buffer);
        // The output was cleared: nothing written yet.
        assert_eq!(unsafe { sfs_points_written(handle) }, 0);
    } else {
        // Rejected: the engine keeps its old input (and its old buffers, kept alive).
        assert!(status as i32 <= -1, "sfs_set_input: {status:?}");
        keep_u32.push(shared);
        keep_u8.push(mask_buffer);
    }
}
