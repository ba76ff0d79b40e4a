//! Object selection in clutter, measured two ways:
//! 1. on the synthetic clutter cases of the test kit (`sfs_testkit::clutter`, true masks): the
//!    share of objects a target pixel on them, or their box as a region, selects (IoU >= 0.8),
//!    printed as a Markdown section (`ci/figures.sh` puts it into `docs/figures.md`);
//! 2. on real cluttered frames (no ground truth): each object of each frame named by a pixel on
//!    it (`Scene::target`), and the frame once without a target; the chosen regions drawn over
//!    the colour image, and the symmetry found for each written as a table.
//!
//! ```text
//! cargo run --release --example targets -- SCENE_DIR OUT_DIR
//! ```
//! `SCENE_DIR`: the real frames `real_posecnn_demo_1..5` (not in the repository; in this
//! project's shared data, `../shared/scenes/real`), each with its colour image `NAME.color.png`
//! on the depth image's pixel grid; when it is absent only the synthetic figures are printed. Writes `OUT_DIR/NAME.png` per frame
//! and `OUT_DIR/targets.md`. The target pixels below were read off the colour images by eye,
//! one inside each visible object (thin flat cards are left out); they are inputs, not results.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use sfs_testkit::clutter;
use sfs_testkit::colour::{self, Rgb};
use sfs_testkit::overlay::Overlay;
use sfs_testkit::scene::LoadedScene;
use sfs_testkit::search::{DEFAULT_BUDGET, HostEngine, OUTPUT_POINTS};
use shape_from_symmetry::{
    CompletedPoint, Config, Error, Provenance, Rect, Report, Scene, Status, Target,
};

