//! The middle loop (paper section 5.3): which part of the object each symmetry applies to.
//!
//! [`DomainSearch`] owns the domain list, each point's [`Owner`], the growth of domains
//! ([`super::growth`]) and the symmetries found. It runs the outer loop ([`TypeSearch`]) on one
//! domain at a time and answers its requests:
//! 1. The whole object is the first domain.
//! 2. A walk asks for hypotheses to be scored ([`Request::Evaluate`]): the caller scores them
//!    over the domain ([`crate::score::Evaluation`]) and hands the score back.
//! 3. When a walk is over and its axial node failed, the domain may be narrowed to the part
//!    one of the node's proposals explains ([`super::parts::decomposes`]), and that part walked
//!    ([`TypeSearch::begin_part`]); if the part's axis is no part, the domain widens back.
//! 4. When a walk is over, its symmetry claims the part of the domain it explains (grown at the
//!    finest match σ); when it was found on a part carved out of the domain, the rest of the
//!    domain goes back to the symmetry the whole domain got. Without one, the domain's points
//!    are exhausted.
//! 5. With parts searched, the largest connected part of the unclaimed points is the next
//!    domain, until it is under `min_leftover` of the object or [`MAX_SYMMETRIES`] are found.
//! 6. At the end the symmetries are ordered strongest first (the points they explain, then
//!    type) and the owners relabelled: the completion reads them.
//!
//! Which growth keeps which points: a narrowing keeps the points the proposal does not
//! contradict (their images cost on average at most an unconfirmed, occluded point), so that
//! the part the climb refines the symmetry on keeps the points seen from one side only. A claim
//! by a symmetry accepted on the whole domain keeps the same points: the walk judged it there.
//! A symmetry found on a narrowed part claims only the points it explains (at most the
//! acceptance threshold): the rest of the domain is why it was narrowed, and goes back to the
//! symmetry the whole domain got, keeping the points it does not contradict.
//!
//! Cost in work units: one per walk step; growth as [`super::growth`] states; one per 16 points
//! gathered. Memory: 2 bytes (domain list) + 1 byte (owner) per point; the growth's flags and
//! queue are lent by the caller.

use super::family::Frame;
use super::growth::{Grown, Growth};
use super::params::{Candidate, Request};
use super::parts;
use super::types::TypeSearch;
use crate::component::Lent;
use crate::config::{Config, ModelConfig};
use crate::engine::{Found, MAX_SYMMETRIES};
use crate::math::Vec3;
use crate::prepare::{Points, Shells};
use crate::score::{Evidence, Level, Scored};
use crate::symmetry::Symmetry;
use crate::voxel::VoxelMap;
use crate::work::{MARKS_PER_UNIT, Meter, Poll};

/// Which symmetry's domain holds a point: an index into the symmetries found, or one of the two
/// markers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub(crate) struct Owner(pub(crate) u8);

impl Owner {
    /// No symmetry claims the point (yet). Also the `CompletedPoint::symmetry` of a visible
    /// point no symmetry explains.
    pub(crate) const UNCLAIMED: Self = Self(u8::MAX);
    /// The point was searched in a domain that held no symmetry.
    pub(crate) const EXHAUSTED: Self = Self(u8::MAX - 1);
}

/// What a domain growth is for.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Growing {
    /// A walk's axial node failed: the part of the domain this proposal explains.
    Narrowing(Candidate),
    /// A domain's symmetry is found: the part of the domain it explains becomes its domain.
    Claiming,
    /// The largest connected part of the unclaimed points, searched next.
    Leftover,
    /// A part was carved out of a domain: the part of the rest of it the domain's own symmetry
    /// does not contradict stays that symmetry's.
    Rest,
}

/// The middle loop's position between type searches.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Middle {
    /// A type search is running (or the loop is idle before `begin`).
    Walking,
    Growing(Growing),
    /// Collecting the unclaimed points into the domain list, from this point on.
    Gathering {
        next: usize,
    },
    /// Every domain is searched; the symmetries are ordered and the owners relabelled.
    Finished,
}

/// What the middle loop reads of the prepared scene for one step.
pub(crate) struct Context<'c, const P: usize, const V: usize, const C: usize> {
    /// The measurement model's view of the scene, for growth.
    pub evidence: &'c Evidence<'c, V, C>,
    /// The sampled object points, in raster order (growth follows their lattice).
    pub points: &'c Points<P>,
    pub config: &'c Config,
    /// The sampling lattice's stride, pixels.
    pub stride: u16,
}

