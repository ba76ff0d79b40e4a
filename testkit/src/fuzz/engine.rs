//! Fuzz harness for the Rust API: arbitrary depth bytes, image size (1..=64 a side),
//! intrinsics (NaN, infinities, zero, huge included), depth scale, optional mask and table plane
//! and type set -> `Scene` -> `start` -> `poll` with arbitrary budgets (0 and 1 included) until
//! `Done` or an error. Checks, beyond "no panic, no overflow":
//!
//! - `start` fails only with an input error, `poll` only with a content error, and a failed
//!   engine repeats its error; a finished one stays `Done` at no cost;
//! - every poll that returns does at least one and at most `max(budget, 1)` work units;
//! - the whole run finishes within [`WORK_BOUND`] work units, hence within `WORK_BOUND` polls
//!   (each poll does at least one unit): the poll loop is bounded;
//! - the report is consistent with the output buffer.
//!
//! Shared by `fuzz/fuzz_targets/engine.rs` and `tests/fuzz_regressions.rs`.

use shape_from_symmetry::{
    CompletedPoint, Config, DefaultEngine, Error, Intrinsics, Plane, Scene, Status, TypeSet,
};

use super::bytes::Bytes;

/// Largest side of the fuzzed images.
pub const MAX_SIDE: u16 = 64;

/// Most work units a whole run may take on an image of at most 64x64 pixels with the
/// `DefaultEngine`. Measured: the most seen was 914 971 units, over about 30 000 fuzz runs
/// (`SFS_FUZZ_REPORT_MAX=1` prints each new maximum; the synthetic objects take 0.38-1.0 M units
/// at 320x240). Preparation is
/// linear in the pixels (at most 4 096 here) and the search and completion are bounded by the
/// grid sizes and `POINTS` (1 024), not by the image: 4 M leaves a wide margin and still catches
/// a runaway loop.
pub const WORK_BOUND: u64 = 4_000_000;

/// Output capacity: often tiny (exhaustion), sometimes ample.
fn output_len(b: &mut Bytes<'_>) -> usize {
    match b.u8() % 4 {
        0 => 0,
        1 => b.u8() as usize % 8,
        2 => b.u16() as usize % 4096,
        _ => 3072,
    }
}

/// Depth image: structured (a table with a box on it, so that runs get past segmentation) with
/// raw fuzz bytes written over part of it, or raw bytes only.
fn depth_image(b: &mut Bytes<'_>, w: usize, h: usize, len: usize) -> Vec<u16> {
    let mode = b.u8();
    let mut depth = vec![0u16; len];
    if mode & 1 == 0 {
        let table = 400 + b.u16() % 3000;
        let slope = (b.u8() as i32) - 128;
        let (bx0, by0) = (b.u8() as usize % w.max(1), b.u8() as usize % h.max(1));
        let (bw, bh) = (
            1 + b.u8() as usize % w.max(1),
            1 + b.u8() as usize % h.max(1),
        );
        let height = b.u16() % 400;
        for (i, d) in depth.iter_mut().enumerate() {
            let (x, y) = (i % w.max(1), i / w.max(1));
            let base = table as i32 + slope * y as i32 / 8;
            let on_box = (bx0..bx0 + bw).contains(&x) && (by0..by0 + bh).contains(&y);
            let value = if on_box { base - height as i32 } else { base };
            *d = value.clamp(0, u16::MAX as i32) as u16;
        }
    }
    // Raw bytes over the image, from an offset, possibly repeated.
    let raw = b.u8();
    let offset = b.u16() as usize;
    let data = b.rest();
    if raw != 0 && !data.is_empty() && len > 0 {
        let words = data.len() / 2;
        let count = if raw & 0x80 != 0 { len } else { words.min(len) };
        for k in 0..count {
            let j = 2 * (k % words.max(1));
            let v = u16::from_le_bytes([data[j % data.len()], data[(j + 1) % data.len()]]);
            depth[(offset + k) % len] = v;
        }
    }
    depth
}

