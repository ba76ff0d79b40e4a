//! Accuracy of the search on scenes with ground truth.
//!
//! ```text
//! cargo run --release --example evaluate -- SCENE_DIR [--out-json F] [--out-md F] [--budget N]
//!     [--only SUBSTRING] [--sweep noise,distance,no-table,no-mask,no-input | all] [--parts]
//!     [--one-object] [--tilted-contact]
//! ```
//! For every scene of `SCENE_DIR` that has ground truth it runs the search (which never sees the
//! ground truth) and measures what `sfs_testkit::metrics` describes: the type found against the true
//! class, whether each found symmetry is a true one, angular and offset errors of its planes and
//! axes, how well the completion covers the whole surface (with two references: the visible
//! object pixels alone, and those pixels reflected through the TRUE symmetry), how much of the
//! completion lies in free space, and time and work. Writes JSON and Markdown and prints the
//! Markdown. Two scenes run at a time.
//!
//! `--sweep` runs every scene again under degraded input ([`sfs_testkit::degrade`]) and reports the
//! totals per setting, one table row each: `noise` adds zero-mean Gaussian depth noise (σ = 1,
//! 2, 4 mm) and 2 % extra dropouts; `distance` keeps every 2nd or 3rd pixel (the object seen
//! from 2 or 3 times farther); `no-table`, `no-mask` and `no-input` withhold the table plane, the
//! mask or both, so that the engine fits the plane (RANSAC) and segments the object itself.
//! Completion and the references are measured with the degraded pixels (and the recorded mask);
//! free space is judged against the recorded depth image. `--one-object` tells the engine that
//! nothing touches the object (`PrepareConfig::with_one_object`): without a mask, it does
//! not part regions at concave creases nor split them at necks. `--tilted-contact` credits
//! contact with the support to mirrors a few degrees off level too
//! (`ModelConfig::tilted_contact`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use serde::Serialize;
use sfs_testkit::baseline;
use sfs_testkit::degrade::Degradation;
use sfs_testkit::metrics::{self, ElementErrors, Fit, Residual, Surface, Validity, Verdict};
use sfs_testkit::result::SymmetryJson;
use sfs_testkit::scene::{self, LoadedScene};
use sfs_testkit::search::{self, Outcome};
use sfs_testkit::truth::GroundTruth;
use sfs_testkit::{Context, Result};
use shape_from_symmetry::{Config, Found, Plane, Provenance, Symmetry};

const USAGE: &str =
    "usage: evaluate SCENE_DIR [--out-json F] [--out-md F] [--budget N] [--only SUBSTRING]
                [--sweep noise,distance,no-table,no-mask,no-input | all] [--parts]
                [--one-object] [--tilted-contact]
  --parts       also search part symmetries (DomainConfig::parts)
  --one-object  nothing touches the object: without a mask, no parting at concave creases
                nor splitting at necks (PrepareConfig::with_one_object)
  --tilted-contact  the contact term also for a mirror a few degrees off level
                (ModelConfig::tilted_contact)";
const THREADS: usize = 2;

/// The noise sweep: σ of the added depth noise (mm), each with [`NOISE_DROPOUT`].
const NOISE_SIGMAS_MM: [f32; 3] = [1.0, 2.0, 4.0];
/// Extra dropouts (share of the valid readings) of every noise setting.
const NOISE_DROPOUT: f32 = 0.02;
/// The distance sweep: keep every k-th pixel.
const DOWNSAMPLES: [u16; 2] = [2, 3];
/// Seed of the added noise (each scene mixes in its name).
const NOISE_SEED: u64 = 2005;

/// A robustness sweep (`--sweep`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Sweep {
    Noise,
    Distance,
    NoTable,
    NoMask,
    NoInput,
}

impl Sweep {
    const ALL: [Sweep; 5] = [
        Sweep::Noise,
        Sweep::Distance,
        Sweep::NoTable,
        Sweep::NoMask,
        Sweep::NoInput,
    ];

    fn name(self) -> &'static str {
        match self {
            Sweep::Noise => "noise",
            Sweep::Distance => "distance",
            Sweep::NoTable => "no-table",
            Sweep::NoMask => "no-mask",
            Sweep::NoInput => "no-input",
        }
    }

    /// The table the sweep's rows go to.
    fn group(self) -> &'static str {
        match self {
            Sweep::Noise => "noise",
            Sweep::Distance => "distance",
            _ => "inputs",
        }
    }

    /// Its settings: a label and the degradation.
    fn settings(self) -> Vec<(String, Degradation)> {
        let none = Degradation::NONE;
        match self {
            Sweep::Noise => NOISE_SIGMAS_MM
                .iter()
                .map(|&sigma_mm| {
                    let label = format!(
                        "noise σ {sigma_mm} mm + {:.0} % dropouts",
                        NOISE_DROPOUT * 100.0
                    );
                    let d = Degradation {
                        sigma_mm,
                        extra_dropout: NOISE_DROPOUT,
                        ..none
                    };
                    (label, d)
                })
                .collect(),
            Sweep::Distance => DOWNSAMPLES
                .iter()
                .map(|&k| {
                    let label = format!("every {} pixel ({k}x farther)", ordinal(k));
                    let d = Degradation {
                        downsample: k,
                        ..none
                    };
                    (label, d)
                })
                .collect(),
            Sweep::NoTable => vec![(
                "no table plane".into(),
                Degradation {
                    table: false,
                    ..none
                },
            )],
            Sweep::NoMask => vec![(
                "no mask".into(),
                Degradation {
                    mask: false,
                    ..none
                },
            )],
            Sweep::NoInput => vec![(
                "no table plane, no mask".into(),
                Degradation {
                    table: false,
                    mask: false,
                    ..none
                },
            )],
        }
    }
}

/// `2nd`, `3rd`, `4th`, ...
fn ordinal(k: u16) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{k}{suffix}")
}

