//! Raw sensor input for the command-line tools, instead of a scene file: a 16-bit depth PNG, its
//! scale, pinhole intrinsics (four numbers, or a ROS `CameraInfo` YAML file, see
//! [`super::camera_info`]), and optionally an object mask and the table plane, loaded into the
//! [`LoadedScene`] a scene file with the same contents gives.
//!
//! The option values are parsed here (`parse_*`); every message names the option that is wrong.
//! So are the values of `--target` and `--roi`, which name the object in raw input and in a
//! scene file alike.

use std::path::{Path, PathBuf};

use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Intrinsics, MAX_DEPTH_SCALE, Plane, Rect, Scene, Target};

use super::Result;
use super::camera_info::CameraInfo;
use super::scene::{self, LoadedScene};

/// Focal lengths and principal point, pixels: the intrinsics less the image size, which the
/// depth image gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
}

impl Pinhole {
    /// Focal lengths positive and finite, principal point finite, all in the range the library
    /// takes; the error says which is not.
    pub fn new(fx: f32, fy: f32, cx: f32, cy: f32) -> Result<Self> {
        for (name, f) in [("fx", fx), ("fy", fy)] {
            if !(f.is_finite() && f > 0.0) {
                return Err(format!(
                    "focal length {name} = {f} must be positive and finite"
                ));
            }
        }
        for (name, c) in [("cx", cx), ("cy", cy)] {
            if !c.is_finite() {
                return Err(format!("principal point {name} = {c} must be finite"));
            }
        }
        let pinhole = Self { fx, fy, cx, cy };
        // Any image size would do: the library checks the numbers, and the size only for zero.
        let any_size = (1, 1);
        match pinhole.intrinsics(any_size).validate() {
            Ok(()) => Ok(pinhole),
            Err(e) => Err(format!(
                "{fx}, {fy}, {cx}, {cy} are out of the library's range: {e}"
            )),
        }
    }

    fn intrinsics(self, (width, height): (u16, u16)) -> Intrinsics {
        let Self { fx, fy, cx, cy } = self;
        Intrinsics {
            width,
            height,
            fx,
            fy,
            cx,
            cy,
        }
    }
}

/// Where the intrinsics come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Camera {
    /// `--intrinsics FX,FY,CX,CY`.
    Pinhole(Pinhole),
    /// `--camera-info FILE.yaml`.
    Info(PathBuf),
}

/// Raw sensor input, as the command line gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct RawInput {
    /// `--depth`: a 16-bit grayscale PNG, row-major, 0 = no reading; its size is the image size.
    pub depth: PathBuf,
    /// `--depth-scale`: metres per depth unit.
    pub depth_scale: f32,
    pub camera: Camera,
    /// `--mask`: an 8-bit grayscale PNG of the depth image's size, nonzero = object pixel.
    pub mask: Option<PathBuf>,
    /// `--table`: the support plane.
    pub table: Option<Plane>,
}

impl LoadedScene {
    /// Read raw sensor input; named as its depth image, less `.png` and a `.depth` suffix (so
    /// `NAME.depth.png` gives `NAME`, as its scene file `NAME.json` does).
    pub fn from_raw(raw: &RawInput) -> Result<Self> {
        let shown = raw.depth.display();
        let depth = scene::decode_gray_png(&raw.depth, png::BitDepth::Sixteen)
            .map_err(|e| format!("--depth: {e}"))?;
        let side = |pixels: u32| {
            u16::try_from(pixels)
                .map_err(|_| format!("--depth: {shown} is larger than {} pixels a side", u16::MAX))
        };
        let size = (side(depth.width)?, side(depth.height)?);
        let depth_size = format!("the depth image {shown} is {}x{}", size.0, size.1);
        let pinhole = match &raw.camera {
            Camera::Pinhole(pinhole) => *pinhole,
            Camera::Info(path) => read_camera_info(path, size, &depth_size)?,
        };
        let mask = match &raw.mask {
            Some(path) => Some(read_mask(path, size, &depth_size)?),
            None => None,
        };
        let stem = scene::scene_name(&raw.depth);
        Ok(Self {
            name: stem.strip_suffix(".depth").unwrap_or(&stem).into(),
            depth: scene::depth_values(&depth.bytes),
            depth_scale: raw.depth_scale,
            intrinsics: pinhole.intrinsics(size),
            table: raw.table,
            mask,
        })
    }
}

