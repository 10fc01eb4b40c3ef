//! The oscillation remover (WO 00/36376; the seed's removers 321, 322): hand
//! tremor makes a gyro swing about zero while the hand holds still; when the mean of the
//! last `a + 1` outputs is below a threshold, `|J(n) + … + J(n−a)| / a < ε`, the output is
//! taken as zero.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Validate, check_finite, check_positive};

/// Most samples the remover can average (`a + 1`).
pub const MAX_OSCILLATION_WINDOW: usize = 16;

/// Settings of an [`OscillationRemover`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OscillationRemoverConfig {
    /// `a`: the window is the last `a + 1` samples, 1 ≤ a < 16 (default 3, the seed's).
    pub a: usize,
    /// `ε`, rad/s (default 0.5°/s).
    pub threshold_rps: f64,
}

impl Default for OscillationRemoverConfig {
    fn default() -> Self {
        Self {
            a: 3,
            threshold_rps: 0.5f64.to_radians(),
        }
    }
}

impl Validate for OscillationRemoverConfig {
    /// `a` in [1, 15], threshold positive.
    fn validate(&self) -> Result<()> {
        if !(1..MAX_OSCILLATION_WINDOW).contains(&self.a) {
            return Err(Error::OutOfRange {
                what: "oscillation_remover.a",
                value: self.a as f64,
                min: 1.0,
                max: (MAX_OSCILLATION_WINDOW - 1) as f64,
            });
        }
        check_positive("oscillation_remover.threshold_rps", self.threshold_rps)?;
        Ok(())
    }
}

/// The last `a + 1` samples (a fixed ring, so that `push` allocates nothing).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OscillationRemover {
    config: OscillationRemoverConfig,
    ring: [f64; MAX_OSCILLATION_WINDOW],
    next: usize,
    filled: usize,
}

impl OscillationRemover {
    /// A remover with validated settings.
    pub fn new(config: OscillationRemoverConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            ring: [0.0; MAX_OSCILLATION_WINDOW],
            next: 0,
            filled: 0,
        })
    }

    /// Takes one rate and returns it, or 0 when the window's sum is below the threshold.
    /// A typed error for a non-finite input (nothing changes then).
    pub fn push(&mut self, j_rps: f64) -> Result<f64> {
        let j = check_finite("gyro rate", j_rps)?;
        let n = self.config.a + 1;
        self.ring[self.next] = j;
        self.next = (self.next + 1) % n;
        self.filled = (self.filled + 1).min(n);
        if self.filled < n {
            return Ok(j);
        }
        let sum: f64 = self.ring[..n].iter().sum();
        if (sum / self.config.a as f64).abs() < self.config.threshold_rps {
            Ok(0.0)
        } else {
            Ok(j)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A tremor that alternates sign sample by sample is removed; a steady turn above the
        /// threshold passes unchanged.
        #[test]
        fn removes_tremor_and_keeps_turns(tremor in 0.0f64..0.5, rate in 0.02f64..3.0) {
            let mut r = OscillationRemover::new(OscillationRemoverConfig::default()).unwrap();
            for k in 0..50 {
                let x = if k % 2 == 0 { tremor } else { -tremor };
                let y = r.push(x).unwrap();
                if k >= 3 {
                    prop_assert_eq!(y, 0.0);
                }
            }
            let mut r = OscillationRemover::new(OscillationRemoverConfig::default()).unwrap();
            for _ in 0..50 {
                prop_assert_eq!(r.push(rate).unwrap(), rate);
            }
        }
    }

    #[test]
    fn bad_input_and_config() {
        assert!(
            OscillationRemover::new(OscillationRemoverConfig {
                a: 0,
                ..Default::default()
            })
            .is_err()
        );
        assert!(
            OscillationRemover::new(OscillationRemoverConfig {
                a: 16,
                ..Default::default()
            })
            .is_err()
        );
        let mut r = OscillationRemover::new(OscillationRemoverConfig::default()).unwrap();
        assert!(r.push(f64::INFINITY).is_err());
    }
}
