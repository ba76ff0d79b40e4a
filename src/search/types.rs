//! The outer loop (paper section 5.2, Table 1): walk the entailment hierarchy bottom-up, each
//! found symmetry constraining the search for the stronger types above it, each failure pruning
//! them.
//!
//! ```text
//! plane (3-D) ──found──> axial, constrained by the planes (2-D) ──found──> spherical on the axis (1-D)
//!    │                       │                                   └─fail──> axial + orthogonal plane (1-D)
//!    │                       └─fail──> dual plane with the plane (2-D) ──found──> triple plane (1-D)
//!    └─none──> point reflection (3-D) ──none──> line reflection (4-D)
//! ```
//! A search restricted to some types still visits the types on the way to them (the planes that
//! constrain an axis), but reports only the types asked for.
//!
//! **Scene context.** When the object rests on a known support plane, the axial node also climbs
//! the axes along the plane's normal ([`Family::AxialNormal`] of the support): an object at rest on
//! a base that is a disc (a can, a bowl, a bottle) stands on it with its axis along gravity. They
//! are searched beside the axes the mirror planes constrain, not instead of them, and the best
//! wins (Schiebener et al. 2016; Bohg et al. 2011). Likewise the line node climbs the half-turns
//! about the lines along the normal ([`Family::LineNormal`]): a half-turn that maps a resting
//! object onto itself keeps its contact with the support only about a vertical line (about a
//! level one it turns the object upside down, its top onto its base). And the plane node also
//! climbs from planes level with the support ([`Family::PlaneLevel`]), as does the dual node for
//! its second plane when its carried plane is upright on the support ([`Family::DualLevel`]): a
//! resting object's level mirror plane lies halfway up it, and a lying object is too thin for
//! the free grid, scored at a σ of its spacing, to see it.
//!
//! **Parts.** When the axial node fails on a domain, its rejected refined hypotheses are kept as
//! proposals ([`TypeSearch::pop_proposal`]): the middle loop ([`super::domains`]) may narrow the
//! domain to the part one of them explains and walk that part ([`TypeSearch::begin_part`]):
//! from the axial node, climbing from the proposal alone in all four of an axis's parameters
//! ([`Family::AxialFree`]; a part's axis need not lie in the planes fitted to the whole domain,
//! whose error it would inherit). The axis found there must make it a part
//! ([`super::parts::Judge::is_part`]); otherwise the walk is over with what the whole domain got.
//! On a domain of points the whole object's symmetry contradicts, a symmetry counts only if it
//! shares a mirror plane with the object's ([`super::parts::Judge::shares_mirror`]).
//!
//! **Appendages.** An axis the axial node accepts is a stronger claim than a plane through it:
//! every plane through the axis is then a mirror. So it is held to the weaker type's evidence
//! (Table 1 reports a stronger type only when its extra elements are confirmed as well as the
//! weaker's). The axis is scored once more over every point of the domain, noting where its
//! images stray. Its climb scored a subsample (`SearchConfig::polish_transformed` of its points'
//! images under every rotation: about a fifth of them on a 700-point object, where a plane's
//! climb scores all of its own); an axis that fails the acceptance test over every point has
//! failed the node, and the walk goes on as Table 1 does from a failed axis (to the dual
//! plane), the axis kept among the alternatives at that score and as a proposal for a part.
//! When the points whose images strayed lie to one side of the axis (their
//! centroid farther from it than their spread about the centroid,
//! [`crate::score::Strays::sidedness`]: a part its rotations send into free space, a mug's
//! handle; the sensor's strays, at the silhouette and the rims, lie all around it), the mirror
//! plane through the axis and that centroid is climbed about the axis
//! ([`Family::PlaneThrough`]) and scored the same way. When that plane is accepted and the
//! axis' images stray more often than the plane's, by the two-proportion test a composite's
//! elements are held to (see [`crate::score`]), the axis holds on a part of the object only:
//! the plane is the domain's symmetry and the walk is over (a second plane through the axis
//! would make a half-turn about it, which strays as the rotations did; one across the axis is
//! a claim about the body alone), and the axis is kept as the proposal a part may be narrowed
//! for (the body the handle is attached to). On an object of revolution the plane's images
//! stray as rarely as the axis' and the axis stands. Cost: two more evaluations over the
//! domain (every point through every map) and a climb in one parameter; the first is the test
//! over every point, at no further cost.
//!
//! Each call of [`TypeSearch::next`] is O(1) work: it hands back the next hypothesis to score,
//! or says the walk is over.

