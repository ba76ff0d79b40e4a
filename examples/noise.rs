//! How the depth noise of scene files correlates between neighbouring pixels
//! (`sfs_testkit::correlation`: planar patches, their residuals' autocorrelation), a Markdown
//! table: a row per scene for a folder of at most 8 (the real frames), and one per folder. The
//! kernel is the σ of the Gaussian smoothing that correlates adjacent pixels as measured, in the
//! image's pixels and as an angle (pixels over the focal length: the same for any camera
//! looking at the same field): what `synth::XTION_NOISE_CORRELATION_MRAD` imitates.
//!
//! With `--gaps`, instead, the readings missing beside depth jumps (`sfs_testkit::gaps`), a row
//! per folder: along the image rows, the jumps whose nearer surface lies left of them and those
//! whose nearer surface lies right, and for each side the share of jumps with no pixel missing
//! and the median run of missing pixels, in pixels and as an angle (milliradians).
//!
//! ```text
//! cargo run --release --example noise -- [--gaps] SCENE_DIR [SCENE_DIR ...]
//! ```
//! `ci/figures.sh` runs it, both ways, on the real frames (`../shared/scenes/real`), the
//! development scenes and the extra views.

use std::path::Path;
use std::process::ExitCode;

use sfs_testkit::correlation::{LAGS, Patch, kernel_sigma_px, median, planar_patches};
use sfs_testkit::gaps::{JumpGaps, jump_gaps};
use sfs_testkit::scene::LoadedScene;

/// Patch side in a 640-column image, pixels: about the size of a planar face of a table-top
/// object at 1 m (24 px ≈ 4 cm), and six times the largest lag; scaled with the image width.
const SIDE_640: usize = 24;

fn main() -> ExitCode {
    let mut dirs: Vec<String> = std::env::args().skip(1).collect();
    let gaps = dirs.first().is_some_and(|a| a == "--gaps");
    if gaps {
        dirs.remove(0);
    }
    if dirs.is_empty() {
        eprintln!("usage: noise [--gaps] SCENE_DIR [SCENE_DIR ...]");
        return ExitCode::from(2);
    }
    if gaps {
        println!(
            "| scenes | jumps, nearer surface left / right | no pixel missing, left / right | \
             median run missing (px), left / right | the same (mrad) |"
        );
        println!("|---|---|---|---|---|");
        for dir in &dirs {
            if let Err(e) = measure_gaps(Path::new(dir)) {
                eprintln!("noise: {e}");
                return ExitCode::FAILURE;
            }
        }
        return ExitCode::SUCCESS;
    }
    let lags: Vec<String> = LAGS.iter().map(|d| format!("ρ({d})")).collect();
    println!(
        "| scenes | planar patches | depth (m) | residual RMS (mm) | {} | kernel (px) | kernel (mrad) |",
        lags.join(" | ")
    );
    println!("|---|---|---|---|{}---|---|", "---|".repeat(LAGS.len()));
    for dir in &dirs {
        match measure(Path::new(dir)) {
            Ok(()) => {}
            Err(e) => {
                eprintln!("noise: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}

/// The scenes in `dir` (its scene files, sorted).
fn scenes(dir: &Path) -> Result<Vec<LoadedScene>, String> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files.iter().map(|f| LoadedScene::load(f)).collect()
}

/// The folder's name and scene count, as a row's first cell.
fn folder(dir: &Path, scenes: usize) -> String {
    let name = dir
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into());
    format!("**{name}** ({scenes} scenes)")
}

/// Print the row of the missing readings beside the depth jumps of the scenes in `dir`.
fn measure_gaps(dir: &Path) -> Result<(), String> {
    let scenes = scenes(dir)?;
    let mut all = JumpGaps::default();
    for scene in &scenes {
        let k = scene.intrinsics;
        all.extend(jump_gaps(
            &scene.depth,
            k.width as usize,
            scene.depth_scale,
            k.fx,
        ));
    }
    // A folder's scenes share their camera.
    let focal = scenes.first().map_or(1.0, |s| s.intrinsics.fx);
    let none =
        |runs: &[u32]| runs.iter().filter(|&&r| r == 0).count() as f32 / runs.len().max(1) as f32;
    let run = |runs: &[u32]| median(runs.iter().map(|&r| r as f32).collect());
    let (left, right) = (&all.nearer_left, &all.nearer_right);
    println!(
        "| {} | {} / {} | {:.0} % / {:.0} % | {:.0} / {:.0} | {:.1} / {:.1} |",
        folder(dir, scenes.len()),
        left.len(),
        right.len(),
        none(left) * 100.0,
        none(right) * 100.0,
        run(left),
        run(right),
        run(left) / focal * 1e3,
        run(right) / focal * 1e3,
    );
    Ok(())
}

/// Print the rows of the scenes in `dir`.
fn measure(dir: &Path) -> Result<(), String> {
    let scenes = scenes(dir)?;
    let (mut all, mut focal) = (Vec::new(), 1.0);
    for scene in &scenes {
        let k = scene.intrinsics;
        let width = k.width as usize;
        focal = k.fx;
        let side = (SIDE_640 * width).div_ceil(640);
        let patches = planar_patches(
            &scene.depth,
            width,
            k.height as usize,
            scene.depth_scale,
            side,
        );
        if scenes.len() <= 8 {
            row(&scene.name, &patches, focal);
        }
        all.extend(patches);
    }
    row(&folder(dir, scenes.len()), &all, focal);
    Ok(())
}

/// One row: the medians over `patches` of a camera of focal length `focal` pixels (a folder's
/// scenes share their camera).
fn row(name: &str, patches: &[Patch], focal: f32) {
    let m = |f: &dyn Fn(&Patch) -> f32| median(patches.iter().map(f).collect());
    let rho: Vec<f32> = (0..LAGS.len()).map(|i| m(&|p| p.correlation[i])).collect();
    let kernel = kernel_sigma_px(rho[0]);
    let cells: Vec<String> = rho.iter().map(|r| format!("{r:.2}")).collect();
    println!(
        "| {name} | {} | {:.2} | {:.2} | {} | {kernel:.2} | {:.2} |",
        patches.len(),
        m(&|p| p.depth),
        m(&|p| p.rms) * 1e3,
        cells.join(" | "),
        kernel / focal * 1e3,
    );
}
