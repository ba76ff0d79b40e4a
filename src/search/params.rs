//! The inner loop (paper section 5.1): for one type, constraint and domain, find the parameter
//! vectors whose score passes the threshold.
//!
//! 1. **Grid**: every grid point of each family is scored on a sparse subset of the points, at a
//!    match σ of half the grid spacing, wider for a dual's second plane (so a true symmetry
//!    between grid points still shows; see [`ParamSearch::grid_sigma`]).
//!    The best distinct local minima are kept (non-maximum suppression at the grid spacing),
//!    and each family's best grid point with them: the families of one search are different
//!    constraints (an axis in one plane, normal to another), and a ridge of near-duplicate minima
//!    in one family must not crowd another family out.
//! 2. **Hill climbing**: each minimum is refined by a pattern search: every parameter is stepped
//!    by ±ρ (see [`super::family`]); improvements are taken; when none is left, ρ and the match σ
//!    halve, down to the finest σ the sampling supports. Scores are taken on a denser subset.
//!    In a retry's climbs (below), at the first step size, where the climb chooses its basin, a
//!    mirror plane none of whose steps improves is also tilted about the lines half its radius
//!    off its centre ([`Family::tilt`]): a tilt and a shift at once. The seen points of a
//!    one-sided view lie lopsided about the true plane, so a grid plane through their centre
//!    may be off it by a tilt about another point; the shift moves every image by 2ρ and the
//!    tilt only the farthest ones, so each alone may score worse at the first ρ than the
//!    diagonal does, and the climb stall short of a plane the model accepts. Cost: at most
//!    `2 × TILTS` more evaluations per round that improved nothing, at the first ρ only.
//! 3. **Merge and threshold**: refined duplicates are merged, the rest sorted by score, and those
//!    below the model's acceptance threshold kept. Those above it are kept apart, best first: the
//!    proposals the domain search may narrow the domain for. With a retry
//!    ([`ParamSearch::retry`], the plane and point nodes'), when no climb passed, the next best
//!    distinct grid minima are climbed too, and for planes the first minima again with the
//!    tilts. Only there: where a climb passes, the tilts would move planes the model already
//!    accepts to nearby optima of its own (a scanned object is not exactly symmetric), and the
//!    axes and parts those planes constrain with them. A dual plane's retry (the dual node's)
//!    climbs its best [`RETRY_ENDS`] rejected ends again in all five of the pair's parameters
//!    ([`Family::retry_dims`]): its first plane too, which the first climbs kept where the plane
//!    node put it. A pair such a wider climb passes is scored once more over every point of the
//!    domain, each mirror also held to the halves test about its own plane, and kept only if it
//!    passes there too: a climb in more parameters fits the subsample it scores more closely
//!    (a bottle on its side, a mug: pairs that pass on the subsample and whose second plane
//!    the rest contradicts). Cost: the retry's climbs, in dual nodes that failed only, and one
//!    evaluation over every point per pair that passes.
//!
//!    A dual's or a triple's climb whose last evaluation scored a subsample of its images (two
//!    or three images per point: more than `SearchConfig::polish_transformed` on a domain of
//!    more than 600 or 400 points, [`Scored::every_point`] false) has its passing end scored
//!    over every point the same way (without the halves test), and kept only if it passes
//!    there: a pair or a triple reported is one the model accepts over all its points, not on
//!    a sample that missed the images contradicting it (an axis is held to the same by the
//!    appendage check, `super::types`; a sphere's and an axis + plane's climbs, which also
//!    polish on a subsample, are not checked again). Cost: one evaluation over every point (two
//!    or three work units a point) per such end; none where the climb already scored them all.
//!
//! The search is a state machine driven by [`ParamSearch::next`]: it receives the score of the
//! hypothesis it last asked for and returns the next one to score. Each call is O(1) work apart
//! from the candidate bookkeeping (at most [`MAX_CANDIDATES`] comparisons).

use super::family::{Family, Frame, TILTS, same_symmetry};
use crate::config::SearchConfig;
use crate::math::Vec3;
use crate::score::Scored;
use crate::symmetry::Symmetry;

/// Most families one search walks (an axial search constrained by two planes, two ways each,
/// and the support's normal).
pub const MAX_FAMILIES: usize = 5;
/// Most local minima refined (the best [`SearchConfig::candidates`], then each family's best
/// grid point that is not among them), and most results kept: room for the default four and
/// the best of every family ([`MAX_FAMILIES`]), so that no family goes unclimbed (the
/// support's normal, searched last, was left out whenever two planes were carried).
pub const MAX_CANDIDATES: usize = 9;
/// Most spare grid minima kept for a retry ([`ParamSearch::retry`]): as many again as the
/// default four first ones.
pub const SPARE: usize = 4;
/// Rejected climb ends a retry climbs again in more parameters ([`Family::retry_dims`]): the
/// best two, as many as the planes a dual node is given (`super::types`), so that the pair
/// each of them leads to may be re-fitted whole.
pub const RETRY_ENDS: usize = 2;

