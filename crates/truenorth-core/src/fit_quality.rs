//! How well a calibration is determined, whatever the calibrator: the figures every fit
//! reports, and those of one scalar coefficient.

use serde::{Deserialize, Serialize};

/// How well a fit is determined, for every calibrator family.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct FitQuality {
    /// Samples used in the solve.
    pub points: usize,
    /// Share of the needed excitation the samples cover, in [0, 1] (e.g. of the heading
    /// circle, of the sphere's directions, of the speed range).
    pub coverage: f64,
    /// RMS of the residuals divided by the size of the fitted quantity (dimensionless;
    /// for a compass, relative to the fitted field).
    pub residual_rms_rel: f64,
    /// Condition number of the solve's information matrix (1 is ideal; large means some
    /// combination of parameters is poorly determined).
    pub condition: f64,
}

/// How good the calibration of one scalar coefficient is (a gyro bias or scale, an odometer
/// wheel scale, the speed coefficient `a`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ScalarQuality {
    /// What every calibrator reports.
    pub fit: FitQuality,
    /// One standard deviation of the estimate, in the coefficient's own unit.
    pub sigma: f64,
}
