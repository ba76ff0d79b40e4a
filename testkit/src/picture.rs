//! The picture the tools write ([`WIDTH`] x [`HEIGHT`] pixels): a title line, two panels side by
//! side and a legend.
//!
//! - Title: the scene's name, the strongest symmetry's type and its confidence.
//! - Left panel, "camera view": the completed points from the real camera (at the origin,
//!   looking along +z; x right, y down).
//! - Right panel, "from behind": the same points from a virtual camera turned [`TURN_DEG`] about
//!   the object's vertical through their centre, showing the side the camera did not see.
//! - Legend: the point colours and the symmetry's line colour.
//!
//! Points are splatted as small discs into a z-buffer, coloured by provenance (seen grey,
//! predicted saturated: see [`super::colour`]) and darkened with depth. Every symmetry of the
//! report is drawn in [`SYMMETRY`] in both panels, through the panel's own camera: a mirror plane
//! as the outline of a square patch of it centred at the foot of its points' centroid and sized
//! to them, an axis as a segment through their extent, a centre as a cross. Where a line passes
//! behind the points it is dashed.

pub(crate) mod font;

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use shape_from_symmetry::math::{Vec3, normalize, orthonormal_basis, rotation};
use shape_from_symmetry::{CompletedPoint, Provenance, Report};

use super::colour::{self, Rgb};
use super::{Context, Result};

/// Picture width: two panels of 480 pixels side by side, about a README column's width.
pub const WIDTH: usize = 960;
/// Picture height: a 306-pixel drawing under the title and captions and above the legend.
pub const HEIGHT: usize = 400;
/// How far the right panel's camera is turned about the vertical, away from the real one: not
/// quite behind, so that the hidden side faces the viewer and a rim of the seen side shows.
pub const TURN_DEG: f32 = 150.0;
/// The colour of the drawn symmetries: a strong blue, apart from the grey of the seen points and
/// from every colour of predicted points (and readable to red-green colour-blind eyes).
pub const SYMMETRY: Rgb = [30, 70, 220];

/// Title and legend text: near black.
const TEXT: Rgb = [30, 30, 35];
/// Panel captions: quieter than the title.
const CAPTION: Rgb = [90, 90, 95];
/// The rules between the bands and panels: just darker than the background.
const RULE: Rgb = [210, 208, 200];

/// Font pixels are drawn as blocks of this side: 14-pixel capitals, readable when the picture is
/// shown at half size.
const TEXT_SCALE: usize = 2;
/// Height of the title band at the top: a line of text with 10 pixels above and below it.
const TITLE_BAND: usize = 34;
/// Height of each panel's caption row, above its drawing: a line of text with 6 pixels above
/// and below it.
const CAPTION_BAND: usize = 26;
/// Height of the legend band at the bottom: as the title band.
const LEGEND_BAND: usize = 34;
/// Space between a picture or panel edge and the text in it: about two characters.
const MARGIN: usize = 12;
/// Space between legend swatches and before their label: they read as one entry.
const SWATCH_GAP: usize = 4;
/// Space between legend entries: they read as separate entries.
const ENTRY_GAP: usize = 2 * MARGIN;

/// Share of a panel's drawing width or height the object and its symmetry fill: a margin keeps
/// them clear of the captions and the panel's edges.
const FILL: f32 = 0.8;
/// The deepest point is this much darker than the nearest one: enough to read depth, little
/// enough that the darkest grey and the darkest predicted colour stay apart.
const DEPTH_SHADE: f32 = 0.35;
/// A disc's rim is drawn this much darker than its middle, so that touching discs stay apart.
const RIM_SHADE: f32 = 0.75;
/// Disc radius as a share of the spacing of the points of its kind (seen or predicted): at
/// least half the diagonal of a square lattice's cell, so that a sampled surface is drawn
/// without gaps and hides what is behind it.
const SPLAT: f32 = 0.75;
/// A predicted point hides a seen one only when it is nearer by this share of the seen points'
/// spacing: where a prediction lands on the seen surface, the measurement shows.
const SEEN_FIRST: f32 = 0.5;
/// Smallest and largest disc radius, pixels: a dense object still shows its points, a sparse
/// one does not turn into blobs.
const RADIUS_RANGE: (f32, f32) = (1.0, 8.0);
/// The points' spacing is measured at this many of them, spread over the list: a stable median
/// at a small share of the cost of measuring every point.
const SPACING_SAMPLES: usize = 256;
/// Closest view depth drawn, metres: lines are clipped there, points nearer are left out (no
/// object is that close to a camera; it only keeps the projection finite).
const NEAR: f32 = 1e-3;

/// A mirror plane's patch reaches this much beyond its points' in-plane extent, so that its
/// outline shows clear of the object.
const PATCH_MARGIN: f32 = 1.15;
/// An axis segment reaches beyond its points' extent by this share of it at each end, so that
/// both ends stick out of the object.
const AXIS_OVERHANG: f32 = 0.15;
/// A direction gives a patch's edges when this much of it (a unit vector) lies in the plane: a
/// direction within about 70° of the plane.
const IN_PLANE: f32 = 0.3;
/// Opacity of a mirror plane's patch over what lies behind it: a tint that leaves the points
/// readable.
const PATCH_ALPHA: f32 = 0.15;
/// Smallest half-size of a patch and smallest axis overhang, metres: a few points still give a
/// visible mark.
const MIN_REACH: f32 = 0.01;
/// Half the width of a drawn line, pixels: 3-pixel lines stand out over the discs.
const LINE_RADIUS: f32 = 1.0;
/// Length of each dash and of each gap where a line is behind the points, pixels: dashes still
/// read as dashes when the picture is shown at half size.
const DASH: usize = 5;
/// A line pixel is behind the points when it is this much deeper than the nearest point there,
/// metres (about a disc's depth spread, so that a line on the surface stays solid).
const HIDDEN_DEPTH: f32 = 0.005;
/// Half the length of a centre's cross arms, pixels: a cross about twice the largest disc.
const CROSS_ARM: f32 = 7.0;

