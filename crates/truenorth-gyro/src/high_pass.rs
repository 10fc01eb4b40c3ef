//! First-order high-pass filter with a variable cutoff, removing a gyro's offset
//! (WO 00/36376): the cutoff (≤ 0.1 Hz in operation) is raised just after power-on so the
//! filter settles fast, then lowered.
//!
//! Discrete form of the analogue RC filter `y' = x' − y/RC` (backward difference):
//! `y(n) = a·(y(n−1) + x(n) − x(n−1))`, `a = RC/(RC + dt)`, `RC = 1/(2π f_c)`.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_dt, check_finite, check_positive, check_range};

/// Settings of a [`HighPassFilter`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct HighPassConfig {
    /// Cutoff in operation, Hz (default 0.1, the seed's upper limit).
    pub cutoff_hz: f64,
    /// Cutoff just after power-on, Hz (default 1).
    pub startup_cutoff_hz: f64,
    /// Time with the start-up cutoff, s (default 2); 0 disables it.
    pub startup_s: f64,
}

impl Default for HighPassConfig {
    fn default() -> Self {
        Self {
            cutoff_hz: 0.1,
            startup_cutoff_hz: 1.0,
            startup_s: 2.0,
        }
    }
}

impl Validate for HighPassConfig {
    /// Cutoffs positive, start-up time ≥ 0.
    fn validate(&self) -> Result<()> {
        check_positive("high_pass.cutoff_hz", self.cutoff_hz)?;
        check_positive("high_pass.startup_cutoff_hz", self.startup_cutoff_hz)?;
        check_range("high_pass.startup_s", self.startup_s, 0.0, 1e9)?;
        Ok(())
    }
}

/// The filter's state: the previous input and output, and the time since power-on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HighPassFilter {
    config: HighPassConfig,
    last_in: Option<f64>,
    out: f64,
    on_s: f64,
}

impl HighPassFilter {
    /// A filter with validated settings.
    pub fn new(config: HighPassConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            last_in: None,
            out: 0.0,
            on_s: 0.0,
        })
    }

    /// The time constant RC in use now, s.
    pub fn rc_s(&self) -> f64 {
        let f = if self.on_s < self.config.startup_s {
            self.config.startup_cutoff_hz
        } else {
            self.config.cutoff_hz
        };
        1.0 / (core::f64::consts::TAU * f)
    }

    /// Filters one sample taken `dt_s` after the previous one (the first sample only starts
    /// the filter, output 0). A typed error for a non-finite input or a `dt_s` that is not
    /// positive; nothing changes then.
    pub fn push(&mut self, x: f64, dt_s: f64) -> Result<f64> {
        let x = check_finite("gyro rate", x)?;
        check_dt(dt_s)?;
        let Some(prev) = self.last_in.replace(x) else {
            return Ok(0.0);
        };
        let rc = self.rc_s();
        let a = rc / (rc + dt_s);
        self.out = a * (self.out + x - prev);
        self.on_s += dt_s;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A constant offset decays to zero; the start-up cutoff makes it decay faster.
        #[test]
        fn removes_a_constant_offset(offset in -1.0f64..1.0) {
            let mut slow = HighPassFilter::new(HighPassConfig { startup_s: 0.0, ..Default::default() }).unwrap();
            let mut fast = HighPassFilter::new(HighPassConfig::default()).unwrap();
            let (mut ys, mut yf) = (0.0, 0.0);
            slow.push(0.0, 0.01).unwrap();
            fast.push(0.0, 0.01).unwrap();
            for _ in 0..300 {
                ys = slow.push(offset, 0.01).unwrap();
                yf = fast.push(offset, 0.01).unwrap();
            }
            prop_assert!(yf.abs() <= ys.abs() + 1e-15);
            for _ in 0..20_000 {
                ys = slow.push(offset, 0.01).unwrap();
            }
            prop_assert!(ys.abs() < 1e-3 * offset.abs().max(1e-12) + 1e-15);
        }

        #[test]
        fn no_panic_on_any_input(x in proptest::num::f64::ANY, dt in proptest::num::f64::ANY) {
            let mut f = HighPassFilter::new(HighPassConfig::default()).unwrap();
            let _ = f.push(0.0, 0.01);
            let before = f;
            if f.push(x, dt).is_err() {
                prop_assert_eq!(f, before);
            }
        }
    }
}
