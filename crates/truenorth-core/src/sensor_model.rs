//! The forward-model trait: truth → raw reading with the sensor's errors.

use crate::{NoiseSource, Result};

/// A forward model of a sensor: the reading it gives for a true physical state.
///
/// Used by the simulator to make realistic streams and by round-trip tests
/// (truth → model → calibration with the model's true parameters → truth). Both methods are
/// fallible: a non-finite truth or a non-positive `dt_s` is a typed error, and the model's
/// time-varying state is left unchanged by a failed call.
pub trait SensorModel {
    /// The true physical quantity (e.g. a field vector and attitude, an angular rate).
    type Truth;
    /// What the sensor reports.
    type Reading;

    /// The reading with only the deterministic errors (offset, scale, misalignment, …) and
    /// no randomness or time-varying state. The inverse of the model's true calibration.
    fn ideal(&self, truth: &Self::Truth) -> Result<Self::Reading>;

    /// The reading with every error, drawing random terms from `noise` and advancing any
    /// time-varying error state (random walks, drifts) by `dt_s` seconds.
    fn sample(
        &mut self,
        truth: &Self::Truth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Self::Reading>;
}
