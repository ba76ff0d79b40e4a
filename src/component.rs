//! The best connected component of a graph, one work unit at a time: a breadth-first search
//! from every node that can seed one and is not reached yet (in the graph's seed order),
//! summing each component up ([`Graph::add`]) and remembering the one of highest
//! [`Graph::rank`] (by default the largest; the first on a tie); then a second search from that
//! component's seed marks it. The segmentation (blocks of the depth buffer, [`crate::prepare`])
//! and the domain growth (points of the sampling lattice, [`crate::search::domains`]) both use
//! it.
//!
//! Storage is the caller's: a flag byte per node, whose bits [`VISITED`] and [`MARKED`] belong to
//! this search (the caller clears them before it starts), and a queue of one entry per node.
//!
//! Cost: one work unit per `NEIGHBOURS_PER_UNIT` ([`crate::work`]) neighbours examined (two a
//! node), per [`Graph::SEEDS_PER_UNIT`] nodes scanned for a seed, and one to end each search.

use crate::work::NEIGHBOURS_PER_UNIT;

/// Reached by the first search.
pub const VISITED: u8 = 1 << 6;
/// In the chosen component (set by the second search).
pub const MARKED: u8 = 1 << 7;

/// The eight neighbours of a cell of a raster, as (column, row) offsets, in raster order.
pub const AROUND: [(i32, i32); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The storage of component searches: a flag byte and a queue entry per node. The engine owns
/// one, sized for its depth cells, and lends it to the segmentation while preparing and to the
/// domain growth once the preparation is over (the two never run at once).
#[derive(Clone, Debug)]
pub(crate) struct Scratch<const N: usize> {
    flags: [u8; N],
    queue: [u16; N],
}

impl<const N: usize> Scratch<N> {
    /// Zeroed storage (`const`: part of an engine that may live in a `static`).
    pub(crate) const fn new() -> Self {
        Self {
            flags: [0; N],
            queue: [0; N],
        }
    }

    /// The flags and queue of the first `n` nodes (all of them when `n` is larger).
    pub(crate) fn lend(&mut self, n: usize) -> Lent<'_> {
        let n = n.min(N);
        Lent {
            flags: &mut self.flags[..n],
            queue: &mut self.queue[..n],
        }
    }

    /// The flags of every node, to read.
    pub(crate) fn flags(&self) -> &[u8] {
        &self.flags
    }

    /// [`Scratch::lend`] of the first `n` nodes, the queue entries beyond them and the flags
    /// beyond them. Free once the segmentation is over (the search lends only `POINTS` nodes to
    /// the domain growth), the queue entries keep the depth grid's neighbourhood minima
    /// ([`crate::depth::DepthGrid::spread_into`]) and the flags the marks of the sampled
    /// points ([`Scratch::marks_mut`]).
    pub(crate) fn split(&mut self, n: usize) -> (Lent<'_>, &mut [u16], &[u8]) {
        let n = n.min(N);
        let (queue, spare) = self.queue.split_at_mut(n);
        let (flags, marks) = self.flags.split_at_mut(n);
        (Lent { flags, queue }, spare, marks)
    }

    /// The flags beyond the first `n` nodes, free once the segmentation is over: a mark per
    /// sampled point (mark `i` for point `i`; the search's `n` is `POINTS`, and there are
    /// `N - POINTS` marks: a point beyond them is unmarked). Preparation marks the mixed
    /// readings ([`crate::prepare::between_surfaces`], [`crate::prepare::with_mark`]).
    pub(crate) fn marks_mut(&mut self, n: usize) -> &mut [u8] {
        &mut self.flags[n.min(N)..]
    }

    /// [`Scratch::marks_mut`], to read.
    pub(crate) fn marks(&self, n: usize) -> &[u8] {
        &self.flags[n.min(N)..]
    }

    /// The queue entries beyond the first `n` nodes, to read (see [`Scratch::split`]).
    pub(crate) fn spare(&self, n: usize) -> &[u16] {
        &self.queue[n.min(N)..]
    }
}

