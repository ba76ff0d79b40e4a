//! The entailment hierarchy (paper Fig. 5) and sets of types a caller may restrict the search to.

use super::SymmetryType;

/// A set of symmetry types (bit `t as u8` set when `t` is in the set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TypeSet(pub u8);

impl TypeSet {
    /// Every type.
    pub const ALL: TypeSet = TypeSet(0xFF);
    /// No type.
    pub const EMPTY: TypeSet = TypeSet(0);

    /// The set holding exactly `types`.
    pub fn of(types: &[SymmetryType]) -> Self {
        TypeSet(types.iter().fold(0, |bits, t| bits | 1 << *t as u8))
    }

    /// Whether `t` is in the set.
    pub const fn contains(self, t: SymmetryType) -> bool {
        self.0 & (1 << t as u8) != 0
    }

    /// Whether the set holds no type.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Every type `t` entails, `t` itself included (its ancestors in Fig. 5, read downward).
    pub const fn entailed_by(t: SymmetryType) -> TypeSet {
        use SymmetryType::*;
        let bits = match t {
            PlaneReflection | LineReflection | PointReflection => 0,
            DualPlane => bit(PlaneReflection) | bit(LineReflection),
            TriplePlane => {
                bit(DualPlane) | bit(PlaneReflection) | bit(LineReflection) | bit(PointReflection)
            }
            Axial => bit(PlaneReflection) | bit(LineReflection),
            AxialPlane => {
                bit(Axial)
                    | bit(DualPlane)
                    | bit(PlaneReflection)
                    | bit(LineReflection)
                    | bit(PointReflection)
            }
            Spherical => {
                bit(AxialPlane)
                    | bit(Axial)
                    | bit(TriplePlane)
                    | bit(DualPlane)
                    | bit(PlaneReflection)
                    | bit(LineReflection)
                    | bit(PointReflection)
            }
        };
        TypeSet(bits | bit(t))
    }

    /// Whether a search restricted to this set must visit `t`: `t` is wanted itself or is a
    /// stepping stone (Table 1) toward a wanted type.
    pub fn needs(self, t: SymmetryType) -> bool {
        SymmetryType::ALL
            .into_iter()
            .any(|wanted| self.contains(wanted) && path_to(wanted).contains(t))
    }
}

const fn bit(t: SymmetryType) -> u8 {
    1 << t as u8
}

/// The types Table 1 searches on its way to `t`, `t` included.
const fn path_to(t: SymmetryType) -> TypeSet {
    use SymmetryType::*;
    let bits = match t {
        PlaneReflection | PointReflection | LineReflection => 0,
        Axial | DualPlane => bit(PlaneReflection),
        Spherical | AxialPlane => bit(PlaneReflection) | bit(Axial),
        TriplePlane => bit(PlaneReflection) | bit(DualPlane),
    };
    TypeSet(bits | bit(t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use SymmetryType::*;

    #[test]
    fn stronger_types_entail_weaker_ones() {
        for t in SymmetryType::ALL {
            for weaker in SymmetryType::ALL {
                if weaker != t && TypeSet::entailed_by(t).contains(weaker) {
                    assert!(weaker.strength() < t.strength(), "{t:?} entails {weaker:?}");
                }
            }
        }
        assert!(TypeSet::entailed_by(Spherical).contains(PointReflection));
        assert!(!TypeSet::entailed_by(Axial).contains(PointReflection));
    }

    #[test]
    fn restricted_search_visits_stepping_stones() {
        let axial_only = TypeSet::of(&[Axial]);
        assert!(axial_only.needs(PlaneReflection) && axial_only.needs(Axial));
        assert!(!axial_only.needs(DualPlane) && !axial_only.needs(LineReflection));
        assert!(TypeSet::of(&[LineReflection]).needs(LineReflection));
        assert!(!TypeSet::of(&[LineReflection]).needs(PlaneReflection));
    }
}
