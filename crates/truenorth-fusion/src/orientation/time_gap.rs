//! Time as a sensor: a step longer than the gyro can bridge is a gap, and a time base whose
//! steps are mostly such gaps contradicts the motion it claims to record.
//!
//! Strapdown integration holds one rate sample over the step; across a gap of seconds the
//! body may have turned any way, so an orientation estimator starts again from the
//! accelerometer and magnetometer after it and says so. A recording in which most steps
//! are gaps is no gyro record at all; the usual cause is a time column in milliseconds
//! read as seconds (every step at 100 Hz then lasts "10 s"), which is refused rather than
//! answered with an attitude re-initialised at every sample.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, check_positive};

/// Shortest step a real IMU gives, s (a 10 kHz sample rate), for the error message.
const MIN_REAL_STEP_S: f64 = 1e-4;

/// What a step is to an orientation estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Step {
    /// Integrate the gyro over it.
    Bridged,
    /// Too long: start again from this sample.
    Gap,
}

/// Counts steps and gaps (validated `max_gap_s` from the estimator's config): part of an
/// orientation estimator's saved state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GapMonitor {
    max_gap_s: f64,
    steps: u64,
    gaps: u64,
}

impl GapMonitor {
    /// A monitor for steps up to `max_gap_s`.
    pub(crate) fn new(max_gap_s: f64) -> Self {
        Self {
            max_gap_s,
            steps: 0,
            gaps: 0,
        }
    }

    /// Classifies a step of `dt_s` without counting it: a gap that would make gaps the
    /// majority of two or more steps is an [`Error::Implausible`] time base.
    pub(crate) fn classify(&self, dt_s: f64) -> Result<Step> {
        if dt_s <= self.max_gap_s {
            return Ok(Step::Bridged);
        }
        let (steps, gaps) = (self.steps + 1, self.gaps + 1);
        if steps >= 2 && 2 * gaps > steps {
            return Err(Error::Implausible {
                what: "time between samples (s)",
                value: dt_s,
                min: MIN_REAL_STEP_S,
                max: self.max_gap_s,
                hint: "most steps are longer than the gyro can bridge (max_gap_s); a time column in milliseconds must be divided by 1000",
            });
        }
        Ok(Step::Gap)
    }

    /// Checks a restored monitor against its estimator's `max_gap_s`: the same limit, and
    /// no more gaps than steps.
    pub(crate) fn check(&self, max_gap_s: f64) -> Result<()> {
        if self.max_gap_s != max_gap_s || self.gaps > self.steps {
            return Err(Error::InvalidSnapshot {
                reason: "the gap count differs from the estimator's max_gap_s or exceeds the steps",
            });
        }
        Ok(())
    }

    /// Counts a step that was classified and taken.
    pub(crate) fn count(&mut self, step: Step) {
        self.steps += 1;
        if step == Step::Gap {
            self.gaps += 1;
        }
    }
}

/// Checks a configured `max_gap_s`: positive, finite.
pub(crate) fn check_max_gap(max_gap_s: f64) -> Result<()> {
    check_positive("max_gap_s", max_gap_s).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A millisecond time base at any IMU rate is refused by its second step; a single
        /// gap in an otherwise regular record is a gap wherever it falls.
        #[test]
        fn milliseconds_are_refused_and_one_gap_is_a_gap(rate_hz in 10.0f64..2000.0, n in 2usize..500, at in 0usize..500) {
            let mut m = GapMonitor::new(2.0);
            let ms_step = 1000.0 / rate_hz;
            prop_assume!(ms_step > 2.0);
            prop_assert_eq!(m.classify(ms_step).unwrap(), Step::Gap);
            m.count(Step::Gap);
            let refused = matches!(m.classify(ms_step), Err(Error::Implausible { .. }));
            prop_assert!(refused);

            let mut m = GapMonitor::new(2.0);
            for k in 0..n {
                let dt = if k == at % n { 3600.0 } else { 1.0 / rate_hz };
                let step = m.classify(dt).unwrap();
                prop_assert_eq!(step == Step::Gap, k == at % n);
                m.count(step);
            }
        }
    }
}