/// A hypothesis the walk wants scored over the current domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Hypothesis {
    pub symmetry: Symmetry,
    /// Match σ, metres.
    pub sigma: f32,
    /// About this many transformed points.
    pub transformed: u32,
    /// Note where its images stray ([`crate::score::Strays`]).
    pub tally: bool,
    /// Hold each mirror to the halves test about its own plane.
    pub every_mirror: bool,
}

/// The middle-loop state machine over at most `P` points.
#[derive(Clone, Debug)]
pub(crate) struct DomainSearch<const P: usize> {
    middle: Middle,
    sigma_fine: f32,
    /// The widest step between two samples of one surface
    /// ([`crate::prepare::ObjectStats::surface_gap`]): a domain's radius is its surface's
    /// ([`frame_of`]).
    gap: f32,
    /// The readings' variance beyond the match σ's ([`crate::ModelConfig::excess2`]).
    excess2: f32,
    domain_len: usize,
    /// Length of the domain a narrowing started from (the narrower domain is its prefix).
    wider_len: usize,
    /// Length of the domain the walk ended in (claimed if the claiming growth finds nothing).
    searched_len: usize,
    /// Index in `found` of the whole object's symmetry: the first domain's, or the one the
    /// rest of the first domain kept when a part was carved out of it. Points of no domain are
    /// completed through it.
    whole: u8,
    /// The first domain's symmetry was accepted on the whole object and no part was carved out
    /// of it: the points it contradicts are searched only for symmetries that share a mirror
    /// plane with it.
    leftovers_keep_whole: bool,
    /// A narrowed domain (a part carved out of the wider one) is walked.
    narrowed: bool,
    walk: TypeSearch,
    /// The symmetries of the finished domains (strongest first once finished).
    found: heapless::Vec<Found, MAX_SYMMETRIES>,
    /// Indices of the points of the domain being searched.
    domain: [u16; P],
    /// The owner of each point.
    owners: [Owner; P],
    growth: Growth<P>,
    /// The model's acceptance threshold: what a symmetry's confidence is measured against.
    accept: f32,
    /// The whole object's runner-up, once the first domain's walk is over.
    runner_up: Option<Found>,
    /// The first domain's walk is over (its runner-up taken).
    first_walked: bool,
}

impl<const P: usize> DomainSearch<P> {
    /// An idle search (`const`: part of an engine that may live in a `static`).
    pub(crate) const fn new(config: &Config) -> Self {
        Self {
            middle: Middle::Walking,
            sigma_fine: 0.0,
            gap: 0.0,
            excess2: 0.0,
            domain_len: 0,
            wider_len: 0,
            searched_len: 0,
            whole: 0,
            leftovers_keep_whole: false,
            narrowed: false,
            walk: TypeSearch::new(config.search),
            found: heapless::Vec::new(),
            domain: [0; P],
            owners: [Owner::UNCLAIMED; P],
            growth: Growth::new(config.domains),
            accept: config.model.accept,
            runner_up: None,
            first_walked: false,
        }
    }

    /// Forget any search in progress (the walk and the loop's position).
    pub(crate) fn reset(&mut self, config: &Config) {
        self.walk = TypeSearch::new(config.search);
        (self.middle, self.narrowed) = (Middle::Walking, false);
    }

    /// Begin with the whole object (`len` points, centred in `frame`) as the first domain, at
    /// the finest match σ `sigma_fine` (the readings' excess variance `excess2`), the object
    /// resting on `support` if known. O(`len`).
    pub(crate) fn begin(
        &mut self,
        config: &Config,
        len: usize,
        frame: Frame,
        (sigma_fine, gap): (f32, f32),
        excess2: f32,
        support: Option<crate::Plane>,
    ) {
        self.walk.set_support(support);
        (self.accept, self.runner_up, self.first_walked) = (config.model.accept, None, false);
        self.owners = [Owner::UNCLAIMED; P];
        self.found.clear();
        (self.whole, self.leftovers_keep_whole) = (0, false);
        self.domain_len = len;
        for (i, slot) in self.domain[..len].iter_mut().enumerate() {
            *slot = i as u16;
        }
        (self.sigma_fine, self.gap, self.excess2) = (sigma_fine, gap, excess2);
        self.begin_domain(config, frame);
    }

    /// The whole object's runner-up (see [`crate::Report::runner_up`]), once its walk is over.
    pub(crate) fn runner_up(&self) -> Option<Found> {
        self.runner_up
    }

    /// The finest match σ of the search, metres.
    pub(crate) fn sigma_fine(&self) -> f32 {
        self.sigma_fine
    }

    /// The readings' variance beyond the match σ's, metres² ([`crate::ModelConfig::excess2`]).
    pub(crate) fn excess2(&self) -> f32 {
        self.excess2
    }

