//! The compact depth buffer: the minimum depth of each `block x block` pixel block of a
//! rectangle of the image, in at most `CELLS` cells.
//!
//! The same structure serves twice: during segmentation it holds, over the whole image, the
//! nearest *object-candidate* depth of each block; during the search it holds, over a crop around
//! the object, the nearest observed depth of each block — the free-space test of the measurement
//! model. Taking the minimum keeps the test conservative: a point is only called free when it lies
//! in front of everything the camera saw in that block.
//!
//! For the search's free-space test, [`DepthGrid::nearest_around`] gives the nearest reading of
//! a cell's 3 x 3 neighbourhood: where the surface seen at a pixel may lie, given the sensor's
//! lateral noise (a structured-light camera places a depth edge about a pixel off).
//!
//! Cost: [`DepthGrid::reset`] clears `CELLS` values; [`DepthGrid::add`] is O(1) per pixel;
//! [`DepthGrid::lookup`] and [`DepthGrid::locate`] are O(1) (one multiply-add per axis, no
//! division); [`DepthGrid::nearest_around`] reads at most nine cells, or one once
//! [`DepthGrid::spread_into`] has written them all.

use crate::component::AROUND;

/// A rectangle of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rect {
    /// First column.
    pub u0: u16,
    /// First row.
    pub v0: u16,
    /// Columns.
    pub width: u16,
    /// Rows.
    pub height: u16,
}

impl Rect {
    /// Whether pixel `(u, v)` is inside.
    #[inline]
    pub fn contains(&self, u: u16, v: u16) -> bool {
        u.wrapping_sub(self.u0) < self.width && v.wrapping_sub(self.v0) < self.height
    }
}

/// What the depth buffer says about a pixel position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Observed {
    /// Outside the rectangle.
    Outside,
    /// Inside, but no pixel of the block had a reading.
    Unknown,
    /// Nearest raw depth value in the block.
    Depth(u16),
}

/// Minimum depth per pixel block over a rectangle (see the module docs).
#[derive(Clone, Debug)]
pub struct DepthGrid<const CELLS: usize> {
    cells: [u16; CELLS],
    rect: Rect,
    block: u16,
    cols: u16,
    rows: u16,
    inv_block: f32,
}

impl<const CELLS: usize> Default for DepthGrid<CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CELLS: usize> DepthGrid<CELLS> {
    pub const fn new() -> Self {
        Self {
            cells: [0; CELLS],
            rect: Rect {
                u0: 0,
                v0: 0,
                width: 0,
                height: 0,
            },
            block: 1,
            cols: 0,
            rows: 0,
            inv_block: 1.0,
        }
    }

    /// Cover `rect` with the smallest block size whose grid fits `CELLS`; clear every cell.
    pub fn reset(&mut self, rect: Rect) {
        let mut block: u32 = 1;
        let cells = |b: u32| (rect.width as u32).div_ceil(b) * (rect.height as u32).div_ceil(b);
        while cells(block) as usize > CELLS {
            block += 1;
        }
        self.rect = rect;
        self.block = block as u16;
        self.inv_block = 1.0 / block as f32;
        self.cols = (rect.width as u32).div_ceil(block) as u16;
        self.rows = (rect.height as u32).div_ceil(block) as u16;
        self.cells.fill(0);
    }

    /// Block edge, pixels.
    pub fn block(&self) -> u16 {
        self.block
    }

    /// Block columns in use.
    pub fn cols(&self) -> u16 {
        self.cols
    }

    /// Block rows in use.
    pub fn rows(&self) -> u16 {
        self.rows
    }

    /// Number of cells in use.
    pub fn len(&self) -> usize {
        self.cols as usize * self.rows as usize
    }

    /// Cell index of pixel `(u, v)`, which must lie inside the rectangle.
    #[inline]
    pub fn cell_of(&self, u: u16, v: u16) -> usize {
        let cu = (u - self.rect.u0) / self.block;
        let cv = (v - self.rect.v0) / self.block;
        cv as usize * self.cols as usize + cu as usize
    }

    /// Record a reading `raw` (non-zero) at pixel `(u, v)`; pixels outside are ignored.
    #[inline]
    pub fn add(&mut self, u: u16, v: u16, raw: u16) {
        if raw != 0 && self.rect.contains(u, v) {
            let i = self.cell_of(u, v);
            let cell = &mut self.cells[i];
            if *cell == 0 || raw < *cell {
                *cell = raw;
            }
        }
    }

    /// Raw value of cell `i` (0 = no reading).
    #[inline]
    pub fn get(&self, i: usize) -> u16 {
        self.cells.get(i).copied().unwrap_or(0)
    }