/// An object's name and a pixel `(u, v)` on it.
type Named = (&'static str, u16, u16);

/// Each frame and its objects.
const FRAMES: [(&str, &[Named]); 5] = [
    (
        "real_posecnn_demo_1",
        &[
            ("power drill", 150, 300),
            ("banana", 190, 410),
            ("mustard bottle", 360, 350),
            ("cracker box", 440, 190),
            ("soup can", 430, 310),
        ],
    ),
    (
        "real_posecnn_demo_2",
        &[
            ("cleanser", 260, 200),
            ("coffee can", 355, 240),
            ("sugar box", 265, 380),
            ("soup can", 435, 305),
            ("scissors", 120, 360),
        ],
    ),
    (
        "real_posecnn_demo_3",
        &[
            ("meat can", 215, 260),
            ("soup can", 225, 400),
            ("bowl", 470, 290),
        ],
    ),
    (
        "real_posecnn_demo_4",
        &[
            ("pitcher", 320, 220),
            ("tuna can", 270, 400),
            ("mustard bottle", 390, 350),
        ],
    ),
    (
        "real_posecnn_demo_5",
        &[
            ("cracker box", 245, 180),
            ("cleanser", 180, 230),
            ("power drill", 340, 190),
            ("sugar box", 270, 370),
            ("clamp", 420, 330),
        ],
    ),
];

/// The mark of the frame's own choice (no target).
const UNTARGETED: Rgb = [255, 255, 255];

/// The engine's report and completed points for `scene`, or its error.
fn search(scene: Scene<'_>) -> Result<(Report, Vec<CompletedPoint>), Error> {
    let mut output = vec![CompletedPoint::ZERO; OUTPUT_POINTS];
    let mut engine = Box::new(HostEngine::new(Config::DEFAULT));
    engine.start(scene, &mut output)?;
    while engine.poll(DEFAULT_BUDGET)? == Status::Working {}
    Ok((engine.report().clone(), engine.points().to_vec()))
}

/// One line of the table: what the search chose and found.
fn row(
    frame: &str,
    object: &str,
    hint: &str,
    result: &Result<(Report, Vec<CompletedPoint>), Error>,
) -> String {
    match result {
        Err(e) => format!("| {frame} | {object} | {hint} | | error: {e} | | | | |\n"),
        Ok((report, _)) => {
            let (candidates, chosen, b) =
                report
                    .segmentation
                    .map_or((String::new(), String::new(), String::new()), |s| {
                        let b = s.object_box;
                        (
                            s.candidates.to_string(),
                            s.chosen.map_or("-".into(), |c| c.to_string()),
                            format!("{},{} {}x{}", b.u0, b.v0, b.width, b.height),
                        )
                    });
            let found = report.symmetries.first().map_or("none".into(), |f| {
                format!("{} ({:.2})", f.symmetry.kind().name(), f.confidence)
            });
            let support = report.support.map_or("-".into(), |p| {
                let n = p.normal;
                format!("{:+.2},{:+.2},{:+.2} {:.2} m", n[0], n[1], n[2], p.offset)
            });
            format!(
                "| {frame} | {object} | {hint} | {support} | {candidates} | {chosen} | {b} | {} | {found} |\n",
                report.object_pixels
            )
        }
    }
}

/// Draw the visible points of `points` (projected to their pixels) and the object box.
fn draw(
    overlay: &mut Overlay,
    scene: &Scene<'_>,
    report: &Report,
    points: &[CompletedPoint],
    rgb: Rgb,
    dashed: bool,
) {
    let k = &scene.intrinsics;
    for p in points
        .iter()
        .filter(|p| p.provenance == Provenance::Visible)
    {
        let [x, y, z] = p.position;
        let (u, v) = (k.fx * x / z + k.cx, k.fy * y / z + k.cy);
        overlay.dot(u.round() as i32, v.round() as i32, rgb);
    }
    if let Some(s) = report.segmentation {
        overlay.outline(s.object_box, rgb, dashed);
    }
}

fn run(dir: &Path, out: &Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut table = String::from(
        "# Object selection on the real frames\n\n\
         Written by `cargo run --release --example targets -- ../shared/scenes/real docs/real`. \
         Each object is named by a pixel on it (`Scene::target`); `(none)` is the frame without \
         a target (the plausible candidate at the optical axis, or else nearest it). In the pictures each \
         object's visible points (as the completion writes them) and box are drawn in its colour, its target pixel as a \
         cross; the choice without a target in white, its box dashed. Candidates: regions of \
         plausible size; chosen: its index among them; box: u0,v0 width x height (pixels); \
         strongest symmetry and its confidence; support: the plane n · X = d the engine fitted. No ground truth: see the pictures.\n\n\
         | frame | object | target | support n, d | candidates | chosen | box | object pixels | strongest |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (frame, objects) in FRAMES {
        let loaded = LoadedScene::load(&dir.join(format!("{frame}.json")))?;
        let mut overlay = Overlay::from_png(&dir.join(format!("{frame}.color.png")))?;
        let base = loaded.scene();
        let result = search(base);
        table += &row(frame, "(none)", "-", &result);
        if let Ok((report, points)) = &result {
            draw(&mut overlay, &base, report, points, UNTARGETED, true);
        }
        let mut labels = Vec::new();
        for (i, &(object, u, v)) in objects.iter().enumerate() {
            let scene = Scene {
                target: Some(Target::Pixel { u, v }),
                ..base
            };
            let rgb = colour::predicted(i);
            let result = search(scene);
            table += &row(frame, object, &format!("{u},{v}"), &result);
            let text = match &result {
                Ok((report, points)) => {
                    draw(&mut overlay, &scene, report, points, rgb, false);
                    let found = report.symmetries.first();
                    format!(
                        "{object}: {}",
                        found.map_or("none", |f| f.symmetry.kind().name())
                    )
                }
                Err(_) => format!("{object}: error"),
            };
            labels.push((u, v, rgb, text));
        }
        for (u, v, rgb, text) in labels {
            overlay.cross(u as i32, v as i32, rgb);
            overlay.label(u as i32 + 8, v as i32 - 12, &text, rgb);
        }
        overlay.write_png(&out.join(format!("{frame}.png")))?;
    }
    let path = out.join("targets.md");
    let mut text = table;
    let _ = writeln!(text);
    for (frame, _) in FRAMES {
        let _ = writeln!(text, "![{frame}]({frame}.png)\n");
    }
    std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// How much a loose box, as an object detector gives, adds to the object's on each side, in per
/// cent of its width and height.
const LOOSE_PERCENT: u16 = 10;

/// `b` grown by [`LOOSE_PERCENT`] of its width and height on each side, clipped at the image's
/// top left (a box past its bottom right is an error, counted as a miss).
fn loosened(b: Rect) -> Rect {
    let grow = |n: u16| (u32::from(n) * u32::from(LOOSE_PERCENT)).div_ceil(100) as u16;
    let (du, dv) = (grow(b.width), grow(b.height));
    let (u0, v0) = (b.u0.saturating_sub(du), b.v0.saturating_sub(dv));
    Rect {
        u0,
        v0,
        width: b.width + (b.u0 - u0) + du,
        height: b.height + (b.v0 - v0) + dv,
    }
}

/// The share of synthetic objects each kind of target selects, as a Markdown section.
fn synthetic() -> Result<String, String> {
    let share = |results: &[clutter::Hinted]| {
        let matched = results.iter().filter(|h| h.iou >= 0.8).count();
        format!(
            "{matched} of {} ({:.1} %)",
            results.len(),
            100.0 * matched as f32 / results.len() as f32
        )
    };
    let pixel = clutter::hinted(|o| o.hint.map(|[u, v]| Target::Pixel { u, v }))
        .map_err(|e| e.to_string())?;
    let region = clutter::hinted(|o| (o.pixels > 0).then_some(Target::Region(o.pixel_box)))
        .map_err(|e| e.to_string())?;
    let loose =
        clutter::hinted(|o| (o.pixels > 0).then_some(Target::Region(loosened(o.pixel_box))))
            .map_err(|e| e.to_string())?;
    let mut text = format!(
        "| target | objects selected (IoU >= 0.8 with the true mask) |\n|---|---|\n\
         | a pixel on the object | {} |\n| the object's box as a region | {} |\n\
         | the box {LOOSE_PERCENT} % wider and taller on each side (a detector's loose box) | {} |\n",
        share(&pixel),
        share(&region),
        share(&loose)
    );
    // The objects either kind of target misses, with both IoUs (an error reads as 0).
    let iou = |results: &[clutter::Hinted], h: &clutter::Hinted| {
        results
            .iter()
            .find(|r| (r.scene, r.object) == (h.scene, h.object))
            .map_or("-".to_string(), |r| format!("{:.3}", r.iou))
    };
    let mut missed: Vec<&clutter::Hinted> = pixel
        .iter()
        .chain(&region)
        .filter(|h| h.iou < 0.8)
        .collect();
    missed.sort_by_key(|h| (h.scene, h.object));
    missed.dedup_by_key(|h| (h.scene, h.object));
    let _ = writeln!(
        text,
        "\nMissed by either ({}): the case, the object (its index and kind), the IoU with a pixel target and with the box.\n\n\
         | case | object | pixel | box |\n|---|---|---|---|",
        missed.len()
    );
    for h in missed {
        let (p, b) = (iou(&pixel, h), iou(&region, h));
        let name = clutter::clutter_cases()
            .find(|c| c.scene.name == h.scene)
            .and_then(|c| c.scene.objects.get(h.object))
            .map_or("?", |o| o.object.name);
        let _ = writeln!(text, "| {} | {} {name} | {p} | {b} |", h.scene, h.object);
    }
    Ok(text)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, out] = args.as_slice() else {
        eprintln!("usage: targets SCENE_DIR OUT_DIR");
        return ExitCode::from(2);
    };
    let dir = PathBuf::from(dir);
    match synthetic().and_then(|table| {
        print!("{table}");
        if dir.is_dir() {
            run(&dir, &PathBuf::from(out))
        } else {
            eprintln!("targets: {} absent: no real frames drawn", dir.display());
            Ok(())
        }
    }) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("targets: {e}");
            ExitCode::FAILURE
        }
    }
}
