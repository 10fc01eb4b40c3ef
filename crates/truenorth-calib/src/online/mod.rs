//! The online least-squares calibrators: the direct ellipse (2-D) and ellipsoid (3-D) fits
//! from running monomial sums, in bounded memory, refreshed in bounded steps as readings
//! arrive; their configurations, their staged refreshes, and the readings they retain for
//! judging coverage.

pub(crate) mod conic;
pub mod conic_sums;
pub mod ellipse;
pub mod ellipsoid;
pub(crate) mod retained;
