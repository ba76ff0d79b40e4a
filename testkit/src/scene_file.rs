//! The built-in scene, stored in flash.
//!
//! A 320 × 240 depth image is 150 KiB: it does not fit the firmware's 192 KiB of RAM next to
//! the engine, so the firmware does not render it at start-up. The host build of this example
//! renders the library's built-in scene once (`--write-scene`) into `builtin_scene.bin`, which
//! is committed; both builds embed that file with `include_bytes!` and decode it at COMPILE
//! time into a `static [u16; N]`, which the linker places in `.rodata` (flash). The decoding is a
//! `const fn`: no `unsafe`, no alignment tricks, and the byte order is explicit. The host build
//! checks at every run that the committed file equals a fresh render, so a change of the
//! renderer cannot go unnoticed (it fails and says how to regenerate).
//!
//! File format, all little-endian, 56-byte header then the pixels:
//!
//! | offset | size | field                                                     |
//! |--------|------|-----------------------------------------------------------|
//! | 0      | 8    | magic `SFSDEPTH`                                          |
//! | 8      | 4    | format version, `1`                                       |
//! | 12     | 2+2  | width, height (u16)                                       |
//! | 16     | 16   | fx, fy, cx, cy (f32)                                      |
//! | 32     | 4    | depth scale, metres per unit (f32)                        |
//! | 36     | 4    | 1 if a table plane follows, else 0 (u32)                  |
//! | 40     | 16   | table normal x, y, z and offset (f32; zero without table) |
//! | 56     | 2·wh | depth, row-major u16, 0 = no reading                      |

use shape_from_symmetry::{Intrinsics, Plane, Scene};

pub const MAGIC: [u8; 8] = *b"SFSDEPTH";
pub const VERSION: u32 = 1;
pub const HEADER_BYTES: usize = 56;

/// The committed file (regenerate with `cargo run --example firmware -- --write-scene`).
pub const FILE: &[u8] = include_bytes!("../data/builtin_scene.bin");

/// Path of the committed file, for the host's check and regeneration.
#[cfg(feature = "std")]
pub const FILE_PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/builtin_scene.bin");

const fn u16_at(b: &[u8], i: usize) -> u16 {
    u16::from_le_bytes([b[i], b[i + 1]])
}

const fn u32_at(b: &[u8], i: usize) -> u32 {
    u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]])
}

const fn f32_at(b: &[u8], i: usize) -> f32 {
    f32::from_bits(u32_at(b, i))
}

const fn header_ok(b: &[u8]) -> bool {
    if b.len() < HEADER_BYTES {
        return false;
    }
    let mut i = 0;
    while i < MAGIC.len() {
        if b[i] != MAGIC[i] {
            return false;
        }
        i += 1;
    }
    u32_at(b, 8) == VERSION
}

const _: () = assert!(header_ok(FILE), "builtin_scene.bin: bad magic or version");

pub const INTRINSICS: Intrinsics = Intrinsics {
    width: u16_at(FILE, 12),
    height: u16_at(FILE, 14),
    fx: f32_at(FILE, 16),
    fy: f32_at(FILE, 20),
    cx: f32_at(FILE, 24),
    cy: f32_at(FILE, 28),
};
pub const DEPTH_SCALE: f32 = f32_at(FILE, 32);
pub const TABLE: Option<Plane> = if u32_at(FILE, 36) == 1 {
    Some(Plane {
        normal: [f32_at(FILE, 40), f32_at(FILE, 44), f32_at(FILE, 48)],
        offset: f32_at(FILE, 52),
    })
} else {
    None
};
pub const PIXELS: usize = INTRINSICS.width as usize * INTRINSICS.height as usize;

const _: () = assert!(
    FILE.len() == HEADER_BYTES + 2 * PIXELS,
    "builtin_scene.bin: size does not match its header"
);

/// The depth image, decoded at compile time; in flash on the target.
pub static DEPTH: [u16; PIXELS] = {
    let mut out = [0u16; PIXELS];
    let mut i = 0;
    while i < PIXELS {
        out[i] = u16_at(FILE, HEADER_BYTES + 2 * i);
        i += 1;
    }
    out
};

/// The scene the firmware and the host search: the depth image with its camera and table
/// plane; no mask (the engine segments the object itself, using the table plane).
pub fn scene() -> Scene<'static> {
    Scene {
        depth: &DEPTH,
        depth_scale: DEPTH_SCALE,
        intrinsics: INTRINSICS,
        table: TABLE,
        mask: None,
        target: None,
    }
}

/// The file bytes for a rendered scene (host only: the generator).
#[cfg(feature = "std")]
pub fn encode(
    intrinsics: &Intrinsics,
    depth_scale: f32,
    table: Option<Plane>,
    depth: &[u16],
) -> Vec<u8> {
    assert_eq!(depth.len(), intrinsics.pixel_count(), "depth size");
    let mut out = Vec::with_capacity(HEADER_BYTES + 2 * depth.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&intrinsics.width.to_le_bytes());
    out.extend_from_slice(&intrinsics.height.to_le_bytes());
    for v in [
        intrinsics.fx,
        intrinsics.fy,
        intrinsics.cx,
        intrinsics.cy,
        depth_scale,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let (flag, plane) = match table {
        Some(p) => (1u32, [p.normal[0], p.normal[1], p.normal[2], p.offset]),
        None => (0u32, [0.0; 4]),
    };
    out.extend_from_slice(&flag.to_le_bytes());
    for v in plane {
        out.extend_from_slice(&v.to_le_bytes());
    }
    debug_assert_eq!(out.len(), HEADER_BYTES);
    for d in depth {
        out.extend_from_slice(&d.to_le_bytes());
    }
    out
}