/// Flags and queue entries lent out of a [`Scratch`] for one call.
#[derive(Debug)]
pub(crate) struct Lent<'s> {
    /// A flag byte per node.
    pub flags: &'s mut [u8],
    /// A queue entry per node.
    pub queue: &'s mut [u16],
}

/// The graph searched. Nodes index the flags and the queue; the queue holds them as `u16`.
pub trait Graph {
    /// Nodes scanned for the next seed per work unit.
    const SEEDS_PER_UNIT: u32;
    /// How many nodes are scanned for seeds.
    fn seeds(&self) -> u32;
    /// The `s`-th node scanned for seeds.
    fn seed(&self, s: u32) -> usize;
    /// Whether `node` may seed a component.
    fn can_seed(&self, flags: &[u8], node: usize) -> bool;
    /// Neighbour `k` ([`AROUND`]`[k]`) of `node`, if it belongs to `node`'s component. The
    /// relation must be symmetric.
    fn joined(&self, flags: &[u8], node: usize, k: usize) -> Option<usize>;
    /// What the search keeps of the component at hand besides its size (`()`: nothing).
    type Summary: Copy + Default + PartialEq + core::fmt::Debug;
    /// Add `node` to the component's summary (`flags`: every node's, as the search left them).
    fn add(&self, _flags: &[u8], _summary: &mut Self::Summary, _node: usize) {}
    /// Whether a complete component counts as a candidate ([`BestComponent::candidates`]).
    fn candidate(&self, _summary: &Self::Summary, _size: u32) -> bool {
        true
    }
    /// The rank of a complete component: the highest wins (the first on a tie); 0 never does.
    /// By default its size.
    fn rank(&self, _summary: &Self::Summary, size: u32) -> u32 {
        size
    }
}

/// What a step left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    Searching,
    /// The best component is known; marking it has begun.
    Marking,
    /// The best component is marked [`MARKED`] (with [`BestComponent::every`], every component
    /// of non-zero rank is).
    Marked,
    /// No component has a non-zero rank (or none could be seeded).
    Empty,
}

/// The search's position; `S`: the graph's [`Graph::Summary`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BestComponent<S> {
    /// Next seed slot to scan.
    seed: u32,
    head: u32,
    tail: u32,
    /// Nodes of the component at hand dequeued so far.
    size: u32,
    /// Neighbours of the node at the head of the queue already examined.
    neighbour: u8,
    marking: bool,
    /// Mark every component of non-zero rank once it is complete ([`BestComponent::every`]).
    every: bool,
    /// While marking a complete component from the queue (`every`): its next entry to mark;
    /// `u32::MAX` otherwise.
    sweep: u32,
    /// Seed node and rank of the best component so far.
    best: (u32, u32),
    /// The summary of the component at hand, and of the best.
    summary: S,
    best_summary: S,
    /// Complete components that count as candidates, and how many of them came before the best.
    candidates: u32,
    best_index: Option<u32>,
}

/// The search for the largest component (its graph keeps no summary).
pub type LargestComponent = BestComponent<()>;

impl LargestComponent {
    /// A search not begun.
    pub const NEW: Self = Self::starting(());
}

impl<S: Copy + Default> BestComponent<S> {
    /// A search not begun; `zero`: the empty summary (`S::default()`).
    pub const fn starting(zero: S) -> Self {
        Self {
            seed: 0,
            head: 0,
            tail: 0,
            size: 0,
            neighbour: 0,
            marking: false,
            every: false,
            sweep: u32::MAX,
            best: (0, 0),
            summary: zero,
            best_summary: zero,
            candidates: 0,
            best_index: None,
        }
    }

    /// A search that marks every component of non-zero rank, each as soon as it is complete
    /// (from the queue, which then holds its nodes: one unit per [`Graph::SEEDS_PER_UNIT`]
    /// nodes), rather than the best one at the end; `zero` as for [`BestComponent::starting`].
    pub const fn every(zero: S) -> Self {
        let mut search = Self::starting(zero);
        search.every = true;
        search
    }

    /// Complete components so far that count as candidates ([`Graph::candidate`]).
    pub fn candidates(&self) -> u32 {
        self.candidates
    }

    /// The chosen component's position among the candidates (first = 0), `None` when it is not
    /// one; final once [`Progress::Marked`].
    pub fn chosen(&self) -> Option<u32> {
        self.best_index
    }