use super::family::{COS_5_DEG, Family, Frame, SIN2_5_DEG, entails, same_symmetry};
use super::params::{Candidate, MAX_CANDIDATES, MAX_FAMILIES, ParamSearch, Request};
use super::parts::{Judge, Trial};
use crate::config::SearchConfig;
use crate::math::{Vec3, normalize};
use crate::score::{Scored, stray_excess};
use crate::symmetry::{Symmetry, SymmetryType, TypeSet};
use crate::{Axis, Plane};

/// Where the walk through Table 1 is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Node {
    Plane,
    Axial,
    Spherical,
    AxialPlane,
    /// An accepted axis against the plane through it and the part it does not hold on: where
    /// the check is.
    Appendage(Appendage),
    Dual,
    Triple,
    Point,
    Line,
    Finished,
}

/// Where the appendage check of an accepted axis is (see the module docs). The axis checked is
/// the walk's `axis`; the plane climbed, the inner search's best.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Appendage {
    /// The axis is scored over every point, for where its images stray.
    Tallying,
    /// The plane through the axis and its strays' centroid is climbed about the axis; the
    /// axis' `(strays, decided)` images.
    Climbing((u32, u32)),
    /// The climbed plane is scored over every point, for its strays.
    Comparing((u32, u32)),
}

/// Planes carried up the hierarchy from the plane search, and duals from the dual search (the
/// best few).
const CARRIED_PLANES: usize = 2;
/// Hypotheses kept as alternatives to the walk's best (the runner-up is among them): the best
/// few of every node's, accepted or not.
const ALTERNATIVES: usize = 4;

/// The outer-loop state machine.
#[derive(Clone, Debug)]
pub struct TypeSearch {
    types: TypeSet,
    node: Node,
    inner: ParamSearch,
    frame: Frame,
    sigma_fine: f32,
    accept: f32,
    /// The best planes the plane node accepted; above the dual node, the best duals it
    /// accepted whose third planes differ ([`carried_duals`]), the one the triple node climbs
    /// from first.
    planes: heapless::Vec<Candidate, CARRIED_PLANES>,
    axis: Option<Candidate>,
    best: Option<Candidate>,
    /// The narrowed domain walked: the domain it was carved from and its proposal (on trial
    /// until its axial node passes; kept when it has, as the walk goes on there).
    trial: Option<Trial>,
    /// The failed axial node's proposals on the whole domain not tried yet, worst first (the
    /// next is popped): what the domain may be narrowed for once its walk is over.
    proposals: heapless::Vec<Candidate, MAX_CANDIDATES>,
    /// The whole object's symmetry when this domain is what it contradicts: a symmetry found
    /// here counts only if it shares a mirror plane with it (`TypeSearch::shares_mirror`).
    object: Option<Symmetry>,
    /// The support plane the object rests on, if known: the axial node also searches the axes
    /// along its normal (the scene's context: an object at rest stands on its base).
    support: Option<Plane>,
    /// The best-scoring hypotheses of the walk's nodes, distinct, best first: what the
    /// runner-up is chosen from ([`TypeSearch::runner_up`]).
    alternatives: heapless::Vec<Candidate, ALTERNATIVES>,
}

impl TypeSearch {
    pub const fn new(config: SearchConfig) -> Self {
        Self {
            types: TypeSet::ALL,
            node: Node::Finished,
            inner: ParamSearch::new(config),
            frame: Frame {
                center: Vec3::ZERO,
                radius: 0.0,
            },
            sigma_fine: 0.0,
            accept: 0.0,
            planes: heapless::Vec::new(),
            axis: None,
            best: None,
            trial: None,
            proposals: heapless::Vec::new(),
            object: None,
            support: None,
            alternatives: heapless::Vec::new(),
        }
    }