/// An RGB picture of [`WIDTH`] x [`HEIGHT`] pixels, row-major.
pub struct Picture {
    rgb: Vec<Rgb>,
}

/// The picture of `report` and its completed `points` for the scene called `name`; `up` is the
/// object's vertical (the table normal, or the camera's up when there is no table). With no
/// points the panels are empty; the title and legend are always there.
pub fn render(name: &str, report: &Report, points: &[CompletedPoint], up: Vec3) -> Picture {
    let mut picture = Picture {
        rgb: vec![colour::BACKGROUND; WIDTH * HEIGHT],
    };
    picture.title(&title(name, report));
    let positions: Vec<Vec3> = points
        .iter()
        .map(|p| Vec3::from_array(p.position))
        .collect();
    let turned = median(&positions).and_then(|c| View::turned(c, up));
    let content = Content {
        points,
        domains: report.symmetries.len(),
        spacing: [Provenance::Visible, Provenance::Generated].map(|provenance| {
            let of_kind = positions.iter().zip(points);
            let selected = of_kind.filter(|(_, p)| p.provenance == provenance);
            spacing(&selected.map(|(&q, _)| q).collect::<Vec<_>>())
        }),
        marks: marks(report, points, up),
    };
    let panels = [
        (0, "camera view".to_string(), Some(View::CAMERA)),
        (1, format!("from behind ({TURN_DEG:.0}° turned)"), turned),
    ];
    for (index, caption, view) in panels {
        let rect = Rect::panel(index);
        picture.text(rect.x + MARGIN, Rect::CAPTION_TOP, &caption, CAPTION);
        if let Some(view) = view {
            picture.panel(rect, &view, &content);
        }
    }
    picture.rules();
    picture.legend(points, content.domains);
    picture
}

/// What both panels draw.
struct Content<'a> {
    points: &'a [CompletedPoint],
    /// Symmetries of the report: the number of domains the colours tell apart.
    domains: usize,
    /// The spacing of the seen and of the predicted points (indexed by [`Provenance`]), metres.
    spacing: [f32; 2],
    marks: Vec<Mark>,
}

/// The title line: `name`, the strongest symmetry and its confidence, and how many more.
fn title(name: &str, report: &Report) -> String {
    let Some(strongest) = report.symmetries.first() else {
        return format!("{name}: no symmetry found");
    };
    let more = match report.symmetries.len() - 1 {
        0 => String::new(),
        1 => " (and 1 part symmetry)".to_string(),
        n => format!(" (and {n} part symmetries)"),
    };
    format!(
        "{name}: {}, confidence {:.2}{more}",
        strongest.symmetry.kind().name(),
        strongest.confidence
    )
}

/// A rectangle of the picture, pixels.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x: usize,
    y: usize,
    w: usize,
    h: usize,
}

impl Rect {
    /// Top of the panel captions' text.
    const CAPTION_TOP: usize = TITLE_BAND + (CAPTION_BAND - font::ASCENT * TEXT_SCALE) / 2;

    /// The drawing area of panel `index` (0 left, 1 right), below its caption.
    fn panel(index: usize) -> Self {
        let top = TITLE_BAND + CAPTION_BAND;
        Self {
            x: index * WIDTH / 2,
            y: top,
            w: WIDTH / 2,
            h: HEIGHT - LEGEND_BAND - top,
        }
    }

    fn contains(&self, x: i64, y: i64) -> bool {
        (self.x as i64..(self.x + self.w) as i64).contains(&x)
            && (self.y as i64..(self.y + self.h) as i64).contains(&y)
    }
}

