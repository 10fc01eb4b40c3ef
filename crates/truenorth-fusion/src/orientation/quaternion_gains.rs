//! The [`crate::QuaternionFilter`]'s per-sample gains, derived from its parameters and the
//! sample interval (kept apart from the parameters and the state, as VQF's coefficients).

use truenorth_core::Real;

use super::quaternion_config::QuaternionFilterConfig;

/// The per-sample gains, derived from the parameters and the sample interval; recomputed
/// only when the interval changes (never on a uniformly sampled stream), so that the
/// per-sample path divides by no time constant. In the filter's float type `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Coefficients<T> {
    pub(crate) dt_s: T,
    /// The inclination low-pass's transition over one interval (see [`butterworth_step`]):
    /// `[φ₁₁, φ₁₂, φ₂₁, φ₂₂]`.
    pub(crate) acc_lowpass: [T; 4],
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
            acc_lowpass: butterworth_step(effective_tau(T::of(cfg.tau_acc_s), startup), dt_s),
            mag: gain(cfg.tau_mag_s),
            mag_rest: gain(cfg.tau_mag_rest_s),
            bias_rest: gain(cfg.bias_tau_rest_s),
        }
    }
}

/// Below this `σ dt`, [`butterworth_step`] sums its series.
const SERIES_MAX: f64 = 0.1;

/// The exact (zero-order-hold) transition over `dt_s` of the second-order Butterworth
/// low-pass with time constant `tau_s`, `τ² ÿ + √2 τ ẏ + y = u`, as the matrix
/// `Φ = exp(A dt)` of the state `(y − u, ẏ)` for an input held over the step:
/// `y' = u + φ₁₁ (y − u) + φ₁₂ ẏ`, `ẏ' = φ₂₁ (y − u) + φ₂₂ ẏ`. With `ω = 1/τ` the poles
/// are `−ω/√2 ± i ω/√2`, so `Φ = e^{−σ dt} (cos(σ dt) I + sin(σ dt)/σ (A + σ I))` with
/// `σ = ω/√2` (the matrix exponential of a 2 × 2 matrix with complex poles). Exact for any
/// step, so a long interval (a slow accelerometer, the start-up's short time constant)
/// cannot make it unstable. `e^{−x}(cos x + i sin x) = e^{(−1 + i) x}` is summed as its
/// series below `x = σ dt = 0.1` (the first term left out, `|z|⁸/8!` with `|z| = √2 x`,
/// is under 10⁻¹¹), so that an interval that changes in its last bits, as a float
/// timestamp's differences do, costs no exponential or sine (on a Cortex-M4F those are
/// `f64` software routines even for an `f32` filter).
pub(crate) fn butterworth_step<T: Real>(tau_s: T, dt_s: T) -> [T; 4] {
    let w = T::one() / tau_s;
    let sigma = w * T::of(core::f64::consts::FRAC_1_SQRT_2);
    let x = sigma * dt_s;
    let (c, s) = if x < T::of(SERIES_MAX) {
        // Σ zⁿ/n! for z = (−1 + i) x, n ≤ 7.
        let (mut re, mut im) = (T::one(), T::zero());
        let (mut tr, mut ti) = (T::one(), T::zero());
        for n in 1..8 {
            let k = x / T::of(f64::from(n));
            (tr, ti) = ((-tr - ti) * k, (tr - ti) * k);
            re += tr;
            im += ti;
        }
        (re, im)
    } else {
        let decay = (-x).exp();
        (decay * x.cos(), decay * x.sin())
    };
    [c + s, s / sigma, -w * w * s / sigma, c - s]
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
            let one = butterworth_step(tau, dt);
            let small = butterworth_step(tau, dt / n as f64);
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
        let below = butterworth_step(tau, SERIES_MAX / sigma * (1.0 - 1e-12));
        let above = butterworth_step(tau, SERIES_MAX / sigma);
        for (a, b) in below.iter().zip(&above) {
            assert!((a - b).abs() < 1e-10, "{a} {b}");
        }
    }

    #[test]
    fn the_lowpass_is_a_butterworth() {
        // A sine at the cut-off ω = 1/τ passes with gain 1/√2 after the transient.
        let (tau, dt) = (2.0, 0.001);
        let phi = butterworth_step(tau, dt);
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
