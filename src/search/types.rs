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
//! **Domains** (section 5.3, interleaved with the parameter search): when the walk over a domain
//! is over and the axial node failed there, its rejected refined hypotheses (the proposals) are
//! offered in turn, best score first: the walk asks the engine to narrow the domain to the part
//! a proposal explains ([`Request::Narrow`], see [`super::domains`]). The first proposal whose
//! part qualifies is searched there, once: the axial node climbs from it, and the walk goes on
//! above the axial node if it passes; otherwise the walk is over with what the whole domain got.
//! The climb is free in all four of an axis's parameters ([`Family::AxialFree`]): the planes
//! that constrained the proposal are the whole domain's, and a part's axis need not lie in
//! them or be normal to them: an axis bound to a plane fitted to the whole domain inherits that
//! plane's error (the synthetic figure's torso on (45°, 30°): 3.6° off bound, 0.4° free).
//! The best-scoring proposal is not always the part's axis: one that turns every point behind
//! the object costs each point the occluded cost, and can score better than the part's axis,
//! which turns the rest of the object into free space; but it explains no point well enough to
//! grow a part, so the next proposal is offered. Only one narrowed domain is searched per
//! domain: each further climb would be one more chance for a marginal fit on a sliver of a
//! whole-symmetric object. This is the decomposition criterion: a part is carved out only for a
//! symmetry that entails what the whole domain got (an axial part of an object that has a
//! mirror plane, two, three, or nothing), never in place of a whole-domain symmetry that an
//! axis does not entail (a spherical one, or an axis: the axial node's own results). A mug's
//! handle breaks its body's axial symmetry: the whole mug gets a mirror plane or three, its body
//! an axis. A box keeps its triple plane when no part of it passes as axial (the dev scenes'
//! cracker box and wood block); a bar of square section, whose corners a turn about its long
//! axis moves by about the match σ, may not.
//!
//! The type alone does not make the part's axis entail what the whole domain got: a climb free
//! of the planes may end on an axis beside them. The part's axis must also agree with the whole
//! domain's symmetry (each of its maps takes the axis onto itself,
//! `TypeSearch::agrees_with_wider`); otherwise the narrowed domain has failed (a cracker box's
//! dual plane is not replaced by an axial + plane 21 mm off one of its planes). It must also be
//! the proposal's axis, refined: within a grid spacing of the proposal over the part
//! (`TypeSearch::refines_proposal`); the part was grown for that proposal, not for whatever axis
//! a climb on it finds.
//!
//! When a part is carved out, what the whole domain got is kept for the rest of the domain
//! ([`TypeSearch::carved_from`]; the engine gives it the points there it does not contradict).
//! When nothing is carved out of the whole object, the points its symmetry contradicts are
//! searched as further domains, and a symmetry found there counts only if it shares a mirror
//! plane with the object's (`TypeSearch::shares_mirror`).
//!
use super::family::{Family, Frame};
use super::params::{Candidate, MAX_CANDIDATES, MAX_FAMILIES, ParamSearch, Request, SearchConfig};
use crate::math::Vec3;
use crate::symmetry::{Sampling, Symmetry, SymmetryType, TypeSet};
use crate::{Axis, Plane};

/// The element of a symmetry of revolution that each plane through is a mirror of it: an axis,
/// or a sphere's centre.
#[derive(Clone, Copy, Debug)]
enum Pivot {
    Axis(Axis),
    Center(Vec3),
}

impl Pivot {
    fn of(symmetry: &Symmetry) -> Option<Self> {
        match symmetry {
            Symmetry::Axial(axis) | Symmetry::AxialPlane(axis, _) => Some(Self::Axis(*axis)),
            Symmetry::Spherical(center) => Some(Self::Center(Vec3::from_array(*center))),
            _ => None,
        }
    }
}

/// Where the walk through Table 1 is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Node {
    Plane,
    Axial,
    Spherical,
    AxialPlane,
    Dual,
    Triple,
    Point,
    Line,
    Finished,
}

/// Planes carried up the hierarchy from the plane search (the best few).
const CARRIED_PLANES: usize = 2;

/// A narrowed domain on trial.
#[derive(Clone, Copy, Debug)]
struct Trial {
    /// The frame of the domain the narrowing started from.
    wider: Frame,
    /// The proposal the narrowed domain was grown for.
    proposal: Symmetry,
    /// What the wider domain's walk got before it was narrowed.
    wider_best: Option<Candidate>,
}