/// `noise,distance` (or `all`) as a sorted list of sweeps.
fn parse_sweeps(text: &str) -> Result<Vec<Sweep>> {
    let mut sweeps = Vec::new();
    for name in text.split(',').map(str::trim) {
        match name {
            "all" => sweeps.extend(Sweep::ALL),
            _ => sweeps.push(
                Sweep::ALL
                    .into_iter()
                    .find(|s| s.name() == name)
                    .ok_or_else(|| format!("--sweep: unknown sweep {name:?}\n{USAGE}"))?,
            ),
        }
    }
    sweeps.sort();
    sweeps.dedup();
    Ok(sweeps)
}

struct Args {
    dir: PathBuf,
    out_json: Option<PathBuf>,
    out_md: Option<PathBuf>,
    budget: u32,
    only: Option<String>,
    sweeps: Vec<Sweep>,
    parts: bool,
    one_object: bool,
    tilted_contact: bool,
}

/// Everything measured on one scene.
#[derive(Serialize)]
struct SceneEval {
    scene: String,
    object: String,
    truth: &'static str,
    found: &'static str,
    verdict: &'static str,
    /// Every symmetry found, strongest first, with its checks.
    symmetries: Vec<FoundEval>,
    /// The runner-up (`Report::runner_up`), with its checks.
    runner_up: Option<FoundEval>,
    /// The measurement model's score of the true symmetry of the whole object (`Engine::score`,
    /// lower is better, accepted below `model.accept`); `null` for an asymmetric object, or one
    /// with too few informative points.
    truth_score: Option<f32>,
    /// The model's score of the strongest symmetry found over every point (the search's
    /// acceptance took it on a subset of the points); `null` when none was found.
    strongest_score_all_points: Option<f32>,
    /// The surface sample's distance to itself: the floor under every validity residual.
    floor: Residual,
    /// The one-plane baseline ([`sfs_testkit::baseline`]) on the engine's input; `null` unless
    /// the engine was given both the mask and the table.
    baseline: Option<BaselineEval>,
    completed: Fit,
    visible: Fit,
    /// Reference 1: every object pixel (mask and a depth reading), nothing completed.
    reference_pixels: Fit,
    /// Reference 2: those pixels and their images under the true symmetry, less free space.
    reference_truth: Fit,
    generated_in_free_space: Option<f32>,
    /// Object pixels with a reading that the engine segmented, and the points it sampled.
    object_pixels: u32,
    sampled_points: u32,
    wall_ms: f64,
    work_units: u64,
    polls: u32,
}

#[derive(Serialize)]
struct FoundEval {
    #[serde(flatten)]
    found: SymmetryJson,
    validity: Validity,
    /// Valid on the seen part of the surface (`metrics::valid_on`): nothing the camera saw
    /// refutes it.
    valid_on_seen: bool,
    /// True by the accuracy issue's lenient test (`metrics::lenient`).
    lenient: bool,
    errors: ElementErrors,
}

/// The one-plane baseline's plane on a scene, judged as a found symmetry is.
#[derive(Serialize)]
struct BaselineEval {
    normal: [f32; 3],
    offset: f32,
    validity: Validity,
    lenient: bool,
    /// The object pixels and their images through the plane, less free space.
    completed: Fit,
}

#[derive(Clone, Serialize)]
struct Totals {
    scenes: usize,
    verdicts: BTreeMap<&'static str, usize>,
    /// Of the scenes with a symmetry found: those whose strongest is a true symmetry of the
    /// whole object, and those whose strongest is one of a part only.
    strongest_found: usize,
    strongest_valid_object: usize,
    strongest_valid_part: usize,
    /// Strongest symmetries true by the accuracy issue's lenient test (`metrics::lenient`).
    strongest_lenient: usize,
    /// The one-plane baseline over the scenes it ran on.
    baseline: BaselineTotals,
    /// Per confidence threshold c: the strongest symmetries reported with confidence >= c, and
    /// how many of them are valid for the whole object.
    calibration: Vec<Calibration>,
    /// Runner-ups reported, and how many are valid for the whole object.
    runner_ups: usize,
    runner_ups_valid: usize,
    /// The scenes of a symmetric object whose strongest symmetry is not a true one of the whole
    /// object, by cause.
    misses: Misses,
    /// Strongest symmetries found whose score over every point is not below the acceptance
    /// threshold, and how many of those are valid for the whole object.
    strongest_over_threshold: usize,
    strongest_over_threshold_valid: usize,
    median_plane_deg: Option<f32>,
    median_plane_offset_mm: Option<f32>,
    /// The offsets toward the camera of the planes facing it most
    /// (`ElementErrors::plane_toward_camera_mm`).
    plane_toward_camera: Toward,
    median_axis_deg: Option<f32>,
    median_axis_offset_mm: Option<f32>,
    /// The axes' offsets toward the camera (`ElementErrors::axis_toward_camera_mm`).
    axis_toward_camera: Toward,
    median_center_mm: Option<f32>,
    /// The centres' offsets toward the camera.
    center_toward_camera: Toward,
    /// Means over the scenes.
    completed: Fit,
    visible: Fit,
    reference_pixels: Fit,
    reference_truth: Fit,
    generated_in_free_space: Option<f32>,
    object_pixels_median: u32,
    sampled_points_median: u32,
    wall_ms_total: f64,
    wall_ms_median: f64,
    work_units_total: u64,
    work_units_median: u64,
}

/// Why the strongest symmetry of a symmetric object was not a true symmetry of the whole
/// object (or none was found): the measurement model accepts the true symmetry (`truth_score`
/// below `model.accept`), so the search did not reach it or the walk reported another one; or it
/// rejects it, and no search could have reported it.
#[derive(Clone, Copy, Default, Serialize)]
struct Misses {
    scenes: usize,
    truth_accepted: usize,
    truth_rejected: usize,
    /// Misses whose strongest symmetry is valid on the seen part of the surface: wrong only
    /// where the camera did not look.
    valid_on_seen: usize,
}

impl Misses {
    fn of(scenes: &[SceneEval]) -> Self {
        let cases = scenes.iter().map(|s| Case {
            symmetric: s.truth != "none",
            valid: s.symmetries.first().is_some_and(|f| f.validity.of_object()),
            valid_on_seen: s.symmetries.first().is_some_and(|f| f.valid_on_seen),
            truth_score: s.truth_score,
        });
        Self::count(cases, Config::DEFAULT.model.accept)
    }

