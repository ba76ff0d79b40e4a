//! Work units: the one measure every stage is budgeted in, what a unit buys in each stage, and
//! the meter through which a poll's budget is spent.
//!
//! **Protocol.** Every stage of the engine (preparation, scoring, growth, completion) advances
//! the same way: `advance(&mut self, <what it reads>, meter: &mut Meter) -> Poll<Output>`. It
//! spends at most what is left on the meter (at least one unit when any is left and it has
//! work: every poll makes progress), keeps its position in its own state, and returns
//! `Poll::Ready(output)` once it is over, the output handed forward as a value, or
//! `Poll::Pending`: call again, in this poll while the meter has units left (a stage may stop
//! at a step boundary before the meter is spent). Nothing in a stage depends on where a poll
//! ends, so the results are bit-identical however the work is sliced.
//!
//! **Weights.** A unit is one transformed point scored: one 3x3 transform, up to eight hash
//! probes and, unless the match already beats occlusion, a division and a depth lookup. The other
//! steps are weighted below to cost about the same, as measured on a Cortex-M4F by
//! `ci/firmware.sh` (instructions per unit in each stage, and no poll of
//! [`crate::RECOMMENDED_BUDGET`] units over 100 000 instructions): the figures of the last run
//! are in `docs/figures.md`.

pub(crate) use core::task::Poll;

