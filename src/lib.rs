#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_debug_implementations)]

pub mod camera;
pub mod complete;
pub mod component;
pub mod depth;
pub mod engine;
mod error;
pub mod geometry;
pub mod math;
pub mod prepare;
pub mod scene;
pub mod score;
pub mod search;
pub mod symmetry;
pub mod voxel;

pub use camera::Intrinsics;
pub use complete::{CompletedPoint, Provenance};
pub use engine::{Config, DefaultEngine, Engine, Found, RECOMMENDED_BUDGET, Report, Stage, Status};
pub use error::Error;
pub use geometry::{Axis, Plane};
pub use scene::{MAX_DEPTH_SCALE, Scene};
pub use symmetry::{Sampling, Symmetry, SymmetryType, TypeSet};