    /// The support plane the object rests on (`None`: unknown, or not to be used), for every
    /// later walk.
    pub fn set_support(&mut self, support: Option<Plane>) {
        self.support = support;
    }

    /// Start the walk for the given types over a domain described by `frame`. `object`: the
    /// symmetry accepted on the whole object, when the domain is made of points it contradicts.
    pub fn begin(
        &mut self,
        types: TypeSet,
        frame: Frame,
        sigma_fine: f32,
        accept: f32,
        object: Option<Symmetry>,
    ) {
        (self.types, self.object) = (types, object);
        (self.frame, self.sigma_fine, self.accept) = (frame, sigma_fine, accept);
        self.planes.clear();
        (self.axis, self.best, self.trial) = (None, None, None);
        self.proposals.clear();
        self.alternatives.clear();
        let first = if types.needs(SymmetryType::PlaneReflection) {
            Node::Plane
        } else {
            self.without_plane()
        };
        self.enter(first);
    }

    /// Whether the walk's symmetry was found on a narrowed part of its domain (once the walk is
    /// over).
    pub fn found_on_part(&self) -> bool {
        self.trial.is_some()
    }

    /// The symmetry the wider domain got, when the walk's was found on a part carved out of it.
    pub fn carved_from(&self) -> Option<Candidate> {
        self.trial.and_then(|trial| trial.wider_best)
    }

    /// The strongest wanted symmetry found so far.
    pub fn best(&self) -> Option<&Candidate> {
        self.best.as_ref()
    }

    /// The runner-up, once the walk is over: the best-scoring hypothesis of a type the walk was
    /// asked for that its best does not entail (an alternative reading of the domain, accepted
    /// or not; with no best, the nearest miss).
    pub fn runner_up(&self) -> Option<Candidate> {
        let other = |c: &&Candidate| !self.entailed_by_best(&c.symmetry);
        self.alternatives.iter().find(other).copied()
    }

    /// Whether the walk's best so far entails `s` (see [`entails`]).
    fn entailed_by_best(&self, s: &Symmetry) -> bool {
        let (center, distance) = (self.frame.center, self.frame.same_within(self.sigma_fine));
        (self.best.as_ref()).is_some_and(|b| entails(&b.symmetry, s, COS_5_DEG, distance, center))
    }

    /// Keep `c` among the alternatives if it is among the best few that the best so far does
    /// not entail (a duplicate keeps the better score).
    fn offer(&mut self, c: Candidate) {
        let wanted = self.types.contains(c.symmetry.kind()) && c.score.is_finite();
        if !wanted || self.entailed_by_best(&c.symmetry) {
            return;
        }
        let (center, distance) = (self.frame.center, self.frame.same_within(self.sigma_fine));
        let alternatives = &mut self.alternatives;
        let same =
            |a: &Candidate| same_symmetry(&a.symmetry, &c.symmetry, COS_5_DEG, distance, center);
        match alternatives.iter().position(same) {
            Some(i) if c.score < alternatives[i].score => alternatives[i] = c,
            Some(_) => return,
            None if alternatives.is_full() => match alternatives.last_mut() {
                Some(worst) if c.score < worst.score => *worst = c,
                _ => return,
            },
            None => {
                let _ = alternatives.push(c);
            }
        }
        alternatives.sort_unstable_by(|a, b| a.score.total_cmp(&b.score));
    }

    /// The next proposal to narrow the domain for, once the walk is over: the failed axial
    /// node's rejected hypotheses, best score first.
    pub fn pop_proposal(&mut self) -> Option<Candidate> {
        self.proposals.pop()
    }

    /// Walk the part (centred in `frame`) of the domain that `proposal` explains: the axial node
    /// again, climbing from the proposal alone, then on up Table 1 if the axis found makes it a
    /// part. The walk keeps what the whole domain got for the rest of it
    /// ([`TypeSearch::carved_from`]); if the axis is no part, the walk is over with that.
    pub fn begin_part(&mut self, proposal: Candidate, frame: Frame) {
        // One narrowed domain is searched per domain: the first that qualified.
        self.proposals.clear();
        self.trial = Some(Trial {
            wider: self.frame,
            proposal: proposal.symmetry,
            wider_best: self.best,
        });
        self.frame = frame;
        self.enter_part(proposal);
    }

