//! Shared mathematics of the calibrators, the floor every other folder stands on: the
//! readings a fit replays and the stores that keep them, small dense linear algebra, the
//! layout of the conic and quadric monomials, blocked sums over the readings and their
//! segments (folded on several threads), the circle through three points, and the reading
//! of a caller's sample without a store-forwarding stall.

pub(crate) mod blocks;
pub mod circumcentre;
pub(crate) mod linalg;
pub(crate) mod monomial_layout;
pub(crate) mod reading;
pub mod readings;
#[cfg(test)]
pub(crate) mod readings_tests;
pub(crate) mod segments;