/// The intrinsics of a camera info file made for images of `size` (`depth_size` says so).
fn read_camera_info(path: &Path, size: (u16, u16), depth_size: &str) -> Result<Pinhole> {
    let shown = path.display();
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("--camera-info: cannot read {shown}: {e}"))?;
    let info = CameraInfo::parse(&text).map_err(|e| format!("--camera-info {shown}: {e}"))?;
    if (info.width, info.height) != (size.0.into(), size.1.into()) {
        return Err(format!(
            "--camera-info {shown} is for {}x{} images, {depth_size}",
            info.width, info.height
        ));
    }
    Ok(info.pinhole)
}

/// An 8-bit mask of the depth image's `size` (`depth_size` says so).
fn read_mask(path: &Path, size: (u16, u16), depth_size: &str) -> Result<Vec<u8>> {
    let mask =
        scene::decode_gray_png(path, png::BitDepth::Eight).map_err(|e| format!("--mask: {e}"))?;
    if (mask.width, mask.height) != (size.0.into(), size.1.into()) {
        return Err(format!(
            "--mask: {} is {}x{}, {depth_size}",
            path.display(),
            mask.width,
            mask.height
        ));
    }
    Ok(mask.bytes)
}

/// A `--depth-scale` value: metres per depth unit, in `(0, MAX_DEPTH_SCALE]`.
pub fn parse_depth_scale(text: &str) -> Result<f32> {
    number(text)
        .filter(|&scale| Scene::depth_scale_ok(scale))
        .ok_or_else(|| {
            format!(
                "--depth-scale {text}: expected metres per depth unit, a number in \
                 (0, {MAX_DEPTH_SCALE}] (0.001 for millimetres)"
            )
        })
}

/// An `--intrinsics` value: `FX,FY,CX,CY` in pixels.
pub fn parse_intrinsics(text: &str) -> Result<Pinhole> {
    numbers(text)
        .and_then(|[fx, fy, cx, cy]| Pinhole::new(fx, fy, cx, cy))
        .map_err(|e| format!("--intrinsics {text}: {e} (expected FX,FY,CX,CY in pixels)"))
}

/// How far from 1 the length of a `--table` normal may be: the rounding of a unit normal
/// written to three decimals (each component off by at most 5e-4, the length by at most
/// 5e-4 · √3 ≈ 8.7e-4). Further off is a mistake, not rounding. The normal is then scaled to
/// unit length, as the scene file's is.
pub const TABLE_NORMAL_TOLERANCE: f32 = 1e-3;

/// A `--table` value: `NX,NY,NZ,D`, the plane `n · X + d = 0` (camera frame, metres), `n` a unit
/// normal pointing away from the table; as the library's plane.
pub fn parse_table(text: &str) -> Result<Plane> {
    let wrong = |e: String| format!("--table {text}: {e}");
    let [nx, ny, nz, d] = numbers(text).map_err(wrong)?;
    let length = Vec3::new(nx, ny, nz).length();
    if (length - 1.0).abs() > TABLE_NORMAL_TOLERANCE {
        return Err(wrong(format!(
            "the normal ({nx}, {ny}, {nz}) has length {length}, it must be a unit vector"
        )));
    }
    scene::table_plane([nx, ny, nz, d]).map_err(wrong)
}

/// A `--target` value: `U,V`, the column and row of a pixel on the object.
pub fn parse_target(text: &str) -> Result<Target> {
    let [u, v] = values(text, "whole numbers", pixel)
        .map_err(|e| format!("--target {text}: {e} (expected U,V: a pixel's column and row)"))?;
    Ok(Target::Pixel { u, v })
}

/// A `--roi` value: `X,Y,W,H`, a region of interest holding the object: its first column and
/// row, its width and height in pixels (each positive).
pub fn parse_roi(text: &str) -> Result<Target> {
    let wrong = |e: String| {
        format!("--roi {text}: {e} (expected X,Y,W,H: first column and row, width, height)")
    };
    let [u0, v0, width, height] = values(text, "whole numbers", pixel).map_err(wrong)?;
    if width == 0 || height == 0 {
        return Err(wrong(format!(
            "the region is {width}x{height}, it must be at least 1x1"
        )));
    }
    Ok(Target::Region(Rect {
        u0,
        v0,
        width,
        height,
    }))
}

/// The command-line form of a target: `--target U,V` or `--roi X,Y,W,H`.
pub fn target_option(target: &Target) -> String {
    match *target {
        Target::Pixel { u, v } => format!("--target {u},{v}"),
        Target::Region(r) => format!("--roi {},{},{},{}", r.u0, r.v0, r.width, r.height),
    }
}