    /// The misses among `cases`, the true symmetry accepted below `accept`.
    fn count(cases: impl Iterator<Item = Case>, accept: f32) -> Self {
        let missed = cases.filter(|o| o.symmetric && !o.valid);
        missed.fold(Self::default(), |m, o| {
            let accepted = o.truth_score.is_some_and(|t| t < accept);
            Self {
                scenes: m.scenes + 1,
                truth_accepted: m.truth_accepted + accepted as usize,
                truth_rejected: m.truth_rejected + !accepted as usize,
                valid_on_seen: m.valid_on_seen + o.valid_on_seen as usize,
            }
        })
    }
}

/// What [`Misses`] reads of a scene.
struct Case {
    /// The object has a symmetry.
    symmetric: bool,
    /// The strongest symmetry found is a true symmetry of the whole object.
    valid: bool,
    /// ... of the seen part of its surface.
    valid_on_seen: bool,
    truth_score: Option<f32>,
}

/// The one-plane baseline's totals: the scenes it ran on, how many of its planes are valid for
/// the whole object, how many pass the lenient test, and its mean completion.
#[derive(Clone, Copy, Default, Serialize)]
struct BaselineTotals {
    scenes: usize,
    valid_object: usize,
    lenient: usize,
    completed: Fit,
}

impl BaselineTotals {
    fn of(scenes: &[SceneEval]) -> Self {
        let ran: Vec<&BaselineEval> = scenes.iter().filter_map(|s| s.baseline.as_ref()).collect();
        Self {
            scenes: ran.len(),
            valid_object: ran.iter().filter(|b| b.validity.of_object()).count(),
            lenient: ran.iter().filter(|b| b.lenient).count(),
            completed: mean_fit(ran.iter().map(|b| b.completed).collect()),
        }
    }
}

#[derive(Clone, Copy, Serialize)]
struct Calibration {
    confidence_at_least: f32,
    reported: usize,
    valid: usize,
}

/// The confidence thresholds of the calibration table.
const CONFIDENCE_STEPS: [f32; 6] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];

#[derive(Serialize)]
struct Evaluation {
    format: &'static str,
    scene_dir: String,
    budget: u32,
    /// Part symmetries searched (`--parts`).
    parts: bool,
    /// The contact term for mirrors off level too (`--tilted-contact`).
    tilted_contact: bool,
    settings: Settings,
    scenes: Vec<SceneEval>,
    totals: Totals,
    /// Scenes without ground truth (not evaluated).
    skipped: Vec<String>,
    /// Scenes that could not be loaded or searched, with the reason.
    failed: Vec<Failure>,
    /// With `--sweep`: the totals under each degradation, the recorded scenes first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    sweeps: Vec<SweepRow>,
}

/// The outcome of every scene under one degradation.
#[derive(Serialize)]
struct SweepRow {
    /// `baseline`, `noise`, `distance`, `no-table`, `no-mask` or `no-input`.
    sweep: &'static str,
    setting: String,
    degradation: Degradation,
    totals: Totals,
    /// Scenes whose search failed under this degradation (an error of the engine, such as no
    /// object found); the totals are over the others.
    failed: Vec<Failure>,
    scenes: Vec<SweepScene>,
}

/// One scene of a sweep row, in brief.
#[derive(Serialize)]
struct SweepScene {
    scene: String,
    found: &'static str,
    verdict: &'static str,
    /// The strongest symmetry is a true one of the `"object"`, of a `"part"`, or `"no"`.
    valid: &'static str,
    completed: Fit,
    object_pixels: u32,
    sampled_points: u32,
    wall_ms: f64,
    work_units: u64,
}

impl SweepScene {
    fn new(s: &SceneEval) -> Self {
        let valid = s.symmetries.first().map_or("-", |f| {
            if f.validity.of_object() {
                "object"
            } else if f.validity.of_part() {
                "part"
            } else {
                "no"
            }
        });
        Self {
            scene: s.scene.clone(),
            found: s.found,
            verdict: s.verdict,
            valid,
            completed: s.completed,
            object_pixels: s.object_pixels,
            sampled_points: s.sampled_points,
            wall_ms: s.wall_ms,
            work_units: s.work_units,
        }
    }
}

#[derive(Clone, Serialize)]
struct Failure {
    scene: String,
    error: String,
}

#[derive(Serialize)]
struct Settings {
    near_mm: f32,
    free_margin_mm: f32,
    valid_mean_mm: f32,
    valid_p90_mm: f32,
    valid_p99_mm: f32,
    reach_mm: f32,
}

const SETTINGS: Settings = Settings {
    near_mm: metrics::NEAR * 1e3,
    free_margin_mm: metrics::FREE_MARGIN * 1e3,
    valid_mean_mm: metrics::VALID_MEAN * 1e3,
    valid_p90_mm: metrics::VALID_P90 * 1e3,
    valid_p99_mm: metrics::VALID_P99 * 1e3,
    reach_mm: metrics::REACH * 1e3,
};

fn main() -> ExitCode {
    sfs_testkit::run_cli(USAGE, parse_args, evaluate)
}

fn parse_args(args: Vec<String>) -> Result<Args> {
    let mut dir = None;
    let (mut out_json, mut out_md, mut only, mut budget) =
        (None, None, None, search::DEFAULT_BUDGET);
    let (mut sweeps, mut parts, mut one_object) = (Vec::new(), false, false);
    let mut tilted_contact = false;
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next()
                .ok_or_else(|| format!("{arg} needs a value\n{USAGE}"))
        };
        match arg.as_str() {
            "--out-json" => out_json = Some(value()?.into()),
            "--out-md" => out_md = Some(value()?.into()),
            "--only" => only = Some(value()?),
            "--budget" => budget = search::parse_budget(&value()?)?,
            "--sweep" => sweeps = parse_sweeps(&value()?)?,
            "--parts" => parts = true,
            "--one-object" => one_object = true,
            "--tilted-contact" => tilted_contact = true,
            flag if flag.starts_with('-') => return Err(format!("unknown option {flag}\n{USAGE}")),
            _ if dir.is_some() => return Err(format!("more than one SCENE_DIR: {arg}\n{USAGE}")),
            _ => dir = Some(PathBuf::from(arg)),
        }
    }
    let dir = dir.ok_or_else(|| format!("no SCENE_DIR given\n{USAGE}"))?;
    Ok(Args {
        dir,
        out_json,
        out_md,
        budget,
        only,
        sweeps,
        parts,
        one_object,
        tilted_contact,
    })
}

