//! How the depth noise of scene files correlates between neighbouring pixels
//! (`sfs_testkit::correlation`: planar patches, their residuals' autocorrelation), a Markdown
//! table: a row per scene for a folder of at most 8 (the real frames), and one per folder. The
//! kernel is the σ of the Gaussian smoothing that correlates adjacent pixels as measured, in the
//! image's pixels and as an angle (pixels over the focal length: the same for any camera
//! looking at the same field): what `synth::XTION_NOISE_CORRELATION_MRAD` imitates.
//!
//! ```text
//! cargo run --release --example noise -- SCENE_DIR [SCENE_DIR ...]
//! ```
//! `ci/figures.sh` runs it on the real frames (`../shared/scenes/real`) and the development
//! scenes.

use std::path::Path;
use std::process::ExitCode;

use sfs_testkit::correlation::{LAGS, Patch, kernel_sigma_px, median, planar_patches};
use sfs_testkit::scene::LoadedScene;

/// Patch side in a 640-column image, pixels: about the size of a planar face of a table-top
/// object at 1 m (24 px ≈ 4 cm), and six times the largest lag; scaled with the image width.
const SIDE_640: usize = 24;

fn main() -> ExitCode {
    let dirs: Vec<String> = std::env::args().skip(1).collect();
    if dirs.is_empty() {
        eprintln!("usage: noise SCENE_DIR [SCENE_DIR ...]");
        return ExitCode::from(2);
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

/// Print the rows of the scenes in `dir`.
fn measure(dir: &Path) -> Result<(), String> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let (mut all, mut focal) = (Vec::new(), 1.0);
    for file in &files {
        let scene = LoadedScene::load(file)?;
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
        if files.len() <= 8 {
            row(&scene.name, &patches, focal);
        }
        all.extend(patches);
    }
    let name = dir
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into());
    row(&format!("**{name}** ({} scenes)", files.len()), &all, focal);
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