/// A scored hypothesis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    pub symmetry: Symmetry,
    pub score: f32,
    /// Index of the family it belongs to.
    pub family: u8,
}

/// What the search wants next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Request {
    /// Score this hypothesis at match σ `sigma` over about `transformed` transformed points;
    /// with `tally`, also note where its images stray ([`crate::score::Strays`]); with
    /// `every_mirror`, hold each mirror to the halves test about its own plane
    /// ([`crate::score::Evaluation::halves_about_every_mirror`]).
    Evaluate {
        symmetry: Symmetry,
        sigma: f32,
        transformed: u32,
        tally: bool,
        every_mirror: bool,
    },
    /// The search is over; [`ParamSearch::accepted`] holds the result.
    Done,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Climb {
    candidate: u8,
    base: Symmetry,
    base_score: Option<f32>,
    rho: f32,
    trial: u8,
    improved: bool,
    rounds: u8,
    /// Times `rho` has been halved; at most [`MAX_HALVINGS`].
    halvings: u8,
}

/// Whether a passing climb of `symmetry` that scored a subsample of its images is confirmed
/// over every point (see the module docs): a dual's or a triple's polishing climb may score a
/// subsample; one mirror, a half-turn or a point reflection scores all of its own on any domain
/// of at most `polish_transformed` points, and an axis is confirmed by the appendage check
/// ([`super::types`]).
fn checked_over_every_point(symmetry: &Symmetry) -> bool {
    matches!(symmetry, Symmetry::DualPlane(_) | Symmetry::TriplePlane(_))
}

/// Most halvings of one climb's step. From half a grid spacing down to a quarter of the finest
/// σ takes about 6; the bound only matters for a frame no real object has (an infinite or NaN
/// step never gets below the finest), where it ends the climb instead of looping.
const MAX_HALVINGS: u8 = 40;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Grid {
        family: u8,
        index: u32,
    },
    Climb(Climb),
    /// A climb that scored a subsample of its images passed, or a retry's climb in more
    /// parameters did: its end is scored over every point of the domain (then the climb of
    /// minimum `next`).
    Verify {
        end: Candidate,
        next: u8,
    },
    Done,
}

/// The inner-loop state machine (see the module docs).
#[derive(Clone, Debug)]
pub struct ParamSearch {
    config: SearchConfig,
    families: heapless::Vec<Family, MAX_FAMILIES>,
    frame: Frame,
    sigma_fine: f32,
    accept: f32,
    phase: Phase,
    pending: Option<Symmetry>,
    /// Per family: grid minima closer than this (cosine of the angle, displacement) are one.
    distinct: [(f32, f32); MAX_FAMILIES],
    minima: heapless::Vec<Candidate, MAX_CANDIDATES>,
    /// Per family: its best grid point, climbed too when no minimum is of that family.
    family_best: [Option<Candidate>; MAX_FAMILIES],
    /// With [`ParamSearch::retry`]: the next best distinct grid minima, climbed only when no
    /// climb from the first ones passed.
    spare: heapless::Vec<Candidate, SPARE>,
    /// Whether spare minima are kept, to be climbed when the first climbs all fail.
    retry: bool,
    /// Whether the climbs are a retry's: a plane's also try the tilts, a dual's step its first
    /// plane too.
    retrying: bool,
    results: heapless::Vec<Candidate, MAX_CANDIDATES>,
    /// The refined candidates the threshold rejected, distinct: what the domain search proposes
    /// parts of the domain for.
    rejected: heapless::Vec<Candidate, MAX_CANDIDATES>,
}

/// Keep `c` in `kept`, at most `room` distinct candidates (`twins`: one candidate), if it is
/// among the best: it replaces a worse twin, takes a free place, or replaces the worst; returns
/// the one displaced, or `c` when not good enough (`None` when it had a twin).
fn keep_best<const N: usize>(
    kept: &mut heapless::Vec<Candidate, N>,
    c: Candidate,
    room: usize,
    twins: impl Fn(&Candidate) -> bool,
) -> Option<Candidate> {
    if let Some(i) = kept.iter().position(twins) {
        if c.score < kept[i].score {
            kept[i] = c;
        }
        return None;
    }
    if kept.len() < room.min(N) {
        let _ = kept.push(c);
        return None;
    }
    let worst = (kept.iter().enumerate())
        .max_by(|a, b| a.1.score.total_cmp(&b.1.score))
        .map(|(i, _)| i);
    Some(match worst.filter(|&w| c.score < kept[w].score) {
        Some(w) => core::mem::replace(&mut kept[w], c),
        None => c,
    })
}