/// Evaluate every selected scene (and with `--sweep` every degraded copy of it), write and print
/// the report. `Ok(false)`: some scene as recorded failed (failures under degradation are results).
fn evaluate(args: &Args) -> Result<bool> {
    let files: Vec<PathBuf> = scene::scene_files(&args.dir)?
        .into_iter()
        .filter(|f| {
            args.only
                .as_ref()
                .is_none_or(|only| scene::scene_name(f).contains(only.as_str()))
        })
        .collect();
    if files.is_empty() {
        return Err(format!(
            "no scene (*.json) in {} matches",
            args.dir.display()
        ));
    }
    // The scenes as recorded first, then every sweep's settings.
    let mut settings = vec![("baseline", "as recorded".to_string(), Degradation::NONE)];
    for sweep in &args.sweeps {
        let name = sweep.name();
        settings.extend(sweep.settings().into_iter().map(|(l, d)| (name, l, d)));
    }
    let jobs = settings.len() * files.len();
    let done = AtomicUsize::new(0);
    let results = in_parallel(jobs, |job| {
        let ((_, label, degradation), file) =
            (&settings[job / files.len()], &files[job % files.len()]);
        let result = evaluate_scene(file, args, degradation);
        let setting = match degradation.is_none() {
            true => String::new(),
            false => format!("{label}: "),
        };
        eprintln!(
            "[{}/{jobs}] {setting}{}",
            done.fetch_add(1, Ordering::Relaxed) + 1,
            progress(file, &result)
        );
        result
    });
    let mut results = results.into_iter();
    let mut rows = Vec::new();
    let (mut baseline, mut skipped, mut failed) = (Vec::new(), Vec::new(), Vec::new());
    for (i, (sweep, setting, degradation)) in settings.into_iter().enumerate() {
        let (mut scenes, mut failures) = (Vec::new(), Vec::new());
        for (file, result) in files.iter().zip(results.by_ref()) {
            match result {
                Ok(Some(eval)) => scenes.push(eval),
                Ok(None) if i == 0 => skipped.push(scene::scene_name(file)),
                Ok(None) => {}
                Err(error) => failures.push(Failure {
                    scene: scene::scene_name(file),
                    error,
                }),
            }
        }
        if !args.sweeps.is_empty() {
            rows.push(SweepRow {
                sweep,
                setting,
                degradation,
                totals: totals(&scenes),
                scenes: scenes.iter().map(SweepScene::new).collect(),
                failed: failures.iter().map(Failure::clone).collect(),
            });
        }
        if i == 0 {
            (baseline, failed) = (scenes, failures);
        }
    }
    let all_ran = failed.is_empty();
    let evaluation = Evaluation {
        format: "shape-from-symmetry/evaluation-1",
        scene_dir: args.dir.display().to_string(),
        budget: args.budget,
        parts: args.parts,
        tilted_contact: args.tilted_contact,
        settings: SETTINGS,
        totals: totals(&baseline),
        scenes: baseline,
        skipped,
        failed,
        sweeps: rows,
    };
    let markdown = markdown(&evaluation);
    print!("{markdown}");
    if let Some(path) = &args.out_md {
        std::fs::write(path, &markdown).context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.out_json {
        sfs_testkit::write_json(path, &evaluation)?;
    }
    Ok(all_ran)
}

/// `job(0..count)` on [`THREADS`] threads, results in index order.
fn in_parallel<T: Send>(count: usize, job: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<T>>> = Mutex::new((0..count).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..THREADS.min(count) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count {
                        break;
                    }
                    let result = job(i);
                    results.lock().expect("a worker panicked")[i] = Some(result);
                }
            });
        }
    });
    results
        .into_inner()
        .expect("a worker panicked")
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

fn progress(file: &Path, result: &Result<Option<SceneEval>>) -> String {
    let name = scene::scene_name(file);
    match result {
        Ok(Some(e)) => format!(
            "{name}: found {} ({}), {:.0} ms",
            e.found, e.verdict, e.wall_ms
        ),
        Ok(None) => format!("{name}: no ground truth, skipped"),
        Err(message) => format!("{name}: FAILED: {message}"),
    }
}

/// Search one scene, degraded as asked, and measure the outcome; `Ok(None)` for a scene without
/// ground truth.
fn evaluate_scene(
    path: &Path,
    args: &Args,
    degradation: &Degradation,
) -> Result<Option<SceneEval>> {
    let Some(truth) = GroundTruth::load(path)? else {
        return Ok(None);
    };
    let recorded = LoadedScene::load(path)?;
    // What the degraded camera saw, with the recorded mask (the references need it) ...
    let seen = Degradation {
        table: true,
        mask: true,
        ..*degradation
    }
    .apply(&recorded, NOISE_SEED);
    // ... and what the engine gets.
    let mut searched = seen.clone();
    searched.table = searched.table.filter(|_| degradation.table);
    searched.mask = searched.mask.take().filter(|_| degradation.mask);
    let mut config = Config::DEFAULT;
    config.domains.parts = args.parts;
    config.model.tilted_contact = args.tilted_contact;
    config.prepare = config.prepare.with_one_object(args.one_object);
    let outcome = search::run(&searched, None, config, args.budget, truth.whole.symmetry())
        .map_err(|e| format!("search: {e}"))?;
    let baseline = searched.table.and_then(|_| baseline::one_plane(&searched));
    Ok(Some(measure(&seen, &recorded, &truth, &outcome, baseline)))
}

