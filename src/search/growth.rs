//! Domain growth (paper section 5.3), the middle loop's sub-machine: the part of a domain a
//! proposed symmetry explains, or the largest connected part of a point set.
//!
//! A domain is grown from the points of the current domain whose transformed points, under a
//! proposed symmetry, cost on average at most a threshold ([`crate::score`]): the cost of an
//! unconfirmed, occluded point when a domain is narrowed for a proposal (every point the proposal
//! does not contradict), when a symmetry accepted on the whole domain claims it, and when the
//! rest of a domain a part was carved out of goes back to the domain's own symmetry; the
//! acceptance threshold when a symmetry found on a narrowed part claims its domain (the points
//! it explains; see `Engine::grow`):
//! 1. **Assess**: each point's mean cost under the proposal's maps.
//! 2. **Grow**: the largest connected component of those points (8-neighbours on the sampling
//!    lattice, found by binary search in the raster-ordered points: no extra storage).
//! 3. **Clean**: absorb the points enclosed by the component (at least five of their eight
//!    neighbours in it) and the object's border points next to it.
//! 4. **Measure**: the domain qualifies when it is at least `min_share` and at most `max_share`
//!    of the current domain and its rim (members with a neighbour in the rest of it) is at most
//!    `max_rim` of its size; one of more than `max_share` is nearly all of it ([`Grown::Nearly`]:
//!    a narrowing has failed, a claim takes the whole domain).
//!
//! The same machinery without a proposal (every point qualifies) finds the largest connected
//! component of the points no symmetry has claimed: the next domain to search.
//!
//! Cost in work units: one per transformed point assessed; one per four neighbour lookups
//! (each O(log n)); one per point started or cleared.

use crate::component::{self, AROUND, Graph, LargestComponent, Lent};
use crate::prepare::Points;
use crate::score::{Evidence, Level, Rest, contact_maps};
use crate::symmetry::{DERIVED, MapSet, Sampling, Symmetry};
use crate::work::{MARKS_PER_UNIT, Meter, POINT_SEEDS_PER_UNIT, Poll};

use crate::config::DomainConfig;

const IN_DOMAIN: u8 = 1;
const GOOD: u8 = 2;
/// In the largest component of the good points.
const MEMBER: u8 = component::MARKED;
/// Absorbed by the cleaning (counts as a member once the cleaning is over).
const ABSORBED: u8 = 16;
/// A member of the grown domain after cleaning.
const IN_RESULT: u8 = MEMBER | ABSORBED;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Start {
        next: u16,
    },
    Assess {
        next: u16,
        map: u8,
        sum: f32,
        count: u8,
    },
    Components(LargestComponent),
    Clean {
        next: u16,
    },
    Measure {
        next: u16,
        size: u16,
        rim: u16,
    },
    Done,
}

/// What a finished growth found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grown {
    /// The domain: the first this many indices of the domain list (the rest follow them).
    Domain(usize),
    /// No part qualified.
    Nothing,
    /// The part is nearly all of the domain (more than `max_share` of it).
    Nearly,
}

/// The domain-growth state machine over at most `P` points. Its per-point flags and queue are
/// lent to each call ([`Lent`]): memory the segmentation used while preparing.
#[derive(Clone, Debug)]
pub struct Growth<const P: usize> {
    maps: MapSet,
    /// The maps whose images may earn the contact term ([`crate::score::contact_maps`]).
    contact: u16,
    level: Option<Level>,
    threshold: f32,
    config: DomainConfig,
    stride: u16,
    phase: Phase,
    result: Option<Grown>,
}

impl<const P: usize> Default for Growth<P> {
    fn default() -> Self {
        Self::new(DomainConfig::DEFAULT)
    }
}

impl<const P: usize> Growth<P> {
    pub const fn new(config: DomainConfig) -> Self {
        Self {
            maps: MapSet::new(),
            contact: 0,
            level: None,
            threshold: 0.0,
            config,
            stride: 1,
            phase: Phase::Done,
            result: None,
        }
    }

    /// Grow, within the domain, the part that `proposal` does not contradict (points whose mean
    /// cost at `level` is at most `threshold`, costed as the score costs them: with the contact
    /// term for an object resting as `rest` says, when given). `stride` is the sampling
    /// lattice's.
    pub fn begin_proposal(
        &mut self,
        proposal: &Symmetry,
        sampling: Sampling,
        level: Level,
        rest: Option<Rest>,
        threshold: f32,
        stride: u16,
    ) {
        self.maps = proposal.maps(sampling);
        self.contact = contact_maps(&self.maps, rest, &level);
        (self.level, self.threshold, self.stride) = (Some(level), threshold, stride.max(1));
        (self.phase, self.result) = (Phase::Start { next: 0 }, None);
    }

    /// Find the largest connected component of the domain (every point qualifies).
    pub fn begin_component(&mut self, stride: u16) {
        (self.level, self.stride) = (None, stride.max(1));
        (self.phase, self.result) = (Phase::Start { next: 0 }, None);
    }

