#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_debug_implementations)]
#![warn(missing_docs)]

pub(crate) mod camera;
pub(crate) mod complete;
pub(crate) mod component;
pub(crate) mod config;
pub(crate) mod depth;
pub(crate) mod engine;
mod error;
pub(crate) mod geometry;
pub mod math;
pub(crate) mod prepare;
pub(crate) mod refine;
pub(crate) mod scene;
pub(crate) mod score;
pub(crate) mod search;
pub mod symmetry;
pub(crate) mod voxel;
pub(crate) mod work;

pub use camera::Intrinsics;
pub use complete::{CompletedPoint, Provenance};
pub use config::{
    Config, DomainConfig, GridConfig, ModelConfig, PrepareConfig, SearchConfig, SensorConfig,
};
pub use depth::Rect;
pub use engine::{
    DefaultEngine, Engine, Found, MAX_SYMMETRIES, RECOMMENDED_BUDGET, Report, Stage, Status,
};
pub use error::Error;
pub use geometry::{Axis, Plane};
pub use prepare::Segmentation;
pub use scene::{MAX_DEPTH_SCALE, Scene, Target};
pub use score::{Cause, ElementEvidence, Explanation, ImageCost};
pub use symmetry::{Sampling, Symmetry, SymmetryType, TypeSet};