/// The outer-loop state machine.
#[derive(Clone, Debug)]
pub struct TypeSearch {
    types: TypeSet,
    /// Narrow a domain to parts for a failed axial node's proposals.
    parts: bool,
    node: Node,
    inner: ParamSearch,
    frame: Frame,
    sigma_fine: f32,
    accept: f32,
    planes: heapless::Vec<Candidate, CARRIED_PLANES>,
    axis: Option<Candidate>,
    best: Option<Candidate>,
    /// The narrowed domain searched: the domain it was carved from and its proposal (on trial
    /// until its axial node passes; kept when it has, as the walk goes on there).
    trial: Option<Trial>,
    /// The proposal of a `Narrow` request that awaits [`TypeSearch::narrowed`].
    awaiting_domain: Option<Candidate>,
    /// The failed axial node's proposals on the whole domain not tried yet, worst first (the
    /// next is popped): what the domain is narrowed for once its walk is over.
    proposals: heapless::Vec<Candidate, MAX_CANDIDATES>,
    /// The whole object's symmetry when this domain is what it contradicts: a symmetry found
    /// here counts only if it shares a mirror plane with it (`TypeSearch::shares_mirror`).
    object: Option<Symmetry>,
}

impl TypeSearch {
    pub const fn new(config: SearchConfig) -> Self {
        Self {
            types: TypeSet::ALL,
            parts: false,
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
            awaiting_domain: None,
            proposals: heapless::Vec::new(),
            object: None,
        }
    }

