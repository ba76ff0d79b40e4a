//! Scene files (`SCENES.md`, format `shape-from-symmetry/scene-1`): the JSON and its PNGs, loaded
//! into owned buffers that lend the library a [`Scene`].

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Intrinsics, Plane, Scene};

use super::{Context, Result};

pub const SCENE_FORMAT: &str = "shape-from-symmetry/scene-1";

/// The scene JSON, less `ground_truth` (see [`super::truth`]): the tool's detection never reads it.
#[derive(Deserialize)]
struct SceneFile {
    format: String,
    depth: String,
    depth_scale: f32,
    #[serde(with = "IntrinsicsJson")]
    intrinsics: Intrinsics,
    table_plane: Option<[f32; 4]>,
    mask: Option<String>,
}

#[derive(Deserialize)]
#[serde(remote = "Intrinsics")]
struct IntrinsicsJson {
    width: u16,
    height: u16,
    fx: f32,
    fy: f32,
    cx: f32,
    cy: f32,
}

/// A scene with its images in memory.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// File name without `.json` (or `builtin`).
    pub name: String,
    /// Row-major depth values; `0` = no reading.
    pub depth: Vec<u16>,
    pub depth_scale: f32,
    pub intrinsics: Intrinsics,
    /// The library's form `n · X = offset` of the file's `n · X + d = 0`.
    pub table: Option<Plane>,
    /// Row-major, nonzero = object pixel.
    pub mask: Option<Vec<u8>>,
}

impl LoadedScene {
    /// Read `NAME.json` and the images it names (paths relative to the JSON's folder).
    pub fn load(json_path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(json_path)
            .context(|| format!("cannot read {}", json_path.display()))?;
        let file: SceneFile = serde_json::from_str(&text)
            .context(|| format!("{} is not a valid scene", json_path.display()))?;
        if file.format != SCENE_FORMAT {
            return Err(format!(
                "{}: format is {:?}, expected {SCENE_FORMAT:?}",
                json_path.display(),
                file.format
            ));
        }
        let dir = json_path.parent().unwrap_or(Path::new("."));
        let size = (file.intrinsics.width as u32, file.intrinsics.height as u32);
        let depth = read_gray_png(&dir.join(&file.depth), png::BitDepth::Sixteen, size)?;
        let mask = match &file.mask {
            Some(name) => Some(read_gray_png(&dir.join(name), png::BitDepth::Eight, size)?),
            None => None,
        };
        Ok(Self {
            name: scene_name(json_path),
            depth: depth_values(&depth),
            depth_scale: file.depth_scale,
            intrinsics: file.intrinsics,
            table: file
                .table_plane
                .map(table_plane)
                .transpose()
                .context(|| json_path.display().to_string())?,
            mask,
        })
    }

    /// The built-in scene (a synthetic can on a table): the committed file the firmware and the
    /// C test search ([`crate::scene_file`]), with its table plane and no mask, so every tool
    /// gives the same result on it.
    pub fn builtin() -> Result<Self> {
        let scene = crate::scene_file::scene();
        Ok(Self {
            name: "builtin".into(),
            depth: scene.depth.to_vec(),
            depth_scale: scene.depth_scale,
            intrinsics: scene.intrinsics,
            table: scene.table,
            mask: None,
        })
    }

