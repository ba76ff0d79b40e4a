//! Voxel-hashed occupancy: a fixed-capacity open-addressing hash from voxel to the index of the
//! first point that fell in it.
//!
//! It answers the measurement model's question "how far is the nearest visible point?" with at
//! most eight probes, and deduplicates completed points. Keys pack three 10-bit voxel coordinates
//! relative to an origin (the object's centre), so the map spans ±512 voxels per axis; points
//! beyond that are out of range, never wrapped onto other voxels.
//!
//! **Levels.** Besides its voxel, every visible point is filed in the voxels of
//! [`LEVELS`]` - 1` coarser grids (each 4 times coarser), represented there by the point nearest
//! the voxel's centre; a level's keys carry its number in their two top bits, so all levels share
//! one table. The search scores coarse hypotheses at a wide match σ: it asks the coarsest level
//! whose voxels are no wider than σ, so a near miss still counts as one.
//!
//! Cost: insert and lookup are O(1) expected (linear probing, load kept at or below 3/4; a probe
//! sequence is bounded by the capacity in the worst case). [`VoxelMap::nearest`] probes the 2x2x2
//! block of voxels around the query, so it is exact for any point within half a voxel (of the
//! level asked) and an upper bound beyond.

use crate::math::Vec3;

/// The key of an empty slot (tag 3, every coordinate bit set: no voxel's key).
const EMPTY: u32 = u32::MAX;
/// Bits of each voxel coordinate: three and the level's two-bit tag fill a 32-bit key.
const COORD_BITS: u32 = 10;
const COORD_RANGE: i32 = 1 << COORD_BITS;
/// Value of a voxel that holds a generated (completed) point rather than a visible one.
pub const GENERATED: u16 = u16::MAX;
/// Grid levels: level `k` has voxels `4^k` times the edge of level 0 (tags 0 to 2 in the key's
/// top bits; tag 3 with all coordinates set is the empty key).
pub const LEVELS: u8 = 3;
const LEVEL_SHIFT: u32 = 3 * COORD_BITS;

/// What an insertion did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insert {
    /// The voxel was empty and now holds the value.
    New,
    /// The voxel was taken; it keeps its value.
    Taken(u16),
    /// The map is at its load limit.
    Full,
    /// The point lies outside the span of the map.
    OutOfRange,
}

/// Fixed-capacity voxel hash with `SLOTS` slots (a power of two).
#[derive(Clone, Debug)]
pub struct VoxelMap<const SLOTS: usize> {
    keys: [u32; SLOTS],
    values: [u16; SLOTS],
    len: usize,
    origin: Vec3,
    inv_size: f32,
}

impl<const SLOTS: usize> Default for VoxelMap<SLOTS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SLOTS: usize> VoxelMap<SLOTS> {
    const CHECK: () = assert!(
        SLOTS.is_power_of_two() && SLOTS >= 16 && SLOTS <= 1 << 28,
        "SLOTS must be a power of two from 16 to 2^28 (probe counts fit a u32)"
    );
    const SHIFT: u32 = 32 - SLOTS.trailing_zeros();
    const LOAD_LIMIT: usize = SLOTS / 4 * 3;

    pub const fn new() -> Self {
        let () = Self::CHECK;
        Self {
            keys: [EMPTY; SLOTS],
            values: [0; SLOTS],
            len: 0,
            origin: Vec3::ZERO,
            inv_size: 1.0,
        }
    }

    /// Empty the map and set its grid: voxels of edge `size` (> 0) with a corner at `origin`
    /// shifted by half the span, so that `origin` sits in the middle of the map.
    pub fn reset(&mut self, origin: Vec3, size: f32) {
        self.keys.fill(EMPTY);
        self.set_grid(origin, size);
    }

    /// Empty the `count` slots from `first` (those in range): with [`VoxelMap::set_grid`] once
    /// every slot is cleared, a [`VoxelMap::reset`] in bounded pieces. O(`count`).
    pub fn clear_slots(&mut self, first: usize, count: usize) {
        let end = first.saturating_add(count).min(SLOTS);
        if let Some(keys) = self.keys.get_mut(first..end) {
            keys.fill(EMPTY);
        }
    }