impl ParamSearch {
    pub const fn new(config: SearchConfig) -> Self {
        Self {
            config,
            families: heapless::Vec::new(),
            frame: Frame {
                center: Vec3::ZERO,
                radius: 0.0,
            },
            sigma_fine: 0.0,
            accept: 0.0,
            phase: Phase::Done,
            pending: None,
            distinct: [(1.0, 0.0); MAX_FAMILIES],
            minima: heapless::Vec::new(),
            family_best: [None; MAX_FAMILIES],
            spare: heapless::Vec::new(),
            retry: false,
            retrying: false,
            results: heapless::Vec::new(),
            rejected: heapless::Vec::new(),
        }
    }

    /// Start searching `families` around `frame`, down to match σ `sigma_fine`, keeping scores
    /// below `accept`.
    pub fn begin(&mut self, families: &[Family], frame: Frame, sigma_fine: f32, accept: f32) {
        self.families.clear();
        for f in families.iter().take(MAX_FAMILIES) {
            let _ = self.families.push(*f);
        }
        self.frame = frame;
        self.sigma_fine = sigma_fine;
        // One grid spacing apart (as an angle at the object's radius and as a displacement).
        for (f, slot) in self.families.iter().zip(self.distinct.iter_mut()) {
            let spacing = f.grid_spacing(&self.config.grid, &frame);
            *slot = (
                crate::math::sin_cos(spacing / frame.radius.max(1e-6)).1,
                spacing,
            );
        }
        self.accept = accept;
        self.phase = Phase::Grid {
            family: 0,
            index: 0,
        };
        self.pending = None;
        self.minima.clear();
        self.family_best = [None; MAX_FAMILIES];
        (self.spare, self.retry, self.retrying) = (heapless::Vec::new(), false, false);
        self.results.clear();
        self.rejected.clear();
    }

    /// From now until the next `begin`: when no climb from the best grid minima passes, climb
    /// from the next best distinct ones too (at most [`SPARE`]), as a multi-start search does
    /// when every start failed, and a mirror plane's from the first ones again with the tilts
    /// (see the module docs). For the roots of Table 1's branches (the plane and point nodes,
    /// see `super::types`); it costs climbs only where the first ones all failed.
    pub fn retry(&mut self) {
        self.retry = true;
    }

    /// Start like [`ParamSearch::begin`], but skip the grid: hill-climb from `seed` alone (a
    /// candidate of one of `families`, e.g. a proposal refined on a wider domain).
    pub fn begin_from(
        &mut self,
        families: &[Family],
        seed: Candidate,
        frame: Frame,
        sigma_fine: f32,
        accept: f32,
    ) {
        self.begin(families, frame, sigma_fine, accept);
        let _ = self.minima.push(seed);
        // Past the last family: the next request starts the climb.
        self.phase = Phase::Grid {
            family: MAX_FAMILIES as u8,
            index: 0,
        };
    }

    /// The accepted symmetries, best first (final once `next` returned `Done`).
    pub fn accepted(&self) -> &[Candidate] {
        &self.results
    }

    /// The distinct refined candidates that missed the threshold, best first (final once `next`
    /// returned `Done`).
    pub fn rejected(&self) -> &[Candidate] {
        &self.rejected
    }

    /// The grid spacing of `family` on the frame searched: the resolution of its grid.
    pub fn grid_spacing(&self, family: Family) -> f32 {
        family.grid_spacing(&self.config.grid, &self.frame)
    }

    /// Starting displacement of the hill climber for `family`: half its grid spacing.
    fn rho0(&self, family: u8) -> f32 {
        self.grid_spacing(self.families[family as usize]) * 0.5
    }

    /// The match σ the grid points of `family` are scored at: half its spacing (the climb's
    /// first step), and for [`Family::DualWith`] √2 times that. A dual's second plane has one
    /// angle and one offset; the grid point nearest the true plane may be half an offset step
    /// off, which moves every image (not only the farthest, as an angle does) by a whole step,
    /// 2σ at half the spacing: cost 2, above `cost_occluded`, so the true plane's grid points
    /// score no better than planes off the object. At √2 times, that image sits at the match
    /// gate (`d² k_match = cost_occluded`). The other families keep half their spacing: the self
    /// radius grows with σ, and at the wider σ it hides a thin part's plane from the free plane
    /// grid (the test kit's figure: its leg's axis 0.8° off at half the spacing, 5.4° at √2
    /// times).
    fn grid_sigma(&self, family: u8) -> f32 {
        let widen = match self.families.get(family as usize) {
            Some(Family::DualWith(_)) => core::f32::consts::SQRT_2,
            _ => 1.0,
        };
        self.sigma(self.rho0(family) * widen)
    }