    /// The chosen component's summary, final once [`Progress::Marked`].
    pub fn chosen_summary(&self) -> S {
        self.best_summary
    }

    /// One work unit of the search.
    pub fn step<G: Graph<Summary = S>>(
        &mut self,
        graph: &G,
        flags: &mut [u8],
        queue: &mut [u16],
    ) -> Progress {
        if self.head < self.tail {
            self.expand(graph, flags, queue);
            return Progress::Searching;
        }
        // The component at hand is complete.
        if self.marking {
            return Progress::Marked;
        }
        if self.sweep < self.tail {
            let end = (self.sweep + G::SEEDS_PER_UNIT).min(self.tail);
            for &node in &queue[self.sweep as usize..end as usize] {
                flags[node as usize] |= MARKED;
            }
            self.sweep = if end < self.tail { end } else { u32::MAX };
            return Progress::Searching;
        }
        if self.size > 0 {
            let candidate = graph.candidate(&self.summary, self.size);
            let rank = graph.rank(&self.summary, self.size);
            if rank > self.best.1 {
                self.best = (graph.seed(self.seed - 1) as u32, rank);
                self.best_summary = self.summary;
                self.best_index = candidate.then_some(self.candidates);
            }
            self.candidates += candidate as u32;
            if self.every && rank > 0 {
                (self.size, self.summary, self.sweep) = (0, S::default(), 0);
                return Progress::Searching;
            }
        }
        (self.size, self.summary) = (0, S::default());
        let end = (self.seed + G::SEEDS_PER_UNIT).min(graph.seeds());
        while self.seed < end && {
            let node = graph.seed(self.seed);
            !graph.can_seed(flags, node) || flags[node] & VISITED != 0
        } {
            self.seed += 1;
        }
        if self.seed < end {
            let node = graph.seed(self.seed);
            self.begin(node, VISITED, flags, queue);
            self.seed += 1;
            return Progress::Searching;
        }
        if end < graph.seeds() {
            return Progress::Searching;
        }
        let (best, size) = self.best;
        if size == 0 {
            return Progress::Empty;
        }
        if self.every {
            return Progress::Marked;
        }
        self.marking = true;
        self.begin(best as usize, MARKED, flags, queue);
        Progress::Marking
    }

    /// Examine the next neighbours of the node at the head of the queue.
    fn expand<G: Graph<Summary = S>>(&mut self, graph: &G, flags: &mut [u8], queue: &mut [u16]) {
        let flag = if self.marking { MARKED } else { VISITED };
        let node = queue[self.head as usize] as usize;
        let first = self.neighbour as usize;
        if first == 0 && !self.marking {
            graph.add(flags, &mut self.summary, node);
        }
        for k in first..first + NEIGHBOURS_PER_UNIT as usize {
            if let Some(n) = graph.joined(flags, node, k) {
                if flags[n] & flag == 0 {
                    flags[n] |= flag;
                    queue[self.tail as usize] = n as u16;
                    self.tail += 1;
                }
            }
        }
        self.neighbour += NEIGHBOURS_PER_UNIT;
        if self.neighbour >= 8 {
            (self.head, self.size, self.neighbour) = (self.head + 1, self.size + 1, 0);
        }
    }

    /// Start a search from `node`.
    fn begin(&mut self, node: usize, flag: u8, flags: &mut [u8], queue: &mut [u16]) {
        flags[node] |= flag;
        queue[0] = node as u16;
        (self.head, self.tail) = (0, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of nodes; neighbours are joined when both are set in `on`.
    struct Row<'a>(&'a [bool]);

    impl Graph for Row<'_> {
        const SEEDS_PER_UNIT: u32 = 2;
        type Summary = ();
        fn seeds(&self) -> u32 {
            self.0.len() as u32
        }
        fn seed(&self, s: u32) -> usize {
            s as usize
        }
        fn can_seed(&self, _: &[u8], node: usize) -> bool {
            self.0[node]
        }
        fn joined(&self, _: &[u8], node: usize, k: usize) -> Option<usize> {
            let (dx, dy) = AROUND[k];
            let n = node as i32 + dx;
            (dy == 0 && (0..self.0.len() as i32).contains(&n) && self.0[n as usize] && self.0[node])
                .then_some(n as usize)
        }
    }