    /// Take the score of the last request, return the next hypothesis to score, or `Done` when
    /// the walk is over (again at every later call). Each call is O(1) work.
    pub fn next(&mut self, mut last: Option<Scored>) -> Request {
        loop {
            if self.node == Node::Finished {
                return Request::Done;
            }
            // The check asks for its own evaluations, except while the inner search climbs.
            if let Node::Appendage(step) = self.node
                && !matches!(step, Appendage::Climbing(_))
            {
                match self.check_appendage(step, last.take()) {
                    Some(request) => return request,
                    None => continue,
                }
            }
            match self.inner.next(last.take()) {
                Request::Done => {
                    let node_best = self
                        .inner
                        .accepted()
                        .iter()
                        .chain(self.inner.rejected().first());
                    let offered: heapless::Vec<Candidate, { MAX_CANDIDATES + 1 }> =
                        node_best.copied().collect();
                    for c in offered {
                        self.offer(c);
                    }
                    // The axial node of a narrowed domain: the only one searched with a narrowed
                    // domain on trial.
                    let on_part = self.node == Node::Axial && self.trial.is_some();
                    let failed = self
                        .inner
                        .accepted()
                        .first()
                        .is_none_or(|found| on_part && !self.is_part(&found.symmetry));
                    if failed && self.node == Node::Axial && !on_part {
                        self.propose(None);
                    }
                    // A narrowed domain stays only if its node succeeded there; otherwise the
                    // walk is over, with what the wider domain got.
                    if let Some(trial) = self.trial.take_if(|_| failed && on_part) {
                        (self.frame, self.node) = (trial.wider, Node::Finished);
                        return Request::Done;
                    }
                    if let Node::Appendage(Appendage::Climbing(strays)) = self.node {
                        if self.inner.accepted().is_empty() {
                            self.keep_axis();
                        } else {
                            self.node = Node::Appendage(Appendage::Comparing(strays));
                        }
                        continue;
                    }
                    let next = self.conclude();
                    self.enter(next);
                }
                evaluate => return evaluate,
            }
        }
    }

    /// The part rules over the domain walked.
    fn judge(&self) -> Judge {
        Judge {
            frame: self.frame,
            sigma_fine: self.sigma_fine,
        }
    }

    /// Whether the axis found on the narrowed domain makes it a part.
    fn is_part(&self, found: &Symmetry) -> bool {
        let spacing = self.inner.grid_spacing(Family::AxialFree);
        self.trial
            .is_none_or(|trial| self.judge().is_part(&trial, spacing, found))
    }

    fn needs(&self, t: SymmetryType) -> bool {
        self.types.needs(t)
    }

    /// The first of `nodes` whose type is needed, or the end of the walk.
    fn first_needed(&self, nodes: [(SymmetryType, Node); 2]) -> Node {
        let needed = nodes.into_iter().find(|&(t, _)| self.needs(t));
        needed.map_or(Node::Finished, |(_, node)| node)
    }

    /// The node after a failed plane node (Table 1).
    fn without_plane(&self) -> Node {
        use SymmetryType as T;
        self.first_needed([
            (T::PointReflection, Node::Point),
            (T::LineReflection, Node::Line),
        ])
    }