/// Measure a search of `seen` (the pixels the references are built from, with their mask), and
/// the `baseline`'s plane; free space is judged against the `recorded` depth image.
fn measure(
    seen: &LoadedScene,
    recorded: &LoadedScene,
    truth: &GroundTruth,
    outcome: &Outcome,
    baseline: Option<Plane>,
) -> SceneEval {
    let surface = Surface::new(truth);
    let report = &outcome.report;
    let completed = outcome.positions(None);
    let visible = outcome.positions(Some(Provenance::Visible));
    let generated = outcome.positions(Some(Provenance::Generated));
    let pixels = seen.object_points();
    let truth_completion = metrics::reflected(&pixels, truth.whole.symmetry().as_ref(), recorded);
    let found = report.symmetries.first().map(|f| f.symmetry.kind());
    let seen_part = metrics::seen_part(&surface, &pixels);
    let judged = |f: &Found| {
        let validity = metrics::validity(&f.symmetry, &surface);
        let errors = metrics::element_errors(&f.symmetry, &validity.elements(truth), truth);
        FoundEval {
            found: SymmetryJson::new(f),
            validity,
            valid_on_seen: metrics::valid_on(&f.symmetry, &seen_part, &surface),
            lenient: metrics::lenient(&f.symmetry, &surface),
            errors,
        }
    };
    let baseline = baseline.map(|plane| {
        let symmetry = Symmetry::PlaneReflection(plane);
        let completion = metrics::reflected(&pixels, Some(&symmetry), recorded);
        BaselineEval {
            normal: plane.normal,
            offset: plane.offset,
            validity: metrics::validity(&symmetry, &surface),
            lenient: metrics::lenient(&symmetry, &surface),
            completed: metrics::fit(&completion, &surface),
        }
    });
    let symmetries = report.symmetries.iter().map(judged).collect();
    let runner_up = report.runner_up.as_ref().map(judged);
    SceneEval {
        scene: seen.name.clone(),
        object: truth.object.clone(),
        truth: truth.whole.class.map_or("none", |c| c.name()),
        found: found.map_or("none", |t| t.name()),
        verdict: metrics::verdict(found, truth).name(),
        symmetries,
        runner_up,
        truth_score: outcome.scored.filter(|s| s.is_finite()),
        strongest_score_all_points: outcome.strongest_scored,
        floor: metrics::floor(&surface),
        baseline,
        completed: metrics::fit(&completed, &surface),
        visible: metrics::fit(&visible, &surface),
        reference_pixels: metrics::fit(&pixels, &surface),
        reference_truth: metrics::fit(&truth_completion, &surface),
        generated_in_free_space: metrics::free_space_share(&generated, recorded),
        object_pixels: report.object_pixels,
        sampled_points: report.sampled_points,
        wall_ms: outcome.wall_ms,
        work_units: report.work_units,
        polls: report.polls,
    }
}

/// The scenes whose strongest symmetry, accepted by the search, scores not below the
/// acceptance threshold over every point.
fn over_threshold(scenes: &[SceneEval]) -> impl Iterator<Item = &SceneEval> {
    let accept = Config::DEFAULT.model.accept;
    (scenes.iter()).filter(move |s| s.strongest_score_all_points.is_some_and(|a| a >= accept))
}

fn totals(scenes: &[SceneEval]) -> Totals {
    let strongest = || scenes.iter().filter_map(|s| s.symmetries.first());
    let picked = |pick: fn(&ElementErrors) -> Option<f32>| -> Vec<f32> {
        strongest().filter_map(|f| pick(&f.errors)).collect()
    };
    let errors = |pick| median(picked(pick));
    let toward = |pick| {
        let offsets = picked(pick);
        Toward {
            toward: offsets.iter().filter(|&&o| o > 0.0).count(),
            of: offsets.len(),
            median_mm: median(offsets),
        }
    };
    let fits = |pick: fn(&SceneEval) -> Fit| mean_fit(scenes.iter().map(pick).collect());
    let mut wall: Vec<f64> = scenes.iter().map(|s| s.wall_ms).collect();
    let mut work: Vec<u64> = scenes.iter().map(|s| s.work_units).collect();
    let mut pixels: Vec<u32> = scenes.iter().map(|s| s.object_pixels).collect();
    let mut sampled: Vec<u32> = scenes.iter().map(|s| s.sampled_points).collect();
    wall.sort_by(f64::total_cmp);
    work.sort_unstable();
    pixels.sort_unstable();
    sampled.sort_unstable();
    let free: Vec<f32> = scenes
        .iter()
        .filter_map(|s| s.generated_in_free_space)
        .collect();
    Totals {
        scenes: scenes.len(),
        verdicts: Verdict::ALL
            .iter()
            .map(|v| {
                (
                    v.name(),
                    scenes.iter().filter(|s| s.verdict == v.name()).count(),
                )
            })
            .collect(),
        strongest_found: strongest().count(),
        strongest_valid_object: strongest().filter(|f| f.validity.of_object()).count(),
        strongest_valid_part: strongest().filter(|f| f.validity.of_part()).count(),
        strongest_lenient: strongest().filter(|f| f.lenient).count(),
        baseline: BaselineTotals::of(scenes),
        calibration: CONFIDENCE_STEPS
            .iter()
            .map(|&c| {
                let reported = || strongest().filter(|f| f.found.confidence >= c);
                Calibration {
                    confidence_at_least: c,
                    reported: reported().count(),
                    valid: reported().filter(|f| f.validity.of_object()).count(),
                }
            })
            .collect(),
        runner_ups: scenes.iter().filter(|s| s.runner_up.is_some()).count(),
        runner_ups_valid: (scenes.iter())
            .filter(|s| s.runner_up.as_ref().is_some_and(|f| f.validity.of_object()))
            .count(),
        misses: Misses::of(scenes),
        strongest_over_threshold: over_threshold(scenes).count(),
        strongest_over_threshold_valid: over_threshold(scenes)
            .filter(|s| s.symmetries.first().is_some_and(|f| f.validity.of_object()))
            .count(),
        median_plane_deg: errors(|e| e.plane_deg),
        median_plane_offset_mm: errors(|e| e.plane_offset_mm),
        plane_toward_camera: toward(|e| e.plane_toward_camera_mm),
        median_axis_deg: errors(|e| e.axis_deg),
        median_axis_offset_mm: errors(|e| e.axis_offset_mm),
        axis_toward_camera: toward(|e| e.axis_toward_camera_mm),
        median_center_mm: errors(|e| e.center_mm),
        center_toward_camera: toward(|e| e.center_toward_camera_mm),
        completed: fits(|s| s.completed),
        visible: fits(|s| s.visible),
        reference_pixels: fits(|s| s.reference_pixels),
        reference_truth: fits(|s| s.reference_truth),
        generated_in_free_space: (!free.is_empty())
            .then(|| free.iter().sum::<f32>() / free.len() as f32),
        object_pixels_median: pixels.get(pixels.len() / 2).copied().unwrap_or_default(),
        sampled_points_median: sampled.get(sampled.len() / 2).copied().unwrap_or_default(),
        wall_ms_total: wall.iter().sum(),
        wall_ms_median: wall.get(wall.len() / 2).copied().unwrap_or_default(),
        work_units_total: work.iter().sum(),
        work_units_median: work.get(work.len() / 2).copied().unwrap_or_default(),
    }
}