    /// The model's per-point constants at match σ `sigma` for this search's readings (their
    /// excess variance credited to a confirmed match): every scoring of the search takes its
    /// level from here.
    pub(crate) fn level<const V: usize>(
        &self,
        model: &ModelConfig,
        sigma: f32,
        voxels: &VoxelMap<V>,
    ) -> Level {
        model.level(sigma, self.excess2, voxels)
    }

    /// The indices of the current domain's points.
    pub(crate) fn domain(&self) -> &[u16] {
        &self.domain[..self.domain_len]
    }

    /// Whether every domain is searched.
    pub(crate) fn is_finished(&self) -> bool {
        self.middle == Middle::Finished
    }

    /// The symmetries found, strongest first once finished.
    pub(crate) fn found(&self) -> &[Found] {
        &self.found
    }

    /// The owner of each point, relabelled strongest first once finished.
    pub(crate) fn owners(&self) -> &[Owner; P] {
        &self.owners
    }

    /// The owners, and the symmetries found to refine in place.
    pub(crate) fn owners_and_found_mut(&mut self) -> (&[Owner; P], &mut [Found]) {
        (&self.owners, &mut self.found)
    }

    /// Once finished: the index (in [`DomainSearch::found`]) of the whole object's symmetry,
    /// through which the points of no domain are completed ([`Owner::UNCLAIMED`]: none).
    pub(crate) fn whole(&self) -> Owner {
        Owner(self.whole)
    }

