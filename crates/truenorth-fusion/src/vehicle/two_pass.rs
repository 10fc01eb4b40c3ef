//! The two-pass start: a drive's first minutes are estimated again once the sensors are
//! known.
//!
//! A drive that starts uncalibrated does not know north until the compass has seen enough
//! of a turn, nor its gyro's gains until it has turned both ways; a causal estimator's
//! track of those first minutes is drawn with what it knew then, and a track is only as
//! good as its worst heading. When the whole log is at hand (post-processing, as the
//! `truenorth drive` command has it) the head of the drive can be held back, in bounded
//! memory, until the estimator has learned its sensors, and then run again from the start
//! by an estimator that knows them ([`VehicleEstimator::with_calibration`]); everything
//! after the head is estimated once, as it comes.

extern crate alloc;

use alloc::vec::Vec;

use truenorth_core::{HeadingEstimator, NavEstimate, Result, VehicleSample};

use super::estimator::VehicleEstimator;

/// When the head of the drive is run again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoPassConfig {
    /// Most samples held back (the memory bound); when it is reached the head is run again
    /// with whatever has been learned.
    pub capacity: usize,
    /// Time the estimator must have had its heading referred to north, with a calibration
    /// learned from gated readings, before the head is run again, s.
    pub settle_s: f64,
}

impl Default for TwoPassConfig {
    /// 2¹⁷ samples (about 8 MB; 3.6 h at 10 Hz, 22 min at 100 Hz), 120 s.
    fn default() -> Self {
        Self {
            capacity: 1 << 17,
            settle_s: 120.0,
        }
    }
}

/// A vehicle estimator with a two-pass start. See the module documentation.
#[derive(Debug, Clone)]
pub struct TwoPassStart {
    config: TwoPassConfig,
    estimator: VehicleEstimator,
    head: Vec<VehicleSample>,
    replayed: bool,
    settled_since_s: Option<f64>,
}

impl TwoPassStart {
    /// Wraps `estimator` (usually fresh from [`VehicleEstimator::new`]).
    pub fn new(estimator: VehicleEstimator, config: TwoPassConfig) -> Self {
        Self {
            config,
            estimator,
            head: Vec::new(),
            replayed: false,
            settled_since_s: None,
        }
    }

    /// The estimator (the second pass's once the head has been run again).
    pub fn estimator(&self) -> &VehicleEstimator {
        &self.estimator
    }

    /// Whether the head has been run again (estimates now come as samples arrive).
    pub fn replayed(&self) -> bool {
        self.replayed
    }

    /// Takes one sample; `emit` receives each sample with its final estimate, in order —
    /// none while the head is held back, the whole head at once when it is run again. A
    /// sample the estimator refuses is an error and is not held back.
    pub fn push(
        &mut self,
        sample: &VehicleSample,
        mut emit: impl FnMut(&VehicleSample, &NavEstimate),
    ) -> Result<()> {
        let estimate = self.estimator.update(sample)?;
        if self.replayed {
            emit(sample, &estimate);
            return Ok(());
        }
        self.head.push(*sample);
        let s = estimate.status;
        if s.heading_absolute && self.estimator.compass_learner().clean_in_use() {
            let since = *self.settled_since_s.get_or_insert(sample.t_s);
            if sample.t_s - since >= self.config.settle_s {
                return self.replay(&mut emit);
            }
        }
        if self.head.len() >= self.config.capacity {
            return self.replay(&mut emit);
        }
        Ok(())
    }

    /// Ends the drive: a head still held back is run again with what was learned.
    pub fn finish(&mut self, mut emit: impl FnMut(&VehicleSample, &NavEstimate)) -> Result<()> {
        if self.replayed {
            Ok(())
        } else {
            self.replay(&mut emit)
        }
    }

    fn replay(&mut self, emit: &mut impl FnMut(&VehicleSample, &NavEstimate)) -> Result<()> {
        let mut second = self.estimator.replay_start()?;
        for s in &self.head {
            // Every sample here was accepted by the first pass, which checks the same.
            let estimate = second.update(s)?;
            emit(s, &estimate);
        }
        self.estimator = second;
        self.head = Vec::new();
        self.replayed = true;
        Ok(())
    }
}
