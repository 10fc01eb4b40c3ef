//! Saving and restoring a [`TurnCalibrator`] exactly ([`Persistent`]).

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_core::extended_float::check_plain_numbers_finite;
use truenorth_core::{Error, Persistent, Result, TimeStep, Validate};

use crate::seed::direction_slots::DirectionSlots;
use crate::seed::turn::{TurnConfig, TurnExtrema, TurnExtremaState};

use super::calibrator::{BLOCKS, Block, Kept, PENDING, PLACED, RING, RawHeading, TurnCalibrator};

/// The saved state of a [`TurnCalibrator`] ([`Persistent::State`]): its configuration,
/// the extremum trackers, the integrated rate, the leading record's blocks, the readings
/// kept for placing extrema and the extrema placed or waiting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnCalibratorState {
    /// The configuration.
    pub config: TurnConfig,
    /// The extremum trackers (opaque), tagged with where each sample was on the relative
    /// heading.
    pub extrema: TurnExtremaState<RawHeading>,
    /// The kept readings by direction slot (72 entries, `None` where empty).
    pub slots: Vec<Option<Vector2<f64>>>,
    /// The last accepted timestamp.
    pub clock: TimeStep,
    /// The first sample's timestamp, s.
    pub first_t_s: Option<f64>,
    /// The last raw rate, rad/s.
    pub last_rate_rps: f64,
    /// Where the last sample was on the relative heading.
    pub at: RawHeading,
    /// Extrema placed per axis, counted since the start (the last 64 are kept).
    pub placed_count: [usize; 2],
    /// The kept placed extrema per axis: (sample index, placed relative heading, value).
    pub placed: [Vec<(usize, f64, f64)>; 2],
    /// Confirmed extrema waiting to be placed, per axis: (sample index, relative heading at
    /// the sample, maximum or not).
    pub pending: [Vec<(usize, f64, bool)>; 2],
    /// Extrema confirmed so far per axis.
    pub confirmed: [usize; 2],
    /// The zero reading (rad/s), its standard deviation and the standstill's length (s),
    /// once found.
    pub zero: Option<(f64, f64, f64)>,
    /// The integral at the last kept reading, raw rad; `-inf` before the first.
    #[serde(with = "truenorth_core::extended_float::scalar")]
    pub last_kept_integral: f64,
    /// Ring slot the next kept reading goes to.
    pub ring_next: usize,
    /// The kept readings in slot order (opaque).
    ring: Vec<Kept>,
    /// The leading record's quarter-second blocks up to the last that holds a sample
    /// (opaque).
    blocks: Vec<Block>,
}

impl Persistent for TurnCalibrator {
    type State = TurnCalibratorState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> TurnCalibratorState {
        let used_blocks = self
            .blocks
            .iter()
            .rposition(|b| b.n > 0)
            .map_or(0, |i| i + 1);
        let placed = |axis: usize| self.placed[axis][..self.placed_len[axis].min(PLACED)].to_vec();
        let pending = |axis: usize| self.pending[axis][..self.pending_len[axis]].to_vec();
        TurnCalibratorState {
            config: self.config,
            extrema: self.extrema.saved(),
            slots: self.slots.to_vec(),
            clock: self.clock,
            first_t_s: self.t0,
            last_rate_rps: self.last_rate,
            at: self.at,
            placed_count: self.placed_len,
            placed: [placed(0), placed(1)],
            pending: [pending(0), pending(1)],
            confirmed: self.confirmed,
            zero: self.zero,
            last_kept_integral: self.last_kept_integral,
            ring_next: self.ring_next,
            ring: self.ring[..self.ring_len].to_vec(),
            blocks: self.blocks[..used_blocks].to_vec(),
        }
    }

    fn from_state(s: TurnCalibratorState) -> Result<Self> {
        s.config.validate()?;
        check_plain_numbers_finite(&s)?;
        let invalid = |reason| Err(Error::InvalidSnapshot { reason });
        let extrema = TurnExtrema::from_saved(s.extrema)?;
        if extrema.x().config() != &s.config.extrema || extrema.y().config() != &s.config.extrema {
            return invalid("the turn's extremum trackers were saved with another configuration");
        }
        let slots = DirectionSlots::from_slice(&s.slots).ok_or(Error::InvalidSnapshot {
            reason: "the turn's direction slots must be 72 finite readings or empty",
        })?;
        let seen = extrema.samples() > 0;
        if seen != s.clock.last_s().is_some() || seen != s.first_t_s.is_some() {
            return invalid("the turn's timestamps do not fit its sample count");
        }
        if s.last_kept_integral.is_nan() || s.last_kept_integral == f64::INFINITY {
            return invalid("the turn's last kept integral is not a number or +inf");
        }
        if s.blocks.len() > BLOCKS
            || s.ring.len() > RING
            || s.ring_next >= RING
            || (s.ring.len() < RING && s.ring_next != s.ring.len())
        {
            return invalid("the turn's leading blocks or kept readings are inconsistent");
        }
        for axis in 0..2 {
            if s.placed[axis].len() != s.placed_count[axis].min(PLACED)
                || s.pending[axis].len() > PENDING
            {
                return invalid("the turn's placed or waiting extrema are inconsistent");
            }
        }
        let mut c = Self::fresh(s.config, extrema);
        c.slots = slots;
        c.clock = s.clock;
        c.t0 = s.first_t_s;
        c.last_rate = s.last_rate_rps;
        c.at = s.at;
        c.blocks[..s.blocks.len()].copy_from_slice(&s.blocks);
        c.ring[..s.ring.len()].copy_from_slice(&s.ring);
        c.ring_len = s.ring.len();
        c.ring_next = s.ring_next;
        c.last_kept_integral = s.last_kept_integral;
        for axis in 0..2 {
            c.placed[axis][..s.placed[axis].len()].copy_from_slice(&s.placed[axis]);
            c.pending[axis][..s.pending[axis].len()].copy_from_slice(&s.pending[axis]);
            c.pending_len[axis] = s.pending[axis].len();
        }
        c.placed_len = s.placed_count;
        c.confirmed = s.confirmed;
        c.zero = s.zero;
        Ok(c)
    }
}