    /// Start the walk for the given types over a domain described by `frame`; with `parts`, a
    /// failed axial node may narrow the domain ([`Request::Narrow`]). `object`: the symmetry
    /// accepted on the whole object, when the domain is made of points it contradicts.
    pub fn begin(
        &mut self,
        types: TypeSet,
        parts: bool,
        frame: Frame,
        sigma_fine: f32,
        accept: f32,
        object: Option<Symmetry>,
    ) {
        (self.types, self.parts, self.object) = (types, parts, object);
        (self.frame, self.sigma_fine, self.accept) = (frame, sigma_fine, accept);
        self.planes.clear();
        (self.axis, self.best, self.awaiting_domain, self.trial) = (None, None, None, None);
        self.proposals.clear();
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

    /// Take the score of the last request, return the next hypothesis to score, or `Done` when
    /// the walk is over. Each call is O(1) work.
    pub fn next(&mut self, mut last_score: Option<f32>) -> Request {
        loop {
            if let Some(proposal) = self.awaiting_domain {
                return Request::Narrow {
                    proposal: proposal.symmetry,
                };
            }
            if self.node == Node::Finished {
                return match self.proposals.pop().filter(|_| self.decomposes()) {
                    Some(proposal) => {
                        self.awaiting_domain = Some(proposal);
                        Request::Narrow {
                            proposal: proposal.symmetry,
                        }
                    }
                    None => Request::Done,
                };
            }
            match self.inner.next(last_score.take()) {
                Request::Done => {
                    // The axial node of a narrowed domain: the only one searched with a narrowed
                    // domain on trial.
                    let on_part = self.node == Node::Axial && self.trial.is_some();
                    let failed = self
                        .inner
                        .accepted()
                        .first()
                        .is_none_or(|found| on_part && !self.is_part(&found.symmetry));
                    if failed && self.node == Node::Axial && !on_part {
                        self.proposals
                            .extend(self.inner.rejected().iter().rev().copied());
                    }
                    // A narrowed domain stays only if its node succeeded there; otherwise the
                    // walk is over, with what the wider domain got.
                    if let Some(trial) = self.trial.take_if(|_| failed && on_part) {
                        (self.frame, self.node) = (trial.wider, Node::Finished);
                        return Request::Widen;
                    }
                    let next = self.conclude();
                    self.enter(next);
                }
                evaluate => return evaluate,
            }
        }
    }

    /// Whether an axial part is worth searching for: parts are searched, axes are wanted, and the
    /// whole domain got nothing or only symmetries an axis entails (planes through it or normal
    /// to it, a half turn about it).
    fn decomposes(&self) -> bool {
        use SymmetryType as T;
        let axial = [T::Axial, T::AxialPlane, T::Spherical];
        self.parts
            && axial.iter().any(|&t| self.types.contains(t))
            && self.best.is_none_or(|b| {
                matches!(
                    b.symmetry.kind(),
                    T::PlaneReflection | T::DualPlane | T::TriplePlane | T::LineReflection
                )
            })
    }

    /// Whether a part's axis agrees with what the wider domain got: each map of the wider
    /// domain's symmetry takes the axis onto itself (a mirror plane through the axis or normal
    /// to it, a half-turn about it or across it) over the part's extent (both ends of the axis's
    /// chord through the part's frame). The part's symmetry then refines the wider one; an axis
    /// the wider symmetry moves contradicts it, and the wider domain's symmetry, found on more
    /// points, stands. Each of the two was fitted to within the finest match σ, so their maps
    /// may disagree by twice that. Cost: a few isometries applied to two points.
    fn agrees_with_wider(&self, part: &Symmetry) -> bool {
        let (Some(wider), Some(axis)) = (self.best, part.axis()) else {
            return true;
        };
        let ends = self.chord_ends(axis);
        let tolerance = self.tolerance_squared();
        // A part is only carved out of a domain that got reflections (`decomposes`), whose maps
        // do not depend on the sampling of continuous symmetries.
        let maps = wider.symmetry.maps(Sampling::default()).maps;
        maps.iter().all(|(map, _)| {
            ends.iter()
                .all(|&end| axis.distance_squared(map.apply(end)) <= tolerance)
        })
    }

    /// Whether `found`, the symmetry of points the whole object's symmetry contradicts, shares
    /// a mirror plane with the object's: one of its planes is a mirror of the object's
    /// symmetry, one of the object's planes is a mirror of it, or both are symmetries of
    /// revolution whose axes (or centres) lie in one plane, which is then a mirror of both. The
    /// appendage of an object symmetric as a whole lies on or across its mirror planes (a mug's
    /// handle, left over by the body's axis or by a triple plane fitted to the whole mug, is
    /// mirror symmetric about a plane through the body's axis); a symmetry with no mirror in
    /// common is a fit to a fragment the object's symmetry gets wrong (the wood block's dev
    /// scene wrist_0, found axial: two strips along its edges passed as dual planes whose
    /// planes stray 10-45 mm from its axis). With no object symmetry, any symmetry counts.
    /// Cost: a few distances to planes.
    fn shares_mirror(&self, found: &Symmetry) -> bool {
        let Some(object) = self.object else {
            return true;
        };
        let pivots = match (Pivot::of(found), Pivot::of(&object)) {
            (Some(Pivot::Axis(a)), Some(Pivot::Axis(b))) => self.coplanar(&a, &b),
            (Some(_), Some(_)) => true,
            _ => false,
        };
        pivots
            || found.planes().iter().any(|p| self.is_mirror(p, &object))
            || object.planes().iter().any(|p| self.is_mirror(p, found))
    }

    /// Whether `plane` is a mirror of `symmetry` over the domain: one of its planes (three
    /// points of it around the domain lie on `plane`), or a plane through its axis or centre
    /// of revolution.
    fn is_mirror(&self, plane: &Plane, symmetry: &Symmetry) -> bool {
        let tolerance = self.tolerance_squared();
        let on_plane = |q: Vec3| {
            let d = plane.signed_distance(q);
            d * d <= tolerance
        };
        let planes = symmetry.planes().iter();
        let one_of = planes
            .map(|p| self.plane_points(p))
            .any(|q| q.into_iter().all(on_plane));
        let through = match Pivot::of(symmetry) {
            Some(Pivot::Axis(axis)) => self.chord_ends(&axis).into_iter().all(on_plane),
            Some(Pivot::Center(center)) => on_plane(center),
            None => false,
        };
        one_of || through
    }

    /// Whether two axes lie in one plane: the distance between their lines is within the
    /// tolerance (parallel axes always do).
    fn coplanar(&self, a: &Axis, b: &Axis) -> bool {
        let normal = a.d().cross(b.d());
        let gap = (b.p() - a.p()).dot(normal);
        gap * gap <= self.tolerance_squared() * normal.length_squared()
    }

    /// The square of how far two symmetries' elements may lie apart and be one: each was fitted
    /// to within the finest match σ, so 2σ.
    fn tolerance_squared(&self) -> f32 {
        4.0 * self.sigma_fine * self.sigma_fine
    }

    /// Whether the axis found on a narrowed domain is the proposal's, refined: both ends of the
    /// axis's chord through the part lie within one grid spacing of the proposal's axis (the
    /// resolution of a free axis's grid on the part). The part is the domain the proposal
    /// explains; an axis the climb found farther away is another hypothesis, for which that part
    /// was not grown (on the synthetic figure, a horizontal axis climbed 67° from its proposal
    /// passed at 0.79 on a 34-point strip of an arm; the parts found on the synthetic objects
    /// and the dev scenes moved at most 4.1° and 3 mm). Cost: two distances.
    fn refines_proposal(&self, part: &Symmetry) -> bool {
        let (Some(trial), Some(axis)) = (self.trial, part.axis()) else {
            return true;
        };
        let Some(proposal) = trial.proposal.axis() else {
            return true;
        };
        let spacing = self.inner.grid_spacing(Family::AxialFree);
        self.chord_ends(axis)
            .iter()
            .all(|&end| proposal.distance_squared(end) <= spacing * spacing)
    }

    /// Whether the symmetry found on a narrowed domain makes it a part: it refines the
    /// proposal the part was grown for, and agrees with what the wider domain got.
    fn is_part(&self, found: &Symmetry) -> bool {
        self.refines_proposal(found) && self.agrees_with_wider(found)
    }

    /// The ends of `axis`'s chord through the domain's frame: ± the frame's radius from the
    /// foot of its centre.
    fn chord_ends(&self, axis: &Axis) -> [Vec3; 2] {
        let middle = Axis::new(axis.d(), axis.p(), self.frame.center).p();
        [-1.0, 1.0].map(|side| middle + axis.d() * (side * self.frame.radius))
    }

    /// Three points of `plane` around the domain: the foot of the frame's centre, and one frame
    /// radius from it along each of two directions in the plane.
    fn plane_points(&self, plane: &Plane) -> [Vec3; 3] {
        let foot = self.frame.center - plane.n() * plane.signed_distance(self.frame.center);
        let (u, v) = crate::math::orthonormal_basis(plane.n());
        [
            foot,
            foot + u * self.frame.radius,
            foot + v * self.frame.radius,
        ]
    }

    /// The answer to a `Narrow` request: the frame of the narrower domain the engine now
    /// searches (the node is searched again there), or `None` when no part qualified (the node
    /// has failed).
    pub fn narrowed(&mut self, domain: Option<Frame>) {
        let Some(proposal) = self.awaiting_domain.take() else {
            return;
        };
        match domain {
            Some(frame) => {
                // One narrowed domain is searched: the first that qualified.
                self.proposals.clear();
                self.trial = Some(Trial {
                    wider: self.frame,
                    proposal: proposal.symmetry,
                    wider_best: self.best,
                });
                self.frame = frame;
                self.enter_part(proposal);
            }
            None => self.node = Node::Finished,
        }
    }

    fn needs(&self, t: SymmetryType) -> bool {
        self.types.needs(t)
    }

    fn without_plane(&self) -> Node {
        if self.needs(SymmetryType::PointReflection) {
            Node::Point
        } else if self.needs(SymmetryType::LineReflection) {
            Node::Line
        } else {
            Node::Finished
        }
    }

    /// Record the finished node's result and pick the next node (Table 1).
    fn conclude(&mut self) -> Node {
        let found = self.inner.accepted().first().copied();
        if let Some(c) = found {
            if self.types.contains(c.symmetry.kind()) && self.shares_mirror(&c.symmetry) {
                self.best = Some(c);
            }
        }
        use SymmetryType as T;
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
            (Node::Axial, Some(c)) => {
                self.axis = Some(c);
                if self.needs(T::Spherical) {
                    Node::Spherical
                } else if self.needs(T::AxialPlane) {
                    Node::AxialPlane
                } else {
                    Node::Finished
                }
            }
            (Node::Axial, None) if self.needs(T::DualPlane) => Node::Dual,
            (Node::Spherical, None) if self.needs(T::AxialPlane) => Node::AxialPlane,
            (Node::Dual, Some(c)) if self.needs(T::TriplePlane) => {
                self.planes.clear();
                if let Symmetry::DualPlane(ps) = c.symmetry {
                    for p in ps {
                        let _ = self.planes.push(Candidate {
                            symmetry: Symmetry::PlaneReflection(p),
                            ..c
                        });
                    }
                }
                Node::Triple
            }
            (Node::Point, None) if self.needs(T::LineReflection) => Node::Line,
            _ => Node::Finished,
        }
    }

