//! The whole one-turn calibration of EP 0640207: the gyro's zero reading
//! and conversion constant together with the compass's centre and radii, from a record that
//! starts at rest and turns through at least one revolution.
//!
//! 1. **Zero reading** (claims 8-9): the gyro's mean output while the vehicle stands before
//!    the turn. The standstill is found afterwards, in constant memory: the first minute is
//!    kept as quarter-second block summaries, and the leading blocks whose magnetometer
//!    reading stays within 3 % of the turn's swing of the first one are the standstill.
//! 2. **Relative heading** `G = ∫(raw − zero) dt` (trapezoid rule), in raw units. It is kept
//!    as `∫raw dt` and the time, so that the zero can be found after the fact.
//! 3. **Conversion constant** (claims 1, 6, 7): `G` at an X maximum and the X minimum of the
//!    same revolution differ by half a turn, so `k = |ΔG|/π` (raw rad per rad); the same for
//!    Y; the constant is the mean of the X and Y means. The patent reads `G` at the sample
//!    where each extremum occurs; a cosine is so flat at its peak that, with 1 % noise, that
//!    sample may lie ten degrees from it (a 5 % error in `k`). Here each extremum is placed
//!    by fitting `a + b cos u + c sin u` (a sinusoid of one turn per revolution, whatever
//!    the soft iron) to the readings within ±60° of `G` around it, twice, re-centred on the
//!    first fit's peak; linear least squares, exact for a noise-free locus, which brings the
//!    error to about a tenth of a degree.
//! 4. **Compass** (claims 4, 5, 10): centre `(max + min)/2` and radii `(max − min)/2` from the
//!    same extrema ([`crate::TurnCompassCalibrator`] and this share [`TurnExtrema`](crate::TurnExtrema)), with
//!    each extremum's value read off the fitted sinusoid rather than the largest noisy
//!    sample, which noise biases outwards.
//!
//! The gain found is that of the direction turned (a cheap gyro's gains often differ by a
//! percent between directions); the calibration applies it to both directions.
//!
//! Refusals: no standstill of at least [`MIN_REST_S`] at the start, a turn under 360°, an
//! extremum at the edge of the record, a turn that reverses, fewer than two readings on
//! either side of an extremum to place it, and (at the sample after it) a step between
//! samples longer than [`TurnConfig::max_gap_s`](crate::TurnConfig::max_gap_s), across which the rate cannot be
//! integrated: the calibrator never pairs extrema across a gap.

//!
//! Files: [`calibrator`] (the calibrator, its samples, result and quality), [`persist`] (its
//! saved state).

pub(crate) mod calibrator;
pub(crate) mod persist;

pub use calibrator::{
    MIN_REST_S, RawHeading, TurnCalibration, TurnCalibrator, TurnQuality, TurnSample,
};
pub use persist::TurnCalibratorState;