    /// What was observed at continuous pixel coordinates `(u, v)` (pixel centres at integers).
    #[inline]
    pub fn lookup(&self, u: f32, v: f32) -> Observed {
        self.locate(u, v).map_or(Observed::Outside, |c| self.at(c))
    }

    /// The column and row of the cell holding continuous pixel coordinates `(u, v)`, if inside
    /// the rectangle.
    #[inline]
    pub fn locate(&self, u: f32, v: f32) -> Option<(usize, usize)> {
        let cu = (u + 0.5 - self.rect.u0 as f32) * self.inv_block;
        let cv = (v + 0.5 - self.rect.v0 as f32) * self.inv_block;
        // The comparisons also reject NaN.
        (cu >= 0.0 && cv >= 0.0 && cu < self.cols as f32 && cv < self.rows as f32)
            .then_some((cu as usize, cv as usize))
    }

    /// What was observed in the cell at `(column, row)` (from [`DepthGrid::locate`]).
    #[inline]
    pub fn at(&self, cell: (usize, usize)) -> Observed {
        observed(self.cells[self.index(cell)])
    }

    /// The nearest reading among the cell at `(column, row)` (from [`DepthGrid::locate`]) and
    /// its 8 neighbours inside the grid; `Unknown` if any of them has none (the camera may have
    /// seen nothing there).
    #[inline]
    pub fn nearest_around(&self, cell: (usize, usize)) -> Observed {
        observed(self.nearest_raw(cell))
    }

    /// [`DepthGrid::nearest_around`] as a raw value (0: unknown).
    #[inline]
    fn nearest_raw(&self, (c, r): (usize, usize)) -> u16 {
        let (cols, rows) = (self.cols as usize, self.rows as usize);
        // A zero (no reading) is the least value: the minimum is 0 iff one of them is unknown.
        let row = |y: usize| {
            let (first, last) = (
                y * cols + c.saturating_sub(1),
                y * cols + (c + 1).min(cols - 1),
            );
            self.cells
                .get(first..=last)
                .map_or(0, |s| s.iter().fold(u16::MAX, |m, &x| m.min(x)))
        };
        let mut nearest = row(r);
        if r > 0 {
            nearest = nearest.min(row(r - 1));
        }
        if r + 1 < rows {
            nearest = nearest.min(row(r + 1));
        }
        nearest
    }

    /// The index of the cell at `(column, row)` (from [`DepthGrid::locate`]).
    #[inline]
    pub fn index(&self, (c, r): (usize, usize)) -> usize {
        r * self.cols as usize + c
    }

    /// Write [`DepthGrid::nearest_around`] of cells `first .. first + count` into `around`
    /// (by cell index; cells beyond the grid or `around` are skipped), for
    /// [`DepthGrid::nearest_around_in`]. Cost: at most nine reads per cell.
    pub fn spread_into(&self, around: &mut [u16], first: usize, count: usize) {
        let end = first
            .saturating_add(count)
            .min(self.len())
            .min(around.len());
        for (i, slot) in around.iter_mut().enumerate().take(end).skip(first) {
            let (c, r) = self.cell_position(i);
            *slot = self.nearest_raw((c as usize, r as usize));
        }
    }

    /// [`DepthGrid::nearest_around`] of `cell`, read from `around` when it holds the whole grid
    /// ([`DepthGrid::spread_into`] over every cell), else computed.
    #[inline]
    pub fn nearest_around_in(&self, around: &[u16], cell: (usize, usize)) -> Observed {
        match around.get(self.index(cell)) {
            Some(&raw) if around.len() >= self.len() => observed(raw),
            _ => self.nearest_around(cell),
        }
    }

    /// Column and row of cell `i`.
    #[inline]
    pub fn cell_position(&self, i: usize) -> (u16, u16) {
        let cols = self.cols.max(1) as usize;
        ((i % cols) as u16, (i / cols) as u16)
    }

    /// The 4-neighbours of cell `i` inside the grid: above, left, right, below (one division,
    /// for the cell's column and row).
    #[inline]
    pub fn four_neighbours(&self, i: usize) -> [Option<usize>; 4] {
        let (c, r) = self.cell_position(i);
        let (cols, rows) = (self.cols as usize, self.rows);
        [
            (r > 0).then(|| i - cols),
            (c > 0).then(|| i - 1),
            ((c as usize) + 1 < cols).then(|| i + 1),
            (r + 1 < rows).then(|| i + cols),
        ]
    }

    /// Neighbour `k` ([`AROUND`]`[k]`) of cell `i` when it shares a side with it (not a
    /// diagonal one) and is inside the grid.
    pub fn side_neighbour(&self, i: usize, k: usize) -> Option<usize> {
        let (dx, dy) = AROUND[k];
        if dx != 0 && dy != 0 {
            return None;
        }
        self.neighbour(i, k)
    }