    /// Enter `node`: set up the inner search with the families its constraints give.
    fn enter(&mut self, node: Node) {
        let families = self.families(node);
        self.node = if families.is_empty() {
            Node::Finished
        } else {
            node
        };
        self.inner
            .begin(&families, self.frame, self.sigma_fine, self.accept);
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
            Node::Plane => families.extend([Family::Plane]),
            Node::Axial => {
                for p in planes {
                    families.extend([Family::AxialIn(p), Family::AxialNormal(p)]);
                }
            }
            Node::Spherical => families.extend(axis.map(Family::SphericalOn)),
            Node::AxialPlane => families.extend(axis.map(Family::AxialPlaneOn)),
            Node::Dual => families.extend(planes.map(Family::DualWith)),
            Node::Triple => {
                let ps: heapless::Vec<_, 2> = planes.collect();
                if let [p1, p2] = ps[..] {
                    families.extend([Family::TripleWith(p1, p2)]);
                }
            }
            Node::Point => families.extend([Family::Point]),
            Node::Line => families.extend([Family::Line]),
            Node::Finished => {}
        }
        families
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CENTER: Vec3 = Vec3::new(0.0, 0.0, 0.5);

    /// The type search on a part of radius 0.1 m (finest match σ 3 mm) whose wider domain got
    /// `wider`.
    fn on_part(wider: Symmetry) -> TypeSearch {
        let mut search = TypeSearch::new(SearchConfig::DEFAULT);
        search.frame = Frame {
            center: CENTER,
            radius: 0.1,
        };
        search.sigma_fine = 0.003;
        search.best = Some(Candidate {
            symmetry: wider,
            score: 0.5,
            family: 0,
        });
        search
    }