/// A camera frame: `x` right, `y` down, `z` forward, rows of the world-to-view rotation.
struct View {
    eye: Vec3,
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

impl View {
    /// The real camera.
    const CAMERA: Self = Self {
        eye: Vec3::ZERO,
        x: Vec3::X,
        y: Vec3::Y,
        z: Vec3::Z,
    };

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

/// What draws the symmetries, in the camera frame.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mark {
    /// A square patch of a mirror plane: centre `foot`, unit edge directions `u` and `v` (the
    /// plane's normal is `u × v`), half its side `half`.
    Patch {
        foot: Vec3,
        u: Vec3,
        v: Vec3,
        half: f32,
    },
    /// A straight line between two points.
    Segment(Vec3, Vec3),
    /// A centre, drawn as a cross.
    Cross(Vec3),
}

impl Mark {
    /// The points the drawing reaches (repeated to fill the four).
    fn ends(&self) -> [Vec3; 4] {
        match *self {
            Mark::Patch { foot, u, v, half } => {
                [u + v, u - v, -u - v, -u + v].map(|c| foot + c * half)
            }
            Mark::Segment(a, b) => [a, b, a, b],
            Mark::Cross(c) => [c; 4],
        }
    }
}

/// The marks of every symmetry of `report`, each sized to the points it explains or made (all
/// the points when the report has one symmetry, or none of the points belongs to it).
fn marks(report: &Report, points: &[CompletedPoint], up: Vec3) -> Vec<Mark> {
    let mut marks = Vec::new();
    let single = report.symmetries.len() == 1;
    let all: Vec<Vec3> = points
        .iter()
        .map(|p| Vec3::from_array(p.position))
        .collect();
    for (index, found) in report.symmetries.iter().enumerate() {
        let in_domain = all.iter().zip(points);
        let in_domain = in_domain.filter(|(_, p)| single || p.symmetry as usize == index);
        let mut members: Vec<Vec3> = in_domain.map(|(&q, _)| q).collect();
        if members.is_empty() {
            members = all.clone();
        }
        let Some(centroid) = mean(&members) else {
            continue;
        };
        let symmetry = &found.symmetry;
        for plane in symmetry.planes() {
            let n = plane.n();
            let foot = centroid - n * plane.signed_distance(centroid);
            // Edges along the object's vertical where the plane holds it (a vertical mirror
            // shows as an upright square), else along the line of sight.
            let u = [up, centroid]
                .into_iter()
                .find_map(|d| {
                    let along = normalize(d).map(|d| d - n * n.dot(d))?;
                    (along.length() > IN_PLANE).then(|| along.normalize())
                })
                .unwrap_or_else(|| orthonormal_basis(n).0);
            let v = n.cross(u);
            let reach = members
                .iter()
                .map(|&p| (p - foot).dot(u).abs().max((p - foot).dot(v).abs()))
                .collect();
            let half = percentiles(reach).map_or(0.0, |(_, high)| high * PATCH_MARGIN);
            let half = half.max(MIN_REACH);
            marks.push(Mark::Patch { foot, u, v, half });
        }
        if let Some(axis) = symmetry.axis() {
            let (d, point) = (
                Vec3::from_array(axis.direction),
                Vec3::from_array(axis.point),
            );
            let along = members.iter().map(|&p| d.dot(p - point)).collect();
            if let Some((low, high)) = percentiles(along) {
                let overhang = ((high - low) * AXIS_OVERHANG).max(MIN_REACH);
                marks.push(Mark::Segment(
                    point + d * (low - overhang),
                    point + d * (high + overhang),
                ));
            }
        }
        if let Some(center) = symmetry.center() {
            marks.push(Mark::Cross(Vec3::from_array(center)));
        }
    }
    marks
}

/// Where a view's image plane lands in a panel: the middle 98 % of the points (by image
/// coordinate, so that a few stray points do not shrink the object) and every mark fill
/// [`FILL`] of it.
#[derive(Clone, Copy, Debug)]
struct Frame {
    rect: Rect,
    focal: f32,
    /// Image-plane coordinates (`x/z`, `y/z`) of the panel's centre.
    middle: (f32, f32),
}

impl Frame {
    /// The frame for view-frame points `seen` (all in front of the camera) and mark ends
    /// `extra` (those in front of the camera count); `None` without points.
    fn fit(rect: Rect, seen: &[Vec3], extra: &[Vec3]) -> Option<Self> {
        let (xs, ys): (Vec<f32>, Vec<f32>) = seen.iter().map(|q| (q.x / q.z, q.y / q.z)).unzip();
        let ((mut x0, mut x1), (mut y0, mut y1)) = (percentiles(xs)?, percentiles(ys)?);
        for q in extra.iter().filter(|q| q.z > NEAR) {
            let (x, y) = (q.x / q.z, q.y / q.z);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        let fits = |pixels: usize, span: f32| FILL * pixels as f32 / span.max(1e-6);
        let focal = fits(rect.w, x1 - x0).min(fits(rect.h, y1 - y0));
        focal.is_finite().then_some(Self {
            rect,
            focal,
            middle: ((x0 + x1) / 2.0, (y0 + y1) / 2.0),
        })
    }

    /// The radius in pixels of the disc of a point at view depth `z` among points `spacing`
    /// metres apart.
    fn radius(&self, spacing: f32, z: f32) -> f32 {
        (SPLAT * spacing * self.focal / z).clamp(RADIUS_RANGE.0, RADIUS_RANGE.1)
    }

    /// Picture coordinates and depth of a view-frame point.
    fn pixel(&self, q: Vec3) -> (f32, f32, f32) {
        let u = self.focal * (q.x / q.z - self.middle.0) + (self.rect.x + self.rect.w / 2) as f32;
        let v = self.focal * (q.y / q.z - self.middle.1) + (self.rect.y + self.rect.h / 2) as f32;
        (u, v, q.z)
    }
}

impl Picture {
    /// Draw `points` and `marks` through `view` into the drawing area `rect`; the frame used,
    /// `None` when no point is in front of the camera.
    fn panel(&mut self, rect: Rect, view: &View, content: &Content) -> Option<Frame> {
        let Content {
            points,
            domains,
            spacing,
            marks,
        } = content;
        // View position, colour, spacing and the depth the z-buffer compares.
        let shown: Vec<(Vec3, Rgb, f32, f32)> = points
            .iter()
            .map(|p| {
                let q = view.to_view(Vec3::from_array(p.position));
                let behind = match p.provenance {
                    Provenance::Visible => 0.0,
                    Provenance::Generated => SEEN_FIRST * spacing[Provenance::Visible as usize],
                };
                let apart = spacing[p.provenance as usize];
                (q, colour::of(p, *domains), apart, q.z + behind)
            })
            .filter(|(q, ..)| q.z > NEAR)
            .collect();
        let positions: Vec<Vec3> = shown.iter().map(|(q, ..)| *q).collect();
        let ends: Vec<Vec3> = marks
            .iter()
            .flat_map(Mark::ends)
            .map(|p| view.to_view(p))
            .collect();
        let frame = Frame::fit(rect, &positions, &ends)?;
        let (near, far) = positions
            .iter()
            .fold((f32::MAX, f32::MIN), |(n, f), q| (n.min(q.z), f.max(q.z)));
        let mut depth = vec![f32::MAX; WIDTH * HEIGHT];
        for &(q, rgb, apart, key) in &shown {
            let shade = 1.0 - DEPTH_SHADE * (q.z - near) / (far - near).max(1e-6);
            let (u, v, _) = frame.pixel(q);
            let radius = frame.radius(apart, q.z);
            self.splat(
                &mut depth,
                frame.rect,
                (u, v, key),
                radius,
                scaled(rgb, shade),
            );
        }
        for mark in marks.iter() {
            if let Mark::Patch { foot, u, v, half } = *mark {
                self.patch(&depth, &frame, view, (foot, u, v, half));
            }
        }
        for mark in marks.iter() {
            match *mark {
                Mark::Patch { .. } => {
                    let corners = mark.ends().map(|c| view.to_view(c));
                    for (i, &a) in corners.iter().enumerate() {
                        self.segment(&depth, &frame, a, corners[(i + 1) % 4]);
                    }
                }
                Mark::Segment(a, b) => {
                    self.segment(&depth, &frame, view.to_view(a), view.to_view(b));
                }
                Mark::Cross(c) => {
                    let q = view.to_view(c);
                    if q.z > NEAR {
                        let (u, v, _) = frame.pixel(q);
                        let arms = [(CROSS_ARM, CROSS_ARM), (CROSS_ARM, -CROSS_ARM)];
                        for (du, dv) in arms {
                            self.line(frame.rect, (u - du, v - dv), (u + du, v + dv), |_, _| true);
                        }
                    }
                }
            }
        }
        Some(frame)
    }

