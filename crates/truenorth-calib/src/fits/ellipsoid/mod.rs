//! Least-squares ellipsoid calibration of a three-axis magnetometer: the direct fit, its
//! refinement by Levenberg–Marquardt into a hard iron and a full symmetric soft iron, and
//! the batch calibrator.

pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod direct;
pub(crate) mod fit;

#[cfg(test)]
mod tests;

pub use calibrator::EllipsoidCalibrator;
pub use config::{EllipsoidConfig, MIN_POINTS_3D};
pub use direct::{Ellipsoid, fit_ellipsoid_direct};
pub use fit::{fit_ellipsoid, fit_ellipsoid_readings};