    /// Record the finished node's result and pick the next node (Table 1).
    fn conclude(&mut self) -> Node {
        use SymmetryType as T;
        let found = self.inner.accepted().first().copied();
        // An accepted axis is the best once the appendage check has scored it over every point.
        if let Some(c) = found.filter(|_| !(self.node == Node::Axial && self.checks_axis())) {
            self.promote(c);
        }
        match (self.node, found) {
            (Node::Plane, Some(_)) => {
                self.planes.clear();
                for c in self.inner.accepted().iter().take(CARRIED_PLANES) {
                    let _ = self.planes.push(*c);
                }
                if self.needs(T::Axial) {
                    Node::Axial
                } else if self.needs(T::DualPlane) {
                    Node::Dual
                } else {
                    Node::Finished
                }
            }
            (Node::Plane, None) => self.without_plane(),
            // An axis on the whole domain is first held to the plane through its strays.
            (Node::Axial, Some(c)) => {
                self.axis = Some(c);
                if self.checks_axis() {
                    Node::Appendage(Appendage::Tallying)
                } else {
                    self.above_axis()
                }
            }
            (Node::Axial, None) => self.without_axis(),
            (Node::Spherical, None) if self.needs(T::AxialPlane) => Node::AxialPlane,
            (Node::Dual, Some(_)) if self.needs(T::TriplePlane) => {
                self.planes = carried_duals(self.inner.accepted());
                Node::Triple
            }
            // A third plane is climbed only across the dual's two: when the best dual has none
            // (a square bar's dual of a face plane and a diagonal one), the next dual's is tried.
            (Node::Triple, None) if self.planes.len() > 1 => {
                self.planes.remove(0);
                Node::Triple
            }
            (Node::Point, None) if self.needs(T::LineReflection) => Node::Line,
            _ => Node::Finished,
        }
    }

    /// Make `c` the walk's best if it is of a type asked for and may stand on this domain
    /// ([`Judge::shares_mirror`]); what it entails is then no alternative to it.
    fn promote(&mut self, c: Candidate) {
        let object = self.object.as_ref();
        if self.types.contains(c.symmetry.kind()) && self.judge().shares_mirror(object, &c.symmetry)
        {
            self.best = Some(c);
            let mut kept = core::mem::take(&mut self.alternatives);
            kept.retain(|a| !self.entailed_by_best(&a.symmetry));
            self.alternatives = kept;
        }
    }

    /// Whether an axis the axial node accepts goes through the appendage check (see the module
    /// docs): on the whole domain, when planes are asked for.
    fn checks_axis(&self) -> bool {
        self.trial.is_none() && self.types.contains(SymmetryType::PlaneReflection)
    }

    /// The node after a failed axial node (Table 1).
    fn without_axis(&self) -> Node {
        if self.needs(SymmetryType::DualPlane) {
            Node::Dual
        } else {
            Node::Finished
        }
    }

    /// Keep the failed axial node's rejected hypotheses as the proposals a part may be narrowed
    /// for, worst first (the best is popped first), and `first`, when given, to be popped
    /// before them.
    fn propose(&mut self, first: Option<Candidate>) {
        let room = MAX_CANDIDATES - first.is_some() as usize;
        for c in self.inner.rejected().iter().take(room).rev() {
            let _ = self.proposals.push(*c);
        }
        if let Some(c) = first {
            let _ = self.proposals.push(c);
        }
    }

    /// The node above an accepted axis (Table 1).
    fn above_axis(&self) -> Node {
        use SymmetryType as T;
        self.first_needed([
            (T::Spherical, Node::Spherical),
            (T::AxialPlane, Node::AxialPlane),
        ])
    }

    /// Score `symmetry` over every point of the domain, through every map, at the finest σ.
    fn tally(&self, symmetry: Symmetry) -> Request {
        Request::Evaluate {
            symmetry,
            sigma: self.sigma_fine,
            transformed: u32::MAX,
            tally: true,
            every_mirror: false,
        }
    }

