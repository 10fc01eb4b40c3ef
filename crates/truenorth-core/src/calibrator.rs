//! Calibration (raw → physical, given parameters) and calibrators (samples → parameters plus
//! a report on how far those parameters can be trusted).

use serde::{Deserialize, Serialize};

use crate::Result;

/// A calibration: turns a raw reading into a physical quantity using stored parameters.
pub trait Calibration {
    /// The raw reading.
    type Raw;
    /// The calibrated quantity.
    type Physical;

    /// Applies the calibration.
    fn apply(&self, raw: &Self::Raw) -> Self::Physical;
}

/// How far a calibrator has got.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Samples accepted so far.
    pub samples: usize,
    /// Share of the needed excitation seen so far, in [0, 1] (e.g. heading bins filled).
    pub coverage: f64,
    /// Whether `solve` would be expected to succeed now.
    pub ready: bool,
}

/// How good a calibration is. Every solve returns one, so a poor calibration is visible.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Quality {
    /// Samples used in the solve.
    pub points: usize,
    /// Share of heading (or direction) bins that hold data, in [0, 1].
    pub coverage: f64,
    /// RMS of the residuals divided by the fitted field magnitude (dimensionless).
    pub residual_rms_rel: f64,
    /// Condition number of the solve (large = poorly determined).
    pub condition: f64,
    /// Predicted bound on the heading error from the residuals and coverage, degrees.
    pub heading_error_bound_deg: f64,
    /// Fitted field magnitude, in the input unit.
    pub field_magnitude: f64,
    /// Fitted field magnitude divided by the expected one (from a geomagnetic model), if
    /// one was supplied. Far from 1 means a disturbed site or wrong units.
    pub field_ratio_to_expected: Option<f64>,
}

/// The result of a successful solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Solution<P> {
    /// The calibration parameters.
    pub params: P,
    /// How far they can be trusted.
    pub quality: Quality,
}

/// A calibrator: fed samples one at a time, solved for parameters when enough were seen.
///
/// Batch (least-squares) and online (seed) calibrators share this trait, so a user can swap
/// one for another with one line.
pub trait Calibrator {
    /// The sample type it learns from.
    type Sample;
    /// The parameters it produces.
    type Params;

    /// Feeds one sample. Non-finite samples are rejected with a typed error and ignored.
    fn push(&mut self, sample: &Self::Sample) -> Result<()>;

    /// How far the calibrator has got.
    fn progress(&self) -> Progress;

    /// Solves for the parameters, or says why the data cannot support a calibration.
    fn solve(&mut self) -> Result<Solution<Self::Params>>;

    /// Forgets all samples.
    fn reset(&mut self);
}