/// Signed offsets of the strongest symmetries' elements toward the camera: a bias of the
/// parameters shows as a median away from 0 and most of them on one side.
#[derive(Clone, Copy, Debug, Default, Serialize)]
struct Toward {
    /// The median offset, mm (positive: toward the camera).
    median_mm: Option<f32>,
    /// How many lie toward the camera...
    toward: usize,
    /// ... of how many.
    of: usize,
}

impl Toward {
    /// `(+0.6 mm toward the camera, 24 of 24)`, or nothing without offsets.
    fn phrase(&self) -> String {
        self.median_mm.map_or(String::new(), |m| {
            format!(
                " (median {m:+.1} mm toward the camera, {} of {} toward)",
                self.toward, self.of
            )
        })
    }
}

fn median(mut values: Vec<f32>) -> Option<f32> {
    values.sort_by(f32::total_cmp);
    values.get(values.len() / 2).copied()
}

/// The mean of each field over `fits`.
fn mean_fit(fits: Vec<Fit>) -> Fit {
    let n = fits.len().max(1) as f32;
    let mean = |pick: fn(&Fit) -> f32| fits.iter().map(pick).sum::<f32>() / n;
    Fit {
        points: (fits.iter().map(|f| f.points).sum::<usize>() as f32 / n).round() as usize,
        coverage: mean(|f| f.coverage),
        precision: mean(|f| f.precision),
        f_score: mean(|f| f.f_score),
    }
}

fn markdown(e: &Evaluation) -> String {
    let mut md = format!("# Shape-from-symmetry evaluation: {}\n\n", e.scene_dir);
    md += &legend(e.budget);
    if e.parts {
        md += "Part symmetries searched (`--parts`).\n\n";
    }
    if e.tilted_contact {
        md += "The contact term also for mirrors off level (`--tilted-contact`).\n\n";
    }
    md += &detection_table(&e.scenes);
    md += &completion_table(&e.scenes);
    md += &totals_section(&e.totals);
    for name in &e.skipped {
        md += &format!("- skipped (no ground truth): {name}\n");
    }
    for Failure { scene, error } in &e.failed {
        md += &format!("- FAILED: {scene}: {error}\n");
    }
    if !e.sweeps.is_empty() {
        md += &sweeps_section(&e.sweeps);
    }
    md
}

/// One table per sweep group (noise, distance, inputs), each led by the scenes as recorded.
fn sweeps_section(rows: &[SweepRow]) -> String {
    let mut md = format!(
        "## Robustness sweeps\n\n\
         The same scenes again with degraded input, one row per setting (totals as above; the \
         first row of each table is the scenes as recorded). Noise: zero-mean Gaussian, added to \
         every valid depth value, rounded to the depth unit, seeded per scene (seed {NOISE_SEED}); \
         the dropouts are extra readings removed at random. Distance: every k-th pixel of every \
         k-th row, intrinsics divided by k (the object k times farther away, same sensor, without \
         the sensor's noise growing with distance). Missing input: the engine fits the table \
         plane by RANSAC and/or segments the object itself. Completion and the references use \
         the degraded pixels with the recorded mask; free space is judged against the recorded \
         depth image. Verdict columns count scenes; failed: the engine stopped with an error \
         (excluded from the other columns).\n\n"
    );
    let baseline = rows.iter().find(|r| r.sweep == "baseline");
    let mut groups: Vec<&str> = Vec::new();
    for row in rows.iter().filter(|r| r.sweep != "baseline") {
        let group = Sweep::ALL
            .into_iter()
            .find(|s| s.name() == row.sweep)
            .map_or(row.sweep, Sweep::group);
        if !groups.contains(&group) {
            groups.push(group);
        }
    }
    for group in groups {
        let title = match group {
            "noise" => "More depth noise",
            "distance" => "Fewer pixels (the object farther away)",
            _ => "Missing table plane or mask",
        };
        md += &format!("### {title}\n\n{}", sweep_header());
        let in_group = rows.iter().filter(|r| {
            Sweep::ALL
                .into_iter()
                .any(|s| s.name() == r.sweep && s.group() == group)
        });
        for row in baseline.into_iter().chain(in_group) {
            md += &sweep_line(row);
        }
        md += "\n";
    }
    md
}

fn sweep_header() -> String {
    let columns = [
        "setting",
        "object px (median)",
        "sampled (median)",
        "exact",
        "weaker",
        "part",
        "wrong",
        "missed",
        "false alarm",
        "correct none",
        "failed",
        "valid object / part of found",
        "plane deg / mm",
        "axis deg / mm",
        "centre mm",
        "completed C / P / F %",
        "ref 1 F %",
        "free space",
        "median ms",
        "median work units",
    ];
    format!(
        "| {} |\n|{}\n",
        columns.join(" | "),
        "---|".repeat(columns.len())
    )
}