    /// Grow over `domain` (point indices; rewritten with the grown domain when one qualifies)
    /// with the flags and queue `lent` (at least one each per point), spending what is left on
    /// `meter`; once over, what was grown. Out of line: it runs only
    /// when parts are searched, and inlined into the engine's poll it would crowd the scoring
    /// loop's registers.
    #[inline(never)]
    pub(crate) fn advance<const V: usize, const C: usize>(
        &mut self,
        evidence: &Evidence<'_, V, C>,
        points: &Points<P>,
        domain: &mut [u16],
        mut lent: Lent<'_>,
        meter: &mut Meter,
    ) -> Poll<Grown> {
        let lent = &mut lent;
        let (budget, mut used) = (meter.left(), 0);
        while used < budget && self.phase != Phase::Done {
            used += 1;
            self.phase = match self.phase {
                Phase::Start { next } => self.start(lent, domain, next),
                Phase::Assess {
                    next,
                    map,
                    sum,
                    count,
                } => self.assess(lent, evidence, domain, next, map, sum, count),
                Phase::Components(search) => {
                    let good = GoodPoints {
                        points,
                        domain,
                        stride: self.stride,
                    };
                    self.components(lent, &good, search)
                }
                Phase::Clean { next } => self.clean(lent, points, domain, next),
                Phase::Measure { next, size, rim } => {
                    self.measure(lent, points, domain, next, size, rim)
                }
                Phase::Done => Phase::Done,
            };
        }
        meter.spend(used);
        match self.result {
            Some(grown) if self.phase == Phase::Done => Poll::Ready(grown),
            _ => Poll::Pending,
        }
    }

    /// Mark the domain's points ([`MARKS_PER_UNIT`] a unit); every point is good without a
    /// proposal.
    fn start(&mut self, lent: &mut Lent<'_>, domain: &[u16], next: u16) -> Phase {
        if next == 0 {
            lent.flags.fill(0);
        }
        let end = (next as usize + MARKS_PER_UNIT).min(domain.len());
        let mark = if self.level.is_some() {
            IN_DOMAIN
        } else {
            IN_DOMAIN | GOOD
        };
        for &i in &domain[next as usize..end] {
            lent.flags[i as usize] = mark;
        }
        match (end == domain.len(), self.level.is_some()) {
            (false, _) => Phase::Start { next: end as u16 },
            (true, true) => Phase::Assess {
                next: 0,
                map: 0,
                sum: 0.0,
                count: 0,
            },
            (true, false) => Phase::Components(LargestComponent::NEW),
        }
    }

    /// One transformed point of one domain point; at its last map, the point is good when its
    /// mean cost is within the threshold (an image that tells nothing, a self-map or an
    /// obstructed one, is left out as in the score).
    #[allow(clippy::too_many_arguments)]
    fn assess<const V: usize, const C: usize>(
        &mut self,
        lent: &mut Lent<'_>,
        evidence: &Evidence<'_, V, C>,
        domain: &[u16],
        next: u16,
        map: u8,
        mut sum: f32,
        mut count: u8,
    ) -> Phase {
        let Some(&i) = domain.get(next as usize) else {
            return Phase::Components(LargestComponent::NEW);
        };
        let (Some(level), Some(&(m, group))) = (self.level, self.maps.maps.get(map as usize))
        else {
            return Phase::Components(LargestComponent::NEW);
        };
        if group != DERIVED {
            let p = evidence.points[i as usize];
            let q = m.apply(p);
            let contact = self.contact & (1 << map) != 0;
            // A self-map or an obstructed image tells nothing, as in the score.
            let cost = (!level.is_self_map(p, q))
                .then(|| evidence.image_cost(q, &level, contact))
                .flatten();
            if let Some(cost) = cost {
                sum += cost;
                count += 1;
            }
        }
        if map as usize + 1 < self.maps.maps.len() {
            return Phase::Assess {
                next,
                map: map + 1,
                sum,
                count,
            };
        }
        if sum <= self.threshold * count.max(1) as f32 {
            lent.flags[i as usize] |= GOOD;
        }
        Phase::Assess {
            next: next + 1,
            map: 0,
            sum: 0.0,
            count: 0,
        }
    }

    fn neighbour(&self, points: &Points<P>, i: usize, k: usize) -> Option<usize> {
        lattice_neighbour(points, self.stride, i, k)
    }

    /// One unit of the search for the largest connected component of the good points
    /// ([`crate::component`]); then the cleaning, or with no proposal the measure.
    fn components(
        &mut self,
        lent: &mut Lent<'_>,
        good: &GoodPoints<P>,
        mut search: LargestComponent,
    ) -> Phase {
        match search.step(good, lent.flags, lent.queue) {
            component::Progress::Searching | component::Progress::Marking => {
                Phase::Components(search)
            }
            component::Progress::Marked if self.level.is_some() => Phase::Clean { next: 0 },
            component::Progress::Marked => Phase::Measure {
                next: 0,
                size: 0,
                rim: 0,
            },
            component::Progress::Empty => {
                self.result = Some(Grown::Nothing);
                Phase::Done
            }
        }
    }

