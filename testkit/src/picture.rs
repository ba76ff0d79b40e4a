//! A picture of the completed object from a side the camera did not see: a virtual camera
//! turned [`TURN_DEG`] about the vertical through the points' centroid, points splatted as small
//! discs into a z-buffer, coloured by provenance (see [`super::colour`]) and darkened with depth.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use shape_from_symmetry::CompletedPoint;
use shape_from_symmetry::math::{Vec3, normalize, rotation};

use super::colour::{self, Rgb};
use super::{Context, Result};

pub const WIDTH: usize = 480;
pub const HEIGHT: usize = 360;
/// How far the virtual camera is turned about the vertical, away from the real one.
pub const TURN_DEG: f32 = 150.0;
/// Share of the picture's width or height the object fills.
const FILL: f32 = 0.75;

/// An RGB picture, row-major.
pub struct Picture {
    rgb: Vec<Rgb>,
}

/// A camera frame: `x` right, `y` down, `z` forward, rows of the world-to-view rotation.
struct View {
    eye: Vec3,
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

impl View {
    /// The real camera (at the origin) turned about `up` through `center`, looking at `center`.
    fn turned(center: Vec3, up: Vec3) -> Option<Self> {
        let eye = center + rotation(up, TURN_DEG.to_radians()) * -center;
        let z = normalize(center - eye)?;
        let y = normalize(z * up.dot(z) - up)?;
        Some(Self {
            eye,
            x: y.cross(z),
            y,
            z,
        })
    }

    fn to_view(&self, p: Vec3) -> Vec3 {
        let r = p - self.eye;
        Vec3::new(r.dot(self.x), r.dot(self.y), r.dot(self.z))
    }
}

/// Render `points` seen from behind; `up` is the object's vertical (the table normal, or the
/// camera's up when there is no table). No points: an empty picture.
pub fn back_view(points: &[CompletedPoint], domains: usize, up: Vec3) -> Picture {
    let mut picture = Picture {
        rgb: vec![colour::BACKGROUND; WIDTH * HEIGHT],
    };
    let positions: Vec<Vec3> = points
        .iter()
        .map(|p| Vec3::from_array(p.position))
        .collect();
    let Some(view) = median(&positions).and_then(|c| View::turned(c, up)) else {
        return picture;
    };
    let seen: Vec<(Vec3, Rgb)> = positions
        .iter()
        .zip(points)
        .map(|(&p, point)| (view.to_view(p), colour::of(point, domains)))
        .filter(|(q, _)| q.z > 1e-3)
        .collect();
    let Some(frame) = Frame::fit(&seen) else {
        return picture;
    };
    let (near, far) = seen.iter().fold((f32::MAX, f32::MIN), |(n, f), (q, _)| {
        (n.min(q.z), f.max(q.z))
    });
    let mut depth = vec![f32::MAX; WIDTH * HEIGHT];
    for (q, rgb) in &seen {
        let shade = 1.0 - 0.45 * (q.z - near) / (far - near).max(1e-6);
        picture.splat(
            &mut depth,
            frame.pixel(*q),
            frame.radius,
            scaled(*rgb, shade),
        );
    }
    picture
}

/// Where the view's image plane lands in the picture: the middle 98 % of the points (by image
/// coordinate, so that a few stray points do not shrink the object) fill [`FILL`] of it.
struct Frame {
    focal: f32,
    /// Image-plane coordinates (`x/z`, `y/z`) of the picture's centre.
    middle: (f32, f32),
    /// Disc radius in pixels.
    radius: f32,
}

impl Frame {
    fn fit(seen: &[(Vec3, Rgb)]) -> Option<Self> {
        let (xs, ys): (Vec<f32>, Vec<f32>) =
            seen.iter().map(|(q, _)| (q.x / q.z, q.y / q.z)).unzip();
        let ((x0, x1), (y0, y1)) = (percentiles(xs)?, percentiles(ys)?);
        let fits = |pixels: usize, span: f32| FILL * pixels as f32 / span.max(1e-6);
        let focal = fits(WIDTH, x1 - x0).min(fits(HEIGHT, y1 - y0));
        // Discs that cover the object's image area about once over.
        let area = (x1 - x0) * (y1 - y0) * focal * focal;
        let radius = (0.6 * (area / seen.len() as f32).sqrt()).clamp(1.5, 6.0);
        focal.is_finite().then_some(Self {
            focal,
            middle: ((x0 + x1) / 2.0, (y0 + y1) / 2.0),
            radius,
        })
    }

    /// Picture coordinates and depth of a view-frame point.
    fn pixel(&self, q: Vec3) -> (f32, f32, f32) {
        let u = self.focal * (q.x / q.z - self.middle.0) + WIDTH as f32 / 2.0;
        let v = self.focal * (q.y / q.z - self.middle.1) + HEIGHT as f32 / 2.0;
        (u, v, q.z)
    }
}

impl Picture {
    /// A disc of `radius` pixels at `(u, v)`, depth `z`, its rim a little darker.
    fn splat(&mut self, depth: &mut [f32], (u, v, z): (f32, f32, f32), radius: f32, rgb: Rgb) {
        let reach = radius.ceil() as i64;
        let (cu, cv) = (u.round() as i64, v.round() as i64);
        for dv in -reach..=reach {
            for du in -reach..=reach {
                let (x, y) = (cu + du, cv + dv);
                let d2 = (du * du + dv * dv) as f32;
                if d2 > radius * radius
                    || !(0..WIDTH as i64).contains(&x)
                    || !(0..HEIGHT as i64).contains(&y)
                {
                    continue;
                }
                let i = y as usize * WIDTH + x as usize;
                if z < depth[i] {
                    depth[i] = z;
                    let rim = d2 > (radius - 1.0).max(0.0).powi(2);
                    self.rgb[i] = if rim { scaled(rgb, 0.75) } else { rgb };
                }
            }
        }
    }

    pub fn write_png(&self, path: &Path) -> Result<()> {
        let shown = path.display();
        let file = File::create(path).context(|| format!("cannot create {shown}"))?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), WIDTH as u32, HEIGHT as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .context(|| format!("cannot write {shown}"))?;
        writer
            .write_image_data(self.rgb.as_flattened())
            .context(|| format!("cannot write {shown}"))?;
        writer.finish().context(|| format!("cannot write {shown}"))
    }
}

/// The per-coordinate median: a centre that stray points do not move.
fn median(points: &[Vec3]) -> Option<Vec3> {
    let mid = |axis: usize| {
        let mut values: Vec<f32> = points.iter().map(|p| p[axis]).collect();
        values.sort_by(f32::total_cmp);
        values[values.len() / 2]
    };
    (!points.is_empty()).then(|| Vec3::new(mid(0), mid(1), mid(2)))
}

/// The 1st and 99th percentiles.
fn percentiles(mut values: Vec<f32>) -> Option<(f32, f32)> {
    values.sort_by(f32::total_cmp);
    let last = values.len().checked_sub(1)? as f32;
    let at = |share: f32| values[(last * share).round() as usize];
    Some((at(0.01), at(0.99)))
}

fn scaled(rgb: Rgb, factor: f32) -> Rgb {
    rgb.map(|c| (c as f32 * factor).round().clamp(0.0, 255.0) as u8)
}