    fn axial(direction: Vec3, through: Vec3) -> Symmetry {
        let direction = crate::math::normalize(direction).unwrap();
        Symmetry::Axial(Axis::new(direction, through, CENTER))
    }

    fn plane(normal: Vec3) -> Plane {
        Plane::through(CENTER, normal)
    }

    #[test]
    fn a_part_axis_agrees_with_the_planes_it_lies_in_or_pierces_at_right_angles() {
        let dual = on_part(Symmetry::DualPlane([plane(Vec3::X), plane(Vec3::Y)]));
        assert!(dual.agrees_with_wider(&axial(Vec3::Z, CENTER)));
        // Tilted by 0.5°: the chord's ends move 1.7 mm, within the two fits' 2σ.
        assert!(dual.agrees_with_wider(&axial(Vec3::new(0.0087, 0.0, 1.0), CENTER)));
        // 10 mm beside the first plane, or tilted out of it by 3°: the mirror moves the axis.
        assert!(!dual.agrees_with_wider(&axial(Vec3::Z, CENTER + Vec3::X * 0.01)));
        assert!(!dual.agrees_with_wider(&axial(Vec3::new(0.052, 0.0, 1.0), CENTER)));
        // Normal to a plane: the plane is the axial + plane's own; wherever it pierces it.
        let single = on_part(Symmetry::PlaneReflection(plane(Vec3::X)));
        assert!(single.agrees_with_wider(&axial(Vec3::X, CENTER + Vec3::Y * 0.05)));
        assert!(!single.agrees_with_wider(&axial(Vec3::new(1.0, 0.1, 0.0), CENTER)));
    }

    #[test]
    fn a_part_axis_agrees_with_a_half_turn_about_it_or_across_it() {
        let line = Symmetry::LineReflection(Axis::new(Vec3::Z, CENTER, CENTER));
        let half_turn = on_part(line);
        assert!(half_turn.agrees_with_wider(&axial(Vec3::Z, CENTER)));
        assert!(half_turn.agrees_with_wider(&axial(Vec3::X, CENTER)));
        // Across the line but 10 mm past it: the half-turn moves it 20 mm.
        assert!(!half_turn.agrees_with_wider(&axial(Vec3::X, CENTER + Vec3::Y * 0.01)));
    }

