//! Correction of an analogue high-pass filter's distortion, with the offset-error compensator
//! (WO 00/36376; the seed's HPF corrector 311 and circuit 31106-31108).
//!
//! A first-order RC high-pass gives `F' = x' − F/RC`, so the input is recovered exactly by
//! `x = F + (1/RC) ∫F dt`; sampled, `J(n) = F(n) + (dt/RC)·Σ F` (the seed's register,
//! constant and adder). The sum also integrates rounding and the filter's own start-up
//! transient, which leave a constant error in `J`: the compensator watches for an output
//! that stays constant for `hold_s` and takes that level as the offset error, removing it
//! from the register. (A constant output is also what a steady rotation gives; the seed
//! accepts that, and so does this piece, which is why it is optional in the detector.)
//!
//! The seed also corrects the constant `dt/RC` from the same signal; here `RC` is known
//! exactly from the filter's configuration, so that part has nothing to correct.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_dt, check_finite, check_positive, check_range};

/// Settings of a [`HighPassCorrection`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct HighPassCorrectionConfig {
    /// Use the offset-error compensator (default `true`).
    pub compensate_offset: bool,
    /// Largest change of the output, rad/s, that still counts as constant (default 0.2°/s).
    pub constant_tol_rps: f64,
    /// Time the output must stay constant before its level is taken as an offset error, s
    /// (default 1).
    pub hold_s: f64,
}

impl Default for HighPassCorrectionConfig {
    fn default() -> Self {
        Self {
            compensate_offset: true,
            constant_tol_rps: 0.2f64.to_radians(),
            hold_s: 1.0,
        }
    }
}

impl Validate for HighPassCorrectionConfig {
    /// Tolerance positive, hold time ≥ 0.
    fn validate(&self) -> Result<()> {
        check_positive(
            "high_pass_correction.constant_tol_rps",
            self.constant_tol_rps,
        )?;
        check_range("high_pass_correction.hold_s", self.hold_s, 0.0, 1e9)?;
        Ok(())
    }
}

/// The register (running integral of the filter output) and the constant-output watch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HighPassCorrection {
    config: HighPassCorrectionConfig,
    /// `∫F dt`, rad.
    integral_rad: f64,
    reference_rps: f64,
    constant_s: f64,
}

impl HighPassCorrection {
    /// A corrector with validated settings.
    pub fn new(config: HighPassCorrectionConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            integral_rad: 0.0,
            reference_rps: 0.0,
            constant_s: 0.0,
        })
    }

    /// Corrects one high-pass output `f_rps` of a filter with time constant `rc_s`, taken
    /// `dt_s` after the previous one: `J = F + (1/RC)·∫F dt`, less the compensated offset
    /// error. A typed error for non-finite input or a non-positive `dt_s` or `rc_s`.
    pub fn push(&mut self, f_rps: f64, rc_s: f64, dt_s: f64) -> Result<f64> {
        let f = check_finite("high-pass output", f_rps)?;
        check_dt(dt_s)?;
        check_positive("high-pass time constant rc_s", rc_s)?;
        self.integral_rad += f * dt_s;
        let j = f + self.integral_rad / rc_s;
        if !self.config.compensate_offset {
            return Ok(j);
        }
        if (j - self.reference_rps).abs() <= self.config.constant_tol_rps {
            self.constant_s += dt_s;
        } else {
            self.reference_rps = j;
            self.constant_s = 0.0;
        }
        if self.constant_s >= self.config.hold_s {
            // The constant level is an offset error: take it out of the register.
            self.integral_rad -= j * rc_s;
            self.reference_rps = 0.0;
            self.constant_s = 0.0;
            return Ok(0.0);
        }
        Ok(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HighPassConfig, HighPassFilter};
    use proptest::prelude::*;

    proptest! {
        /// High-pass then correction gives the input back (without the compensator), for a
        /// swing of any amplitude and period.
        #[test]
        fn undoes_the_high_pass(amp in 0.1f64..3.0, period in 0.5f64..20.0) {
            let mut hp = HighPassFilter::new(HighPassConfig { startup_s: 0.0, ..Default::default() }).unwrap();
            let mut c = HighPassCorrection::new(HighPassCorrectionConfig { compensate_offset: false, ..Default::default() }).unwrap();
            let dt = 0.005;
            let mut worst: f64 = 0.0;
            for k in 0..4000 {
                let x = amp * (core::f64::consts::TAU * k as f64 * dt / period).sin();
                let f = hp.push(x, dt).unwrap();
                let j = c.push(f, hp.rc_s(), dt).unwrap();
                worst = worst.max((j - x).abs());
            }
            // Backward-difference filter against a rectangle-rule integral: O(dt/RC) of the
            // signal per step, accumulated over a period.
            prop_assert!(worst < 0.02 * amp, "worst {worst}");
        }

        /// With the compensator, an output that stays at a constant level (an offset error)
        /// is re-zeroed.
        #[test]
        fn compensator_rezeroes_a_constant_output(level in 0.01f64..1.0) {
            let mut c = HighPassCorrection::new(HighPassCorrectionConfig::default()).unwrap();
            let mut j = 1.0;
            for _ in 0..300 {
                // F = 0 after the filter settled, with a stuck integral of `level`·RC.
                j = c.push(if j == 1.0 { level } else { 0.0 }, 1e9, 0.01).unwrap();
            }
            let _ = j;
            c.integral_rad = level * 1.6;
            for _ in 0..300 {
                j = c.push(0.0, 1.6, 0.01).unwrap();
            }
            prop_assert!(j.abs() < 1e-9, "{j}");
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let mut c = HighPassCorrection::new(HighPassCorrectionConfig::default()).unwrap();
        assert!(c.push(f64::NAN, 1.0, 0.01).is_err());
        assert!(c.push(0.0, 0.0, 0.01).is_err());
        assert!(c.push(0.0, 1.0, -0.01).is_err());
    }
}