    fn sigma(&self, rho: f32) -> f32 {
        self.sigma_fine.max(rho)
    }

    /// Transformed points per hill-climbing evaluation at step `rho`.
    fn transformed(&self, rho: f32) -> u32 {
        if rho < self.sigma_fine {
            self.config.polish_transformed
        } else {
            self.config.climb_transformed
        }
    }

    /// Take the score of the last request, return the next request.
    pub fn next(&mut self, last: Option<Scored>) -> Request {
        let last_score = last.map(|s| s.score);
        match self.phase {
            Phase::Grid { family, index } => {
                if let (Some(symmetry), Some(score)) = (self.pending.take(), last_score) {
                    self.offer(Candidate {
                        symmetry,
                        score,
                        family,
                    });
                }
                self.next_grid_point(family, index)
            }
            Phase::Climb(climb) => self.climb(climb, last),
            Phase::Verify { mut end, next } => {
                // Rejected over every point: kept among the rejected at that score.
                let every = last_score.unwrap_or(f32::INFINITY);
                if every >= self.accept {
                    end.score = every;
                }
                self.keep_result(end);
                self.start_climb(next)
            }
            Phase::Done => Request::Done,
        }
    }

    fn next_grid_point(&mut self, mut family: u8, mut index: u32) -> Request {
        while let Some(f) = self.families.get(family as usize) {
            if index >= f.grid_len(&self.config.grid) {
                (family, index) = (family + 1, 0);
                continue;
            }
            let point = f.grid_point(index, &self.config.grid, &self.frame);
            index += 1;
            if let Some(symmetry) = point {
                self.phase = Phase::Grid { family, index };
                self.pending = Some(symmetry);
                let sigma = self.grid_sigma(family);
                return Request::Evaluate {
                    symmetry,
                    sigma,
                    transformed: self.config.grid_transformed,
                    tally: false,
                    every_mirror: false,
                };
            }
        }
        self.add_family_bests();
        self.start_climb(0)
    }

    /// Add to the minima each family's best grid point when none of the minima is of that
    /// family (as many as there is room for, in family order).
    fn add_family_bests(&mut self) {
        for best in self.family_best.iter().flatten() {
            if !self.minima.iter().any(|m| m.family == best.family) {
                let _ = self.minima.push(*best);
            }
        }
    }

    /// Keep `c` if it is among the best distinct minima so far, or the best of its family; with
    /// a retry, the one it displaces (or `c`, not good enough) among the spare ones.
    fn offer(&mut self, c: Candidate) {
        if !c.score.is_finite() {
            return;
        }
        let best = &mut self.family_best[c.family as usize];
        if best.is_none_or(|b| c.score < b.score) {
            *best = Some(c);
        }
        let room = (self.config.candidates as usize).clamp(1, MAX_CANDIDATES);
        let twins = self.twins(&c);
        let out = keep_best(&mut self.minima, c, room, twins);
        if let Some(out) = out.filter(|_| self.retry) {
            let twins = self.twins(&out);
            keep_best(&mut self.spare, out, SPARE, twins);
        }
    }

    /// Whether a candidate is `c` within a grid spacing of `c`'s family (one minimum).
    fn twins(&self, c: &Candidate) -> impl Fn(&Candidate) -> bool + use<> {
        let ((cos, spacing), center, s) = (
            self.distinct[c.family as usize],
            self.frame.center,
            c.symmetry,
        );
        move |m: &Candidate| same_symmetry(&m.symmetry, &s, cos, spacing, center)
    }

    /// Append to the minima the spare ones no minimum already stands for, best first (as
    /// many as there is room for); the spare ones are spent.
    fn add_spare(&mut self) {
        let mut spare = core::mem::take(&mut self.spare);
        spare.sort_unstable_by(|a, b| a.score.total_cmp(&b.score));
        for c in spare {
            let twins = self.twins(&c);
            if !self.minima.iter().any(twins) && self.minima.push(c).is_err() {
                break;
            }
        }
    }

    fn start_climb(&mut self, mut candidate: u8) -> Request {
        // Spare minima are kept only with a retry, and spent by it: once, climbing the first
        // minima again too, with the tilts, where a family has them.
        if candidate as usize == self.minima.len() && self.results.is_empty() && !self.retrying {
            // A composite's retry: its best rejected ends again, in all their parameters.
            if self.retry && self.families.iter().any(|f| f.retry_dims() > f.dims()) {
                self.retrying = true;
                self.minima.clear();
                for end in self.rejected.iter().take(RETRY_ENDS) {
                    let _ = self.minima.push(*end);
                }
                return self.start_climb(0);
            }
            self.add_spare();
            self.retrying = self.retry;
            if self.retry && self.families.iter().any(Family::tilts) {
                candidate = 0;
            }
        }
        let Some(start) = self.minima.get(candidate as usize).copied() else {
            return self.finish();
        };
        let rho = self.rho0(start.family);
        self.phase = Phase::Climb(Climb {
            candidate,
            base: start.symmetry,
            base_score: None,
            rho,
            trial: 0,
            improved: false,
            rounds: 0,
            halvings: 0,
        });
        self.climb_request(start.symmetry, rho)
    }

