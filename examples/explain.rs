//! Why a scene's symmetries score what they score: searches the scene, then explains
//! (`Engine::explain`) the strongest symmetry found, the runner-up and, when the scene has
//! ground truth, the true symmetry, element by element: the mean cost the acceptance test
//! reads and where the images went (confirmed by a seen point, unseen, a little into free
//! space, stray; of the strays, those beyond the observed crop, taken for seen free space
//! whatever the camera read there), and whether the element's strays fail it.
//!
//! ```text
//! cargo run --release --example explain -- SCENE.json [--shift ELEMENT] [--images OUT.csv]
//!     [--target U,V] [--symmetry FILE.json]
//! ```
//! `--shift K` moves the true symmetry's element `K`, -8 mm to +8 mm in 1 mm steps: a plane
//! along its normal, an axis (element 0 of an axial or axial + plane symmetry) or a centre
//! (a spherical one's) toward the camera, square to the axis (positive: nearer the camera);
//! and prints the element's evidence at each offset: the model's cost landscape about the
//! truth, where a found element off the true one shows which images pull it there.
//! `--images OUT.csv` writes every transformed point of the explained symmetries (which, its
//! element, cause, cost, seen point, image, and the depth it was judged against,
//! `ImageCost::reading`: empty where the camera saw nothing, `inf` beyond the crop; camera
//! frame, metres). `--target U,V` names the object by a pixel on it, as `complete`'s does (a
//! scene without a mask: a real frame).
//! `--symmetry FILE.json` explains a hand-made hypothesis too (`given`), its elements written
//! as a scene's `ground_truth` block writes them, without the surface (`sfs_testkit::truth::
//! Elements::from_json`): an axis fitted by hand on a real frame, which has no ground truth.

use std::io::Write;
use std::path::Path;

use sfs_testkit::raw;
use sfs_testkit::scene::LoadedScene;
use sfs_testkit::search::HostEngine;
use sfs_testkit::truth::{Elements, GroundTruth};
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{
    Axis, Cause, CompletedPoint, Config, Explanation, ImageCost, Scene, Status, Symmetry,
};

/// The causes in table order, with their column names.
const CAUSES: [(Cause, &str); 4] = [
    (Cause::Confirmed, "confirmed"),
    (Cause::Unseen, "unseen"),
    (Cause::FreeSpace, "free space"),
    (Cause::Stray, "stray"),
];

/// Offsets of `--shift`, millimetres: a few match σ either side of the truth.
const SHIFTS_MM: std::ops::RangeInclusive<i32> = -8..=8;

