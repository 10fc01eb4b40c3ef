//! The digital variant of the gyro's offset removal (WO 00/36376; the seed's
//! IIR filter 315 with delay buffers P1, P2, the positive/negative definer 316, the buffer
//! reset 317 and the input-offset correction 318-320).
//!
//! A second-order Butterworth high-pass (bilinear transform, direct form II: the two delay
//! buffers are the seed's P1 and P2). When the output changes sign, the buffers are reset
//! (which removes the slow tail an IIR high-pass leaves after a swing) and the input offset
//! is corrected towards the output just before the change,
//! `OS(n) = OS(n−1) − m·(OS(n−1) − D(n−1))`, `0 < m ≤ 0.5`; the filter's input is the
//! sample less `OS`.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_dt, check_finite, check_positive, check_range};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Settings of an [`IirHighPass`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct IirHighPassConfig {
    /// Cutoff, Hz (default 0.1).
    pub cutoff_hz: f64,
    /// Reset the delay buffers when the output changes sign (default `true`).
    pub reset_on_sign_change: bool,
    /// Gain `m` of the input-offset correction, in (0, 0.5]; 0 disables it (default 0.1).
    pub offset_gain: f64,
}

impl Default for IirHighPassConfig {
    fn default() -> Self {
        Self {
            cutoff_hz: 0.1,
            reset_on_sign_change: true,
            offset_gain: 0.1,
        }
    }
}

impl Validate for IirHighPassConfig {
    /// Cutoff positive, offset gain in [0, 0.5].
    fn validate(&self) -> Result<()> {
        check_positive("iir_high_pass.cutoff_hz", self.cutoff_hz)?;
        check_range("iir_high_pass.offset_gain", self.offset_gain, 0.0, 0.5)?;
        Ok(())
    }
}

/// Biquad coefficients for one sample interval (derived from the config and `dt`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Coefficients {
    dt_s: f64,
    b0: f64,
    a1: f64,
    a2: f64,
}

impl Coefficients {
    /// Butterworth high-pass by the bilinear transform with prewarping (b1 = −2·b0,
    /// b2 = b0).
    fn new(cutoff_hz: f64, dt_s: f64) -> Self {
        // Keep the cutoff below Nyquist.
        let w = (core::f64::consts::PI * cutoff_hz * dt_s).min(1.5).tan();
        let w2 = w * w;
        let r2 = core::f64::consts::SQRT_2 * w;
        let norm = 1.0 / (1.0 + r2 + w2);
        Self {
            dt_s,
            b0: norm,
            a1: 2.0 * (w2 - 1.0) * norm,
            a2: (1.0 - r2 + w2) * norm,
        }
    }
}

/// The filter: delay buffers, input offset, last output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IirHighPass {
    config: IirHighPassConfig,
    coefficients: Option<Coefficients>,
    /// The seed's delay buffers P1 = w(n−1), P2 = w(n−2).
    p1: f64,
    p2: f64,
    offset: f64,
    last_out: f64,
}

impl IirHighPass {
    /// A filter with validated settings.
    pub fn new(config: IirHighPassConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            coefficients: None,
            p1: 0.0,
            p2: 0.0,
            offset: 0.0,
            last_out: 0.0,
        })
    }

    /// Filters one sample taken `dt_s` after the previous one. A typed error for a
    /// non-finite input or a non-positive `dt_s`; nothing changes then.
    pub fn push(&mut self, x: f64, dt_s: f64) -> Result<f64> {
        let x = check_finite("gyro rate", x)?;
        check_dt(dt_s)?;
        let c = match self.coefficients {
            Some(c) if (c.dt_s - dt_s).abs() <= 1e-9 * dt_s => c,
            _ => Coefficients::new(self.config.cutoff_hz, dt_s),
        };
        self.coefficients = Some(c);
        let w = (x - self.offset) - c.a1 * self.p1 - c.a2 * self.p2;
        let y = c.b0 * (w - 2.0 * self.p1 + self.p2);
        self.p2 = self.p1;
        self.p1 = w;
        if y * self.last_out < 0.0 {
            if self.config.reset_on_sign_change {
                self.p1 = 0.0;
                self.p2 = 0.0;
            }
            let m = self.config.offset_gain;
            self.offset -= m * (self.offset - self.last_out);
        }
        self.last_out = y;
        Ok(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Without resets, a constant input decays to zero and a swing well above the cutoff
        /// passes nearly unchanged.
        #[test]
        fn is_a_high_pass(offset in -1.0f64..1.0, amp in 0.1f64..2.0) {
            let cfg = IirHighPassConfig { reset_on_sign_change: false, offset_gain: 0.0, ..Default::default() };
            let mut f = IirHighPass::new(cfg).unwrap();
            let mut y = 0.0;
            for _ in 0..20_000 {
                y = f.push(offset, 0.01).unwrap();
            }
            prop_assert!(y.abs() < 1e-3 * offset.abs() + 1e-12);
            let mut g = IirHighPass::new(cfg).unwrap();
            let mut worst: f64 = 0.0;
            for k in 0..4000 {
                let x = amp * (core::f64::consts::TAU * 2.0 * k as f64 * 0.01).sin();
                let y = g.push(x, 0.01).unwrap();
                if k > 2000 {
                    worst = worst.max((y - x).abs());
                }
            }
            // Gain 1 − 3·10⁻⁶ at f = 20 f_c, phase lead ≈ √2 f_c/f = 0.071 rad.
            prop_assert!(worst < 0.075 * amp, "{worst}");
        }

        #[test]
        fn no_panic_on_any_input(x in proptest::num::f64::ANY, dt in proptest::num::f64::ANY) {
            let mut f = IirHighPass::new(IirHighPassConfig::default()).unwrap();
            let _ = f.push(0.3, 0.01);
            let before = f;
            match f.push(x, dt) {
                Ok(y) => prop_assert!(y.is_finite() || !x.is_finite()),
                Err(_) => prop_assert_eq!(f, before),
            }
        }
    }
}
