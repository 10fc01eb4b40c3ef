//! Least-squares ellipse calibration of a two-axis compass: the direct fit, its geometric
//! refinement into a hard and a symmetric soft iron, and the batch calibrator.

pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod direct;
pub(crate) mod fit;

#[cfg(test)]
mod tests;

pub use calibrator::EllipseCalibrator;
pub use config::{EllipseConfig, MIN_POINTS_2D};
pub use direct::{Ellipse, fit_ellipse_direct};
pub use fit::{fit_ellipse, fit_ellipse_readings};
