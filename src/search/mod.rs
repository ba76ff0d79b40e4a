//! The search in symmetry space (paper section 5): the outer loop over types ([`types`]), the
//! inner loop over parameters ([`params`]), and the parametrised families both walk ([`family`]).

pub mod family;
pub mod params;
pub mod types;

pub use family::{Frame, GridConfig};
pub use params::{Candidate, Request, SearchConfig};
pub use types::TypeSearch;
