//! The Python package `shape_from_symmetry`: one function, `complete`, that runs the library's
//! search on a depth image given as a numpy array and returns the symmetries found and the
//! completed points as numpy arrays. Built by maturin (`pip install ./python`); tested by
//! `python/tests` (ci/python.sh).

#![deny(unsafe_code)]

mod input;
mod output;
mod search;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use input::Arguments;
use output::{Completion, FoundSymmetry, ObjectSegmentation};
use search::Failure;

/// Find an object's symmetries in one depth image and predict its hidden back side
/// (Thrun & Wegbreit, ICCV 2005).
#[pymodule]
#[pyo3(name = "shape_from_symmetry")]
fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(complete, m)?)?;
    m.add_class::<Completion>()?;
    m.add_class::<FoundSymmetry>()?;
    m.add_class::<ObjectSegmentation>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))
}

/// Find the symmetries of the object in a depth image and complete its hidden side.
///
/// All geometry is in the camera frame, metres: x right, y down, z forward.
///
/// Args:
///     depth: (H, W) numpy array of uint16, depth along the optical axis in units of
///         depth_scale; 0 = no reading.
///     depth_scale: metres per depth unit (0.001 for millimetres), at most 1.
///     intrinsics: a mapping with fx, fy, cx, cy in pixels (as a scene file's; width and
///         height, if present, must be W and H), or a 3x3 matrix
///         K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]].
///     mask: optional (H, W) array, nonzero = object pixel. Without it the object is
///         segmented: support plane removed, the candidate region of plausible size at the
///         optical axis kept, or else the one nearest it (or the one target or roi names).
///     table: optional support plane (nx, ny, nz, d): n · X + d = 0, n pointing away from
///         the table toward the camera's side. Without it the plane is fitted.
///     types: optional list of the symmetry types wanted: "plane_reflection",
///         "line_reflection", "point_reflection", "axial", "spherical", "dual_plane",
///         "triple_plane", "axial_plane". Default: all eight.
///     parts: search part symmetries too (one symmetry per domain of the object).
///     budget: work units per poll (default 50000, as the command-line tool); the result
///         does not depend on it.
///     target: optional pixel (u, v) on the object (column, row): without a mask, the object
///         is the candidate region holding it.
///     roi: optional region of interest (x, y, w, h) in pixels: without a mask, the object is
///         the candidate region with the most of its pixels in it. Not with target.
///     one_object: nothing touches the object: without a mask, a part that meets its body at
///         a concave crease or a neck (a handle, a bottle's neck) stays with it instead of
///         being parted from it as a touching object is (PrepareConfig::with_one_object).
///
/// Returns:
///     Completion: .symmetries (strongest first; each with type, planes, axis, centre,
///     score -- lower is better --, confidence in [0, 1] and domain_points), .runner_up
///     (another reading of the whole object, or None), .points ((N, 3) float32),
///     .provenance ((N,) uint8: 0 visible, 1 generated), .symmetry ((N,) uint8: index
///     into .symmetries, 255 = none), .plausibility ((N,) float32), .segmentation (without a
///     mask: candidates, chosen -- an index or None -- and object_box (x, y, w, h); else None),
///     and the counts points_dropped, work_units, polls.
///
/// Raises:
///     ValueError: for any unusable input (wrong dtype, shape or type, non-finite numbers,
///         unknown type names, both target and roi), with the library's message for what it
///         rejects (no valid depth, no object, a target outside the image or on no object,
///         too few points...).
///     RuntimeError: the search thread could not start.
///
/// The search runs without the GIL, on a thread of its own.
#[pyfunction]
#[pyo3(
    signature = (
        depth, depth_scale, intrinsics, mask=None, table=None, types=None, parts=None,
        budget=None, target=None, roi=None, one_object=None
    ),
    text_signature = "(depth, depth_scale, intrinsics, mask=None, table=None, types=None, \
                      parts=False, budget=None, target=None, roi=None, one_object=False)"
)]
#[expect(
    clippy::too_many_arguments,
    reason = "the Python signature's eleven arguments"
)]
fn complete(
    py: Python<'_>,
    depth: &Bound<'_, PyAny>,
    depth_scale: &Bound<'_, PyAny>,
    intrinsics: &Bound<'_, PyAny>,
    mask: Option<&Bound<'_, PyAny>>,
    table: Option<&Bound<'_, PyAny>>,
    types: Option<&Bound<'_, PyAny>>,
    parts: Option<&Bound<'_, PyAny>>,
    budget: Option<&Bound<'_, PyAny>>,
    target: Option<&Bound<'_, PyAny>>,
    roi: Option<&Bound<'_, PyAny>>,
    one_object: Option<&Bound<'_, PyAny>>,
) -> PyResult<Completion> {
    let arguments = Arguments {
        depth,
        depth_scale,
        intrinsics,
        mask,
        table,
        types,
        parts,
        budget,
        target,
        roi,
        one_object,
    };
    let input = arguments.parse()?;
    let output = py.detach(|| search::run(&input)).map_err(python_error)?;
    Ok(Completion::new(py, &output))
}

/// The library's rejection as a `ValueError` with its message; a thread failure as a
/// `RuntimeError`.
fn python_error(failure: Failure) -> PyErr {
    match failure {
        Failure::Rejected(error) => PyValueError::new_err(error.to_string()),
        Failure::Thread(message) => PyRuntimeError::new_err(message),
    }
}