    /// One step, spending at least one unit of `meter` (which must have one left): a growth or
    /// a gathering spends what is left, a walk step one unit. `last` is the score of the
    /// hypothesis the previous step asked for (when it asked for one); returns the next
    /// hypothesis to score, if any. `published` receives the symmetries found so far (and the
    /// walk's current best) at the points the report is updated. `lent`: the growth's flags and
    /// queue, one each per point.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        last: Option<Scored>,
        meter: &mut Meter,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
        lent: Lent<'_>,
    ) -> Option<Hypothesis> {
        match self.middle {
            Middle::Growing(growing) => {
                let domain = &mut self.domain[..self.domain_len];
                if let Poll::Ready(grown) =
                    self.growth
                        .advance(cx.evidence, cx.points, domain, lent, meter)
                {
                    self.middle = Middle::Walking;
                    self.grown(cx, growing, grown, published);
                }
                return None;
            }
            Middle::Gathering { next } => {
                self.gather(cx, next, meter, published);
                return None;
            }
            // Never asked: the caller completes once the search is finished.
            Middle::Finished => return None,
            Middle::Walking => {}
        }
        meter.spend(1);
        let mut hypothesis = None;
        match self.walk.next(last) {
            Request::Evaluate {
                symmetry,
                sigma,
                transformed,
                tally,
                every_mirror,
            } => {
                hypothesis = Some(Hypothesis {
                    symmetry,
                    sigma,
                    transformed,
                    tally,
                    every_mirror,
                })
            }
            Request::Done => self.walked(cx, published),
        }
        self.publish(published);
        hypothesis
    }

    /// Start the type search on the domain (the first `domain_len` points of the list).
    fn begin_domain(&mut self, config: &Config, frame: Frame) {
        self.wider_len = self.domain_len;
        let object = self.found.first().filter(|_| self.leftovers_keep_whole);
        self.walk.begin(
            config.types,
            frame,
            self.sigma_fine,
            config.model.accept,
            object.map(|f| f.symmetry),
        );
    }

    /// Grow, in the domain, the part `symmetry` explains, at the finest match σ (see the module
    /// docs for the threshold each growth uses).
    fn grow<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        symmetry: &Symmetry,
        growing: Growing,
    ) {
        let model = &cx.config.model;
        let level = self.level(model, self.sigma_fine, cx.evidence.voxels);
        let threshold = match growing {
            Growing::Narrowing(_) | Growing::Rest => model.cost_occluded,
            Growing::Claiming if !self.walk.found_on_part() => model.cost_occluded,
            Growing::Claiming | Growing::Leftover => model.accept,
        };
        self.growth.begin_proposal(
            symmetry,
            cx.config.sampling,
            level,
            cx.evidence.view.rest(),
            threshold,
            cx.stride,
        );
        self.middle = Middle::Growing(growing);
    }

    /// A growth is over: hand a narrower domain to the type search, claim a symmetry's domain,
    /// or search the leftover part.
    fn grown<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        growing: Growing,
        grown: Grown,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        match (growing, grown) {
            (Growing::Narrowing(proposal), Grown::Domain(len)) => {
                self.wider_len = self.domain_len;
                self.domain_len = len;
                let frame = frame_of(cx.points.positions(), &self.domain[..len], self.gap);
                self.narrowed = true;
                self.walk.begin_part(proposal, frame);
            }
            // No part qualified: the walk stays over; the next step offers the next proposal.
            (Growing::Narrowing(_), Grown::Nothing | Grown::Nearly) => {}
            (Growing::Claiming, grown) => {
                let len = match grown {
                    Grown::Domain(len) => len,
                    Grown::Nothing | Grown::Nearly => self.searched_len,
                };
                self.claim(cx, len, published);
            }
            (Growing::Rest, Grown::Domain(len)) => self.claim_rest(cx, len, published),
            (Growing::Rest, Grown::Nearly) => self.claim_rest(cx, self.domain_len, published),
            (Growing::Rest, Grown::Nothing) => self.next_domain(cx, published),
            (Growing::Leftover, Grown::Domain(len)) => {
                self.domain_len = len;
                if self.leftover_is_large(cx) {
                    let frame = frame_of(cx.points.positions(), &self.domain[..len], self.gap);
                    self.begin_domain(cx.config, frame);
                } else {
                    self.finish(published);
                }
            }
            (Growing::Leftover, Grown::Nothing | Grown::Nearly) => self.finish(published),
        }
    }

    fn leftover_is_large<const V: usize, const C: usize>(&self, cx: &Context<'_, P, V, C>) -> bool {
        let least = (cx.config.domains.min_leftover * cx.points.len as f32) as usize;
        self.domain_len >= least.max(crate::prepare::MIN_POINTS as usize)
    }

    /// The walk of a domain is over. A narrowed domain whose axis is no part widens back to
    /// the domain it was carved from (whose walk is over too). Otherwise the domain is narrowed
    /// to the part the walk's next proposal explains, when it decomposes; or it is finished.
    fn walked<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if core::mem::take(&mut self.narrowed) && !self.walk.found_on_part() {
            self.domain_len = self.wider_len;
            return;
        }
        let config = cx.config;
        if parts::decomposes(config.domains.parts, config.types, self.walk.best()) {
            if let Some(proposal) = self.walk.pop_proposal() {
                self.grow(cx, &proposal.symmetry, Growing::Narrowing(proposal));
                return;
            }
        }
        self.finish_domain(cx, published);
    }

    /// The type search of a domain is over. A symmetry found claims the part of the domain it
    /// explains (grown from the domain, at the acceptance threshold; all of it when no part
    /// qualifies); without one, the domain's points are exhausted.
    fn finish_domain<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if !core::mem::replace(&mut self.first_walked, true) {
            let (all, accept) = (cx.points.len as u32, self.accept);
            self.runner_up =
                (self.walk.runner_up()).map(|c| Found::new(c.symmetry, c.score, all, accept));
        }
        match self.walk.best().copied() {
            Some(best) if !self.found.is_full() && cx.config.domains.parts => {
                // Claim from the whole domain the walk started in: the refined symmetry may
                // explain more than the part it was found on.
                self.searched_len = self.domain_len;
                self.domain_len = self.wider_len;
                self.grow(cx, &best.symmetry, Growing::Claiming);
            }
            Some(_) if !self.found.is_full() => self.claim(cx, self.domain_len, published),
            _ => {
                for &i in &self.domain[..self.domain_len] {
                    self.owners[i as usize] = Owner::EXHAUSTED;
                }
                self.next_domain(cx, published);
            }
        }
    }

    /// The first `len` points of the domain go to the domain's symmetry. When it was found on
    /// a part carved out of the domain, the rest of the domain is offered to the symmetry the
    /// domain got before it was carved; otherwise, the next domain.
    fn claim<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        len: usize,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if let Some(best) = self.walk.best().copied() {
            if self.found.is_empty() {
                self.leftovers_keep_whole = !self.walk.found_on_part();
            }
            self.push_found(best, len);
        }
        match self.walk.carved_from() {
            Some(wider) if !self.found.is_full() => {
                // The rest: the domain's points after the part's, moved to the front.
                let end = self.domain_len;
                self.domain.copy_within(len..end, 0);
                self.domain_len = end - len;
                self.grow(cx, &wider.symmetry, Growing::Rest);
            }
            _ => self.next_domain(cx, published),
        }
    }

    /// The rest of a domain a part was carved out of: its first `len` points go to the symmetry
    /// the domain got before it was carved. That symmetry was accepted on all of the domain;
    /// the points of it the part's symmetry does not explain need no new hypothesis where it does
    /// not contradict them (the paper's mug: the handle keeps the mug's mirror plane). Searched
    /// alone, such a rest can pass as a symmetry of itself that is not one of the object (a band
    /// of a bottle's body has a plane across the bottle's axis).
    fn claim_rest<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        len: usize,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if let Some(wider) = self.walk.carved_from() {
            if self.found.len() == 1 {
                // Only the part of the first domain is found: the rest keeps the whole object's.
                self.whole = 1;
            }
            self.push_found(wider, len);
        }
        self.next_domain(cx, published);
    }

    /// Record `symmetry` as found, with the first `len` points of the domain.
    fn push_found(&mut self, symmetry: Candidate, len: usize) {
        let found = Found::new(symmetry.symmetry, symmetry.score, len as u32, self.accept);
        if self.found.push(found).is_ok() {
            let owner = Owner((self.found.len() - 1) as u8);
            for &i in &self.domain[..len] {
                self.owners[i as usize] = owner;
            }
        }
    }

    /// With parts searched, gather the unclaimed points to find the next domain among them;
    /// otherwise the whole object was the only domain: finish.
    fn next_domain<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if cx.config.domains.parts {
            self.middle = Middle::Gathering { next: 0 };
        } else {
            self.finish(published);
        }
    }

    /// Collect the unclaimed points into the domain list, [`MARKS_PER_UNIT`] a unit; then find
    /// their largest connected part (the next domain), or finish.
    fn gather<const V: usize, const C: usize>(
        &mut self,
        cx: &Context<'_, P, V, C>,
        next: usize,
        meter: &mut Meter,
        published: &mut heapless::Vec<Found, MAX_SYMMETRIES>,
    ) {
        if next == 0 {
            self.domain_len = 0;
        }
        let len = cx.points.len;
        let end = (next + MARKS_PER_UNIT * meter.left().max(1) as usize).min(len);
        for i in next..end {
            if self.owners[i] == Owner::UNCLAIMED {
                self.domain[self.domain_len] = i as u16;
                self.domain_len += 1;
            }
        }
        meter.spend((end - next).div_ceil(MARKS_PER_UNIT).max(1) as u32);
        if end < len {
            self.middle = Middle::Gathering { next: end };
        } else if self.leftover_is_large(cx) && !self.found.is_full() {
            self.growth.begin_component(cx.stride);
            self.middle = Middle::Growing(Growing::Leftover);
        } else {
            self.finish(published);
        }
        self.publish(published);
    }

    /// Write the symmetries found so far (the finished domains' and, while a walk is on, its
    /// current best) into `published`, strongest first.
    fn publish(&self, published: &mut heapless::Vec<Found, MAX_SYMMETRIES>) {
        published.clone_from(&self.found);
        let walking = matches!(
            self.middle,
            Middle::Walking | Middle::Growing(Growing::Narrowing(_) | Growing::Claiming)
        );
        if walking {
            if let Some(best) = self.walk.best() {
                let (len, accept) = (self.domain_len as u32, self.accept);
                let found = Found::new(best.symmetry, best.score, len, accept);
                let _ = published.push(found);
            }
        }
    }

    /// Every domain is searched: order the symmetries strongest first (the points they explain,
    /// then type) and relabel the owners (a point of an exhausted domain becomes unclaimed).
    fn finish(&mut self, published: &mut heapless::Vec<Found, MAX_SYMMETRIES>) {
        let found = &self.found;
        let mut order: heapless::Vec<u8, MAX_SYMMETRIES> = (0..found.len() as u8).collect();
        let key = |f: &Found| {
            (
                core::cmp::Reverse(f.domain_points),
                core::cmp::Reverse(f.symmetry.kind().strength()),
            )
        };
        order.sort_unstable_by_key(|&k| key(&found[k as usize]));
        let mut rank = [Owner::UNCLAIMED; MAX_SYMMETRIES];
        for (new, &old) in order.iter().enumerate() {
            rank[old as usize] = Owner(new as u8);
        }
        for owner in self.owners.iter_mut() {
            *owner = rank
                .get(owner.0 as usize)
                .copied()
                .unwrap_or(Owner::UNCLAIMED);
        }
        let sorted: heapless::Vec<Found, MAX_SYMMETRIES> =
            order.iter().map(|&k| found[k as usize]).collect();
        self.found = sorted;
        // When the whole object's walk finds nothing, no domain is searched after it and
        // `rank[0]` is unclaimed.
        self.whole = rank[self.whole as usize].0;
        self.middle = Middle::Finished;
        self.publish(published);
    }
}

