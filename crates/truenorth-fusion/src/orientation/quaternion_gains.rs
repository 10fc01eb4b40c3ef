//! The [`crate::QuaternionFilter`]'s coefficients: its parameters in its float type, as the
//! per-sample path compares and multiplies with them, and the per-sample gains for the
//! sample interval (kept apart from the parameters and the state, as VQF's coefficients).
//! Computed once, and the gains again only when the interval changes, so that the
//! per-sample path converts no parameter from `f64` and divides by no time constant: on a
//! Cortex-M4F each conversion and each `f64` product is a software routine of tens of
//! instructions, even for an `f32` filter.

use truenorth_core::Real;

use super::attitude_uncertainty::{InclinationConstants, UncertaintyConstants};
use super::hard_iron::HardIronThresholds;
use super::mag_reference::MagThresholds;
use super::min_max::at_most;
use super::quaternion_config::QuaternionFilterConfig;
use super::rest_detector::RestThresholds;

/// Every time constant during the start-up, s at most.
const STARTUP_TAU_S: f64 = 0.1;

/// The correction loops' time constants in effect, s, and what the gains are computed
/// from: the parameters' after the start-up, each cut to [`STARTUP_TAU_S`] during it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Taus<T> {
    /// Of the heading correction in motion and at rest.
    pub(crate) mag: T,
    pub(crate) mag_rest: T,
    /// The inclination low-pass (of time constant `tau_acc_s`).
    lowpass: Butterworth<T>,
    /// The inclination loop as the σ follows it.
    pub(crate) inclination: InclinationConstants<T>,
    /// `1/τ` of the heading corrections and of the bias estimate at rest, 1/s.
    inv_mag: T,
    inv_mag_rest: T,
    inv_bias_rest: T,
}

impl<T: Real> Taus<T> {
    fn of(
        cfg: &QuaternionFilterConfig,
        uncertainty: &UncertaintyConstants<T>,
        startup: bool,
    ) -> Self {
        let tau = |tau_s: f64| {
            if startup {
                tau_s.min(STARTUP_TAU_S)
            } else {
                tau_s
            }
        };
        let tau_acc = T::of(tau(cfg.tau_acc_s));
        Self {
            mag: T::of(tau(cfg.tau_mag_s)),
            mag_rest: T::of(tau(cfg.tau_mag_rest_s)),
            lowpass: Butterworth::new(tau_acc),
            inclination: uncertainty.inclination(tau_acc),
            inv_mag: T::of(1.0 / tau(cfg.tau_mag_s)),
            inv_mag_rest: T::of(1.0 / tau(cfg.tau_mag_rest_s)),
            inv_bias_rest: T::of(1.0 / tau(cfg.bias_tau_rest_s)),
        }
    }

    /// The heading gain over `dt_s`, at rest or in motion.
    pub(crate) fn mag_gain(&self, dt_s: T, at_rest: bool) -> T {
        gain(
            dt_s,
            if at_rest {
                self.inv_mag_rest
            } else {
                self.inv_mag
            },
        )
    }
}

/// The gain `dt/τ` of a first-order correction, at most 1, from `1/τ`.
fn gain<T: Real>(dt_s: T, inv_tau: T) -> T {
    at_most(dt_s * inv_tau, T::one())
}

/// The per-sample gains for one sample interval, in the filter's float type `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gains<T> {
    /// The interval they are for (0 before the first step: no real interval).
    dt_s: T,
    /// The inclination low-pass's transition over one interval (see [`Butterworth`]):
    /// `[φ₁₁, φ₁₂, φ₂₁, φ₂₂]`.
    pub(crate) acc_lowpass: [T; 4],
    /// Heading gains in motion and at rest.
    pub(crate) mag: T,
    pub(crate) mag_rest: T,
    /// Gain of the bias estimate at rest.
    pub(crate) bias_rest: T,
}

impl<T: Real> Gains<T> {
    /// With multiplications only: a float timestamp's differences change in their last
    /// bits from one sample to the next, and the gains follow them.
    fn new(taus: &Taus<T>, dt_s: T) -> Self {
        Self {
            dt_s,
            acc_lowpass: taus.lowpass.step(dt_s),
            mag: taus.mag_gain(dt_s, false),
            mag_rest: taus.mag_gain(dt_s, true),
            bias_rest: gain(dt_s, taus.inv_bias_rest),
        }
    }
}

