//! The completed object as an ASCII PLY point cloud: position, colour (see [`super::colour`]),
//! provenance (0 visible, 1 generated), the index of the symmetry that explains or made the point
//! (255: none) and its plausibility.

use std::fmt::Write as _;
use std::path::Path;

use shape_from_symmetry::CompletedPoint;

use super::{Context, Result, colour};

pub fn write(path: &Path, points: &[CompletedPoint], domains: usize) -> Result<()> {
    std::fs::write(path, encode(points, domains))
        .context(|| format!("cannot write {}", path.display()))
}

fn encode(points: &[CompletedPoint], domains: usize) -> String {
    let mut text = format!(
        "ply\nformat ascii 1.0\ncomment shape-from-symmetry completion, camera frame, metres\n\
         comment provenance: 0 visible, 1 generated; symmetry: index in the result, 255 none\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar provenance\n\
         property uchar symmetry\nproperty float plausibility\nend_header\n",
        points.len()
    );
    for p in points {
        let [x, y, z] = p.position;
        let [r, g, b] = colour::of(p, domains);
        let (provenance, symmetry, plausibility) = (p.provenance as u8, p.symmetry, p.plausibility);
        // Writing to a String cannot fail.
        let _ = writeln!(
            text,
            "{x} {y} {z} {r} {g} {b} {provenance} {symmetry} {plausibility}"
        );
    }
    text
}