    /// Score `symmetry` at the resolution of hill-climbing step `rho`.
    fn climb_request(&self, symmetry: Symmetry, rho: f32) -> Request {
        Request::Evaluate {
            symmetry,
            sigma: self.sigma(rho),
            transformed: self.transformed(rho),
            tally: false,
            every_mirror: false,
        }
    }

    fn climb(&mut self, mut c: Climb, last: Option<Scored>) -> Request {
        let score = last.map_or(f32::INFINITY, |s| s.score);
        // Whether the score a climb ends on scored every point: the last one, as every
        // evaluation of its last step size scores the same points.
        let every_point = last.is_some_and(|s| s.every_point);
        let family = self.families[self.minima[c.candidate as usize].family as usize];
        // A retry's climbs may step more parameters than the first ones (a dual's first plane).
        let dims = if self.retrying {
            family.retry_dims()
        } else {
            family.dims()
        };
        let steps = 2 * dims;
        match (c.base_score, self.pending.take()) {
            (None, _) => c.base_score = Some(score),
            (Some(base), Some(trial)) => {
                if score < base {
                    (c.base, c.base_score, c.improved) = (trial, Some(score), true);
                }
                c.trial += 1;
            }
            (Some(_), None) => c.trial += 1,
        }
        loop {
            // The steps, then, in a retry's climbs at the first ρ when none improved, the tilts
            // (module docs).
            let tilts = if self.retrying && c.halvings == 0 && !c.improved {
                2 * TILTS
            } else {
                0
            };
            if c.trial < steps + tilts {
                let rho = if c.trial.is_multiple_of(2) {
                    c.rho
                } else {
                    -c.rho
                };
                let moved = if c.trial < steps {
                    family.step(&c.base, c.trial / 2, rho, &self.frame)
                } else {
                    family.tilt(&c.base, (c.trial - steps) / 2, rho, &self.frame)
                };
                if let Some(symmetry) = moved {
                    self.phase = Phase::Climb(c);
                    self.pending = Some(symmetry);
                    return self.climb_request(symmetry, c.rho);
                }
                c.trial += 1;
                continue;
            }
            if c.improved && c.rounds + 1 < self.config.rounds_per_level {
                (c.trial, c.improved, c.rounds) = (0, false, c.rounds + 1);
                continue;
            }
            let sigma_before = self.sigma(c.rho);
            c.rho *= 0.5;
            c.halvings += 1;
            let finest = self.sigma_fine * self.config.finest_step;
            if c.rho < finest || c.halvings >= MAX_HALVINGS {
                let family_index = self.minima[c.candidate as usize].family;
                let done = Candidate {
                    symmetry: c.base,
                    score: c.base_score.unwrap_or(f32::INFINITY),
                    family: family_index,
                };
                let next = c.candidate + 1;
                let wider = dims > family.dims();
                let sampled = checked_over_every_point(&done.symmetry) && !every_point;
                if (wider || sampled) && done.score < self.accept {
                    self.phase = Phase::Verify { end: done, next };
                    return Request::Evaluate {
                        symmetry: done.symmetry,
                        sigma: self.sigma_fine,
                        transformed: u32::MAX,
                        tally: false,
                        every_mirror: wider,
                    };
                }
                self.keep_result(done);
                return self.start_climb(next);
            }
            (c.trial, c.improved, c.rounds) = (0, false, 0);
            if self.sigma(c.rho) != sigma_before
                || self.transformed(c.rho) != self.transformed(c.rho * 2.0)
            {
                c.base_score = None;
                self.phase = Phase::Climb(c);
                return self.climb_request(c.base, c.rho);
            }
        }
    }

    /// Add a refined candidate to the results (or, above the threshold, to the rejected) unless
    /// a better duplicate is there; replace a worse one.
    fn keep_result(&mut self, c: Candidate) {
        let passes = c.score < self.accept;
        if !passes && !c.score.is_finite() {
            return;
        }
        let distance = self.frame.same_within(self.sigma_fine);
        let center = self.frame.center;
        let kept = if passes {
            &mut self.results
        } else {
            &mut self.rejected
        };
        match kept.iter().position(|r| {
            same_symmetry(
                &r.symmetry,
                &c.symmetry,
                super::family::COS_5_DEG,
                distance,
                center,
            )
        }) {
            Some(i) if c.score < kept[i].score => kept[i] = c,
            Some(_) => {}
            None => {
                let _ = kept.push(c);
            }
        }
    }