    /// The library's view of this scene (borrowing the buffers).
    pub fn scene(&self) -> Scene<'_> {
        Scene {
            depth: &self.depth,
            depth_scale: self.depth_scale,
            intrinsics: self.intrinsics,
            table: self.table,
            mask: self.mask.as_deref(),
            target: None,
        }
    }

    /// The observed depth (metres) at the pixel `p` projects to; `None` outside the image or
    /// where the camera has no reading.
    pub fn observed_depth(&self, p: Vec3) -> Option<f32> {
        let raw = self.depth[self.pixel_of(p)?];
        (raw != 0).then_some(raw as f32 * self.depth_scale)
    }

    /// Whether the pixel `p` projects to is in the mask (every pixel is without a mask); `false`
    /// outside the image.
    pub fn is_object_at(&self, p: Vec3) -> bool {
        self.pixel_of(p)
            .is_some_and(|i| self.mask.as_ref().is_none_or(|m| m[i] != 0))
    }

    /// The row-major index of the pixel `p` projects to (rounded), if inside the image.
    fn pixel_of(&self, p: Vec3) -> Option<usize> {
        let k = &self.intrinsics;
        let (u, v) = k.project(p)?;
        let (u, v) = (u.round(), v.round());
        if !(0.0..k.width as f32).contains(&u) || !(0.0..k.height as f32).contains(&v) {
            return None;
        }
        Some(v as usize * k.width as usize + u as usize)
    }

    /// Whether `p` lies in free space: the camera saw a surface more than `margin` metres behind it.
    pub fn in_free_space(&self, p: Vec3, margin: f32) -> bool {
        self.observed_depth(p).is_some_and(|z| z > p.z + margin)
    }

    /// The object's vertical: the table normal, or the camera's up (`-y`) when there is no table.
    pub fn up(&self) -> Vec3 {
        self.table.map_or(Vec3::NEG_Y, |t| t.n())
    }

    /// The camera-frame points of the object's pixels (mask and a depth reading); every valid
    /// pixel when the scene has no mask.
    pub fn object_points(&self) -> Vec<Vec3> {
        let width = self.intrinsics.width as usize;
        let selected = |i: usize| self.mask.as_ref().is_none_or(|m| m[i] != 0);
        (0..self.depth.len())
            .filter(|&i| self.depth[i] != 0 && selected(i))
            .map(|i| {
                let (u, v) = ((i % width) as f32, (i / width) as f32);
                self.intrinsics
                    .unproject(u, v, self.depth[i] as f32 * self.depth_scale)
            })
            .collect()
    }
}

/// The built-in scene for `"builtin"`, else `dir/NAME.json` (for the benchmarks).
pub fn load_named(dir: &Path, name: &str) -> Result<LoadedScene> {
    if name == "builtin" {
        LoadedScene::builtin()
    } else {
        LoadedScene::load(&dir.join(format!("{name}.json")))
    }
}

