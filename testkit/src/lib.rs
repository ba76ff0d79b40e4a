//! The test kit of shape-from-symmetry: what the examples, tests, benchmarks and fuzz harnesses
//! share, and nothing the robot runs. Never published.
//!
//! - Always (`no_std`): [`scene_file`], the committed built-in scene; [`harness`], the poll loop
//!   both firmware builds run and the digest of every bit of a result.
//! - With the feature `std`: `synth`, the Kinect-like renderer of synthetic
//!   scenes; `clutter`, several objects touching on a table in a room and their true masks;
//!   `scene` and `truth`, scene files of `SCENES.md` and their ground truth; `raw` and
//!   `camera_info`, raw sensor input (a depth PNG, intrinsics, a ROS camera info file); `metrics`,
//!   `degrade`, `nearest`: accuracy against ground truth; `correlation`: how a depth
//!   camera's noise correlates between neighbouring pixels; `gaps`: the readings missing beside
//!   its depth jumps; `baseline`: the one-plane baseline the
//!   search is measured against; `parts`: part symmetries on synthetic
//!   objects; `search`, `stages`, `scaling`: timed runs; `picture`, `ply`, `result`, `json`,
//!   `colour`: what the tools write; `fuzz`: the fuzz targets' harnesses, also replayed by
//!   `cargo test`.
#![cfg_attr(not(feature = "std"), no_std)]

pub mod harness;
pub mod scene_file;

#[cfg(feature = "std")]
pub mod baseline;
#[cfg(feature = "std")]
pub mod camera_info;
#[cfg(feature = "std")]
pub mod clutter;
#[cfg(feature = "std")]
pub mod colour;
#[cfg(feature = "std")]
pub mod correlation;
#[cfg(feature = "std")]
pub mod degrade;
#[cfg(feature = "std")]
pub mod fuzz;
#[cfg(feature = "std")]
pub mod gaps;
#[cfg(feature = "std")]
pub mod generate;
#[cfg(feature = "std")]
pub mod json;
#[cfg(feature = "std")]
pub mod metrics;
#[cfg(feature = "std")]
pub mod nearest;
#[cfg(feature = "std")]
pub mod overlay;
#[cfg(feature = "std")]
pub mod parts;
#[cfg(feature = "std")]
pub mod picture;
#[cfg(feature = "std")]
pub mod ply;
#[cfg(feature = "std")]
pub mod raw;
#[cfg(feature = "std")]
pub mod result;
#[cfg(feature = "std")]
pub mod scaling;
#[cfg(feature = "std")]
pub mod scene;
#[cfg(feature = "std")]
pub mod search;
#[cfg(feature = "std")]
pub mod stages;
#[cfg(feature = "std")]
pub mod synth;
#[cfg(feature = "std")]
pub mod truth;

#[cfg(feature = "std")]
pub mod tool;
#[cfg(feature = "std")]
pub use tool::{Context, Result, run_cli, write_json};