    /// One step of the appendage check (see the module docs) at `step`, on the score of its
    /// last request: the next request, or `None` when the check moved the walk on (to the
    /// climb, or to the next node).
    fn check_appendage(&mut self, step: Appendage, last: Option<Scored>) -> Option<Request> {
        let axis = self.axis.and_then(|c| c.symmetry.axis().copied());
        let plane = self.inner.accepted().first().copied();
        let Some(scored) = last else {
            // The check's next evaluation: the axis, then the plane climbed (both exist by
            // construction; without one the walk ends rather than asks for nothing).
            let asked = match step {
                Appendage::Tallying => self.axis,
                _ => plane,
            };
            if asked.is_none() {
                self.node = Node::Finished;
            }
            return asked.map(|c| self.tally(c.symmetry));
        };
        match step {
            Appendage::Tallying if scored.score >= self.accept => {
                self.reject_axis(scored.score);
            }
            Appendage::Tallying => {
                // The axis holds over every point: the walk's best, until the check finds the
                // part it does not hold on.
                if let Some(axis) = self.axis {
                    self.promote(axis);
                }
                // Strays to one side of the axis, as a handle's are: their centroid farther
                // from it than their spread about the centroid (`Strays::sidedness` over 1/2).
                // The sensor's strays, at the silhouette and the rims, lie all around it.
                let one_side = |a: &Axis| scored.strays.sidedness(a).is_some_and(|s| s > 0.5);
                let seed = (scored.strays.centroid()).zip(axis.filter(one_side));
                let seed = seed.and_then(|(m, a)| {
                    let normal = normalize(a.d().cross(m - a.p()))?;
                    Some((a, Plane::through(a.p(), normal)))
                });
                let Some((a, plane)) = seed else {
                    self.keep_axis();
                    return None;
                };
                let seed = Candidate {
                    symmetry: Symmetry::PlaneReflection(plane),
                    score: f32::INFINITY,
                    family: 0,
                };
                let family = [Family::PlaneThrough(a)];
                (self.inner).begin_from(&family, seed, self.frame, self.sigma_fine, self.accept);
                self.node = Node::Appendage(Appendage::Climbing(scored.strays.counts()));
            }
            Appendage::Comparing(strays) => {
                let exceed = stray_excess(strays, scored.strays.counts()) > 0.0;
                match plane.filter(|_| exceed) {
                    Some(plane) => self.keep_plane(plane),
                    None => self.keep_axis(),
                }
            }
            // The climb's requests are the inner search's (`next`).
            Appendage::Climbing(_) => {}
        }
        None
    }

    /// The appendage check kept the axis: on up Table 1 from it.
    fn keep_axis(&mut self) {
        let next = self.above_axis();
        self.enter(next);
    }

    /// The axis the climb accepted fails the acceptance test over every point of the domain
    /// (`score`, from the check's tally): the climb scored a subsample, and the domain's other
    /// points contradict the axis. The axial node has failed: the walk goes on as Table 1 goes
    /// on from a failed axis, and the axis, among the alternatives with the score over every
    /// point, is a proposal for the part it may hold on.
    fn reject_axis(&mut self, score: f32) {
        if let Some(axis) = self.axis.take() {
            let (center, distance) = (self.frame.center, self.frame.same_within(self.sigma_fine));
            let same = |a: &Candidate| {
                same_symmetry(&a.symmetry, &axis.symmetry, COS_5_DEG, distance, center)
            };
            for a in self.alternatives.iter_mut().filter(|a| same(a)) {
                a.score = a.score.max(score);
            }
            (self.alternatives).sort_unstable_by(|a, b| a.score.total_cmp(&b.score));
            self.propose(Some(axis));
        }
        let next = self.without_axis();
        self.enter(next);
    }

    /// The appendage check found the axis holds on a part only: the plane through it is the
    /// domain's symmetry, and the axis the proposal a part may be narrowed for.
    fn keep_plane(&mut self, plane: Candidate) {
        let counts = self
            .judge()
            .shares_mirror(self.object.as_ref(), &plane.symmetry);
        self.best = counts.then_some(plane);
        self.proposals.clear();
        if let Some(axis) = self.axis.take() {
            self.offer(axis);
            let _ = self.proposals.push(axis);
        }
        // The walk stops at the plane: a second plane through the axis makes the half-turn
        // about it, a rotation the axis' strays refute; one across the axis is a claim about
        // the body alone, for the part narrowed for the axis to make.
        self.enter(Node::Finished);
    }