/// A pixel coordinate or size, in the library's range.
fn pixel(item: &str) -> Result<u16> {
    item.trim()
        .parse()
        .map_err(|_| format!("{item:?} is not a whole number from 0 to {}", u16::MAX))
}

/// `N` comma-separated numbers, or what is wrong with them.
fn numbers<const N: usize>(text: &str) -> Result<[f32; N]> {
    values(text, "numbers", |item| {
        number(item).ok_or_else(|| format!("{item:?} is not a finite number"))
    })
}

/// `N` comma-separated values (`kind` in the message), each read by `read`.
fn values<T: Copy + Default, const N: usize>(
    text: &str,
    kind: &str,
    read: impl Fn(&str) -> Result<T>,
) -> Result<[T; N]> {
    let items: Vec<&str> = text.split(',').collect();
    if items.len() != N {
        return Err(format!(
            "expected {N} comma-separated {kind}, got {}",
            items.len()
        ));
    }
    let mut values = [T::default(); N];
    for (value, item) in values.iter_mut().zip(items) {
        *value = read(item)?;
    }
    Ok(values)
}

/// A finite number, read as serde_json reads a scene file's numbers (to `f64`, then rounded to
/// `f32`), so that the same digits give the same bits in either form.
pub(crate) fn number(text: &str) -> Option<f32> {
    let value = text.trim().parse::<f64>().ok()? as f32;
    value.is_finite().then_some(value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::tests::{Scratch, write_png, write_scene};

    /// The raw form of `write_scene`'s files.
    fn raw(dir: &Path) -> RawInput {
        RawInput {
            depth: dir.join("s.depth.png"),
            depth_scale: 0.001,
            camera: Camera::Pinhole(parse_intrinsics("5,5,1.5,1").unwrap()),
            mask: Some(dir.join("s.mask.png")),
            table: Some(parse_table("0,-1,0,0.25").unwrap()),
        }
    }

    #[test]
    fn gives_the_scene_the_scene_file_gives() {
        let dir = Scratch::new("raw-same");
        let json = LoadedScene::load(&write_scene(&dir.0, 4)).unwrap();
        let mut raw = raw(&dir.0);
        let info = dir.0.join("info.yaml");
        let k = "K: [5, 0, 1.5, 0, 5, 1, 0, 0, 1]";
        std::fs::write(&info, format!("height: 3\nwidth: 4\n{k}\n")).unwrap();
        for camera in [raw.camera.clone(), Camera::Info(info)] {
            raw.camera = camera;
            let scene = LoadedScene::from_raw(&raw).unwrap();
            assert_eq!((&scene.name, &scene.depth), (&json.name, &json.depth));
            assert_eq!((&scene.mask, scene.table), (&json.mask, json.table));
            assert_eq!(
                (scene.depth_scale, scene.intrinsics),
                (json.depth_scale, json.intrinsics)
            );
        }
    }

    #[test]
    fn rejects_images_of_the_wrong_kind_or_size() {
        let dir = Scratch::new("raw-bad");
        write_scene(&dir.0, 4);
        let mut raw = raw(&dir.0);
        write_png(
            &dir.0.join("small.png"),
            (4, 2),
            png::BitDepth::Eight,
            &[0; 8],
        );
        raw.mask = Some(dir.0.join("small.png"));
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.starts_with("--mask: "), "{error}");
        assert!(
            error.contains("small.png is 4x2, the depth image "),
            "{error}"
        );
        raw.depth = dir.0.join("s.mask.png");
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.starts_with("--depth: "), "{error}");
        assert!(error.ends_with("must be 16-bit grayscale, it is 8-bit Grayscale"));
        raw.depth = dir.0.join("absent.png");
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.starts_with("--depth: cannot open "), "{error}");
    }

    #[test]
    fn rejects_a_camera_info_of_another_size_or_form() {
        let dir = Scratch::new("raw-info");
        write_scene(&dir.0, 4);
        let mut raw = raw(&dir.0);
        let info = dir.0.join("info.yaml");
        raw.camera = Camera::Info(info.clone());
        let k = "K: [5, 0, 1.5, 0, 5, 1, 0, 0, 1]";
        std::fs::write(&info, format!("height: 3\nwidth: 5\n{k}\n")).unwrap();
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.contains("info.yaml is for 5x3 images, the depth image "));
        std::fs::write(&info, "height: 3\nwidth: 4\n").unwrap();
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.starts_with("--camera-info "), "{error}");
        assert!(error.ends_with("info.yaml: no K or k or camera_matrix.data"));
        raw.camera = Camera::Info(dir.0.join("absent.yaml"));
        let error = LoadedScene::from_raw(&raw).unwrap_err();
        assert!(error.starts_with("--camera-info: cannot read "), "{error}");
    }

    #[test]
    fn parses_option_values() {
        assert_eq!(parse_depth_scale("0.001"), Ok(0.001));
        let pinhole = parse_intrinsics(" 285, 285.0,159.5,119.5").unwrap();
        assert_eq!(pinhole, Pinhole::new(285.0, 285.0, 159.5, 119.5).unwrap());
        let table = parse_table("0.020074,-0.875507,-0.482789,0.240346").unwrap();
        assert!((table.n().length() - 1.0).abs() < 1e-6);
        assert_eq!(
            table.offset,
            -0.240346 / Vec3::new(0.020074, -0.875507, -0.482789).length()
        );
    }

    #[test]
    fn rejects_bad_option_values_with_a_reason() {
        for scale in ["0", "-0.001", "NaN", "inf", "mm", "2", ""] {
            let error = parse_depth_scale(scale).unwrap_err();
            assert!(error.starts_with(&format!("--depth-scale {scale}: expected metres")));
        }
        let intrinsics = |text: &str| parse_intrinsics(text).unwrap_err();
        let table = |text: &str| parse_table(text).unwrap_err();
        assert!(
            intrinsics("285,285,159.5").starts_with(
                "--intrinsics 285,285,159.5: expected 4 comma-separated numbers, got 3"
            )
        );
        assert!(intrinsics("285,f,1,1").contains(": \"f\" is not a finite number"));
        assert!(intrinsics("285,nan,1,1").contains(": \"nan\" is not a finite number"));
        assert!(intrinsics("0,285,1,1").contains(": focal length fx = 0 must be positive"));
        assert!(intrinsics("285,-1,1,1").contains(": focal length fy = -1 must be positive"));
        assert!(intrinsics("285,285,1e39,1").contains(": \"1e39\" is not a finite number"));
        assert!(
            intrinsics("1e-9,285,1,1")
                .contains("0.000000001, 285, 1, 1 are out of the library's range")
        );
        assert!(table("0,-1,0").ends_with("expected 4 comma-separated numbers, got 3"));
        assert!(table("0,-2,0,0.25").contains("has length 2, it must be a unit vector"));
        assert!(table("0,0,0,0.25").contains("has length 0, it must be a unit vector"));
        assert!(table("0,-1,0,x").ends_with("\"x\" is not a finite number"));
    }

    #[test]
    fn parses_targets() {
        assert_eq!(
            parse_target("320, 250"),
            Ok(Target::Pixel { u: 320, v: 250 })
        );
        let roi = Rect {
            u0: 0,
            v0: 10,
            width: 65_535,
            height: 1,
        };
        assert_eq!(parse_roi("0,10,65535,1"), Ok(Target::Region(roi)));
        assert_eq!(target_option(&parse_target("3,4").unwrap()), "--target 3,4");
        assert_eq!(target_option(&Target::Region(roi)), "--roi 0,10,65535,1");
    }

    #[test]
    fn rejects_bad_targets_with_a_reason() {
        let target = |text: &str| parse_target(text).unwrap_err();
        let roi = |text: &str| parse_roi(text).unwrap_err();
        assert_eq!(
            target("3"),
            "--target 3: expected 2 comma-separated whole numbers, got 1 \
             (expected U,V: a pixel's column and row)"
        );
        assert!(target("3,4,5").contains(": expected 2 comma-separated whole numbers, got 3"));
        assert!(target("-1,4").contains(": \"-1\" is not a whole number from 0 to 65535"));
        assert!(target("3,65536").contains(": \"65536\" is not a whole number from 0 to 65535"));
        assert!(target("3.5,4").contains(": \"3.5\" is not a whole number"));
        assert!(target("3,").contains(": \"\" is not a whole number"));
        assert!(roi("1,2,3").starts_with("--roi 1,2,3: expected 4 comma-separated whole numbers"));
        assert!(roi("1,2,x,4").contains(": \"x\" is not a whole number"));
        assert!(
            roi("1,2,0,4").contains(": the region is 0x4, it must be at least 1x1 (expected X,Y")
        );
        assert!(roi("1,2,4,0").contains(": the region is 4x0, it must be at least 1x1"));
    }
}
