//! Overlays on a camera's colour image: which pixels the engine chose as the object, drawn over
//! the frame the depth image is registered to (the same pixel grid).
//!
//! The colour image is dimmed to half its brightness so that the marks stand out; each chosen
//! object's sampled pixels are filled squares of its colour, its pixel box an outline, the
//! caller's target a cross, and a label names it above its box.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use shape_from_symmetry::Rect;

use crate::colour::Rgb;
use crate::picture::font;
use crate::{Context, Result};

/// Share of the original brightness kept under the marks.
const DIM: f32 = 0.5;
/// Half the side of a sampled pixel's square: 1 makes 3 x 3 squares, which touch at the
/// sampling strides of a 640 x 480 frame (2-4 pixels) and read as a filled region.
const DOT: i32 = 1;
/// Half the length of a target cross's arms, pixels.
const CROSS: i32 = 6;

/// An RGB image in memory.
pub struct Overlay {
    pub width: usize,
    pub height: usize,
    rgb: Vec<Rgb>,
}

impl Overlay {
    /// The 8-bit RGB (or RGBA, alpha dropped) PNG at `path`, dimmed.
    pub fn from_png(path: &Path) -> Result<Self> {
        let shown = path.display();
        let file = File::open(path).context(|| format!("cannot open {shown}"))?;
        let mut reader = png::Decoder::new(BufReader::new(file))
            .read_info()
            .context(|| format!("{shown} is not a readable PNG"))?;
        let mut buf = vec![0; reader.output_buffer_size().ok_or("PNG too large")?];
        let info = reader
            .next_frame(&mut buf)
            .context(|| format!("{shown} is not a readable PNG"))?;
        let channels = match (info.color_type, info.bit_depth) {
            (png::ColorType::Rgb, png::BitDepth::Eight) => 3,
            (png::ColorType::Rgba, png::BitDepth::Eight) => 4,
            (kind, depth) => {
                return Err(format!(
                    "{shown} must be 8-bit RGB, it is {}-bit {kind:?}",
                    depth as u8
                ));
            }
        };
        let (width, height) = (info.width as usize, info.height as usize);
        let dim = |c: u8| (c as f32 * DIM) as u8;
        let rgb = (0..width * height)
            .map(|i| {
                let row = &buf[i / width * info.line_size + i % width * channels..];
                [dim(row[0]), dim(row[1]), dim(row[2])]
            })
            .collect();
        Ok(Self { width, height, rgb })
    }

    /// A grey picture of a depth image (`0`: black; nearer is brighter), for frames without a
    /// colour image.
    pub fn from_depth(depth: &[u16], width: usize, height: usize) -> Self {
        let valid = depth.iter().filter(|&&d| d != 0);
        let (lo, hi) = valid.fold((u16::MAX, 0), |(lo, hi), &d| (lo.min(d), hi.max(d)));
        let span = (hi.saturating_sub(lo)).max(1) as f32;
        let grey = |d: u16| match d {
            0 => [0, 0, 0],
            d => [((1.0 - (d - lo) as f32 / span) * 200.0 * DIM) as u8 + 20; 3],
        };
        Self {
            width,
            height,
            rgb: depth.iter().map(|&d| grey(d)).collect(),
        }
    }

    fn put(&mut self, x: i32, y: i32, rgb: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            self.rgb[y as usize * self.width + x as usize] = rgb;
        }
    }

    /// A filled square at a sampled pixel.
    pub fn dot(&mut self, u: i32, v: i32, rgb: Rgb) {
        for dy in -DOT..=DOT {
            for dx in -DOT..=DOT {
                self.put(u + dx, v + dy, rgb);
            }
        }
    }

    /// The outline of `r`, `dashed` or solid.
    pub fn outline(&mut self, r: Rect, rgb: Rgb, dashed: bool) {
        let (u0, v0) = (r.u0 as i32, r.v0 as i32);
        let (u1, v1) = (u0 + r.width as i32 - 1, v0 + r.height as i32 - 1);
        let on = |t: i32| !dashed || (t / 4) % 2 == 0;
        for u in u0..=u1 {
            if on(u - u0) {
                self.put(u, v0, rgb);
                self.put(u, v1, rgb);
            }
        }
        for v in v0..=v1 {
            if on(v - v0) {
                self.put(u0, v, rgb);
                self.put(u1, v, rgb);
            }
        }
    }

    /// A cross at `(u, v)` in `rgb`, outlined in black.
    pub fn cross(&mut self, u: i32, v: i32, rgb: Rgb) {
        for (ink, width) in [([0, 0, 0], 1), (rgb, 0)] {
            for t in -CROSS..=CROSS {
                for w in -width..=width {
                    self.put(u + t, v + w, ink);
                    self.put(u + w, v + t, ink);
                }
            }
        }
    }

    /// `text` with its top left at `(x, y)` on a black band; returns the x after it.
    pub fn label(&mut self, x: i32, y: i32, text: &str, rgb: Rgb) -> i32 {
        let width = (text.chars().count() * font::ADVANCE) as i32 + 2;
        for dy in -1..font::GLYPH_ROWS as i32 {
            for dx in -1..width {
                self.put(x + dx, y + dy, [0, 0, 0]);
            }
        }
        let mut left = x;
        for c in text.chars() {
            for (row, bits) in font::glyph(c).iter().enumerate() {
                for column in 0..font::GLYPH_WIDTH {
                    if bits >> (font::GLYPH_WIDTH - 1 - column) & 1 != 0 {
                        self.put(left + column as i32, y + row as i32, rgb);
                    }
                }
            }
            left += font::ADVANCE as i32;
        }
        left
    }

    pub fn write_png(&self, path: &Path) -> Result<()> {
        crate::picture::write_rgb_png(path, self.width, self.height, &self.rgb)
    }
}
