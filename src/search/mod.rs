//! The search in symmetry space (paper section 5), one owner per loop: the middle loop over
//! domains ([`domains`], with the growth of a domain in [`growth`] and the part rules in
//! [`parts`]) runs the outer loop over types ([`types`]) on each domain, which runs the inner loop
//! over parameters ([`params`]) on each node, over the parametrised families of [`family`].

pub mod domains;
pub mod family;
pub mod growth;
pub mod params;
pub mod parts;
pub mod types;

pub use family::Frame;