    /// Enter `node`: set up the inner search with the families its constraints give.
    fn enter(&mut self, node: Node) {
        // The appendage check sets up its own climb (`check_appendage`).
        if let Node::Appendage(_) = node {
            self.node = node;
            return;
        }
        let families = self.families(node);
        self.node = if families.is_empty() {
            Node::Finished
        } else {
            node
        };
        self.inner
            .begin(&families, self.frame, self.sigma_fine, self.accept);
        // The roots of Table 1's two branches: the plane's failure prunes every type a plane
        // leads to, and the point reflection is searched only once every plane has failed (a
        // one-sided view sends most of its images to the unseen back, where few grid centres
        // are confirmed enough to climb from). And the dual node, whose first plane is the
        // plane node's optimum, not the pair's: its retry re-fits the pair whole.
        if matches!(node, Node::Plane | Node::Point | Node::Dual) {
            self.inner.retry();
        }
    }

    /// Enter the axial node on a narrowed domain: climb from the wider domain's `proposal`
    /// alone, in all four of an axis's parameters (a part's axis is not bound by the planes of
    /// the domain it was carved from).
    fn enter_part(&mut self, proposal: Candidate) {
        self.node = Node::Axial;
        let seed = Candidate {
            family: 0,
            ..proposal
        };
        self.inner.begin_from(
            &[Family::AxialFree],
            seed,
            self.frame,
            self.sigma_fine,
            self.accept,
        );
    }

    /// The families `node` searches, given the planes and axis found below it (Table 1).
    fn families(&self, node: Node) -> heapless::Vec<Family, MAX_FAMILIES> {
        let planes = self.planes.iter().filter_map(|c| match c.symmetry {
            Symmetry::PlaneReflection(p) => Some(p),
            _ => None,
        });
        let axis = self.axis.and_then(|c| c.symmetry.axis().copied());
        let mut families = heapless::Vec::new();
        match node {
            Node::Plane => {
                // A lying object is too thin for the free grid to see its level plane.
                families.extend([Family::Plane]);
                families.extend(self.support.map(Family::PlaneLevel));
            }
            Node::Axial => {
                for p in planes {
                    families.extend([Family::AxialIn(p), Family::AxialNormal(p)]);
                }
                families.extend(self.support.map(Family::AxialNormal));
            }
            Node::Spherical => families.extend(axis.map(Family::SphericalOn)),
            Node::AxialPlane => families.extend(axis.map(Family::AxialPlaneOn)),
            Node::Dual => {
                families.extend(planes.clone().map(Family::DualWith));
                // A resting object's level mirror plane, with each carried plane upright on the
                // support (within the library's 5°).
                if let Some(support) = self.support {
                    let up = support.n();
                    let upright = |p: &Plane| p.n().dot(up) * p.n().dot(up) <= SIN2_5_DEG;
                    families.extend(
                        planes
                            .filter(upright)
                            .map(|p| Family::DualLevel(p, support)),
                    );
                }
            }
            // Its one family, the planes through the axis, is climbed from a seed.
            Node::Appendage(_) => {}
            Node::Triple => {
                let dual = self.planes.first().map(|c| c.symmetry);
                if let Some(Symmetry::DualPlane([p1, p2])) = dual {
                    families.extend([Family::TripleWith(p1, p2)]);
                }
            }
            Node::Point => families.extend([Family::Point]),
            Node::Line => {
                families.extend([Family::Line]);
                families.extend(self.support.map(Family::LineNormal));
            }
            Node::Finished => {}
        }
        families
    }
}