fn sweep_line(row: &SweepRow) -> String {
    let t = &row.totals;
    let count = |v: Verdict| t.verdicts.get(v.name()).copied().unwrap_or_default();
    let verdicts: Vec<String> = Verdict::ALL.iter().map(|&v| count(v).to_string()).collect();
    format!(
        "| {} | {} | {} | {} | {} | {} / {} of {} | {} | {} | {} | {} | {:.0} | {} | {:.0} | {} |\n",
        row.setting,
        t.object_pixels_median,
        t.sampled_points_median,
        verdicts.join(" | "),
        row.failed.len(),
        t.strongest_valid_object,
        t.strongest_valid_part,
        t.strongest_found,
        pair(t.median_plane_deg, t.median_plane_offset_mm),
        pair(t.median_axis_deg, t.median_axis_offset_mm),
        opt(t.median_center_mm, 1),
        fit(&t.completed),
        t.reference_pixels.f_score * 100.0,
        percent(t.generated_in_free_space),
        t.wall_ms_median,
        t.work_units_median
    )
}

fn legend(budget: u32) -> String {
    let t = &SETTINGS;
    format!(
        "Budget {budget} work units per poll. How to read the tables:\n\n\
         - **verdict**: the strongest type found against the true class: exact; weaker (a type the class \
           entails); part (the class of one of the object's parts); wrong; missed; false_alarm; correct_none.\n\
         - **valid**: every map of the symmetry moves the ground-truth surface sample onto itself: \
           nearest-neighbour distance of the mapped samples to the sample set, mean <= {} mm, p90 <= {} mm, \
           p99 <= {} mm for the worst map (distances capped at {} mm); else the same for one part's samples. \
           The JSON's `validity.planes` holds each mirror plane's residual: which plane of a composite fails.\n\
         - **floor**: the sample's own spacing (each sample to its nearest other one): what a perfect map scores.\n\
         - **plane / axis**: angle (deg) and offset (mm, beside the object's centroid) of the worst plane and of \
           the axis from the nearest true element (planes through a continuous axis and anything through a \
           sphere's centre count); **centre**: distance to the true or implied centre.\n\
         - **completion**: coverage / precision / F-score (%) against the whole surface at {} mm. visible only: \
           the engine's visible points; ref 1: every object pixel; ref 2: those pixels and their images under \
           the TRUE symmetry, less free space (what a perfect detector could complete).\n\
         - **free space**: generated points in front of the observed depth by more than {} mm.\n\n",
        t.valid_mean_mm, t.valid_p90_mm, t.valid_p99_mm, t.reach_mm, t.near_mm, t.free_margin_mm
    )
}

fn detection_table(scenes: &[SceneEval]) -> String {
    let mut md = "## Detection (strongest symmetry)\n\n| scene | truth | found | verdict | score | valid | worst map mean / p90 / p99 mm | floor mean / p90 / p99 mm | plane deg / mm | axis deg / mm | centre mm | ms | work units |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n".to_string();
    for s in scenes {
        let strongest = s.symmetries.first();
        let errors = strongest.map(|f| f.errors).unwrap_or_default();
        md += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} | {} |\n",
            s.scene,
            s.truth,
            s.found,
            s.verdict,
            opt(strongest.map(|f| f.found.score), 3),
            strongest.map_or("-".into(), |f| if f.validity.valid {
                format!("yes ({})", f.validity.of)
            } else {
                "no".into()
            }),
            strongest.map_or("-".into(), |f| residual(&f.validity.worst)),
            residual(&s.floor),
            pair(errors.plane_deg, errors.plane_offset_mm),
            pair(errors.axis_deg, errors.axis_offset_mm),
            opt(errors.center_mm, 1),
            s.wall_ms,
            s.work_units
        );
    }
    md + "\n"
}

fn completion_table(scenes: &[SceneEval]) -> String {
    let mut md = "## Completion (coverage / precision / F, %)\n\n| scene | completed | visible only | ref 1: object pixels | ref 2: pixels + true symmetry | generated in free space |\n|---|---|---|---|---|---|\n".to_string();
    for s in scenes {
        md += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            s.scene,
            fit(&s.completed),
            fit(&s.visible),
            fit(&s.reference_pixels),
            fit(&s.reference_truth),
            percent(s.generated_in_free_space)
        );
    }
    md + "\n"
}

fn totals_section(t: &Totals) -> String {
    let verdicts: Vec<String> = t
        .verdicts
        .iter()
        .filter(|(_, n)| **n > 0)
        .map(|(v, n)| format!("{v} {n}"))
        .collect();
    format!(
        "## Totals ({} scenes)\n\n\
         - type against the true class: {}\n\
         - strongest symmetry valid: {} for the whole object, {} for a part only, of {} scenes with a \
           symmetry found\n\
         - median errors of the strongest: plane {} deg / {} mm{}, axis {} deg / {} mm{}, centre {} mm{}\n\
         - completion, mean C / P / F %: completed {}, visible only {}; ref 1 (object pixels) {}, \
           ref 2 (pixels + true symmetry) {}\n\
         - generated points in free space: {} (mean over scenes with generated points)\n\
         - time: {:.0} ms in all, median {:.1} ms; work units: {} in all, median {}\n\
         - confidence of the strongest symmetry (reported with confidence >= c: valid / reported): {}\n\
         - runner-up valid for the whole object: {} of {}\n\
         - symmetric objects whose strongest symmetry is not a true one of the whole object: {}; \
           the model accepts the true symmetry on {} (the search did not reach it, or the walk \
           reported another), rejects it on {}; the strongest is valid on the seen part of the \
           surface (wrong only where the camera did not look) on {}\n\
         - strongest symmetries scoring not below the threshold over every point (the search \
           accepts on a subset): {} of {}, valid for the whole object {}\n\
         {}\n",
        t.scenes,
        if verdicts.is_empty() {
            "-".into()
        } else {
            verdicts.join(", ")
        },
        t.strongest_valid_object,
        t.strongest_valid_part,
        t.strongest_found,
        opt(t.median_plane_deg, 2),
        opt(t.median_plane_offset_mm, 1),
        t.plane_toward_camera.phrase(),
        opt(t.median_axis_deg, 2),
        opt(t.median_axis_offset_mm, 1),
        t.axis_toward_camera.phrase(),
        opt(t.median_center_mm, 1),
        t.center_toward_camera.phrase(),
        fit(&t.completed),
        fit(&t.visible),
        fit(&t.reference_pixels),
        fit(&t.reference_truth),
        percent(t.generated_in_free_space),
        t.wall_ms_total,
        t.wall_ms_median,
        t.work_units_total,
        t.work_units_median,
        calibration(&t.calibration),
        t.runner_ups_valid,
        t.runner_ups,
        t.misses.scenes,
        t.misses.truth_accepted,
        t.misses.truth_rejected,
        t.misses.valid_on_seen,
        t.strongest_over_threshold,
        t.strongest_found,
        t.strongest_over_threshold_valid,
        against_baseline(t)
    )
}

