//! Shared mathematics of the calibrators: small dense linear algebra, blocked sums over
//! the readings and their segments (folded on several threads), the circle through three points, a bounded sample of readings spread
//! by direction, and the reading of a caller's sample without a store-forwarding stall.

pub(crate) mod blocks;
pub mod circumcentre;
pub(crate) mod direction_slots;
pub(crate) mod linalg;
pub(crate) mod reading;
pub(crate) mod segments;
