//! The result file (`SCENES.md`, format `shape-from-symmetry/result-1`).

use serde::Serialize;
use shape_from_symmetry::{Found, Segmentation};

use super::json::{AxisJson, PlaneJson};
use super::search::Outcome;

pub const RESULT_FORMAT: &str = "shape-from-symmetry/result-1";

#[derive(Debug, Serialize)]
pub struct ResultJson {
    pub format: &'static str,
    /// `"symmetric"` or `"no_symmetry"`.
    pub status: &'static str,
    /// Strongest first, one per domain.
    pub symmetries: Vec<SymmetryJson>,
    /// Extension: the whole object's runner-up (`Report::runner_up`), when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub runner_up: Option<SymmetryJson>,
    /// Extension: how the engine chose the object (`Report::segmentation`), when it segmented
    /// it (no mask given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub segmentation: Option<SegmentationJson>,
    pub points: PointsJson,
    pub work: WorkJson,
}

#[derive(Debug, Serialize)]
pub struct SymmetryJson {
    #[serde(rename = "type")]
    pub kind: &'static str,
    pub score: f32,
    /// Extension: `Found::confidence`.
    pub confidence: f32,
    pub domain_points: u32,
    pub planes: Vec<PlaneJson>,
    pub axes: Vec<AxisJson>,
    pub center: Option<[f32; 3]>,
}

/// Extension: the object's segmentation.
#[derive(Debug, Serialize)]
pub struct SegmentationJson {
    /// Candidate object regions.
    pub candidates: u16,
    /// The chosen candidate's index (raster order of their first block, from 0); `null` when
    /// the target named a region of implausible size.
    pub chosen: Option<u16>,
    /// The object's pixel box: `[u0, v0, width, height]`.
    pub object_box: [u16; 4],
}

impl From<&Segmentation> for SegmentationJson {
    fn from(s: &Segmentation) -> Self {
        let b = s.object_box;
        Self {
            candidates: s.candidates,
            chosen: s.chosen,
            object_box: [b.u0, b.v0, b.width, b.height],
        }
    }
}

#[derive(Debug, Serialize)]
pub struct PointsJson {
    pub visible: u32,
    pub generated: u32,
    /// Extension: points left out because the output storage was full (0: the output is whole).
    pub dropped: u32,
    /// Extension: object pixels with a depth reading, and the points sampled from them.
    pub object_pixels: u32,
    pub sampled: u32,
}

#[derive(Debug, Serialize)]
pub struct WorkJson {
    pub polls: u32,
    pub work_units: u64,
    /// Milliseconds, rounded to the microsecond.
    pub wall_ms: f64,
}

impl ResultJson {
    pub fn new(outcome: &Outcome) -> Self {
        let report = &outcome.report;
        let status = if report.symmetries.is_empty() {
            "no_symmetry"
        } else {
            "symmetric"
        };
        Self {
            format: RESULT_FORMAT,
            status,
            symmetries: report.symmetries.iter().map(SymmetryJson::new).collect(),
            runner_up: report.runner_up.as_ref().map(SymmetryJson::new),
            segmentation: report.segmentation.as_ref().map(SegmentationJson::from),
            points: PointsJson {
                visible: report.points_visible,
                generated: report.points_generated,
                dropped: report.points_dropped,
                object_pixels: report.object_pixels,
                sampled: report.sampled_points,
            },
            work: WorkJson {
                polls: report.polls,
                work_units: report.work_units,
                wall_ms: (outcome.wall_ms * 1e3).round() / 1e3,
            },
        }
    }
}

impl SymmetryJson {
    pub fn new(found: &Found) -> Self {
        let s = &found.symmetry;
        Self {
            kind: s.kind().name(),
            score: found.score,
            confidence: found.confidence,
            domain_points: found.domain_points,
            planes: s.planes().iter().map(PlaneJson::from).collect(),
            axes: s.axis().into_iter().map(AxisJson::from).collect(),
            center: s.center(),
        }
    }
}