/// The filter's parameters as the per-sample path uses them, and the gains for the last
/// interval (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Coefficients<T> {
    pub(crate) startup_s: T,
    pub(crate) max_bias_rps: T,
    /// The rest time after which the bias counts as known, s, and the in-motion bias
    /// estimate's time constant before it and its change up to then, s.
    pub(crate) bias_known_after_rest_s: T,
    pub(crate) bias_tau_unknown_s: T,
    pub(crate) bias_tau_change_s: T,
    /// After the start-up (`[0]`) and during it (`[1]`).
    taus: [Taus<T>; 2],
    pub(crate) rest: RestThresholds<T>,
    pub(crate) mag: MagThresholds<T>,
    pub(crate) hard_iron: HardIronThresholds<T>,
    pub(crate) uncertainty: UncertaintyConstants<T>,
    /// The gains for the last interval after the start-up and during it.
    gains: [Gains<T>; 2],
}

impl<T: Real> Coefficients<T> {
    /// For validated parameters.
    pub(crate) fn new(cfg: &QuaternionFilterConfig) -> Self {
        let uncertainty = UncertaintyConstants::of(cfg);
        let taus = [false, true].map(|startup| Taus::of(cfg, &uncertainty, startup));
        Self {
            startup_s: T::of(cfg.startup_s),
            max_bias_rps: T::of(cfg.max_bias_rps),
            bias_known_after_rest_s: T::of(cfg.bias_known_after_rest_s),
            bias_tau_unknown_s: T::of(cfg.bias_tau_unknown_s),
            bias_tau_change_s: T::of(cfg.bias_tau_motion_s - cfg.bias_tau_unknown_s),
            taus,
            rest: RestThresholds::of(&cfg.rest),
            mag: MagThresholds::of(&cfg.mag),
            hard_iron: HardIronThresholds::of(&cfg.hard_iron),
            uncertainty,
            gains: taus.map(|t| Gains::new(&t, T::zero())),
        }
    }

    /// The time constants in effect in the start-up or after it.
    pub(crate) fn taus(&self, startup: bool) -> &Taus<T> {
        &self.taus[usize::from(startup)]
    }

    /// The gains for a step of `dt_s` in the start-up or after it: those of the last step,
    /// unless the interval changed.
    pub(crate) fn gains(&mut self, dt_s: T, startup: bool) -> Gains<T> {
        let i = usize::from(startup);
        if self.gains[i].dt_s != dt_s {
            self.gains[i] = Gains::new(&self.taus[i], dt_s);
        }
        self.gains[i]
    }
}

/// Below this `σ dt`, [`Butterworth::step`] sums its series.
const SERIES_MAX: f64 = 0.1;

/// The second-order Butterworth low-pass with time constant `τ`, `τ² ÿ + √2 τ ẏ + y = u`,
/// as the constants of its transition over a step.
///
/// Its exact (zero-order-hold) transition over `dt` is the matrix `Φ = exp(A dt)` of the
/// state `(y − u, ẏ)` for an input held over the step: `y' = u + φ₁₁ (y − u) + φ₁₂ ẏ`,
/// `ẏ' = φ₂₁ (y − u) + φ₂₂ ẏ`. With `ω = 1/τ` the poles are `−ω/√2 ± i ω/√2`, so
/// `Φ = e^{−σ dt} (cos(σ dt) I + sin(σ dt)/σ (A + σ I))` with `σ = ω/√2` (the matrix
/// exponential of a 2 × 2 matrix with complex poles). Exact for any step, so a long interval
/// (a slow accelerometer, the start-up's short time constant) cannot make it unstable.
/// `e^{−x}(cos x + i sin x) = e^{(−1 + i) x}` is summed as its series below
/// `x = σ dt = 0.1` (the first term left out, `|z|⁸/8!` with `|z| = √2 x`, is under
/// 10⁻¹¹), so that an interval that changes in its last bits, as a float timestamp's
/// differences do, costs no exponential or sine (on a Cortex-M4F those are `f64` software
/// routines even for an `f32` filter), and no division.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Butterworth<T> {
    /// `σ = ω/√2`, its inverse and `ω²/σ`.
    sigma: T,
    inv_sigma: T,
    w2_over_sigma: T,
}