    /// Set the grid of [`VoxelMap::reset`] and count no voxel: the map is empty when every slot
    /// was cleared ([`VoxelMap::clear_slots`]).
    pub fn set_grid(&mut self, origin: Vec3, size: f32) {
        self.len = 0;
        self.inv_size = 1.0 / size.max(1e-6);
        self.origin = origin - Vec3::splat(size * (COORD_RANGE / 2) as f32);
    }

    /// Whether the map is at its load limit: a new voxel is refused ([`Insert::Full`]).
    pub fn is_full(&self) -> bool {
        self.len >= Self::LOAD_LIMIT
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Continuous voxel coordinates of `p`.
    #[inline]
    fn grid(&self, p: Vec3) -> Vec3 {
        (p - self.origin) * self.inv_size
    }

    /// Packed key of integer voxel coordinates, `None` outside the span.
    #[inline]
    fn pack(x: i32, y: i32, z: i32) -> Option<u32> {
        let inside = |c: i32| (0..COORD_RANGE).contains(&c);
        (inside(x) && inside(y) && inside(z))
            .then_some(x as u32 | (y as u32) << COORD_BITS | (z as u32) << (2 * COORD_BITS))
    }

    /// Key of the voxel holding `p`.
    #[inline]
    fn key_of(&self, p: Vec3) -> Option<u32> {
        self.key_at(p, 0)
    }

    /// Key of the voxel of level `level` holding `p`.
    #[inline]
    fn key_at(&self, p: Vec3, level: u8) -> Option<u32> {
        let g = self.grid(p);
        if !g.is_finite() {
            return None;
        }
        // `as` saturates; out-of-span values are rejected by `pack`.
        let fl = |c: f32| if c < 0.0 { -1 } else { c as i32 >> (2 * level) };
        Self::pack(fl(g.x), fl(g.y), fl(g.z)).map(|k| k | (level as u32) << LEVEL_SHIFT)
    }

    /// Centre of the voxel of level `level` holding `p`.
    fn centre_at(&self, p: Vec3, level: u8) -> Vec3 {
        let edge = (1u32 << (2 * level)) as f32;
        let g = self.grid(p) / edge;
        (Vec3::new(libm::floorf(g.x), libm::floorf(g.y), libm::floorf(g.z)) + Vec3::splat(0.5))
            * edge
            / self.inv_size
            + self.origin
    }

    /// File visible point `points[value]` in the coarser levels: it represents a voxel it finds
    /// empty, or one whose representative is farther from the voxel's centre. `Full` when the
    /// table was at its load limit for some level.
    pub fn insert_coarse(&mut self, value: u16, points: &[Vec3]) -> Insert {
        let Some(&p) = points.get(value as usize) else {
            return Insert::OutOfRange;
        };
        let mut outcome = Insert::New;
        for level in 1..LEVELS {
            let Some(key) = self.key_at(p, level) else {
                return Insert::OutOfRange;
            };
            match self.find(key) {
                Some(slot) if self.keys[slot] == key => {
                    let centre = self.centre_at(p, level);
                    let held = points
                        .get(self.values[slot] as usize)
                        .copied()
                        .unwrap_or(Vec3::splat(f32::INFINITY));
                    if (p - centre).length_squared() < (held - centre).length_squared() {
                        self.values[slot] = value;
                    }
                }
                Some(slot) if self.len < Self::LOAD_LIMIT => {
                    (self.keys[slot], self.values[slot]) = (key, value);
                    self.len += 1;
                }
                _ => outcome = Insert::Full,
            }
        }
        outcome
    }

    /// The coarsest level whose voxels are no wider than `width` (metres).
    pub fn level_for(&self, width: f32) -> u8 {
        let ratio = width * self.inv_size;
        (1..LEVELS)
            .rev()
            .find(|&k| ratio >= (1u32 << (2 * k)) as f32)
            .unwrap_or(0)
    }

    #[inline]
    fn home(key: u32) -> usize {
        (key.wrapping_mul(0x9E37_79B1) >> Self::SHIFT) as usize
    }

    /// Slot holding `key`, or the empty slot where it would go.
    #[inline]
    fn find(&self, key: u32) -> Option<usize> {
        let mut slot = Self::home(key);
        for _ in 0..SLOTS {
            let k = self.keys[slot];
            if k == key || k == EMPTY {
                return Some(slot);
            }
            slot = (slot + 1) & (SLOTS - 1);
        }
        None
    }

    /// Put `value` in the voxel of `p` unless it is taken.
    pub fn insert(&mut self, p: Vec3, value: u16) -> Insert {
        let Some(key) = self.key_of(p) else {
            return Insert::OutOfRange;
        };
        match self.find(key) {
            Some(slot) if self.keys[slot] == key => Insert::Taken(self.values[slot]),
            Some(slot) if self.len < Self::LOAD_LIMIT => {
                self.keys[slot] = key;
                self.values[slot] = value;
                self.len += 1;
                Insert::New
            }
            _ => Insert::Full,
        }
    }

    /// The value in the voxel of `p`.
    pub fn get(&self, p: Vec3) -> Option<u16> {
        let key = self.key_of(p)?;
        self.find(key)
            .filter(|&s| self.keys[s] == key)
            .map(|s| self.values[s])
    }

    /// Squared distance from `q` to the nearest visible point stored in the 2x2x2 block of
    /// voxels of level `level` around `q` (`f32::INFINITY` when there is none). `points[value]`
    /// is the point of a voxel.
    #[inline]
    pub fn nearest(&self, q: Vec3, points: &[Vec3], level: u8) -> f32 {
        self.nearest_probed(q, points, level).0
    }

    /// [`VoxelMap::nearest`], and the number of slots its eight probe runs read:
    /// [`SPARSE_PROBES`] on a sparse table, several times that at the load limit (32 on average
    /// in the unit test below), `8 × SLOTS` at worst. The completion charges its work by it.
    /// Always inlined: it is the inner loop of scoring and completion (see `Evidence::image_cost`).
    #[inline(always)]
    pub fn nearest_probed(&self, q: Vec3, points: &[Vec3], level: u8) -> (f32, u32) {
        let mut best = f32::INFINITY;
        let probes = self.each_near(q, level, |value| {
            if let Some(p) = points.get(value as usize).filter(|_| value != GENERATED) {
                best = best.min((*p - q).length_squared());
            }
        });
        (best, probes)
    }

    /// The index of the visible point nearest `q` in the 2x2x2 block of voxels of level `level`
    /// around it, with its squared distance (`None` when there is none).
    pub fn nearest_point(&self, q: Vec3, points: &[Vec3], level: u8) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        self.each_near(q, level, |value| {
            if let Some(p) = points.get(value as usize).filter(|_| value != GENERATED) {
                let d2 = (*p - q).length_squared();
                if best.is_none_or(|(b, _)| d2 < b) {
                    best = Some((d2, value as usize));
                }
            }
        });
        best
    }