/// Run one input. Panics (the fuzz finding) on a broken invariant.
pub fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let w = 1 + (b.u8() as u16 % MAX_SIDE);
    let h = 1 + (b.u8() as u16 % MAX_SIDE);
    let sizes = b.u8();
    let w = if sizes == 255 { 0 } else { w };
    let (fw, fh) = (w.max(1) as f32, h.max(1) as f32);
    let k = Intrinsics {
        width: w,
        height: h,
        fx: b.f32_near(fw),
        fy: b.f32_near(fw),
        cx: b.f32_near(fw / 2.0),
        cy: b.f32_near(fh / 2.0),
    };
    let depth_scale = b.f32_near(0.001);
    let pixels = k.pixel_count();
    // Occasionally a wrong length.
    let depth_len = if sizes == 254 {
        pixels + 1
    } else if sizes == 253 {
        pixels.saturating_sub(1)
    } else {
        pixels
    };
    let flags = b.u8();
    let mask_mode = b.u8();
    let (mx0, my0, mw, mh) = (b.u8(), b.u8(), b.u8(), b.u8());
    let table = (flags & 1 != 0).then(|| {
        let n = [b.f32_near(0.0), b.f32_near(-0.7), b.f32_near(-0.7)];
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let normal = if flags & 2 != 0 && norm.is_finite() && norm > 0.0 {
            [n[0] / norm, n[1] / norm, n[2] / norm]
        } else {
            n
        };
        Plane {
            normal,
            offset: b.f32_near(0.5),
        }
    });
    let types = if flags & 4 != 0 {
        TypeSet(b.u8().max(1))
    } else {
        TypeSet::ALL
    };
    let mut budgets = [0u32; 8];
    for slot in &mut budgets {
        *slot = match b.u8() % 8 {
            0 => 0,
            1 => 1,
            2 => 2 + b.u8() as u32,
            3 => 140,
            4 => u32::MAX,
            5 => b.u32(),
            _ => 1000 + b.u16() as u32 * 16,
        };
    }
    let out_len = output_len(&mut b);
    let (wu, hu) = (w as usize, h as usize);
    let mask: Option<Vec<u8>> = match mask_mode % 4 {
        0 | 1 => None,
        2 => {
            let (x0, y0) = (mx0 as usize % wu.max(1), my0 as usize % hu.max(1));
            let (x1, y1) = (
                x0 + 1 + mw as usize % wu.max(1),
                y0 + 1 + mh as usize % hu.max(1),
            );
            Some(
                (0..pixels)
                    .map(|i| {
                        let (x, y) = (i % wu.max(1), i / wu.max(1));
                        ((x0..x1).contains(&x) && (y0..y1).contains(&y)) as u8
                    })
                    .collect(),
            )
        }
        _ => Some(
            (0..depth_len)
                .map(|i| (mx0 ^ (i as u8).wrapping_mul(mw)) & 1)
                .collect(),
        ),
    };
    let depth = depth_image(&mut b, wu, hu, depth_len);

    let mut output = vec![CompletedPoint::ZERO; out_len];
    let mut engine = Box::new(DefaultEngine::new(Config::DEFAULT.with_types(types)));
    let scene = Scene {
        depth: &depth,
        depth_scale,
        intrinsics: k,
        table,
        mask: mask.as_deref(),
        target: None,
    };
    if let Err(e) = engine.start(scene, &mut output) {
        assert!(
            matches!(
                e,
                Error::EmptyImage
                    | Error::InvalidIntrinsics
                    | Error::DepthSizeMismatch { .. }
                    | Error::MaskSizeMismatch { .. }
                    | Error::InvalidDepthScale
                    | Error::InvalidTablePlane
            ),
            "start: {e:?}"
        );
        assert_eq!(engine.poll(1), Err(Error::NotStarted));
        return;
    }
    assert!(k.validate().is_ok() && depth.len() == pixels);

    let mut polls: u64 = 0;
    let mut units = 0u64;
    loop {
        let budget = budgets[(polls % budgets.len() as u64) as usize];
        polls += 1;
        assert!(polls <= WORK_BOUND, "more than {WORK_BOUND} polls");
        let result = engine.poll(budget);
        let now = engine.report().work_units;
        let used = now - units;
        units = now;
        assert!(
            used <= budget.max(1) as u64,
            "poll({budget}) did {used} units"
        );
        assert!(
            units <= WORK_BOUND,
            "{units} work units (bound {WORK_BOUND})"
        );
        match result {
            Ok(Status::Working) => assert!(used >= 1, "a Working poll did no work"),
            Ok(Status::Done) => break,
            Err(e) => {
                assert!(
                    matches!(
                        e,
                        Error::NoValidDepth
                            | Error::NoSupportPlane
                            | Error::NoObject
                            | Error::TooFewPoints { .. }
                    ),
                    "poll: {e:?}"
                );
                assert_eq!(
                    engine.poll(budget),
                    Err(e),
                    "a failed engine repeats its error"
                );
                return;
            }
        }
    }
    // Done: stays done at no cost; the report matches the output.
    assert_eq!(engine.poll(7), Ok(Status::Done));
    let report = engine.report().clone();
    assert_eq!(report.work_units, units);
    let written = report.points_visible as usize + report.points_generated as usize;
    assert!(
        written <= out_len,
        "{written} points written into {out_len}"
    );
    assert_eq!(engine.points().len(), written);
    for (i, p) in engine.points().iter().enumerate() {
        assert!(
            p.position.iter().all(|c| c.is_finite()),
            "point {i}: {:?}",
            p.position
        );
        assert!(
            (0.0..=1.0).contains(&p.plausibility),
            "point {i}: {}",
            p.plausibility
        );
    }
    for f in &report.symmetries {
        assert!(f.score.is_finite(), "{f:?}");
    }
    MAX_SEEN.fetch_max(units, std::sync::atomic::Ordering::Relaxed);
}

/// The most work units a finished run took in this process (for measuring [`WORK_BOUND`]).
pub static MAX_SEEN: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
