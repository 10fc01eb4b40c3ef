//! Calibration (raw → physical, given parameters) and calibrators (samples → parameters plus
//! a report on how far those parameters can be trusted).
//!
//! A [`Calibrator`] learns from samples pushed one at a time and is asked for a solution with
//! [`Calibrator::solve`], which takes `&self`: asking never changes what the calibrator has
//! learned, so an estimator can poll it while it keeps learning. Calibrators that keep a
//! current estimate as they go also implement [`OnlineCalibrator`], whose
//! [`OnlineCalibrator::estimate`] costs O(1); [`Calibrator::push`] says with
//! [`Pushed::NewEstimate`] when that estimate changed.

use serde::{Deserialize, Serialize};

use crate::{CompassQuality, Result};

/// A calibration: turns a raw reading into a physical quantity using stored parameters.
///
/// Fallible because parameters are plain data a user may have loaded from disk (a zero
/// scale, a singular soft iron) and readings may be non-finite: both are typed errors, never
/// NaN outputs.
pub trait Calibration {
    /// The raw reading.
    type Raw;
    /// The calibrated quantity.
    type Physical;

    /// Applies the calibration, or says why the reading or the parameters cannot be used.
    fn apply(&self, raw: &Self::Raw) -> Result<Self::Physical>;
}

/// What a [`Calibrator::push`] did with a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Pushed {
    /// The sample was valid but not used (e.g. too close to the previous one, or outside the
    /// conditions the method learns in).
    Ignored,
    /// The sample was used; the current estimate, if any, is unchanged.
    Accepted,
    /// The sample was used and the current estimate changed (see
    /// [`OnlineCalibrator::estimate`]).
    NewEstimate,
}

/// How far a calibrator has got.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Samples accepted so far.
    pub samples: usize,
    /// Share of the needed excitation seen so far, in [0, 1] (e.g. heading bins filled).
    pub coverage: f64,
    /// `true` exactly when [`Calibrator::solve`] would succeed now: every calibrator
    /// computes it from the same tests `solve` applies, so the two never disagree.
    pub ready: bool,
}

/// The result of a successful solve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Solution<P, Q = CompassQuality> {
    /// The calibration parameters.
    pub params: P,
    /// How far they can be trusted.
    pub quality: Q,
}

/// A calibrator: fed samples one at a time, solved for parameters when enough were seen.
///
/// Batch (least-squares) and online (seed) calibrators share this trait, so a user can swap
/// one for another with one line.
pub trait Calibrator {
    /// The sample type it learns from.
    type Sample;
    /// The parameters it produces.
    type Params;
    /// The quality report of its family ([`CompassQuality`], [`ScalarQuality`](crate::ScalarQuality), …).
    type Quality;

    /// Feeds one sample. Non-finite samples are rejected with a typed error and change
    /// nothing.
    fn push(&mut self, sample: &Self::Sample) -> Result<Pushed>;

    /// How far the calibrator has got. `progress().ready` is `true` exactly when
    /// [`Calibrator::solve`] would succeed.
    fn progress(&self) -> Progress;

    /// Solves for the parameters from everything learned so far, or says why the data
    /// cannot support a calibration. Does not change the calibrator.
    fn solve(&self) -> Result<Solution<Self::Params, Self::Quality>>;

    /// Forgets all samples (the configuration stays).
    fn reset(&mut self);
}

/// A calibrator that keeps a current estimate as samples arrive.
pub trait OnlineCalibrator: Calibrator {
    /// The current estimate, if the calibrator has one: O(1), no allocation. It is the
    /// result of the latest refresh, which [`Calibrator::push`] announces with
    /// [`Pushed::NewEstimate`].
    fn estimate(&self) -> Option<Solution<Self::Params, Self::Quality>>;
}