    /// A disc of `radius` pixels at `(u, v)` within `rect`, drawn where its depth `z` is nearer
    /// than `depth`'s, its rim a little darker.
    fn splat(
        &mut self,
        depth: &mut [f32],
        rect: Rect,
        (u, v, z): (f32, f32, f32),
        radius: f32,
        rgb: Rgb,
    ) {
        let reach = radius.ceil() as i64;
        let (cu, cv) = (u.round() as i64, v.round() as i64);
        for dv in -reach..=reach {
            for du in -reach..=reach {
                let (x, y) = (cu + du, cv + dv);
                let d2 = (du * du + dv * dv) as f32;
                if d2 > radius * radius || !rect.contains(x, y) {
                    continue;
                }
                let i = y as usize * WIDTH + x as usize;
                if z < depth[i] {
                    depth[i] = z;
                    let rim = d2 > (radius - 1.0).max(0.0).powi(2);
                    self.rgb[i] = if rim { scaled(rgb, RIM_SHADE) } else { rgb };
                }
            }
        }
    }

    /// Tint the pixels where the world-frame patch `(foot, u, v, half)` (see [`Mark::Patch`])
    /// is in front of the points of `depth` with [`SYMMETRY`]: a pane of tinted glass.
    fn patch(&mut self, depth: &[f32], frame: &Frame, view: &View, patch: (Vec3, Vec3, Vec3, f32)) {
        let (foot, u, v, half) = patch;
        let turn = |d: Vec3| Vec3::new(d.dot(view.x), d.dot(view.y), d.dot(view.z));
        let (foot, u, v) = (view.to_view(foot), turn(u), turn(v));
        let n = u.cross(v);
        let rect = frame.rect;
        let centre = ((rect.x + rect.w / 2) as f32, (rect.y + rect.h / 2) as f32);
        for y in rect.y..rect.y + rect.h {
            for x in rect.x..rect.x + rect.w {
                // The ray through the pixel, scaled to unit view depth.
                let ray = Vec3::new(
                    (x as f32 - centre.0) / frame.focal + frame.middle.0,
                    (y as f32 - centre.1) / frame.focal + frame.middle.1,
                    1.0,
                );
                let z = n.dot(foot) / n.dot(ray);
                let hit = ray * z - foot;
                let i = y * WIDTH + x;
                if z > NEAR && z < depth[i] && hit.dot(u).abs() <= half && hit.dot(v).abs() <= half
                {
                    self.rgb[i] = mixed(self.rgb[i], SYMMETRY, PATCH_ALPHA);
                }
            }
        }
    }

    /// The view-frame segment `a`-`b`, clipped to the depth [`NEAR`], dashed where it is behind
    /// the points of `depth`.
    fn segment(&mut self, depth: &[f32], frame: &Frame, a: Vec3, b: Vec3) {
        let clip = |p: Vec3, other: Vec3| {
            if p.z >= NEAR {
                p
            } else {
                p + (other - p) * ((NEAR - p.z) / (other.z - p.z))
            }
        };
        if a.z < NEAR && b.z < NEAR {
            return;
        }
        let (a, b) = (clip(a, b), clip(b, a));
        let ((ua, va, za), (ub, vb, zb)) = (frame.pixel(a), frame.pixel(b));
        // Depth along the picture line: its inverse is linear in picture coordinates.
        let depth_at = |t: f32| 1.0 / (1.0 / za + (1.0 / zb - 1.0 / za) * t);
        let shown = |t: f32, step: usize| {
            let (x, y) = (ua + (ub - ua) * t, va + (vb - va) * t);
            let (x, y) = (x.round() as i64, y.round() as i64);
            let front = !frame.rect.contains(x, y)
                || depth_at(t) <= depth[y as usize * WIDTH + x as usize] + HIDDEN_DEPTH;
            front || dash_on(step)
        };
        self.line(frame.rect, (ua, va), (ub, vb), shown);
    }