impl<T: Real> Butterworth<T> {
    pub(crate) fn new(tau_s: T) -> Self {
        let w = T::one() / tau_s;
        let sigma = w * T::of(core::f64::consts::FRAC_1_SQRT_2);
        Self {
            sigma,
            inv_sigma: T::one() / sigma,
            w2_over_sigma: w * w / sigma,
        }
    }

    /// The transition over `dt_s`: `[φ₁₁, φ₁₂, φ₂₁, φ₂₂]`.
    pub(crate) fn step(&self, dt_s: T) -> [T; 4] {
        /// `1/n` for the series' terms.
        const INV_N: [f64; 7] = [
            1.0,
            1.0 / 2.0,
            1.0 / 3.0,
            1.0 / 4.0,
            1.0 / 5.0,
            1.0 / 6.0,
            1.0 / 7.0,
        ];
        let x = self.sigma * dt_s;
        let (c, s) = if x < T::of(SERIES_MAX) {
            // Σ zⁿ/n! for z = (−1 + i) x, n ≤ 7.
            let (mut re, mut im) = (T::one(), T::zero());
            let (mut tr, mut ti) = (T::one(), T::zero());
            for inv_n in INV_N {
                let k = x * T::of(inv_n);
                (tr, ti) = ((-tr - ti) * k, (tr - ti) * k);
                re += tr;
                im += ti;
            }
            (re, im)
        } else {
            let decay = (-x).exp();
            (decay * x.cos(), decay * x.sin())
        };
        [c + s, s * self.inv_sigma, -s * self.w2_over_sigma, c - s]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The transition over one step equals that over many smaller ones (it is exact,
        /// whether summed as a series or not).
        #[test]
        fn the_lowpass_step_is_exact(tau in 0.05f64..20.0, dt in 1e-4f64..2.0, n in 2usize..50) {
            let lowpass = Butterworth::new(tau);
            let one = lowpass.step(dt);
            let small = lowpass.step(dt / n as f64);
            let (mut y, mut v) = (1.0, 0.3);
            for _ in 0..n {
                (y, v) = (small[0] * y + small[1] * v, small[2] * y + small[3] * v);
            }
            let (y1, v1) = (one[0] + one[1] * 0.3, one[2] + one[3] * 0.3);
            prop_assert!((y - y1).abs() < 1e-9 * (1.0 + y1.abs()), "{y} {y1}");
            prop_assert!((v - v1).abs() < 1e-9 * (1.0 + v1.abs()), "{v} {v1}");
        }
    }

    #[test]
    fn the_series_meets_the_exact_functions() {
        // Just below and above the switch: the two ways agree.
        let tau = 1.0;
        let sigma = core::f64::consts::FRAC_1_SQRT_2;
        let lowpass = Butterworth::new(tau);
        let below = lowpass.step(SERIES_MAX / sigma * (1.0 - 1e-12));
        let above = lowpass.step(SERIES_MAX / sigma);
        for (a, b) in below.iter().zip(&above) {
            assert!((a - b).abs() < 1e-10, "{a} {b}");
        }
    }

    #[test]
    fn the_lowpass_is_a_butterworth() {
        // A sine at the cut-off ω = 1/τ passes with gain 1/√2 after the transient.
        let (tau, dt) = (2.0, 0.001);
        let phi = Butterworth::new(tau).step(dt);
        let (mut y, mut v, mut peak) = (0.0f64, 0.0, 0.0f64);
        for k in 0..200_000 {
            let u = (k as f64 * dt / tau).sin();
            (y, v) = (
                u + phi[0] * (y - u) + phi[1] * v,
                phi[2] * (y - u) + phi[3] * v,
            );
            if k > 100_000 {
                peak = peak.max(y.abs());
            }
        }
        assert!(
            (peak - core::f64::consts::FRAC_1_SQRT_2).abs() < 2e-3,
            "{peak}"
        );
    }
}
