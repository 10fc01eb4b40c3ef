//! The least-squares fits: the direct ellipse (2-D) and ellipsoid (3-D) fits refined by
//! Levenberg–Marquardt on a geometric residual, the normalisation of the data before a fit,
//! and the joint magnetometer + accelerometer calibration, with the batch calibrators built
//! on them.

pub mod ellipse;
pub mod ellipsoid;
pub(crate) mod lm;
pub mod mag_accel;
pub(crate) mod normalise;
