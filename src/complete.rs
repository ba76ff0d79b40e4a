//! Completion: the visible points plus the points each symmetry predicts in occluded space.

/// Where a completed point comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Provenance {
    /// A visible (sampled) point of the object.
    Visible = 0,
    /// A point a symmetry predicts in space the camera could not see.
    Generated = 1,
}

/// One point of the completed object, in caller storage.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub struct CompletedPoint {
    /// Camera frame, metres.
    pub position: [f32; 3],
    /// How plausible the point is, in `[0, 1]`: 1 for visible points; for generated points the
    /// support of the symmetry that made them (see [`crate::score`]).
    pub plausibility: f32,
    pub provenance: Provenance,
    /// Index into [`crate::Report::symmetries`] of the symmetry whose domain holds the point
    /// (visible) or that generated it; `u8::MAX` for a visible point no symmetry explains.
    pub symmetry: u8,
}

impl CompletedPoint {
    pub const ZERO: Self =
        Self { position: [0.0; 3], plausibility: 0.0, provenance: Provenance::Visible, symmetry: u8::MAX };
}