/// Centre and radius of the points of `domain`: the radius of the points on the surface the
/// domain's median point is on, `gap` the widest step between two samples of one surface
/// ([`Shells`]).
fn frame_of(points: &[Vec3], domain: &[u16], gap: f32) -> Frame {
    let n = domain.len().max(1) as f32;
    let center = domain
        .iter()
        .fold(Vec3::ZERO, |acc, &i| acc + points[i as usize])
        / n;
    let d2s = domain
        .iter()
        .map(|&i| (points[i as usize] - center).length_squared());
    let mut shells = Shells::new(gap);
    d2s.clone().for_each(|d2| shells.add(d2));
    Frame {
        center,
        radius: shells.radius(d2s).max(1e-3),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Plane;
    use crate::component::Scratch;
    use crate::config::{DomainConfig, ModelConfig};
    use crate::score::plate::{self, COLUMNS, PLATE_MM, ROWS};
    use crate::score::{Rest, View};
    use crate::search::growth::{Grown, Growth};
    use crate::symmetry::{Sampling, SymmetryType, TypeSet};
    use crate::work::Poll;

    const P: usize = 1024;
    type Plate = plate::Plate<P, 2048>;
    /// Units a step may spend: a walk step takes one, a growth or a gathering all five.
    const BUDGET: u32 = 5;

    /// Plane reflections only: one node of Table 1, so a walk is a grid and its climbs.
    fn config(parts: bool) -> Config {
        let types = TypeSet::of(&[SymmetryType::PlaneReflection]);
        let domains = DomainConfig {
            parts,
            ..DomainConfig::DEFAULT
        };
        Config {
            domains,
            ..Config::DEFAULT.with_types(types)
        }
    }

    /// The mirror `x = 0`'s image of `p`.
    fn across(p: Vec3) -> Vec3 {
        Vec3::new(-p.x, p.y, p.z)
    }

    /// An oracle for which the plate is mirror symmetric about `x = 0`: a hypothesis' match cost
    /// (eq. 8) were each of its images of the domain's points matched by the mirror's image.
    fn about_x0(points: &[Vec3], h: &Hypothesis, domain: &[u16]) -> f32 {
        let map = h.symmetry.maps(Sampling::default()).maps[0].0;
        let sum: f32 = domain
            .iter()
            .map(|&i| (map.apply(points[i as usize]) - across(points[i as usize])).length_squared())
            .sum();
        0.5 * sum / domain.len() as f32 / (h.sigma * h.sigma)
    }

    /// What a search left.
    struct Searched {
        search: DomainSearch<P>,
        published: heapless::Vec<Found, MAX_SYMMETRIES>,
        /// The sizes of the domains walked, in turn.
        walked: heapless::Vec<usize, MAX_SYMMETRIES>,
    }

    /// Search the plate as the engine does, `BUDGET` units a step, each hypothesis scored by
    /// `oracle(hypothesis, domain)`.
    fn search(plate: &Plate, parts: bool, oracle: impl Fn(&Hypothesis, &[u16]) -> f32) -> Searched {
        let config = config(parts);
        let evidence = plate.evidence();
        let cx = Context {
            evidence: &evidence,
            points: &plate.points,
            config: &config,
            stride: 1,
        };
        let len = plate.points.len;
        let all: heapless::Vec<u16, P> = (0..len as u16).collect();
        let stats = crate::prepare::ObjectStats {
            spacing: plate.spacing,
            centroid: [0.0, 0.0, 0.5],
            ..Default::default()
        };
        let gap = stats.surface_gap(&config.sensor);
        let frame = frame_of(plate.points.positions(), &all, gap);
        let mut search = DomainSearch::<P>::new(&config);
        search.begin(&config, len, frame, (plate.sigma(), gap), 0.0, None);
        let (mut scratch, mut published) = (Scratch::<P>::new(), heapless::Vec::new());
        let (mut last, mut walked) = (None, heapless::Vec::new());
        // A bound far above the steps a walk of one node takes (a grid of 864, and its climbs).
        for _ in 0..100_000 {
            if search.is_finished() {
                return Searched {
                    search,
                    published,
                    walked,
                };
            }
            let mut meter = Meter::new(BUDGET);
            let asked = search.step(
                &cx,
                last.take(),
                &mut meter,
                &mut published,
                scratch.lend(P),
            );
            assert!(meter.left() < BUDGET, "every step spends a unit");
            if let Some(h) = asked {
                let domain = search.domain();
                if walked.last() != Some(&domain.len()) {
                    walked.push(domain.len()).unwrap();
                }
                let strays = crate::score::Strays::NONE;
                last = Some(Scored {
                    score: oracle(&h, domain),
                    strays,
                    every_point: h.transformed == u32::MAX,
                });
            }
        }
        panic!("the search ends");
    }

    /// Whether `symmetry` maps every plate point within 2σ of where `x = 0` maps it (the part
    /// rules' tolerance for two fits of one element).
    fn is_across(plate: &Plate, symmetry: &Symmetry) -> bool {
        let map = symmetry.maps(Sampling::default()).maps[0].0;
        let tolerance = 2.0 * plate.sigma();
        plate
            .points
            .positions()
            .iter()
            .all(|&p| (map.apply(p) - across(p)).length() < tolerance)
    }

    #[test]
    fn without_parts_the_whole_object_is_the_one_domain() {
        let plate = Plate::square();
        let n = plate.points.len;
        let points = plate.points.positions();
        let s = search(&plate, false, |h, domain| about_x0(points, h, domain));
        let found = s.search.found();
        assert_eq!(s.walked, [n]);
        assert_eq!(found.len(), 1);
        assert!(found[0].score < ModelConfig::DEFAULT.accept);
        assert!(is_across(&plate, &found[0].symmetry), "{found:?}");
        assert_eq!(found[0].domain_points, n as u32);
        assert!(s.search.owners()[..n].iter().all(|&o| o == Owner(0)));
        assert_eq!(s.search.whole(), Owner(0));
        assert_eq!(&s.published[..], found);
    }

    #[test]
    fn a_domain_without_a_symmetry_leaves_its_points_unclaimed() {
        let plate = Plate::square();
        let n = plate.points.len;
        // Every hypothesis above the acceptance threshold (0.85).
        let s = search(&plate, true, |_, _| 2.0);
        assert!(s.search.is_finished() && s.search.found().is_empty());
        assert!(
            s.search.owners()[..n]
                .iter()
                .all(|&o| o == Owner::UNCLAIMED)
        );
        assert_eq!(s.search.whole(), Owner::UNCLAIMED);
        assert!(s.published.is_empty());
    }

    #[test]
    fn with_parts_a_symmetry_claims_what_it_explains_and_the_rest_is_searched_next() {
        // The square plate and a ledge of 10 columns to its right, 5 cm nearer the camera:
        // mirrored about `x = 0`, the ledge lands left of the plate, in front of the wall.
        let plate = Plate::new(|u, v| match u {
            _ if !ROWS.contains(&v) => None,
            22..=41 => Some(PLATE_MM),
            42..=51 => Some(PLATE_MM - 50),
            _ => None,
        });
        let (n, points) = (plate.points.len, plate.points.positions());
        // The oracle: symmetric about `x = 0` where the square is in the domain, nothing on
        // the ledge alone.
        let s = search(&plate, true, |h, domain| {
            let square = |&i: &u16| COLUMNS.contains(&plate.points.pixel[i as usize][0]);
            match domain.iter().any(square) {
                true => about_x0(points, h, domain),
                false => 2.0,
            }
        });
        // The claim (grown under the measurement model): the square, and the ledge's two corner
        // points next to it (border points with a member neighbour are absorbed).
        let claimed = |[u, v]: [u16; 2]| COLUMNS.contains(&u) || (u == 42 && (v == 14 || v == 33));
        let claims = (0..n).filter(|&i| claimed(plate.points.pixel[i])).count();
        assert_eq!(claims, 402);
        // The whole plate, then the rest of the ledge.
        assert_eq!(s.walked, [n, n - claims]);
        let found = s.search.found();
        assert_eq!(found.len(), 1);
        assert!(is_across(&Plate::square(), &found[0].symmetry));
        assert_eq!(found[0].domain_points, claims as u32);
        for i in 0..n {
            let owner = match claimed(plate.points.pixel[i]) {
                true => Owner(0),
                false => Owner::UNCLAIMED,
            };
            assert_eq!(s.search.owners()[i], owner, "point {i}");
        }
        assert_eq!(s.search.whole(), Owner(0));
        assert_eq!(&s.published[..], found);
    }

    /// Points on the pixels `on` says, in raster order.
    fn lattice(on: impl Fn(u16, u16) -> bool) -> Points<P> {
        let mut points = Points::new();
        for v in 0..48 {
            for u in 0..64 {
                if on(u, v) {
                    (points.pixel[points.len], points.len) = ([u, v], points.len + 1);
                }
            }
        }
        points
    }

    /// Run `growth` over every point, `slice` units a call: what it grew, the domain list
    /// after, the units spent.
    fn grow<const V: usize, const C: usize>(
        growth: &mut Growth<P>,
        evidence: &Evidence<'_, V, C>,
        points: &Points<P>,
        slice: u32,
    ) -> (Grown, heapless::Vec<u16, P>, u32) {
        let mut domain: heapless::Vec<u16, P> = (0..points.len as u16).collect();
        let (mut scratch, mut units) = (Scratch::<P>::new(), 0);
        loop {
            let mut meter = Meter::new(slice);
            let lent = scratch.lend(P);
            let poll = growth.advance(evidence, points, &mut domain, lent, &mut meter);
            units += slice - meter.left();
            if let Poll::Ready(grown) = poll {
                return (grown, domain, units);
            }
            assert!(meter.left() < slice, "every call makes progress");
        }
    }

    #[test]
    fn growth_finds_the_largest_connected_part_on_the_sampling_lattice() {
        // Two blocks of even pixels, three lattice steps apart: 5 x 4 and 3 x 3 points.
        let big = |u: u16, v: u16| (10..=18).contains(&u) && (10..=16).contains(&v);
        let small = |u: u16, v: u16| (24..=28).contains(&u) && (10..=14).contains(&v);
        let even = |u: u16, v: u16| u.is_multiple_of(2) && v.is_multiple_of(2);
        let points = lattice(|u, v| even(u, v) && (big(u, v) || small(u, v)));
        // A component search reads no evidence.
        let observed = crate::depth::DepthGrid::<64>::new();
        let voxels = crate::voxel::VoxelMap::<16>::new();
        let evidence = Evidence {
            view: crate::score::View {
                intrinsics: &plate::K,
                depth_scale: plate::SCALE,
                observed: &observed,
                around: &[],
                table: None,
                lowest: 0.0,
                lateral_cost: f32::INFINITY,
                front: 0.0,
                top: f32::INFINITY,
            },
            voxels: &voxels,
            points: &[],
        };
        let mut growth = Growth::<P>::default();
        growth.begin_component(2);
        let (grown, domain, units) = grow(&mut growth, &evidence, &points, u32::MAX);
        assert_eq!(grown, Grown::Domain(20));
        // The members first, then the others, each in their order.
        let in_big = |&i: &u16| {
            let [u, v] = points.pixel[i as usize];
            big(u, v)
        };
        let (members, others) = domain.split_at(20);
        assert!(members.iter().all(in_big) && members.is_sorted());
        assert!(!others.iter().any(in_big) && others.is_sorted());
        // The same one unit at a time.
        growth.begin_component(2);
        assert_eq!(
            grow(&mut growth, &evidence, &points, 1),
            (grown, domain, units)
        );
        // On a lattice of stride 1, no two of these points are neighbours.
        growth.begin_component(1);
        assert_eq!(grow(&mut growth, &evidence, &points, 7).0, Grown::Domain(1));
    }

    #[test]
    fn growth_for_a_proposal_keeps_the_points_it_does_not_contradict() {
        let plate = Plate::square();
        let model = ModelConfig::DEFAULT;
        let mut growth = Growth::<P>::default();
        let mut grown = |normal: Vec3, offset: f32| {
            let mirror = Symmetry::PlaneReflection(Plane::new(normal, offset).unwrap());
            let (level, occluded) = (plate.level(), model.cost_occluded);
            growth.begin_proposal(&mirror, Sampling::default(), level, None, occluded, 1);
            grow(&mut growth, &plate.evidence(), &plate.points, BUDGET).0
        };
        // The square's own mirror explains all of it: more than `max_share` of the domain.
        assert_eq!(grown(Vec3::X, 0.0), Grown::Nearly);
        // A mirror 5 cm before the plate puts every image 0.1 m in front of it: none qualifies.
        assert_eq!(grown(Vec3::Z, 0.45), Grown::Nothing);
    }

    #[test]
    fn growth_costs_images_as_the_score_does_with_the_contact_term() {
        let plate = Plate::square();
        let model = ModelConfig::DEFAULT;
        let on_wall = Evidence {
            view: View {
                table: Some(plate::WALL),
                ..plate.view()
            },
            ..plate.evidence()
        };
        let mut growth = Growth::<P>::default();
        // Halfway between the plate and the wall: every image lies on the wall, hidden behind
        // the plate, at the acceptance threshold (a part's claim) ...
        let level = Symmetry::PlaneReflection(Plane::new(Vec3::Z, 0.65).unwrap());
        let mut grown = |rest: Option<Rest>| {
            let (costs, accept) = (plate.level(), model.accept);
            growth.begin_proposal(&level, Sampling::default(), costs, rest, accept, 1);
            grow(&mut growth, &on_wall, &plate.points, BUDGET).0
        };
        // ... explained as the underside touching the support the plate rests on ...
        assert_eq!(grown(on_wall.view.rest()), Grown::Nearly);
        // ... and only occluded without it (`cost_occluded`, above the threshold).
        assert_eq!(grown(None), Grown::Nothing);
    }
}
