//! The track to divide a wheel-distance difference by, as a function of the turn.
//!
//! For rear wheels it is the fixed track (US 4,788,645 eq. 7). For Ackermann-steered front
//! wheels it shrinks in a turn (eq. 3/14); three sources implement this trait: the exact
//! geometry ([`crate::AckermannGeometry`]), the patent's formula
//! ([`crate::PatentAckermannTrack`]) and its look-up table ([`crate::EffectiveTrackTable`]).

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, check_finite};

use truenorth_core::check_positive;

/// A source of effective track as a function of the measured curvature ratio.
pub trait EffectiveTrack {
    /// Effective track, m, at the curvature ratio `ratio = ΔD/AD` (difference of the two
    /// wheel distances over their mean; signed, dimensionless, about T/R). A typed error
    /// when `ratio` is not finite or beyond [`EffectiveTrack::max_ratio`].
    fn effective_track_m(&self, ratio: f64) -> Result<f64>;

    /// Largest |ratio| accepted.
    fn max_ratio(&self) -> f64;
}

/// A track that does not change with the turn: rear wheels on a rigid axle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FixedTrack {
    track_m: f64,
}

impl FixedTrack {
    /// A fixed track of `track_m` metres (positive, finite).
    pub fn new(track_m: f64) -> Result<Self> {
        Ok(Self {
            track_m: check_positive("track_m", track_m)?,
        })
    }

    /// The track, m.
    pub fn track_m(&self) -> f64 {
        self.track_m
    }
}

impl EffectiveTrack for FixedTrack {
    fn effective_track_m(&self, ratio: f64) -> Result<f64> {
        check_finite("curvature ratio ΔD/AD", ratio)?;
        Ok(self.track_m)
    }

    fn max_ratio(&self) -> f64 {
        f64::INFINITY
    }
}
