//! A scene's `ground_truth` block and its surface sample (`SCENES.md`). Only the evaluator reads
//! this; the library and the tool's detection never see it.

use std::path::Path;

use serde::Deserialize;
use shape_from_symmetry::math::Vec3;
use shape_from_symmetry::{Axis, Plane, Symmetry, SymmetryType};

use super::json::{AxisJson, PlaneJson};
use super::{Context, Result};

#[derive(Deserialize)]
struct SceneFile {
    ground_truth: Option<TruthJson>,
}

#[derive(Deserialize)]
struct TruthJson {
    #[serde(default)]
    object: String,
    #[serde(flatten)]
    elements: ElementsJson,
    #[serde(default)]
    parts: Vec<PartJson>,
    surface: String,
}

#[derive(Deserialize)]
struct ElementsJson {
    class: String,
    #[serde(default)]
    planes: Vec<PlaneJson>,
    #[serde(default)]
    axes: Vec<TruthAxisJson>,
    center: Option<[f32; 3]>,
}

#[derive(Deserialize)]
struct TruthAxisJson {
    #[serde(flatten)]
    axis: AxisJson,
    order: u32,
    #[serde(default)]
    implied: bool,
}

#[derive(Deserialize)]
struct PartJson {
    name: String,
    #[serde(flatten)]
    elements: ElementsJson,
    surface_range: [usize; 2],
}

/// A symmetry axis of the ground truth.
#[derive(Clone, Copy, Debug)]
pub struct TruthAxis {
    pub axis: Axis,
    /// 0 = continuous rotation, n = n-fold.
    pub order: u32,
    /// A 2-fold axis that two listed planes already imply.
    pub implied: bool,
}

/// The symmetry elements of the whole object or of one part.
#[derive(Clone, Debug)]
pub struct Elements {
    /// The strongest type; `None` for an asymmetric object.
    pub class: Option<SymmetryType>,
    /// Mirror planes (with a continuous axis, the planes through it are implied, not listed).
    pub planes: Vec<Plane>,
    pub axes: Vec<TruthAxis>,
    /// Centre of point and spherical symmetry.
    pub center: Option<Vec3>,
}

/// A part symmetry: the part's elements and which surface samples are its surface.
#[derive(Clone, Debug)]
pub struct Part {
    pub name: String,
    pub elements: Elements,
    pub surface_range: std::ops::Range<usize>,
}

/// The ground truth of one scene.
#[derive(Clone, Debug)]
pub struct GroundTruth {
    pub object: String,
    pub whole: Elements,
    pub parts: Vec<Part>,
    /// The whole object surface, sampled, camera frame (metres).
    pub surface: Vec<Vec3>,
}

impl GroundTruth {
    /// The ground truth of the scene `json_path`, `Ok(None)` when it has none.
    pub fn load(json_path: &Path) -> Result<Option<Self>> {
        let shown = json_path.display();
        let text = std::fs::read_to_string(json_path).context(|| format!("cannot read {shown}"))?;
        let file: SceneFile =
            serde_json::from_str(&text).context(|| format!("{shown}: bad ground_truth"))?;
        let Some(truth) = file.ground_truth else {
            return Ok(None);
        };
        let dir = json_path.parent().unwrap_or(Path::new("."));
        let surface = read_surface(&dir.join(&truth.surface))?;
        let parts = truth
            .parts
            .iter()
            .map(|p| p.part(surface.len()))
            .collect::<Result<_>>()?;
        let whole = truth
            .elements
            .elements()
            .context(|| format!("{shown}: ground_truth"))?;
        Ok(Some(Self {
            object: truth.object,
            whole,
            parts,
            surface,
        }))
    }

    /// The surface samples of a part.
    pub fn part_surface(&self, part: &Part) -> &[Vec3] {
        &self.surface[part.surface_range.clone()]
    }

    /// Every element set: the whole object's, then each part's.
    pub fn all_elements(&self) -> impl Iterator<Item = &Elements> {
        std::iter::once(&self.whole).chain(self.parts.iter().map(|p| &p.elements))
    }
}