/// `NAME` of `.../NAME.json`.
pub fn scene_name(json_path: &Path) -> String {
    json_path.file_stem().map_or_else(
        || json_path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// The scene files (`*.json`) of a folder, sorted by name.
pub fn scene_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).context(|| format!("cannot list {}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    Ok(files)
}

/// `[nx, ny, nz, d]` (`n · X + d = 0`) as the library's `n · X = -d`.
pub(crate) fn table_plane([nx, ny, nz, d]: [f32; 4]) -> Result<Plane> {
    Plane::new(Vec3::new(nx, ny, nz), -d)
        .ok_or_else(|| format!("table_plane {:?} has no usable normal", [nx, ny, nz, d]))
}

/// Big-endian 16-bit PNG samples as values.
pub(crate) fn depth_values(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect()
}

/// The raw bytes of a one-channel PNG with the given bit depth and size (16-bit samples stay
/// big-endian, as PNG stores them).
fn read_gray_png(
    path: &Path,
    bit_depth: png::BitDepth,
    (width, height): (u32, u32),
) -> Result<Vec<u8>> {
    let image = decode_gray_png(path, bit_depth)?;
    if (image.width, image.height) != (width, height) {
        return Err(format!(
            "{} is {}x{}, the intrinsics say {width}x{height}",
            path.display(),
            image.width,
            image.height
        ));
    }
    Ok(image.bytes)
}

/// A one-channel PNG's samples, row-major, rows packed (16-bit samples big-endian).
pub(crate) struct GrayPng {
    pub bytes: Vec<u8>,
    pub width: u32,
    pub height: u32,
}

/// Read a one-channel PNG of the given bit depth, whatever its size.
pub(crate) fn decode_gray_png(path: &Path, bit_depth: png::BitDepth) -> Result<GrayPng> {
    let shown = path.display();
    let file = File::open(path).context(|| format!("cannot open {shown}"))?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder
        .read_info()
        .context(|| format!("{shown} is not a readable PNG"))?;
    let mut buf = vec![
        0;
        reader
            .output_buffer_size()
            .ok_or_else(|| format!("{shown} is too large"))?
    ];
    let info = reader
        .next_frame(&mut buf)
        .context(|| format!("{shown} is not a readable PNG"))?;
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != bit_depth {
        return Err(format!(
            "{shown} must be {}-bit grayscale, it is {}-bit {:?}",
            bit_depth as u8, info.bit_depth as u8, info.color_type
        ));
    }
    buf.truncate(info.line_size * info.height as usize);
    Ok(GrayPng {
        bytes: buf,
        width: info.width,
        height: info.height,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A folder under the system's temporary directory, removed when dropped.
    pub(crate) struct Scratch(pub PathBuf);

    impl Scratch {
        pub(crate) fn new(name: &str) -> Self {
            let dir = std::env::temp_dir().join(format!("sfs-tools-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    pub(crate) fn write_png(
        path: &Path,
        (width, height): (u32, u32),
        depth: png::BitDepth,
        data: &[u8],
    ) {
        let mut encoder = png::Encoder::new(File::create(path).unwrap(), width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(depth);
        encoder
            .write_header()
            .unwrap()
            .write_image_data(data)
            .unwrap();
    }

    /// `dir/s.json`: a 4x3 scene (depth, mask, table plane) whose intrinsics give `width`.
    pub(crate) fn write_scene(dir: &Path, width: u16) -> PathBuf {
        let depth: Vec<u8> = (0..12u16).flat_map(|v| (v * 100).to_be_bytes()).collect();
        write_png(
            &dir.join("s.depth.png"),
            (4, 3),
            png::BitDepth::Sixteen,
            &depth,
        );
        write_png(
            &dir.join("s.mask.png"),
            (4, 3),
            png::BitDepth::Eight,
            &[0, 255, 0, 0, 0, 0, 0, 0, 0, 0, 0, 9],
        );
        let json = format!(
            r#"{{"format": "{SCENE_FORMAT}", "depth": "s.depth.png", "depth_scale": 0.001,
               "intrinsics": {{"width": {width}, "height": 3, "fx": 5, "fy": 5, "cx": 1.5, "cy": 1}},
               "table_plane": [0, -1, 0, 0.25], "mask": "s.mask.png", "ground_truth": {{}}}}"#
        );
        let path = dir.join("s.json");
        std::fs::write(&path, json).unwrap();
        path
    }

    #[test]
    fn loads_depth_mask_and_table() {
        let dir = Scratch::new("ok");
        let scene = LoadedScene::load(&write_scene(&dir.0, 4)).unwrap();
        assert_eq!(scene.name, "s");
        assert_eq!(scene.depth[..3], [0, 100, 200]);
        assert_eq!(scene.depth[11], 1100);
        assert_eq!(scene.mask.as_deref().unwrap()[1], 255);
        let table = scene.table.unwrap();
        assert_eq!((table.normal, table.offset), ([0.0, -1.0, 0.0], -0.25));
        assert_eq!(scene.object_points().len(), 2);
        assert!(scene.scene().validate().is_ok());
    }

    #[test]
    fn rejects_a_size_the_intrinsics_do_not_state() {
        let dir = Scratch::new("size");
        let error = LoadedScene::load(&write_scene(&dir.0, 5)).unwrap_err();
        assert!(
            error.ends_with("s.depth.png is 4x3, the intrinsics say 5x3"),
            "{error}"
        );
    }

    #[test]
    fn rejects_a_depth_image_of_the_wrong_bit_depth() {
        let dir = Scratch::new("bits");
        let path = write_scene(&dir.0, 4);
        std::fs::copy(dir.0.join("s.mask.png"), dir.0.join("s.depth.png")).unwrap();
        let error = LoadedScene::load(&path).unwrap_err();
        assert!(
            error.ends_with("must be 16-bit grayscale, it is 8-bit Grayscale"),
            "{error}"
        );
    }
}