    /// Absorb a non-member domain point with at least five member neighbours (enclosed), or on the
    /// object's border (a neighbour missing) with a member neighbour. Two units a point.
    fn clean(
        &mut self,
        lent: &mut Lent<'_>,
        points: &Points<P>,
        domain: &[u16],
        next: u16,
    ) -> Phase {
        let Some(&i) = domain.get(next as usize) else {
            return Phase::Measure {
                next: 0,
                size: 0,
                rim: 0,
            };
        };
        let i = i as usize;
        if lent.flags[i] & MEMBER == 0 {
            let (mut members, mut present) = (0, 0);
            for k in 0..8 {
                if let Some(n) = self.neighbour(points, i, k) {
                    present += 1;
                    members += (lent.flags[n] & MEMBER != 0) as u32;
                }
            }
            if members >= 5 || (present < 8 && members >= 1) {
                lent.flags[i] |= ABSORBED;
            }
        }
        Phase::Clean { next: next + 1 }
    }

    /// Count members and rim; at the end, decide and write the domain back.
    fn measure(
        &mut self,
        lent: &mut Lent<'_>,
        points: &Points<P>,
        domain: &mut [u16],
        next: u16,
        mut size: u16,
        mut rim: u16,
    ) -> Phase {
        if let Some(&i) = domain.get(next as usize) {
            let i = i as usize;
            if lent.flags[i] & IN_RESULT != 0 {
                size += 1;
                let outside =
                    |n: usize| lent.flags[n] & IN_RESULT == 0 && lent.flags[n] & IN_DOMAIN != 0;
                rim += (0..8)
                    .filter_map(|k| self.neighbour(points, i, k))
                    .any(outside) as u16;
            }
            return Phase::Measure {
                next: next + 1,
                size,
                rim,
            };
        }
        let (n, all) = (size as f32, domain.len() as f32);
        let qualifies = match self.level {
            Some(_) => {
                n >= self.config.min_share * all
                    && n <= self.config.max_share * all
                    && rim as f32 <= self.config.max_rim * n
            }
            None => size > 0,
        };
        self.result = Some(if qualifies {
            Grown::Domain(Self::compact(lent, domain))
        } else if self.level.is_some() && n > self.config.max_share * all {
            Grown::Nearly
        } else {
            Grown::Nothing
        });
        Phase::Done
    }

    /// Reorder `domain`: the members first, then the others, each in their order (so the wider
    /// domain can be restored); returns how many members.
    fn compact(lent: &mut Lent<'_>, domain: &mut [u16]) -> usize {
        let (mut kept, mut others) = (0, 0);
        for j in 0..domain.len() {
            let i = domain[j];
            if lent.flags[i as usize] & IN_RESULT != 0 {
                domain[kept] = i;
                kept += 1;
            } else {
                lent.queue[others] = i;
                others += 1;
            }
        }
        domain[kept..].copy_from_slice(&lent.queue[..others]);
        kept
    }
}

/// Point index of the lattice neighbour `k` ([`AROUND`]`[k]`) of point `i`, if it exists (a
/// binary search in the raster-ordered points).
fn lattice_neighbour<const P: usize>(
    points: &Points<P>,
    stride: u16,
    i: usize,
    k: usize,
) -> Option<usize> {
    let [u, v] = points.pixel[i];
    let (du, dv) = AROUND[k];
    let s = stride as i32;
    let (nu, nv) = (u as i32 + du * s, v as i32 + dv * s);
    if !(0..=u16::MAX as i32).contains(&nu) || !(0..=u16::MAX as i32).contains(&nv) {
        return None;
    }
    points.index_of(nu as u16, nv as u16)
}

/// The good points of the domain as a graph: lattice neighbours are joined when both are good.
struct GoodPoints<'a, const P: usize> {
    points: &'a Points<P>,
    domain: &'a [u16],
    stride: u16,
}

impl<const P: usize> Graph for GoodPoints<'_, P> {
    const SEEDS_PER_UNIT: u32 = POINT_SEEDS_PER_UNIT;
    type Summary = ();

    fn seeds(&self) -> u32 {
        self.domain.len() as u32
    }

    fn seed(&self, s: u32) -> usize {
        self.domain[s as usize] as usize
    }

    fn can_seed(&self, flags: &[u8], point: usize) -> bool {
        flags[point] & GOOD != 0
    }

    fn joined(&self, flags: &[u8], point: usize, k: usize) -> Option<usize> {
        lattice_neighbour(self.points, self.stride, point, k)
            .filter(|&n| flags[n] & (IN_DOMAIN | GOOD) == IN_DOMAIN | GOOD)
    }
}
