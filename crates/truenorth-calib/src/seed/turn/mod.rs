//! The compass half of the one-turn calibration (EP 0640207
//! claims 4, 5 and 10).
//!
//! The vehicle turns through at least one full revolution. Each magnetometer axis passes a
//! maximum and a minimum once per revolution; the centre of the locus is
//! `X₀ = (X_max + X_min)/2`, `Y₀ = (Y_max + Y_min)/2` (claim 4), its radii
//! `a = (X_max − X_min)/2`, `b = (Y_max − Y_min)/2` (claim 5), and the heading is the angle of
//! the line from the centre to the reading with the axes scaled by `a` and `b` (claim 10).
//!
//! The extrema come from [`crate::seed::extrema`], which the gyro half (conversion constant `k`
//! from the relative heading at the extrema, §A.2–3) reuses: [`TurnExtrema`] is generic over
//! the tag recorded with each extremum, and pairs each maximum with the minimum next to it in
//! time — within one revolution, never across revolutions (§A.3) — averaging over all such
//! pairs when the turn goes on for more than one revolution.
//!
//! Refusals: a turn of less than 360° ([`Error::IncompleteTurn`](truenorth_core::Error::IncompleteTurn)); an axis whose maximum or
//! minimum lies at the start or end of the record, where the true extremum may be outside it
//! ([`Error::Degenerate`](truenorth_core::Error::Degenerate)); a turn that reverses direction.
//!
//! The method scales the two axes but cannot remove a *rotated* soft iron (an ellipse whose
//! axes are not the sensor's): the quality report gives what that leaves (the two-cycle part
//! of the residual) as `heading_error_systematic_deg`.
//!
//! `progress().ready` runs the acceptance tests of `solve` (the extrema, then the arc of the
//! calibrated readings), so the two always agree; the calibrator saves and restores its whole
//! state through [`Persistent`](truenorth_core::Persistent).
//!
//! Files: [`turn_extrema`] (the two axes' extrema and the ellipse and turn angle they give),
//! [`config`] (the settings both halves share), [`compass`] (the compass half and its saved
//! state).

pub(crate) mod compass;
pub(crate) mod config;
#[cfg(test)]
mod tests;
pub(crate) mod turn_extrema;

pub use compass::{TurnCompassCalibrator, TurnCompassCalibratorState};
pub use config::{DEFAULT_MAX_GAP_S, TurnConfig};
pub use turn_extrema::{MIN_TURN_SAMPLES, TurnEllipse, TurnExtrema, TurnExtremaState, TurnTag};