/// Pixels of a preparation pass per unit (a depth read, a compare, sometimes an unprojection).
pub(crate) const PIXELS_PER_UNIT: u32 = 8;
/// Depth cells whose neighbourhood minimum is written per unit (one division for the cell's
/// column and row, at most nine reads and compares: measured on the Cortex-M4F, a unit of two
/// costs about the preparation's average unit).
pub(crate) const CELLS_SPREAD_PER_UNIT: u32 = 2;
/// Sampling-lattice points per unit (nearly all are object pixels, each unprojected and stored:
/// dearer than the average pixel of a full pass).
pub(crate) const LATTICE_POINTS_PER_UNIT: u32 = 4;
/// ... and with `PrepareConfig::drop_edge_pixels`, each also checked against its four
/// neighbours for a depth jump (measured on the M4F: at 3 a poll of them came within 5 % of the
/// per-poll bound, at 2 it stays 10 % under it).
pub(crate) const LATTICE_POINTS_WITH_EDGES_PER_UNIT: u32 = 2;
/// Pixels of the sampling's lattice lines per unit, when the outline is sampled (`prepare`,
/// step 3b): each is tested as an object pixel, and one off a lattice point also its two
/// neighbours along its line (whether it ends a run: the outline); a kept one is unprojected
/// and stored, and with `PrepareConfig::drop_edge_pixels` checked against its four neighbours
/// for a depth jump. At most three tests a pixel, each about a third of a unit
/// (`OBJECT_AREA_PIXELS_PER_UNIT`), and the edge check on the few that are kept.
pub(crate) const LINE_PIXELS_PER_UNIT: u32 = 1;
/// RANSAC residuals per unit (a dot product and a compare each).
pub(crate) const SAMPLES_PER_UNIT: u32 = 16;
/// Depth blocks scanned for the next seed of a segmentation component per unit (a flag test
/// each).
pub(crate) const BLOCK_SEEDS_PER_UNIT: u32 = 32;
/// Depth blocks of a distance-transform pass per unit (four neighbours' flags read, a minimum
/// and a store each: about a crease block's reads, a quarter of its arithmetic).
pub(crate) const DISTANCE_CELLS_PER_UNIT: u32 = 8;
/// Pixels of the segmentation's candidate pass per unit: a pixel above `min_height` is compared
/// with three σ of the sensor's noise at its depth, and a candidate pixel is also checked
/// against its four neighbours for a depth jump and its block's core (measured on the M4F at
/// the recommended budget: at 5 the largest preparing poll takes 88 860 instructions; at 6,
/// 88 355, but the search's polls then fall so that one takes 99 375, too near the bound).
pub(crate) const CANDIDATE_PIXELS_PER_UNIT: u32 = 5;
/// Pixels of the segmented object's area counted per unit: nearly all of them are the object's
/// or beside it, and each costs its block's flags, its point and its height (measured on the
/// Cortex-M4F: about 2.5 times a pixel of a whole-image pass, most of which are rejected on
/// their reading or height); one beside the object, or behind the sample of its block where
/// that block straddles a depth discontinuity, also up to five depth tests against block
/// samples (`prepare::on_block_surface`; the largest preparing poll, `docs/figures.md`).
pub(crate) const OBJECT_AREA_PIXELS_PER_UNIT: u32 = 3;
/// Depth blocks tested for a concave crease per unit (four lines through the block, up to
/// eight neighbours' depths read each).
pub(crate) const CREASE_BLOCKS_PER_UNIT: u32 = 2;
/// Depth blocks tested per unit for touching the object across a concave crease, when looking
/// for a part that hangs from the object (`prepare::Hanging`): up to four neighbours' and, for
/// a crease block among them, its four neighbours' flags and depths read, each with a depth
/// step test: about a crease block's reads.
pub(crate) const HANGING_SEEDS_PER_UNIT: u32 = 2;
/// Lattice points scanned for the next seed of a domain component per unit (a flag test and an
/// index load each).
pub(crate) const POINT_SEEDS_PER_UNIT: u32 = 16;
/// Neighbours of a node examined per unit by a component search (each a lattice or block lookup;
/// a point's is a binary search in the raster-ordered points; a block's also reads the two
/// blocks beyond the pair for a crease between them, found by index arithmetic (a remainder
/// for a step along a row): with a grid lookup for each, two divisions apiece, the
/// segmentation's polls became the preparing stage's largest on the Cortex-M4F; this way its
/// largest poll is the one it had before the crease test).
pub(crate) const NEIGHBOURS_PER_UNIT: u8 = 4;
/// Points marked (a store each) per unit when a domain growth starts, and points gathered into
/// the next domain per unit.
pub(crate) const MARKS_PER_UNIT: usize = 16;
/// Units per transformed point of a refinement round (matched to its nearest visible point and
/// added to its element's moments): on the Cortex-M4F one costs about twice a scored point
/// (1 058 instructions against 455, from the searching stage's totals with and without
/// refinement).
pub(crate) const UNITS_PER_MATCH: u32 = 2;
/// Extra units per matched point of a mirror plane's refinement round, for the surface normal at
/// the match: four lattice neighbours (two of them binary searches in the raster-ordered points,
/// as [`NEIGHBOURS_PER_UNIT`] weighs them four a unit), a cross product and a normalisation.
pub(crate) const UNITS_PER_NORMAL: u32 = 1;
/// Hash slots read beyond the first [`crate::voxel::SPARSE_PROBES`] of a completion test's
/// nearest-point lookup per extra unit. With it a completion unit costs about what a search unit
/// does; charging a test one unit whatever it probed had let a poll near the voxel table's load
/// limit reach 115 800 instructions.
pub(crate) const PROBES_PER_UNIT: u32 = 64;
/// Voxel-hash slots emptied per unit when the completion rebuilds the hash for its dense pass:
/// a 4-byte store each, against the few hundred instructions of a unit (at most two
/// instructions a slot: a unit's share with room to spare).
pub(crate) const SLOTS_CLEARED_PER_UNIT: u32 = 256;

/// One poll's budget, spent by the stages in turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Meter {
    left: u32,
}

impl Meter {
    /// A meter holding `budget` units.
    pub(crate) const fn new(budget: u32) -> Self {
        Self { left: budget }
    }

    /// Units left.
    pub(crate) const fn left(&self) -> u32 {
        self.left
    }

    /// Whether any unit is left.
    pub(crate) const fn has_left(&self) -> bool {
        self.left > 0
    }

    /// Spend `units` (at most what is left: a stage never overspends).
    pub(crate) fn spend(&mut self, units: u32) {
        debug_assert!(
            units <= self.left,
            "{units} units spent, {} left",
            self.left
        );
        self.left = self.left.saturating_sub(units);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_meter_spends_down_to_zero() {
        let mut meter = Meter::new(5);
        assert!(meter.has_left());
        meter.spend(3);
        assert_eq!(meter.left(), 2);
        meter.spend(2);
        assert!(!meter.has_left());
    }
}
