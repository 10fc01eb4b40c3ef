//! The [`crate::QuaternionFilter`]'s per-sample gains, derived from its parameters and the
//! sample interval (kept apart from the parameters and the state, as VQF's coefficients).

use truenorth_core::{Real, STANDARD_GRAVITY_MPS2};

use super::quaternion_config::QuaternionFilterConfig;

/// The per-sample gains, derived from the parameters and the sample interval; recomputed
/// only when the interval changes (never on a uniformly sampled stream), so that the
/// per-sample path divides by no time constant. In the filter's float type `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Coefficients<T> {
    pub(crate) dt_s: T,
    /// Low-pass gain of the reference-frame specific force.
    pub(crate) acc_lowpass: T,
    /// Inclination gain per m/s² of horizontal specific force.
    pub(crate) acc: T,
    /// Heading gains in motion and at rest.
    pub(crate) mag: T,
    pub(crate) mag_rest: T,
    /// Gain of the bias estimate at rest.
    pub(crate) bias_rest: T,
}

/// Every time constant during the start-up, s at most.
const STARTUP_TAU_S: f64 = 0.1;

/// The time constant `tau_s` in effect: cut to [`STARTUP_TAU_S`] during the start-up.
pub(crate) fn effective_tau<T: Real>(tau_s: T, startup: bool) -> T {
    if startup {
        tau_s.min(T::of(STARTUP_TAU_S))
    } else {
        tau_s
    }
}

impl<T: Real> Coefficients<T> {
    /// The gains for interval `dt_s`; with `startup`, every time constant is cut to
    /// [`STARTUP_TAU_S`].
    pub(crate) fn new(cfg: &QuaternionFilterConfig, dt_s: T, startup: bool) -> Self {
        let gain = |tau: f64| (dt_s / effective_tau(T::of(tau), startup)).min(T::one());
        Self {
            dt_s,
            acc_lowpass: gain(cfg.acc_lowpass_s),
            acc: gain(cfg.tau_acc_s) / T::of(STANDARD_GRAVITY_MPS2),
            mag: gain(cfg.tau_mag_s),
            mag_rest: gain(cfg.tau_mag_rest_s),
            bias_rest: gain(cfg.bias_tau_rest_s),
        }
    }
}