    fn run(row: &[bool]) -> (Progress, [u8; 8], u32) {
        let (mut flags, mut queue) = ([0u8; 8], [0u16; 8]);
        let mut search = LargestComponent::NEW;
        for units in 1..100 {
            match search.step(&Row(row), &mut flags[..row.len()], &mut queue) {
                Progress::Searching | Progress::Marking => {}
                done => return (done, flags, units),
            }
        }
        unreachable!("the search ends")
    }

    #[test]
    fn marks_the_largest_run() {
        let (x, o) = (true, false);
        let (progress, flags, units) = run(&[x, o, x, x, x, o, x, x]);
        assert_eq!(progress, Progress::Marked);
        assert_eq!(flags.map(|f| f & MARKED != 0), [o, o, x, x, x, o, o, o]);
        // Searching: 2 units a node (6 nodes), 5 seed scans; marking: 2 units a node (3), 1 to end.
        assert_eq!(units, 12 + 5 + 6 + 1);
    }

    /// A row whose components rank by the sum of their nodes' indices (the rightmost wins) and
    /// count as candidates from two nodes up.
    struct Ranked<'a>(&'a [bool]);

    impl Graph for Ranked<'_> {
        const SEEDS_PER_UNIT: u32 = 2;
        type Summary = u32;
        fn seeds(&self) -> u32 {
            Row(self.0).seeds()
        }
        fn seed(&self, s: u32) -> usize {
            s as usize
        }
        fn can_seed(&self, flags: &[u8], node: usize) -> bool {
            Row(self.0).can_seed(flags, node)
        }
        fn joined(&self, flags: &[u8], node: usize, k: usize) -> Option<usize> {
            Row(self.0).joined(flags, node, k)
        }
        fn add(&self, _: &[u8], summary: &mut u32, node: usize) {
            *summary += node as u32;
        }
        fn candidate(&self, _: &u32, size: u32) -> bool {
            size >= 2
        }
        fn rank(&self, summary: &u32, _: u32) -> u32 {
            *summary
        }
    }

    #[test]
    fn marks_the_best_ranked_and_counts_the_candidates() {
        let (x, o) = (true, false);
        let row = [x, x, x, o, x, o, x, x];
        let (mut flags, mut queue) = ([0u8; 8], [0u16; 8]);
        let mut search = BestComponent::starting(0u32);
        while search.step(&Ranked(&row), &mut flags, &mut queue) != Progress::Marked {}
        // Components {0,1,2} (sum 3), {4} (4, too small), {6,7} (13): the last wins.
        assert_eq!(flags.map(|f| f & MARKED != 0), [o, o, o, o, o, o, x, x]);
        assert_eq!((search.candidates(), search.chosen()), (2, Some(1)));
        assert_eq!(search.chosen_summary(), 13);
    }

    #[test]
    fn every_component_of_nonzero_rank_is_marked() {
        let (x, o) = (true, false);
        let run = |row: &[bool; 8]| {
            let (mut flags, mut queue) = ([0u8; 8], [0u16; 8]);
            let mut search = BestComponent::every(0u32);
            for _ in 0..100 {
                match search.step(&Ranked(row), &mut flags, &mut queue) {
                    Progress::Searching | Progress::Marking => {}
                    done => return (done, flags.map(|f| f & MARKED != 0)),
                }
            }
            unreachable!("the search ends")
        };
        // {0} ranks 0 (the sum of its indices) and stays; {2, 3, 4} (9) and {6, 7} (13) are
        // marked, each as it is complete.
        let marked = [o, o, x, x, x, o, x, x];
        assert_eq!(run(&[x, o, x, x, x, o, x, x]), (Progress::Marked, marked));
        assert_eq!(run(&[x, o, o, o, o, o, o, o]), (Progress::Empty, [o; 8]));
    }

    #[test]
    fn no_seed_is_empty() {
        assert_eq!(run(&[false; 5]).0, Progress::Empty);
    }
}