/// The totals' line comparing the strongest symmetry with the one-plane baseline's plane on the
/// scenes the baseline ran on (empty when it ran on none).
fn against_baseline(t: &Totals) -> String {
    let b = &t.baseline;
    if b.scenes == 0 {
        return String::new();
    }
    let none = t
        .verdicts
        .get(Verdict::CorrectNone.name())
        .copied()
        .unwrap_or_default();
    format!(
        "- against the one-plane baseline (`sfs_testkit::baseline`: one mirror plane containing the \
           table normal, always reported; on the {} scenes with mask and table): valid for the \
           whole object or correctly none, this project {} and the baseline {}; by the lenient test \
           (`metrics::lenient`: mean <= max(4 mm, 2.5 % of the object's size), p90 <= max(8 mm, \
           5 %), no p99 bound; correctly none counts), this project {} and the baseline {}; \
           completion F {:.1} % and {:.1} %\n",
        b.scenes,
        t.strongest_valid_object + none,
        b.valid_object,
        t.strongest_lenient + none,
        b.lenient,
        t.completed.f_score * 100.0,
        b.completed.f_score * 100.0
    )
}

fn calibration(table: &[Calibration]) -> String {
    let step = |c: &Calibration| {
        format!(
            "c {:.1}: {} / {}",
            c.confidence_at_least, c.valid, c.reported
        )
    };
    table.iter().map(step).collect::<Vec<_>>().join(", ")
}

fn opt(value: Option<f32>, decimals: usize) -> String {
    value.map_or("-".into(), |v| format!("{v:.decimals$}"))
}

fn pair(angle: Option<f32>, offset: Option<f32>) -> String {
    match (angle, offset) {
        (None, None) => "-".into(),
        _ => format!("{} / {}", opt(angle, 2), opt(offset, 1)),
    }
}

fn residual(r: &Residual) -> String {
    format!("{:.1} / {:.1} / {:.1}", r.mean_mm, r.p90_mm, r.p99_mm)
}

fn fit(f: &Fit) -> String {
    format!(
        "{:.0} / {:.0} / {:.0}",
        f.coverage * 100.0,
        f.precision * 100.0,
        f.f_score * 100.0
    )
}

fn percent(share: Option<f32>) -> String {
    share.map_or("-".into(), |s| format!("{:.1} %", s * 100.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(line: &str) -> Result<Args> {
        parse_args(line.split_whitespace().map(String::from).collect())
    }

    #[test]
    fn misses_are_split_by_whether_the_model_accepts_the_truth() {
        let case = |symmetric, valid, valid_on_seen, truth_score| Case {
            symmetric,
            valid,
            valid_on_seen,
            truth_score,
        };
        let scenes = [
            case(true, false, true, Some(0.5)), // the truth accepted: a search or walk miss
            case(true, false, false, Some(0.9)), // rejected: a model miss
            case(true, false, false, None),     // too few informative points: rejected
            case(true, true, true, Some(0.5)),  // found: no miss
            case(false, false, false, None),    // asymmetric: not counted
        ];
        let m = Misses::count(scenes.into_iter(), 0.85);
        assert_eq!((m.scenes, m.truth_accepted, m.truth_rejected), (3, 1, 2));
        assert_eq!(m.valid_on_seen, 1);
    }

    #[test]
    fn parses_the_ci_command_without_sweeps() {
        let args = parse("dir --only wrist_0 --out-json e.json --out-md e.md").unwrap();
        assert_eq!(args.dir, PathBuf::from("dir"));
        assert_eq!(args.only.as_deref(), Some("wrist_0"));
        assert!(args.sweeps.is_empty());
        assert_eq!((args.budget, args.parts), (search::DEFAULT_BUDGET, false));
        assert!(parse("dir --parts").unwrap().parts);
        assert!(!args.tilted_contact && parse("dir --tilted-contact").unwrap().tilted_contact);
    }

    #[test]
    fn parses_sweeps_in_a_fixed_order_without_repeats() {
        let sweeps = |line: &str| parse(line).unwrap().sweeps;
        assert_eq!(
            sweeps("d --sweep no-mask,noise,noise"),
            [Sweep::Noise, Sweep::NoMask]
        );
        assert_eq!(sweeps("d --sweep all,distance"), Sweep::ALL);
        let error = parse("d --sweep blur").err().unwrap();
        assert!(
            error.starts_with("--sweep: unknown sweep \"blur\""),
            "{error}"
        );
    }

    #[test]
    fn every_setting_degrades_the_scene_and_is_named() {
        let settings: Vec<_> = Sweep::ALL.iter().flat_map(|s| s.settings()).collect();
        assert_eq!(settings.len(), 3 + 2 + 3);
        assert!(
            settings
                .iter()
                .all(|(label, d)| !d.is_none() && !label.is_empty())
        );
        assert_eq!(settings[3].0, "every 2nd pixel (2x farther)");
        assert_eq!(
            (ordinal(1), ordinal(3), ordinal(12)),
            ("1st".into(), "3rd".into(), "12th".into())
        );
    }
}
