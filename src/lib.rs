#![doc = include_str!("../README.md")]
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_debug_implementations)]

pub mod camera;
pub mod complete;
pub mod component;
pub mod depth;
pub mod engine;
mod error;
#[cfg(feature = "ffi")]
#[allow(unsafe_code)] // the C API: the only `unsafe` in the crate, each block with its SAFETY note
pub mod ffi;
pub mod geometry;
pub mod math;
pub mod prepare;
pub mod scene;
pub mod score;
pub mod search;
pub mod symmetry;
pub mod synth;
pub mod voxel;

pub use camera::Intrinsics;
pub use complete::{CompletedPoint, Provenance};
pub use engine::{Config, DefaultEngine, Engine, Found, RECOMMENDED_BUDGET, Report, Stage, Status};
pub use error::Error;
pub use geometry::{Axis, Plane};
pub use scene::{MAX_DEPTH_SCALE, Scene};
pub use symmetry::{Sampling, Symmetry, SymmetryType, TypeSet};