    /// Neighbour `k` ([`AROUND`]`[k]`) of cell `i`, if it is inside the grid.
    pub fn neighbour(&self, i: usize, k: usize) -> Option<usize> {
        let cols = self.cols as usize;
        let (x, y) = (i % cols.max(1), i / cols.max(1));
        let (dx, dy) = AROUND[k];
        let (nx, ny) = (
            x.checked_add_signed(dx as isize)?,
            y.checked_add_signed(dy as isize)?,
        );
        (nx < cols && ny < self.rows as usize).then_some(ny * cols + nx)
    }
}

/// A cell's raw value as an observation.
#[inline]
fn observed(raw: u16) -> Observed {
    match raw {
        0 => Observed::Unknown,
        raw => Observed::Depth(raw),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_size_fits_capacity() {
        let mut g = DepthGrid::<100>::new();
        g.reset(Rect {
            u0: 0,
            v0: 0,
            width: 320,
            height: 240,
        });
        assert!(g.len() <= 100);
        assert_eq!(g.block(), 30);
        g.reset(Rect {
            u0: 10,
            v0: 20,
            width: 10,
            height: 10,
        });
        assert_eq!((g.block(), g.cols(), g.rows()), (1, 10, 10));
    }

    #[test]
    fn keeps_the_nearest_reading() {
        let mut g = DepthGrid::<16>::new();
        g.reset(Rect {
            u0: 4,
            v0: 4,
            width: 8,
            height: 8,
        });
        assert_eq!(g.block(), 2);
        g.add(4, 4, 900);
        g.add(5, 5, 800);
        g.add(5, 4, 0);
        g.add(0, 0, 10);
        assert_eq!(g.lookup(4.0, 4.0), Observed::Depth(800));
        assert_eq!(g.lookup(6.0, 4.0), Observed::Unknown);
        assert_eq!(g.lookup(3.0, 4.0), Observed::Outside);
        assert_eq!(g.lookup(f32::NAN, 4.0), Observed::Outside);
        assert_eq!(g.lookup(12.0, 4.0), Observed::Outside);
    }

    /// A 4 x 4 pixel grid of one-pixel cells, empty.
    fn four_by_four() -> DepthGrid<16> {
        let mut g = DepthGrid::new();
        g.reset(Rect {
            u0: 0,
            v0: 0,
            width: 4,
            height: 4,
        });
        g
    }

    #[test]
    fn finds_the_nearest_reading_of_each_neighbourhood() {
        let mut g = four_by_four();
        (0..16u16).for_each(|i| g.add(i % 4, i / 4, 1000 - i));
        let around =
            |g: &DepthGrid<16>, u, v| g.locate(u, v).map(|c| (g.at(c), g.nearest_around(c)));
        // Corner: itself and three neighbours, the nearest the diagonal one.
        let corner = around(&g, 0.0, 0.0);
        assert_eq!(corner, Some((Observed::Depth(1000), Observed::Depth(995))));
        // All nine read (pixel 15, 985, is beyond them).
        let inner = around(&g, 1.0, 1.0);
        assert_eq!(inner, Some((Observed::Depth(995), Observed::Depth(990))));
        assert_eq!(around(&g, 4.0, 0.0), None);
        // A neighbour without a reading makes the neighbourhood unknown.
        g.cells[15] = 0;
        let beside = around(&g, 2.0, 2.0);
        assert_eq!(beside, Some((Observed::Depth(990), Observed::Unknown)));
    }

    #[test]
    fn spread_minima_are_the_computed_ones() {
        let mut g = DepthGrid::<64>::new();
        g.reset(Rect {
            u0: 0,
            v0: 0,
            width: 7,
            height: 5,
        });
        // Readings in an irregular pattern, a few missing.
        (0..35u16).for_each(|i| g.add(i % 7, i / 7, (i * 37 % 11) * 100 * u16::from(i % 9 != 4)));
        let mut around = [0u16; 35];
        g.spread_into(&mut around, 0, 20);
        g.spread_into(&mut around, 20, 100);
        for i in 0..35 {
            let cell = (i % 7, i / 7);
            assert_eq!(
                g.nearest_around_in(&around, cell),
                g.nearest_around(cell),
                "cell {i}"
            );
        }
        // Too short to hold the grid: computed.
        let short = [1u16; 10];
        assert_eq!(
            g.nearest_around_in(&short, (0, 0)),
            g.nearest_around((0, 0))
        );
    }

    #[test]
    fn neighbours_stay_inside() {
        let g = four_by_four();
        let count = |i| (0..8).filter_map(|k| g.neighbour(i, k)).count();
        assert_eq!(count(0), 3);
        assert_eq!(count(5), 8);
        assert_eq!(count(15), 3);
    }
}