    fn finish(&mut self) -> Request {
        for kept in [&mut self.results, &mut self.rejected] {
            kept.sort_unstable_by(|a, b| a.score.total_cmp(&b.score));
        }
        self.phase = Phase::Done;
        Request::Done
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Plane;
    use crate::score::Strays;

    /// `score` as an evaluation reports it, over every point or over a subsample of them (a
    /// domain with more images than the request's `transformed`).
    fn scored(score: f32, every_point: bool) -> Option<Scored> {
        Some(Scored {
            score,
            strays: Strays::NONE,
            every_point,
        })
    }

    /// Drives a search with constant scores and returns how many hypotheses it asked for.
    fn requests_until_done(frame: Frame, sigma_fine: f32) -> u32 {
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        search.begin(&[Family::Plane], frame, sigma_fine, 0.85);
        let mut requests = 0;
        let mut score = None;
        while let Request::Evaluate { .. } = search.next(score) {
            requests += 1;
            assert!(requests < 100_000, "the search does not end");
            score = scored(0.5, false);
        }
        requests
    }

    /// Requests, accepted and rejected results of a plane search scoring every hypothesis
    /// `score`, with or without a retry.
    fn constant_search(retry: bool, score: f32) -> (u32, usize, usize) {
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.05,
        };
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        search.begin(&[Family::Plane], frame, 0.003, 0.85);
        if retry {
            search.retry();
        }
        let (mut requests, mut last) = (0, None);
        while let Request::Evaluate { .. } = search.next(last) {
            (requests, last) = (requests + 1, scored(score, false));
        }
        (requests, search.accepted().len(), search.rejected().len())
    }

    #[test]
    fn a_retry_climbs_the_next_minima_only_when_every_climb_failed() {
        // A climb passes: the retry costs nothing and changes nothing.
        assert_eq!(constant_search(true, 0.5), constant_search(false, 0.5));
        // Every climb fails: the next best distinct minima are climbed too.
        let (first, retried) = (constant_search(false, 1.0), constant_search(true, 1.0));
        assert_eq!(first.2, SearchConfig::DEFAULT.candidates as usize);
        assert_eq!(retried.2, first.2 + SPARE);
        assert!(retried.0 > first.0);
    }