impl Elements {
    /// Elements written as a `ground_truth` block writes them, without its surface: `{"class":
    /// "axial", "axes": [{"direction": [..], "point": [..], "order": 0}]}` (`planes`, `axes`
    /// and `center` as the class needs): a hand-made hypothesis to score.
    ///
    /// ```
    /// # use sfs_testkit::truth::Elements;
    /// let json = r#"{"class": "plane_reflection", "planes": [{"normal": [1, 0, 0], "offset": 0.1}]}"#;
    /// let symmetry = Elements::from_json(json).unwrap().symmetry().unwrap();
    /// assert_eq!(symmetry.kind().name(), "plane_reflection");
    /// assert!(Elements::from_json(r#"{"class": "cube"}"#).is_err());
    /// ```
    pub fn from_json(text: &str) -> Result<Self> {
        let elements: ElementsJson =
            serde_json::from_str(text).context(|| "bad symmetry elements".to_string())?;
        elements.elements()
    }

    /// The library's symmetry of this class built from these elements (the evaluator maps points
    /// with it); `None` for an asymmetric object or when the listed elements do not make one.
    pub fn symmetry(&self) -> Option<Symmetry> {
        let continuous = || self.axes.iter().find(|a| a.order == 0).map(|a| a.axis);
        Some(match self.class? {
            SymmetryType::PlaneReflection => Symmetry::PlaneReflection(*self.planes.first()?),
            SymmetryType::LineReflection => {
                Symmetry::LineReflection(self.axes.iter().find(|a| a.order % 2 == 0)?.axis)
            }
            SymmetryType::PointReflection => Symmetry::PointReflection(self.center?.to_array()),
            SymmetryType::Spherical => Symmetry::Spherical(self.center?.to_array()),
            SymmetryType::Axial => Symmetry::Axial(continuous()?),
            SymmetryType::DualPlane => {
                let [a, b] = self.orthogonal_planes()?;
                Symmetry::DualPlane([a, b])
            }
            SymmetryType::TriplePlane => Symmetry::TriplePlane(self.orthogonal_planes()?),
            SymmetryType::AxialPlane => {
                let axis = continuous()?;
                let plane = self
                    .planes
                    .iter()
                    .find(|p| p.n().dot(axis.d()).abs() > 0.99)?;
                Symmetry::AxialPlane(axis, *plane)
            }
        })
    }

    /// The first `N` listed planes that are mutually orthogonal (within ~3 deg).
    fn orthogonal_planes<const N: usize>(&self) -> Option<[Plane; N]> {
        let mut chosen: Vec<Plane> = Vec::with_capacity(N);
        for plane in &self.planes {
            if chosen.iter().all(|c| c.n().dot(plane.n()).abs() < 0.05) {
                chosen.push(*plane);
            }
        }
        chosen.truncate(N);
        chosen.try_into().ok()
    }
}

impl ElementsJson {
    fn elements(&self) -> Result<Elements> {
        let class = match self.class.as_str() {
            "none" => None,
            name => Some(
                SymmetryType::from_name(name).ok_or_else(|| format!("unknown class {name:?}"))?,
            ),
        };
        let axes = self.axes.iter().map(|a| {
            Ok(TruthAxis {
                axis: a.axis.axis()?,
                order: a.order,
                implied: a.implied,
            })
        });
        Ok(Elements {
            class,
            planes: self
                .planes
                .iter()
                .map(PlaneJson::plane)
                .collect::<Result<_>>()?,
            axes: axes.collect::<Result<_>>()?,
            center: self.center.map(Vec3::from_array),
        })
    }
}

impl PartJson {
    fn part(&self, samples: usize) -> Result<Part> {
        let [start, end] = self.surface_range;
        if start > end || end > samples {
            return Err(format!(
                "part {:?}: surface_range {start}..{end} outside the {samples} samples",
                self.name
            ));
        }
        let elements = self
            .elements
            .elements()
            .context(|| format!("part {:?}", self.name))?;
        Ok(Part {
            name: self.name.clone(),
            elements,
            surface_range: start..end,
        })
    }
}

/// Little-endian f32 `x, y, z` triples.
fn read_surface(path: &Path) -> Result<Vec<Vec3>> {
    let bytes = std::fs::read(path).context(|| format!("cannot read {}", path.display()))?;
    if bytes.len() % 12 != 0 {
        return Err(format!(
            "{}: {} bytes is not a whole number of xyz triples",
            path.display(),
            bytes.len()
        ));
    }
    let value = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok(bytes
        .chunks_exact(12)
        .map(|t| Vec3::new(value(&t[0..4]), value(&t[4..8]), value(&t[8..12])))
        .collect())
}