    /// A line of [`SYMMETRY`] from `a` to `b` within `rect`, one dot a pixel step; `shown(t,
    /// step)` says whether the dot at share `t` of the way, step number `step`, is drawn.
    fn line(
        &mut self,
        rect: Rect,
        a: (f32, f32),
        b: (f32, f32),
        shown: impl Fn(f32, usize) -> bool,
    ) {
        let span = (b.0 - a.0).abs().max((b.1 - a.1).abs());
        // A line far outside the picture (an end just in front of the camera) is not walked
        // pixel by pixel beyond this.
        let steps = span.ceil().clamp(1.0, (4 * (WIDTH + HEIGHT)) as f32) as usize;
        let reach = LINE_RADIUS.ceil() as i64;
        for step in 0..=steps {
            let t = step as f32 / steps as f32;
            if !shown(t, step) {
                continue;
            }
            let (u, v) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            let (cu, cv) = (u.round() as i64, v.round() as i64);
            for dv in -reach..=reach {
                for du in -reach..=reach {
                    let (x, y) = (cu + du, cv + dv);
                    let d2 = (du * du + dv * dv) as f32;
                    if d2 <= LINE_RADIUS * LINE_RADIUS && rect.contains(x, y) {
                        self.rgb[y as usize * WIDTH + x as usize] = SYMMETRY;
                    }
                }
            }
        }
    }

    /// `text` in the font at [`TEXT_SCALE`], its glyph cells' top-left corner at `(x, y)`;
    /// the pixel column after it. Clipped at the picture's edges.
    fn text(&mut self, x: usize, y: usize, text: &str, rgb: Rgb) -> usize {
        let mut left = x;
        for c in text.chars() {
            let glyph = font::glyph(c);
            for (row, bits) in glyph.iter().enumerate() {
                for column in 0..font::GLYPH_WIDTH {
                    if bits >> (font::GLYPH_WIDTH - 1 - column) & 1 == 0 {
                        continue;
                    }
                    let (x0, y0) = (left + column * TEXT_SCALE, y + row * TEXT_SCALE);
                    self.fill(x0, y0, TEXT_SCALE, TEXT_SCALE, rgb);
                }
            }
            left += font::ADVANCE * TEXT_SCALE;
        }
        left
    }

    /// The rectangle `w` x `h` at `(x, y)` in `rgb`, clipped at the picture's edges.
    fn fill(&mut self, x: usize, y: usize, w: usize, h: usize, rgb: Rgb) {
        for row in y..(y + h).min(HEIGHT) {
            for column in x..(x + w).min(WIDTH) {
                self.rgb[row * WIDTH + column] = rgb;
            }
        }
    }

    /// The title line in the title band.
    fn title(&mut self, title: &str) {
        let top = (TITLE_BAND - font::ASCENT * TEXT_SCALE) / 2;
        self.text(MARGIN, top, title, TEXT);
    }

    /// Rules under the title band, above the legend band and between the panels.
    fn rules(&mut self) {
        self.fill(0, TITLE_BAND - 1, WIDTH, 1, RULE);
        self.fill(0, HEIGHT - LEGEND_BAND, WIDTH, 1, RULE);
        let bottom = HEIGHT - LEGEND_BAND;
        self.fill(WIDTH / 2, TITLE_BAND, 1, bottom - TITLE_BAND, RULE);
    }

    /// The legend band: a swatch of each colour of seen and of predicted points (one a domain
    /// when there are several) with their counts, and the symmetry's line, solid and dashed.
    fn legend(&mut self, points: &[CompletedPoint], domains: usize) {
        let count = |p: Provenance| points.iter().filter(|q| q.provenance == p).count();
        let shown = domains.max(1);
        let seen: Vec<Rgb> = if domains > 1 {
            (0..shown).map(colour::seen_in).collect()
        } else {
            vec![colour::VISIBLE]
        };
        let predicted: Vec<Rgb> = (0..shown).map(colour::predicted).collect();
        let top = HEIGHT - LEGEND_BAND + (LEGEND_BAND - font::ASCENT * TEXT_SCALE) / 2;
        let middle = top + font::ASCENT * TEXT_SCALE / 2;
        // Swatch side: as tall as a capital.
        let side = font::ASCENT * TEXT_SCALE;
        let mut x = MARGIN;
        let entries = [
            (seen, format!("seen ({})", count(Provenance::Visible))),
            (
                predicted,
                format!("predicted ({})", count(Provenance::Generated)),
            ),
        ];
        for (swatches, label) in entries {
            for rgb in swatches {
                self.fill(x, top, side, side, rgb);
                x += side + SWATCH_GAP;
            }
            x = self.text(x + SWATCH_GAP, top, &label, TEXT) + ENTRY_GAP;
        }
        // The line samples: as long as three swatches.
        let sample = 3 * side;
        let whole = Rect {
            x: 0,
            y: 0,
            w: WIDTH,
            h: HEIGHT,
        };
        for (label, dashed) in [("symmetry", false), ("behind the points", true)] {
            let (a, b) = (
                (x as f32, middle as f32),
                ((x + sample) as f32, middle as f32),
            );
            self.line(whole, a, b, |_, step| !dashed || dash_on(step));
            x = self.text(x + sample + 2 * SWATCH_GAP, top, label, TEXT) + ENTRY_GAP;
        }
    }