    /// Call `visit` with the value of each voxel of the 2x2x2 block of level `level` around
    /// `q` that holds one; returns the slots the eight probe runs read (0 out of range).
    #[inline(always)]
    fn each_near(&self, q: Vec3, level: u8, mut visit: impl FnMut(u16)) -> u32 {
        let edge = (1u32 << (2 * level)) as f32;
        let g = self.grid(q) / edge - Vec3::splat(0.5);
        // One range check for the whole block (it also rejects NaN).
        let limit = (COORD_RANGE - 1) as f32;
        if !(g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0 && g.x < limit && g.y < limit && g.z < limit) {
            return 0;
        }
        let base = g.x as u32
            | (g.y as u32) << COORD_BITS
            | (g.z as u32) << (2 * COORD_BITS)
            | (level as u32) << LEVEL_SHIFT;
        const CORNERS: [u32; SPARSE_PROBES as usize] = {
            let (x, y, z) = (1u32, 1u32 << COORD_BITS, 1u32 << (2 * COORD_BITS));
            [0, x, y, x + y, z, x + z, y + z, x + y + z]
        };
        let mut probes = 0u32;
        for corner in CORNERS {
            let key = base + corner;
            let mut slot = Self::home(key);
            // Probe to the key or an empty slot (the load limit keeps one within reach).
            for _ in 0..SLOTS {
                probes += 1;
                let k = self.keys[slot];
                if k == key {
                    visit(self.values[slot]);
                    break;
                }
                if k == EMPTY {
                    break;
                }
                slot = (slot + 1) & (SLOTS - 1);
            }
        }
        probes
    }
}