    #[test]
    fn climbs_end_for_any_frame() {
        let grid = Family::Plane.grid_len(&crate::config::GridConfig::DEFAULT);
        let real = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.05,
        };
        assert!(requests_until_done(real, 0.003) > grid);
        // A frame no real object has (the fuzzer's 6.9e17 m per depth unit gave one): a step
        // that never gets below the finest σ must still end each climb.
        for radius in [f32::INFINITY, f32::NAN, 1e30] {
            let frame = Frame { radius, ..real };
            let requests = requests_until_done(frame, 0.003);
            assert!(requests >= grid, "{radius}: {requests}");
        }
    }

    #[test]
    fn a_duals_second_plane_is_gridded_at_a_wider_sigma() {
        // The first request of each search is its first grid point, at its family's grid σ.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.1,
        };
        let first_sigma = |family: Family| {
            let mut search = ParamSearch::new(SearchConfig::DEFAULT);
            search.begin(&[family], frame, 0.003, 0.85);
            let half = search.grid_spacing(family) * 0.5;
            match search.next(None) {
                Request::Evaluate { sigma, .. } => sigma / half,
                Request::Done => f32::NAN,
            }
        };
        let first = Plane::new(Vec3::X, 0.0).unwrap();
        assert!((first_sigma(Family::Plane) - 1.0).abs() < 1e-6);
        assert!((first_sigma(Family::AxialIn(first)) - 1.0).abs() < 1e-6);
        let dual = first_sigma(Family::DualWith(first));
        assert!((dual - core::f32::consts::SQRT_2).abs() < 1e-6, "{dual}");
    }

    #[test]
    fn each_family_gets_its_best_grid_point_climbed() {
        // Every plane scores better than every point reflection: without its family's share,
        // the point reflection would never be climbed.
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.05,
        };
        search.begin(&[Family::Plane, Family::Point], frame, 0.003, 0.85);
        let score = |s: &Symmetry| match s {
            Symmetry::PlaneReflection(p) => 0.5 + 0.1 * p.normal[0].abs(),
            _ => 0.7,
        };
        let mut last = None;
        while let Request::Evaluate { symmetry, .. } = search.next(last) {
            last = scored(score(&symmetry), false);
        }
        let families: heapless::Vec<u8, MAX_CANDIDATES> =
            search.accepted().iter().map(|c| c.family).collect();
        assert!(
            families.contains(&0) && families.contains(&1),
            "{families:?}"
        );
    }

    #[test]
    fn the_supports_axes_are_climbed_beside_two_planes_two_ways_each() {
        // The axial node's most families: axes in and across each of two carried planes, and
        // along the support's normal, searched last and scoring worst (yet accepted): it is
        // climbed all the same.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.05,
        };
        let plane = |n: Vec3| Plane::through(frame.center, n);
        let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
        let families = [
            Family::AxialIn(plane(x)),
            Family::AxialNormal(plane(x)),
            Family::AxialIn(plane(y)),
            Family::AxialNormal(plane(y)),
            Family::AxialNormal(plane(z)),
        ];
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        search.begin(&families, frame, 0.003, 0.85);
        let score = |s: &Symmetry| 0.5 + 0.3 * s.axis().map_or(1.0, |a| a.d().dot(z).abs());
        let mut last = None;
        while let Request::Evaluate { symmetry, .. } = search.next(last) {
            last = scored(score(&symmetry), false);
        }
        let climbed: heapless::Vec<u8, MAX_CANDIDATES> =
            search.accepted().iter().map(|c| c.family).collect();
        assert!(climbed.contains(&4), "families climbed: {climbed:?}");
    }

    /// Drives a dual search from `carried` (with a retry when asked), each hypothesis scoring
    /// `score` and each check over every point `every` (`None`: as the climb scores it), the
    /// climbs scoring every point when `whole` (a small domain). Returns the finished search,
    /// its checks over every point and those with the halves test.
    fn dual_search(
        carried: Plane,
        frame: Frame,
        retry: bool,
        score: impl Fn(&Symmetry) -> f32,
        every: Option<f32>,
        whole: bool,
    ) -> (ParamSearch, u32, u32) {
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        search.begin(&[Family::DualWith(carried)], frame, 0.003, 0.85);
        if retry {
            search.retry();
        }
        let (mut last, mut checks, mut halves) = (None, 0, 0);
        while let Request::Evaluate {
            symmetry,
            transformed,
            every_mirror,
            ..
        } = search.next(last)
        {
            // Every passing end of a pair is checked over every point; a retry's also with the
            // halves test about each mirror.
            let every_point = transformed == u32::MAX;
            assert!(every_point || !every_mirror);
            (checks, halves) = (checks + every_point as u32, halves + every_mirror as u32);
            let checked = every.filter(|_| every_point);
            last = scored(checked.unwrap_or(score(&symmetry)), whole || every_point);
        }
        (search, checks, halves)
    }

    #[test]
    fn a_duals_retry_refits_its_first_plane_and_checks_the_pair_over_every_point() {
        // The true pair: the planes through the centre normal to x and y. The dual node is given
        // the first plane turned 0.1 rad about z; every pair with it scores 0.9 or more (the
        // second plane, orthogonal to it, is as far off), over the threshold: only a climb that
        // turns the first plane too gets below it.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.1,
        };
        let (sin, cos) = crate::math::sin_cos(0.1);
        let carried = Plane::through(frame.center, Vec3::new(cos, sin, 0.0));
        let off = |q: &Plane, axis: Vec3| {
            let d = q.signed_distance(frame.center);
            40.0 * (1.0 - q.n().dot(axis).abs()) + 4e3 * d * d
        };
        let score = |s: &Symmetry| match s {
            Symmetry::DualPlane([a, b]) => 0.5 + off(a, Vec3::X) + off(b, Vec3::Y),
            _ => f32::INFINITY,
        };
        // (accepted, rejected, checks) with or without a retry, the check scoring `every`
        // (`None`: as the climb did). No first climb passes, so every check is a retry's, with
        // the halves test.
        let search = |retry: bool, every: Option<f32>| {
            let (search, checks, halves) = dual_search(carried, frame, retry, score, every, false);
            assert_eq!(checks, halves);
            let first = |c: &[Candidate]| c.first().map(|c| c.symmetry);
            (first(search.accepted()), first(search.rejected()), checks)
        };
        assert!(matches!(search(false, None), (None, Some(_), 0)));
        let (found, _, checks) = search(true, None);
        let Some(Symmetry::DualPlane([a, b])) = found else {
            panic!("no dual accepted: {found:?}");
        };
        assert!(checks >= 1);
        assert!(off(&a, Vec3::X) + off(&b, Vec3::Y) < 0.05, "{a:?} {b:?}");
        // The pair passes the climb's test but not the test over every point: rejected.
        let (found, rejected, checks) = search(true, Some(1.0));
        assert!(found.is_none() && rejected.is_some() && checks >= 1);
        // The retry's check adds the halves test: it runs where the climb scored every point.
        let (_, checks, halves) = dual_search(carried, frame, true, score, None, true);
        assert!(checks >= 1 && checks == halves, "{checks} {halves}");
    }

    #[test]
    fn a_pair_that_passes_on_its_subsample_is_kept_only_if_every_point_passes_it() {
        // The dual node given the true first plane: its climbs pass on the polishing
        // subsample. Each passing end is scored once more over every point (without the halves
        // test, which only a retry's wider climb adds) and kept only if it passes there too.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.1,
        };
        let carried = Plane::through(frame.center, Vec3::X);
        let score = |s: &Symmetry| match s {
            Symmetry::DualPlane([_, b]) => 0.5 + 40.0 * (1.0 - b.n().dot(Vec3::Y).abs()),
            _ => f32::INFINITY,
        };
        // (accepted, rejected, checks over every point), the check scoring `every`.
        let search = |every: f32, whole: bool| {
            let (search, checks, halves) =
                dual_search(carried, frame, false, score, Some(every), whole);
            assert_eq!(halves, 0);
            (search.accepted().len(), search.rejected().len(), checks)
        };
        let (accepted, _, checks) = search(0.6, false);
        assert!(
            accepted >= 1 && checks as usize >= accepted,
            "{accepted} {checks}"
        );
        let (accepted, rejected, checks) = search(0.9, false);
        assert!(
            accepted == 0 && rejected >= 1 && checks >= 1,
            "{rejected} {checks}"
        );
        // On a domain whose every image the climb scores, its score is the check's already:
        // no check is asked for (`every` would reject every pair it scored).
        let (accepted, _, checks) = search(0.9, true);
        assert!(accepted >= 1 && checks == 0, "{accepted} {checks}");
    }

    #[test]
    fn a_single_planes_climb_is_not_checked_again() {
        // One mirror maps each point once: its polishing climb scores every point already.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.05,
        };
        let mut search = ParamSearch::new(SearchConfig::DEFAULT);
        search.begin(&[Family::Plane], frame, 0.003, 0.85);
        let mut last = None;
        while let Request::Evaluate { transformed, .. } = search.next(last) {
            assert_ne!(transformed, u32::MAX);
            last = scored(0.5, false);
        }
        assert!(!search.accepted().is_empty());
    }

    #[test]
    fn a_retry_tilts_a_stalled_plane_about_a_line_off_the_centre() {
        // The true plane is level through the centre; the start is turned 0.2 rad about the
        // line along y through `p`, half the radius from the centre, and the score is stiff in
        // `p`'s distance to the plane (and above the threshold everywhere, so the retry runs).
        // A turn about the centre's foot or a shift moves `p` off the plane by more than the
        // turn gains, at every step of the climb: those steps stall at the start. A turn about
        // a line through `p` gains.
        let frame = Frame {
            center: Vec3::new(0.0, 0.0, 0.8),
            radius: 0.1,
        };
        let p = Vec3::new(0.05, 0.0, 0.8);
        let off_level = |q: &Plane| crate::math::acos(q.n().dot(Vec3::Z).abs());
        let score = |s: &Symmetry| match s {
            Symmetry::PlaneReflection(q) => {
                let d = q.signed_distance(p);
                0.9 + 1e5 * d * d + (1.0 - q.n().dot(Vec3::Z).abs())
            }
            _ => f32::INFINITY,
        };
        let (sin, cos) = crate::math::sin_cos(0.2);
        let start = Symmetry::PlaneReflection(Plane::through(p, Vec3::new(sin, 0.0, cos)));
        let seed = Candidate {
            symmetry: start,
            score: score(&start),
            family: 0,
        };
        let best = |retry: bool| {
            let mut search = ParamSearch::new(SearchConfig::DEFAULT);
            search.begin_from(&[Family::Plane], seed, frame, 0.003, 0.85);
            if retry {
                search.retry();
            }
            let mut last = None;
            while let Request::Evaluate { symmetry, .. } = search.next(last) {
                last = scored(score(&symmetry), false);
            }
            match search.rejected().first().map(|c| c.symmetry) {
                Some(Symmetry::PlaneReflection(found)) => found,
                other => panic!("no plane climbed: {other:?}"),
            }
        };
        // Without the retry the climb stalls where it starts.
        assert!(off_level(&best(false)) > 0.19);
        // Two tilts of 0.128 rad (the first step on this frame) take 0.2 rad to 0.056.
        let found = best(true);
        assert!(off_level(&found) < 0.1, "{} rad off", off_level(&found));
        assert!(found.signed_distance(p).abs() < 1e-3, "{found:?}");
    }
}
