//! Nearest-neighbour distances in a point set, exact up to a reach: a hashed grid of cubic
//! cells (only occupied cells are stored, so stray far-away points cost nothing), searched in
//! growing shells of cells around the query's cell.

use std::collections::HashMap;

use shape_from_symmetry::math::Vec3;

type Cell = [i32; 3];

/// A point set indexed for nearest-neighbour queries.
pub struct Nearest<'a> {
    points: &'a [Vec3],
    cell: f32,
    /// Queries look no farther than this.
    reach: f32,
    /// The points of each occupied cell: `order[start..end]`.
    cells: HashMap<Cell, (u32, u32)>,
    order: Vec<u32>,
}

impl<'a> Nearest<'a> {
    /// Index `points` with cells of edge `cell` metres; queries find neighbours up to `reach`.
    pub fn new(points: &'a [Vec3], cell: f32, reach: f32) -> Self {
        let key = |i: u32| cell_of(points[i as usize], cell);
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        order.sort_unstable_by_key(|&i| key(i));
        let mut cells = HashMap::new();
        let mut start = 0;
        for run in order.chunk_by(|&a, &b| key(a) == key(b)) {
            cells.insert(key(run[0]), (start as u32, (start + run.len()) as u32));
            start += run.len();
        }
        Self {
            points,
            cell,
            reach,
            cells,
            order,
        }
    }

    /// Distance from `q` to the nearest point, `None` when none is within `reach`.
    pub fn distance(&self, q: Vec3) -> Option<f32> {
        self.nearest_where(q, |_| true)
    }

    /// Distance from point `i` of the set to the nearest *other* point, `None` beyond `reach`.
    pub fn distance_to_others(&self, i: usize) -> Option<f32> {
        self.nearest_where(self.points[i], |j| j != i)
    }

    /// Whether some point lies within `radius` (at most `reach`) of `q`.
    pub fn within(&self, q: Vec3, radius: f32) -> bool {
        self.distance(q).is_some_and(|d| d <= radius)
    }

    fn nearest_where(&self, q: Vec3, accept: impl Fn(usize) -> bool) -> Option<f32> {
        let center = cell_of(q, self.cell);
        let mut best = self.reach * self.reach;
        let mut found = false;
        for shell in 0..=(self.reach / self.cell).ceil() as i32 + 1 {
            self.for_shell(center, shell, |i| {
                let d2 = (self.points[i] - q).length_squared();
                if d2 <= best && accept(i) {
                    (best, found) = (d2, true);
                }
            });
            // Every point in a farther shell is at least `shell` cells away from `q`.
            if found && best.sqrt() <= shell as f32 * self.cell {
                break;
            }
        }
        found.then(|| best.sqrt())
    }

    /// Visit the points of the cells whose Chebyshev distance from `center` is `shell`.
    fn for_shell(&self, center: Cell, shell: i32, mut visit: impl FnMut(usize)) {
        let [cx, cy, cz] = center;
        for x in cx - shell..=cx + shell {
            for y in cy - shell..=cy + shell {
                let rim = (x - cx).abs() == shell || (y - cy).abs() == shell;
                // Inside the shell's x-y rim only its two z faces belong to the shell.
                let step = if rim || shell == 0 {
                    1
                } else {
                    2 * shell as usize
                };
                for z in (cz - shell..=cz + shell).step_by(step) {
                    if let Some(&(start, end)) = self.cells.get(&[x, y, z]) {
                        self.order[start as usize..end as usize]
                            .iter()
                            .for_each(|&i| visit(i as usize));
                    }
                }
            }
        }
    }
}

fn cell_of(p: Vec3, cell: f32) -> Cell {
    (p / cell).floor().to_array().map(|c| c as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic points in a 20 cm cube, clustered and scattered.
    fn points(n: usize, seed: u32) -> Vec<Vec3> {
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32 * 0.2
        };
        (0..n).map(|_| Vec3::new(next(), next(), next())).collect()
    }

    #[test]
    fn matches_brute_force_within_reach() {
        let set = points(2000, 1);
        let index = Nearest::new(&set, 0.005, 0.03);
        for q in points(500, 2)
            .into_iter()
            .map(|q| q * 1.3 - Vec3::splat(0.03))
        {
            let brute = set
                .iter()
                .map(|p| (*p - q).length())
                .fold(f32::MAX, f32::min);
            let expected = (brute <= 0.03).then_some(brute);
            assert_eq!(
                index.distance(q).map(|d| (d * 1e6).round()),
                expected.map(|d| (d * 1e6).round())
            );
        }
    }

    #[test]
    fn distance_to_others_skips_the_point_itself() {
        let set = [
            Vec3::ZERO,
            Vec3::new(0.002, 0.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
        ];
        let index = Nearest::new(&set, 0.005, 0.01);
        assert!((index.distance_to_others(0).unwrap() - 0.002).abs() < 1e-7);
        assert_eq!(index.distance_to_others(2), None);
        assert!(index.within(Vec3::new(0.0, 0.004, 0.0), 0.005));
        assert!(
            Nearest::new(&[], 0.005, 0.01)
                .distance(Vec3::ZERO)
                .is_none()
        );
    }
}
