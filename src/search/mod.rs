//! The search in symmetry space (paper section 5): the outer loop over types ([`types`]), the
//! middle loop over domains ([`domains`]), the inner loop over parameters ([`params`]), and the
//! parametrised families the loops walk ([`family`]).

pub mod domains;
pub mod family;
pub mod growth;
pub mod params;
pub mod parts;
pub mod types;

pub use family::Frame;