/// Slots a nearest-point lookup reads on a sparse table: one per corner of the 2x2x2 block.
pub const SPARSE_PROBES: u32 = 8;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insert_get_and_dedup() {
        let mut m = VoxelMap::<64>::new();
        m.reset(Vec3::new(0.0, 0.0, 0.5), 0.01);
        assert_eq!(m.insert(Vec3::new(0.001, 0.001, 0.501), 3), Insert::New);
        assert_eq!(
            m.insert(Vec3::new(0.002, 0.003, 0.502), 4),
            Insert::Taken(3)
        );
        assert_eq!(m.get(Vec3::new(0.004, 0.004, 0.504)), Some(3));
        assert_eq!(m.get(Vec3::new(0.5, 0.0, 0.5)), None);
        assert_eq!(m.insert(Vec3::new(100.0, 0.0, 0.5), 1), Insert::OutOfRange);
        assert_eq!(
            m.insert(Vec3::new(f32::NAN, 0.0, 0.5), 1),
            Insert::OutOfRange
        );
    }

    #[test]
    fn reports_full_at_the_load_limit() {
        let mut m = VoxelMap::<16>::new();
        m.reset(Vec3::ZERO, 0.01);
        let results: heapless::Vec<Insert, 16> = (0..16)
            .map(|i| m.insert(Vec3::new(i as f32 * 0.02, 0.0, 0.0), i))
            .collect();
        assert_eq!(results.iter().filter(|r| **r == Insert::New).count(), 12);
        assert!(results[12..].iter().all(|r| *r == Insert::Full));
    }

    #[test]
    fn probe_counts_grow_as_the_table_fills() {
        let mut m = VoxelMap::<256>::new();
        m.reset(Vec3::ZERO, 0.01);
        let q = |i: i32| Vec3::new((i % 16) as f32 * 0.03, (i / 16) as f32 * 0.03, 0.0);
        assert_eq!(
            m.nearest_probed(q(0), &[], 0).1,
            8,
            "one slot per corner when empty"
        );
        assert_eq!(
            m.nearest_probed(Vec3::splat(100.0), &[], 0).1,
            0,
            "out of range"
        );
        // A 16 x 12 sheet of voxels three apart: 192 of 256 slots, the load limit.
        for i in 0..192 {
            assert_eq!(m.insert(q(i), 0), Insert::New);
        }
        let probes: u32 = (0..192)
            .map(|i| m.nearest_probed(q(i) + Vec3::splat(0.015), &[], 0).1)
            .sum();
        assert!(
            probes > 192 * 16,
            "{probes} slots for 192 lookups at a 3/4 load"
        );
    }

    #[test]
    fn nearest_is_exact_within_half_a_voxel() {
        let pts = [
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(0.013, 0.0, 0.5),
            Vec3::new(0.0, -0.021, 0.507),
        ];
        let mut m = VoxelMap::<64>::new();
        m.reset(Vec3::new(0.0, 0.0, 0.5), 0.01);
        for (i, p) in pts.iter().enumerate() {
            m.insert(*p, i as u16);
        }
        for q in [
            Vec3::new(0.004, 0.001, 0.502),
            Vec3::new(0.011, 0.002, 0.499),
            Vec3::new(0.0, -0.018, 0.505),
        ] {
            let exact = pts
                .iter()
                .map(|p| (*p - q).length_squared())
                .fold(f32::INFINITY, f32::min);
            assert_eq!(m.nearest(q, &pts, 0), exact);
        }
        assert_eq!(m.nearest(Vec3::new(0.2, 0.0, 0.5), &pts, 0), f32::INFINITY);
    }

    #[test]
    fn coarse_levels_see_farther() {
        let pts = [Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.003, 0.0, 0.5)];
        let mut m = VoxelMap::<64>::new();
        m.reset(Vec3::new(0.0, 0.0, 0.5), 0.002);
        for i in 0..pts.len() as u16 {
            m.insert(pts[i as usize], i);
            assert_eq!(m.insert_coarse(i, &pts), Insert::New);
        }
        let q = Vec3::new(0.0, 0.02, 0.5); // 2 cm away: beyond level 0's block
        assert_eq!(m.nearest(q, &pts, 0), f32::INFINITY);
        let d2 = m.nearest(q, &pts, 2);
        assert!(d2.is_finite() && d2 < 0.03 * 0.03, "{d2}");
        assert_eq!(m.level_for(0.001), 0);
        assert_eq!(m.level_for(0.009), 1);
        assert_eq!(m.level_for(0.04), 2);
    }
}