    pub fn write_png(&self, path: &Path) -> Result<()> {
        write_rgb_png(path, WIDTH, HEIGHT, &self.rgb)
    }
}

/// Write `rgb` (`width` x `height`, row-major) as an 8-bit RGB PNG at `path`.
pub fn write_rgb_png(path: &Path, width: usize, height: usize, rgb: &[Rgb]) -> Result<()> {
    let shown = path.display();
    let file = File::create(path).context(|| format!("cannot create {shown}"))?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder
        .write_header()
        .context(|| format!("cannot write {shown}"))?;
    writer
        .write_image_data(rgb.as_flattened())
        .context(|| format!("cannot write {shown}"))?;
    writer.finish().context(|| format!("cannot write {shown}"))
}

/// Whether step `step` of a dashed line falls on a dash (rather than a gap).
fn dash_on(step: usize) -> bool {
    (step / DASH).is_multiple_of(2)
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

/// The points' spacing: the median distance from a point to its nearest other point, over up
/// to [`SPACING_SAMPLES`] of them; 0 with fewer than two distinct points.
fn spacing(points: &[Vec3]) -> f32 {
    let stride = points.len().div_ceil(SPACING_SAMPLES).max(1);
    let nearest = points.iter().step_by(stride).filter_map(|&p| {
        let distances = points.iter().map(|&q| q.distance(p)).filter(|&d| d > 0.0);
        distances.min_by(f32::total_cmp)
    });
    let mut nearest: Vec<f32> = nearest.collect();
    nearest.sort_by(f32::total_cmp);
    nearest.get(nearest.len() / 2).copied().unwrap_or(0.0)
}

/// The centroid.
fn mean(points: &[Vec3]) -> Option<Vec3> {
    let sum = points.iter().fold(Vec3::ZERO, |s, &p| s + p);
    (!points.is_empty()).then(|| sum / points.len() as f32)
}

/// The 1st and 99th percentiles.
fn percentiles(mut values: Vec<f32>) -> Option<(f32, f32)> {
    values.sort_by(f32::total_cmp);
    let last = values.len().checked_sub(1)? as f32;
    let at = |share: f32| values[(last * share).round() as usize];
    Some((at(0.01), at(0.99)))
}

/// `share` of `top` over `1 - share` of `under`.
fn mixed(under: Rgb, top: Rgb, share: f32) -> Rgb {
    std::array::from_fn(|i| {
        (under[i] as f32 + (top[i] as f32 - under[i] as f32) * share).round() as u8
    })
}

fn scaled(rgb: Rgb, factor: f32) -> Rgb {
    rgb.map(|c| (c as f32 * factor).round().clamp(0.0, 255.0) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shape_from_symmetry::{Axis, Found, Plane, Symmetry};
    use std::io::BufReader;

    const CENTRE: Vec3 = Vec3::new(0.0, 0.0, 0.5);
    const RADIUS: f32 = 0.04;
    const UP: Vec3 = Vec3::NEG_Y;

    /// A sphere of points about [`CENTRE`]: the half facing the camera seen, the far half
    /// predicted by symmetry 0.
    fn sphere() -> Vec<CompletedPoint> {
        let n = 1200;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                let phi = golden * i as f32;
                let direction = Vec3::new(r * phi.cos(), y, r * phi.sin());
                let provenance = if direction.z < 0.0 {
                    Provenance::Visible
                } else {
                    Provenance::Generated
                };
                CompletedPoint {
                    position: (CENTRE + direction * RADIUS).to_array(),
                    provenance,
                    symmetry: 0,
                    ..CompletedPoint::ZERO
                }
            })
            .collect()
    }

    fn report(symmetries: &[Symmetry]) -> Report {
        let mut report = Report::default();
        for &symmetry in symmetries {
            let found = Found {
                symmetry,
                score: 0.2,
                confidence: 0.6,
                domain_points: 600,
            };
            report.symmetries.push(found).unwrap();
        }
        report
    }

    fn blank() -> Picture {
        Picture {
            rgb: vec![colour::BACKGROUND; WIDTH * HEIGHT],
        }
    }

    fn content<'a>(points: &'a [CompletedPoint], report: &Report) -> Content<'a> {
        let positions: Vec<Vec3> = points
            .iter()
            .map(|p| Vec3::from_array(p.position))
            .collect();
        let of = |provenance| {
            let selected = positions.iter().zip(points);
            let selected = selected.filter(|(_, p)| p.provenance == provenance);
            spacing(&selected.map(|(&q, _)| q).collect::<Vec<_>>())
        };
        Content {
            points,
            domains: report.symmetries.len(),
            spacing: [of(Provenance::Visible), of(Provenance::Generated)],
            marks: marks(report, points, UP),
        }
    }

    /// Both panels of `content`, drawn on a blank picture, with their views and frames.
    fn panels(content: &Content) -> (Picture, [(View, Frame); 2]) {
        let mut picture = blank();
        let turned = View::turned(CENTRE, UP).unwrap();
        let mut draw = |index, view: View| {
            let frame = picture.panel(Rect::panel(index), &view, content).unwrap();
            (view, frame)
        };
        let drawn = [draw(0, View::CAMERA), draw(1, turned)];
        (picture, drawn)
    }

    /// The pixel where the world point `p` lands in a panel.
    fn pixel_of((view, frame): &(View, Frame), p: Vec3) -> (usize, usize) {
        let (u, v, _) = frame.pixel(view.to_view(p));
        (u.round() as usize, v.round() as usize)
    }

    fn at(picture: &Picture, (x, y): (usize, usize)) -> Rgb {
        picture.rgb[y * WIDTH + x]
    }