fn main() {
    if let Err(message) = run() {
        eprintln!("explain: {message}");
        eprintln!(
            "usage: explain SCENE.json [--shift ELEMENT] [--images OUT.csv] [--target U,V] \
             [--symmetry FILE.json]"
        );
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().ok_or("no scene given")?;
    let value = |flag: &str| {
        let at = args.iter().position(|a| a == flag)?;
        Some(
            args.get(at + 1)
                .cloned()
                .ok_or(format!("{flag} takes a value")),
        )
    };
    let shift: Option<usize> = match value("--shift").transpose()? {
        Some(k) => Some(
            k.parse()
                .map_err(|_| format!("--shift takes an element, not {k}"))?,
        ),
        None => None,
    };
    let mut images = match value("--images").transpose()? {
        Some(file) => {
            let file = std::fs::File::create(&file).map_err(|e| format!("{file}: {e}"))?;
            let mut out = std::io::BufWriter::new(file);
            writeln!(out, "symmetry,element,cause,cost,sx,sy,sz,ix,iy,iz,reading")
                .map_err(|e| e.to_string())?;
            Some(out)
        }
        None => None,
    };
    let target = match value("--target").transpose()? {
        Some(t) => Some(raw::parse_target(&t).map_err(|e| e.to_string())?),
        None => None,
    };
    let given = match value("--symmetry").transpose()? {
        Some(file) => {
            let text = std::fs::read_to_string(&file).map_err(|e| format!("{file}: {e}"))?;
            let elements = Elements::from_json(&text).map_err(|e| format!("{file}: {e}"))?;
            Some(elements.symmetry().ok_or(format!(
                "{file}: the elements do not make a symmetry of their class"
            ))?)
        }
        None => None,
    };
    let path = Path::new(path);
    let scene = LoadedScene::load(path).map_err(|e| e.to_string())?;
    let truth = GroundTruth::load(path).map_err(|e| e.to_string())?;
    let truth = truth.and_then(|t| t.whole.symmetry());

    let mut out = vec![CompletedPoint::ZERO; 1];
    let mut engine = Box::new(HostEngine::new(Config::DEFAULT));
    let input = Scene {
        target,
        ..scene.scene()
    };
    engine.start(input, &mut out).map_err(|e| e.to_string())?;
    while engine.poll(u32::MAX).map_err(|e| e.to_string())? == Status::Working {}
    let report = engine.report().clone();
    let accept = Config::DEFAULT.model.accept;
    println!("{}: accepted below {accept}\n", scene.name);

    let candidates = [
        ("found", report.symmetries.first().map(|f| f.symmetry)),
        ("runner-up", report.runner_up.map(|f| f.symmetry)),
        ("truth", truth),
    ];
    let candidates = candidates
        .into_iter()
        .chain(given.map(|g| ("given", Some(g))));
    for (label, symmetry) in candidates {
        let Some(symmetry) = symmetry else {
            println!("{label}: none\n");
            continue;
        };
        let mut tally = Tally::default();
        let explained = engine.explain(&symmetry, |image| {
            tally.add(image);
            if let Some(out) = images.as_mut() {
                let _ = write_image(out, label, image);
            }
        });
        let explained = explained.ok_or("the engine was not prepared")?;
        println!("{label}: {} {symmetry:?}", symmetry.kind().name());
        print_table(&explained, &tally, accept);
    }

    if let Some(k) = shift {
        let truth = truth.ok_or("--shift needs a scene with a true symmetry")?;
        let missing = || format!("the true symmetry has no element {k} to move");
        let (_, how) = shifted_element(&truth, k, 0.0).ok_or_else(missing)?;
        println!("true element {k} moved {how} (element {k}'s evidence):\n");
        println!("| shift mm | score | mean | images | confirmed | unseen | free space | stray |");
        println!("|---|---|---|---|---|---|---|---|");
        for mm in SHIFTS_MM {
            let (shifted, _) = shifted_element(&truth, k, mm as f32 * 1e-3).ok_or_else(missing)?;
            let mut tally = Tally::default();
            let explained = engine
                .explain(&shifted, |image| tally.add(image))
                .ok_or("the engine was not prepared")?;
            let mean = explained.elements.get(k).map_or(f32::INFINITY, |e| e.mean);
            let counts = tally.counts(k);
            println!(
                "| {mm:+} | {:.3} | {mean:.3} | {} | {} | {} | {} | {} |",
                explained.score,
                counts.iter().sum::<u32>(),
                counts[0],
                counts[1],
                counts[2],
                counts[3]
            );
        }
    }
    if let Some(mut out) = images {
        out.flush().map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Images per element and cause, and the strays beyond the observed crop.
#[derive(Default)]
struct Tally {
    counts: [[u32; CAUSES.len()]; 3],
    beyond: [u32; 3],
}

impl Tally {
    fn add(&mut self, image: &ImageCost) {
        let cause = CAUSES.iter().position(|(c, _)| *c == image.cause);
        let k = image.element as usize;
        if let (Some(row), Some(cause)) = (self.counts.get_mut(k), cause) {
            row[cause] += 1;
        }
        if let Some(n) = (self.beyond.get_mut(k)).filter(|_| image.stray_beyond_crop()) {
            *n += 1;
        }
    }

    fn counts(&self, element: usize) -> [u32; CAUSES.len()] {
        self.counts.get(element).copied().unwrap_or_default()
    }

    fn beyond(&self, element: usize) -> u32 {
        self.beyond.get(element).copied().unwrap_or_default()
    }
}

fn print_table(explained: &Explanation, tally: &Tally, accept: f32) {
    let verdict = if explained.score < accept {
        "accepted"
    } else {
        "rejected"
    };
    println!(
        "score {:.3} ({verdict}), {} images left out (self-maps, or hidden by another object)\n",
        explained.score, explained.uninformative
    );
    let names: Vec<&str> = CAUSES.iter().map(|(_, name)| *name).collect();
    println!(
        "| element | images | mean | {} | of which beyond the crop | strays fail it |",
        names.join(" | ")
    );
    println!("|---|---|---|{}---|---|", "---|".repeat(CAUSES.len()));
    for (k, element) in explained.elements.iter().enumerate() {
        let counts = tally.counts(k).map(|n| n.to_string());
        println!(
            "| {k} | {} | {:.3} | {} | {} | {} |",
            element.images,
            element.mean,
            counts.join(" | "),
            tally.beyond(k),
            if element.contradicted { "yes" } else { "no" }
        );
    }
    println!();
}

/// `symmetry` with its element `k` moved `by` metres, and which way it moves: a plane along its
/// normal, an axis or a centre toward the camera (square to the axis); `None` when it has no
/// such element.
fn shifted_element(symmetry: &Symmetry, k: usize, by: f32) -> Option<(Symmetry, &'static str)> {
    const TOWARD: &str = "toward the camera";
    // The unit vector from `p` toward the camera centre, square to `along` (if given).
    let toward = |p: Vec3, along: Option<Vec3>| {
        let to_camera = -p;
        let square = along.map_or(to_camera, |d| to_camera - d * d.dot(to_camera));
        square.try_normalize()
    };
    let moved = |a: &Axis| {
        let step = toward(a.p(), Some(a.d()))? * by;
        Some(Axis::new(a.d(), a.p() + step, a.p()))
    };
    let mut shifted = *symmetry;
    let plane = match &mut shifted {
        Symmetry::Axial(a) if k == 0 => return Some((Symmetry::Axial(moved(a)?), TOWARD)),
        Symmetry::AxialPlane(a, p) if k == 0 => {
            return Some((Symmetry::AxialPlane(moved(a)?, *p), TOWARD));
        }
        Symmetry::Spherical(c) if k == 0 => {
            let c = Vec3::from(*c);
            let centre = (c + toward(c, None)? * by).to_array();
            return Some((Symmetry::Spherical(centre), TOWARD));
        }
        Symmetry::PlaneReflection(p) if k == 0 => p,
        Symmetry::AxialPlane(_, p) if k == 1 => p,
        Symmetry::DualPlane(planes) => planes.get_mut(k)?,
        Symmetry::TriplePlane(planes) => planes.get_mut(k)?,
        _ => return None,
    };
    plane.offset += by;
    Some((shifted, "along its normal"))
}

fn write_image(out: &mut impl Write, label: &str, image: &ImageCost) -> std::io::Result<()> {
    let [sx, sy, sz] = image.source;
    let [ix, iy, iz] = image.image;
    let cause = CAUSES
        .iter()
        .find(|(c, _)| *c == image.cause)
        .map_or("self-map", |(_, name)| name);
    // Empty where the camera saw nothing; `inf` beyond the observed crop.
    let reading = image.reading.map_or(String::new(), |r| r.to_string());
    writeln!(
        out,
        "{label},{},{cause},{},{sx},{sy},{sz},{ix},{iy},{iz},{reading}",
        image.element, image.cost
    )
}