    #[test]
    fn a_part_axis_refines_its_proposal_within_a_grid_spacing() {
        let mut search = on_part(Symmetry::PlaneReflection(plane(Vec3::X)));
        search.trial = Some(Trial {
            wider: search.frame,
            proposal: axial(Vec3::Z, CENTER),
            wider_best: None,
        });
        search.inner.begin(&[], search.frame, 0.003, 0.85);
        // A free axis's grid spacing on a part of radius 0.1 m: 51 mm at the chord's ends.
        let tilted = Vec3::new(0.176, 0.0, 1.0);
        assert!(search.refines_proposal(&axial(tilted, CENTER)));
        assert!(search.refines_proposal(&axial(Vec3::Z, CENTER + Vec3::Y * 0.03)));
        assert!(!search.refines_proposal(&axial(Vec3::Y, CENTER)));
        assert!(!search.refines_proposal(&axial(Vec3::Z, CENTER + Vec3::Y * 0.06)));
    }

    #[test]
    fn only_what_an_axis_entails_is_narrowed_to_parts() {
        let planes = [plane(Vec3::X), plane(Vec3::Y), plane(Vec3::Z)];
        let entailed = [
            Symmetry::PlaneReflection(planes[0]),
            Symmetry::DualPlane([planes[0], planes[1]]),
            Symmetry::TriplePlane(planes),
            Symmetry::LineReflection(Axis::new(Vec3::Z, CENTER, CENTER)),
        ];
        for wider in entailed {
            let mut search = on_part(wider);
            search.parts = true;
            assert!(search.decomposes(), "{wider:?}");
            search.parts = false;
            assert!(!search.decomposes(), "{wider:?}");
        }
        let mut search = on_part(axial(Vec3::Z, CENTER));
        search.parts = true;
        assert!(!search.decomposes());
        search.best = None;
        assert!(search.decomposes());
    }

    #[test]
    fn a_leftover_symmetry_counts_only_if_it_shares_a_mirror_with_the_whole_objects() {
        let mut search = on_part(Symmetry::PlaneReflection(plane(Vec3::X)));
        let reflection = |normal: Vec3, through: Vec3| {
            Symmetry::PlaneReflection(Plane::through(through, normal))
        };
        // The object axial about z: a mirror through its axis, an axis that meets it or runs
        // parallel to it (the plane through both is a mirror of both).
        search.object = Some(axial(Vec3::Z, CENTER));
        assert!(search.shares_mirror(&reflection(Vec3::X, CENTER)));
        assert!(search.shares_mirror(&axial(Vec3::X, CENTER + Vec3::Z * 0.05)));
        assert!(search.shares_mirror(&axial(Vec3::Z, CENTER + Vec3::X * 0.05)));
        // 10 mm beside the axis, across it, or an axis that passes it 10 mm away: no mirror
        // in common.
        assert!(!search.shares_mirror(&reflection(Vec3::X, CENTER + Vec3::X * 0.01)));
        assert!(!search.shares_mirror(&reflection(Vec3::Z, CENTER)));
        assert!(!search.shares_mirror(&axial(Vec3::X, CENTER + Vec3::Y * 0.01)));
        // The object mirror symmetric about x = 0: its own plane, or an axis in it.
        search.object = Some(reflection(Vec3::X, CENTER));
        let dual = Symmetry::DualPlane([plane(Vec3::Y), plane(Vec3::X)]);
        assert!(search.shares_mirror(&dual));
        assert!(search.shares_mirror(&axial(Vec3::Y, CENTER)));
        assert!(!search.shares_mirror(&reflection(Vec3::Y, CENTER)));
        assert!(!search.shares_mirror(&axial(Vec3::X, CENTER)));
        // A spherical object: planes through its centre, any symmetry of revolution.
        search.object = Some(Symmetry::Spherical(CENTER.to_array()));
        assert!(search.shares_mirror(&reflection(Vec3::Y, CENTER)));
        assert!(!search.shares_mirror(&reflection(Vec3::Y, CENTER + Vec3::Y * 0.01)));
        assert!(search.shares_mirror(&axial(Vec3::X, CENTER + Vec3::Y * 0.05)));
        search.object = None;
        assert!(search.shares_mirror(&reflection(Vec3::Y, CENTER + Vec3::Y * 0.01)));
    }

    #[test]
    fn with_nothing_found_on_the_wider_domain_any_part_axis_agrees() {
        let mut search = on_part(Symmetry::PlaneReflection(plane(Vec3::X)));
        search.best = None;
        assert!(search.agrees_with_wider(&axial(Vec3::new(1.0, 1.0, 0.0), CENTER)));
    }
}