    /// The pixels of panel `index`'s drawing area.
    fn area(picture: &Picture, index: usize) -> Vec<Rgb> {
        let r = Rect::panel(index);
        let rows = r.y..r.y + r.h;
        rows.flat_map(|y| (r.x..r.x + r.w).map(move |x| picture.rgb[y * WIDTH + x]))
            .collect()
    }

    fn is_seen(rgb: Rgb) -> bool {
        rgb != colour::BACKGROUND && colour::saturation(rgb) <= 8
    }

    fn is_predicted(rgb: Rgb) -> bool {
        let [r, g, b] = rgb.map(i32::from);
        g > r + 40 && g > b + 30
    }

    #[test]
    fn the_picture_is_as_large_as_documented_and_the_panels_tile_it() {
        let points = sphere();
        let picture = render("sphere", &report(&[]), &points, UP);
        assert_eq!(picture.rgb.len(), WIDTH * HEIGHT);
        let path = std::env::temp_dir().join(format!("sfs-picture-{}.png", std::process::id()));
        picture.write_png(&path).unwrap();
        let decoder = png::Decoder::new(BufReader::new(File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        let info = reader.info();
        assert_eq!((info.width, info.height), (WIDTH as u32, HEIGHT as u32));
        assert_eq!(
            (info.width, info.height),
            (960, 400),
            "the size the docs state"
        );
        std::fs::remove_file(&path).unwrap();
        let (left, right) = (Rect::panel(0), Rect::panel(1));
        assert_eq!(
            (left.x, left.x + left.w, right.x + right.w),
            (0, right.x, WIDTH)
        );
        assert_eq!(left.y + left.h, HEIGHT - LEGEND_BAND);
    }

    #[test]
    fn the_camera_view_shows_the_seen_side_and_the_turned_view_the_predicted_one() {
        let points = sphere();
        let picture = render("sphere", &report(&[]), &points, UP);
        let (left, right) = (area(&picture, 0), area(&picture, 1));
        let count =
            |pixels: &[Rgb], test: fn(Rgb) -> bool| pixels.iter().filter(|&&c| test(c)).count();
        let (left_seen, left_predicted) = (count(&left, is_seen), count(&left, is_predicted));
        let (right_seen, right_predicted) = (count(&right, is_seen), count(&right, is_predicted));
        assert!(
            left_seen > 4 * left_predicted,
            "{left_seen} seen, {left_predicted} predicted"
        );
        assert!(
            right_predicted > 2 * right_seen,
            "{right_seen} seen, {right_predicted} predicted"
        );
        let differing = left.iter().zip(&right).filter(|(a, b)| a != b).count();
        assert!(
            differing > left.len() / 20,
            "only {differing} pixels differ"
        );
    }

    #[test]
    fn a_seen_and_a_predicted_point_land_in_their_colours() {
        let points = sphere();
        let report = report(&[]);
        let content = content(&points, &report);
        let (picture, [camera, turned]) = panels(&content);
        // The point nearest to each camera: seen for the real one, predicted for the turned one.
        let nearest = |(view, _): &(View, Frame)| {
            let depth = |p: &&CompletedPoint| view.to_view(Vec3::from_array(p.position)).z;
            let p = points
                .iter()
                .min_by(|a, b| depth(a).total_cmp(&depth(b)))
                .unwrap();
            (Vec3::from_array(p.position), p.provenance)
        };
        let (seen, provenance) = nearest(&camera);
        assert_eq!(provenance, Provenance::Visible);
        assert_eq!(at(&picture, pixel_of(&camera, seen)), colour::VISIBLE);
        let (predicted, provenance) = nearest(&turned);
        assert_eq!(provenance, Provenance::Generated);
        assert_eq!(
            at(&picture, pixel_of(&turned, predicted)),
            colour::predicted(0)
        );
        assert!(colour::saturation(colour::predicted(0)) > 100);
    }

    #[test]
    fn a_mirror_planes_outline_is_drawn_in_the_symmetry_colour() {
        let points = sphere();
        let plane = Plane {
            normal: [0.0, 0.0, 1.0],
            offset: CENTRE.z,
        };
        let report = report(&[Symmetry::PlaneReflection(plane)]);
        let content = content(&points, &report);
        let [Mark::Patch { foot, half, .. }] = content.marks[..] else {
            panic!("one patch expected, got {:?}", content.marks)
        };
        assert!(
            foot.distance(CENTRE) < 1e-3,
            "the patch is centred at {foot}"
        );
        assert!((RADIUS..RADIUS * 1.2).contains(&half), "half side {half}");
        let (picture, [camera, _]) = panels(&content);
        let corners = content.marks[0].ends();
        for (i, &a) in corners.iter().enumerate() {
            let middle = (a + corners[(i + 1) % 4]) / 2.0;
            assert_eq!(
                at(&picture, pixel_of(&camera, middle)),
                SYMMETRY,
                "edge {i}"
            );
        }
        // Both panels outline the patch and tint the background it covers; from behind it is
        // seen from its far side.
        let tint = mixed(colour::BACKGROUND, SYMMETRY, PATCH_ALPHA);
        for index in 0..2 {
            let count = |rgb| area(&picture, index).iter().filter(|&&c| c == rgb).count();
            let (outline, tinted) = (count(SYMMETRY), count(tint));
            assert!(
                outline > 400 && tinted > 2000,
                "panel {index}: {outline}, {tinted}"
            );
        }
        // Without the symmetry nothing is drawn in its colour.
        let (bare, _) = panels(&self::content(&points, &self::report(&[])));
        assert!(bare.rgb.iter().all(|&c| c != SYMMETRY));
    }

    #[test]
    fn an_axis_and_a_centre_are_drawn_in_both_panels() {
        let points = sphere();
        let axis = Axis {
            direction: UP.to_array(),
            point: CENTRE.to_array(),
        };
        let axial = report(&[Symmetry::Axial(axis)]);
        let content = content(&points, &axial);
        let [Mark::Segment(a, b)] = content.marks[..] else {
            panic!("one segment expected, got {:?}", content.marks)
        };
        // Through the sphere's extent along the axis, and beyond it at both ends.
        assert!(a.distance(CENTRE) > RADIUS && b.distance(CENTRE) > RADIUS);
        assert!(a.distance(CENTRE) < 2.0 * RADIUS && b.distance(CENTRE) < 2.0 * RADIUS);
        assert!(
            (a - CENTRE).cross(b - CENTRE).length() < 1e-6,
            "off the axis: {a} {b}"
        );
        let (picture, drawn) = panels(&content);
        for panel in &drawn {
            for end in [a, b] {
                // Just inside the end: beyond the sphere, so drawn solid.
                let p = end + (CENTRE - end) * 0.05;
                assert_eq!(at(&picture, pixel_of(panel, p)), SYMMETRY);
            }
        }
        let spherical = report(&[Symmetry::Spherical(CENTRE.to_array())]);
        let content = self::content(&points, &spherical);
        assert_eq!(content.marks, [Mark::Cross(CENTRE)]);
        let (picture, drawn) = panels(&content);
        for panel in &drawn {
            let (x, y) = pixel_of(panel, CENTRE);
            let arm = CROSS_ARM as usize - 1;
            for corner in [(x - arm, y - arm), (x + arm, y + arm), (x + arm, y - arm)] {
                assert_eq!(at(&picture, corner), SYMMETRY);
            }
            assert_ne!(
                at(&picture, (x, y - arm)),
                SYMMETRY,
                "a cross, not a square"
            );
        }
    }

    #[test]
    fn the_title_names_the_scene_and_the_strongest_symmetry_and_text_is_drawn() {
        let points = sphere();
        let axial = report(&[Symmetry::Spherical(CENTRE.to_array())]);
        assert_eq!(title("ball", &axial), "ball: spherical, confidence 0.60");
        assert_eq!(title("ball", &report(&[])), "ball: no symmetry found");
        let two = report(&[Symmetry::Spherical([0.0; 3]); 2]);
        assert_eq!(
            title("b", &two),
            "b: spherical, confidence 0.60 (and 1 part symmetry)"
        );
        let band = |picture: &Picture| picture.rgb[..(TITLE_BAND - 1) * WIDTH].to_vec();
        let inked = |pixels: Vec<Rgb>| pixels.iter().filter(|&&c| c == TEXT).count();
        let ball = render("ball", &axial, &points, UP);
        let long = render("a longer name", &axial, &points, UP);
        assert!(inked(band(&ball)) > 100);
        assert!(
            inked(band(&long)) > inked(band(&ball)),
            "the name is not drawn"
        );
        // The legend: a swatch of each kind of point, labels, and the symmetry's line.
        let legend = ball.rgb[(HEIGHT - LEGEND_BAND + 1) * WIDTH..].to_vec();
        for rgb in [colour::VISIBLE, colour::predicted(0), SYMMETRY] {
            assert!(legend.contains(&rgb), "{rgb:?} missing from the legend");
        }
        assert!(inked(legend) > 300);
    }

    #[test]
    fn text_is_drawn_glyph_by_glyph_at_the_text_scale() {
        let mut picture = blank();
        let end = picture.text(0, 0, "|.", TEXT);
        assert_eq!(end, 2 * font::ADVANCE * TEXT_SCALE);
        let inked = |x: usize, y: usize| picture.rgb[y * WIDTH + x] == TEXT;
        // `|`: the middle column, all seven rows above the baseline.
        let bar = 2 * TEXT_SCALE..3 * TEXT_SCALE;
        for y in 0..font::ASCENT * TEXT_SCALE {
            for x in 0..font::ADVANCE * TEXT_SCALE {
                assert_eq!(inked(x, y), bar.contains(&x), "({x}, {y})");
            }
        }
        // `.`: two by two font pixels on the baseline.
        let dot = font::ADVANCE * TEXT_SCALE + TEXT_SCALE;
        assert!(inked(dot, 5 * TEXT_SCALE) && inked(dot + 2 * TEXT_SCALE - 1, 7 * TEXT_SCALE - 1));
        assert!(!inked(dot, 4 * TEXT_SCALE));
    }

    #[test]
    fn no_points_leave_the_panels_empty_under_their_captions() {
        let picture = render("empty", &report(&[]), &[], UP);
        for index in 0..2 {
            let area = area(&picture, index);
            assert!(area.iter().all(|&c| c == colour::BACKGROUND || c == RULE));
        }
        let captions = &picture.rgb[TITLE_BAND * WIDTH..(TITLE_BAND + CAPTION_BAND) * WIDTH];
        assert!(captions.contains(&CAPTION));
    }

    #[test]
    fn the_spacing_is_the_distance_to_the_nearest_neighbour() {
        let lattice: Vec<Vec3> = (0..400)
            .map(|i| Vec3::new((i % 20) as f32 * 0.01, (i / 20) as f32 * 0.01, 0.5))
            .collect();
        assert!((spacing(&lattice) - 0.01).abs() < 1e-5);
        assert_eq!(spacing(&lattice[..1]), 0.0);
    }
}