/// The best of `accepted` duals (best first) whose third planes differ, at most
/// [`CARRIED_PLANES`]: duals whose third plane's normal (across both of theirs) lies within 5° of
/// a better one's would repeat its climb (the same diagonal plane with a level plane at two
/// heights).
fn carried_duals(accepted: &[Candidate]) -> heapless::Vec<Candidate, CARRIED_PLANES> {
    let third = |d: &Candidate| match d.symmetry {
        Symmetry::DualPlane([p1, p2]) => crate::math::normalize(p1.n().cross(p2.n())),
        _ => None,
    };
    let mut carried: heapless::Vec<Candidate, CARRIED_PLANES> = heapless::Vec::new();
    for c in accepted {
        let new = third(c).is_some_and(|n| {
            carried
                .iter()
                .filter_map(third)
                .all(|m| n.dot(m).abs() < COS_5_DEG)
        });
        if new && carried.push(*c).is_err() {
            break;
        }
    }
    carried
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn with_a_support_the_plane_axial_and_line_nodes_also_climb_along_its_normal() {
        let support = Plane::new(Vec3::NEG_Y, -0.1).unwrap();
        let mut walk = TypeSearch::new(SearchConfig::DEFAULT);
        assert!(
            walk.families(Node::Axial).is_empty(),
            "no plane, no support"
        );
        walk.set_support(Some(support));
        assert_eq!(
            walk.families(Node::Axial)[..],
            [Family::AxialNormal(support)]
        );
        // ... the line node its lines, the plane node its level planes; no other node.
        assert_eq!(
            walk.families(Node::Line)[..],
            [Family::Line, Family::LineNormal(support)]
        );
        assert_eq!(
            walk.families(Node::Plane)[..],
            [Family::Plane, Family::PlaneLevel(support)]
        );
        assert_eq!(walk.families(Node::Point)[..], [Family::Point]);
    }

    #[test]
    fn the_dual_node_also_climbs_from_level_planes_with_an_upright_one() {
        let support = Plane::new(Vec3::NEG_Y, -0.1).unwrap();
        let (upright, tilted) = (
            Plane::new(Vec3::X, 0.0).unwrap(),
            Plane::new(Vec3::new(1.0, 0.2, 0.0), 0.0).unwrap(),
        );
        let mut walk = TypeSearch::new(SearchConfig::DEFAULT);
        for p in [upright, tilted] {
            let _ = walk.planes.push(Candidate {
                symmetry: Symmetry::PlaneReflection(p),
                score: 0.5,
                family: 0,
            });
        }
        let without = [Family::DualWith(upright), Family::DualWith(tilted)];
        assert_eq!(walk.families(Node::Dual)[..], without);
        walk.set_support(Some(support));
        // The tilted plane is 11° off upright: no level planes with it.
        let with = [without[0], without[1], Family::DualLevel(upright, support)];
        assert_eq!(walk.families(Node::Dual)[..], with);
    }

    #[test]
    fn the_triple_node_tries_the_next_dual_when_the_best_has_no_third_plane() {
        let plane = |n: Vec3| Plane::new(n, 0.0).unwrap();
        let (x, z, xy) = (Vec3::X, Vec3::Z, Vec3::new(1.0, 1.0, 0.0));
        let mut walk = TypeSearch::new(SearchConfig::DEFAULT);
        for (score, [p1, p2]) in [(0.5, [plane(z), plane(xy)]), (0.6, [plane(z), plane(x)])] {
            let _ = walk.planes.push(Candidate {
                symmetry: Symmetry::DualPlane([p1, p2]),
                score,
                family: 0,
            });
        }
        assert_eq!(
            walk.families(Node::Triple)[..],
            [Family::TripleWith(plane(z), plane(xy))]
        );
        // No triple accepted across the best dual: the next one's planes are climbed ...
        walk.node = Node::Triple;
        assert_eq!(walk.conclude(), Node::Triple);
        assert_eq!(
            walk.families(Node::Triple)[..],
            [Family::TripleWith(plane(z), plane(x))]
        );
        // ... and with none across it either, the walk is over.
        assert_eq!(walk.conclude(), Node::Finished);
    }

    #[test]
    fn duals_with_the_same_third_plane_are_carried_once() {
        let plane = |n: Vec3, offset: f32| Plane::new(n, offset).unwrap();
        let (x, z, xy) = (Vec3::X, Vec3::Z, Vec3::new(1.0, 1.0, 0.0));
        let dual = |p1, p2, score| Candidate {
            symmetry: Symmetry::DualPlane([p1, p2]),
            score,
            family: 0,
        };
        // The second repeats the first's third plane (the level plane at another height).
        let accepted = [
            dual(plane(z, 0.0), plane(xy, 0.0), 0.5),
            dual(plane(z, 0.04), plane(xy, 0.0), 0.6),
            dual(plane(z, 0.0), plane(x, 0.0), 0.65),
        ];
        let carried = carried_duals(&accepted);
        assert_eq!(carried[..], [accepted[0], accepted[2]]);
    }
}
