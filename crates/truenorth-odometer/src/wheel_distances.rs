//! The two quantities every odometer model speaks in, below the vehicle geometries that use
//! them: the left and right wheels' distances, and the range of tracks a wheeled vehicle can
//! have.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, check_range};

/// Distances of the left and right odometer wheels over one step (or cumulative), m.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelDistances {
    /// Left wheel, m.
    pub left_m: f64,
    /// Right wheel, m.
    pub right_m: f64,
}

/// The tracks a wheeled vehicle can have, m: from a 1 cm micro-robot to 100 m, ten times a
/// mining truck's. A track is the lever that turns the wheels' difference into a turn
/// (`Δθ = Δd/T`): one far below any vehicle's (10⁻³⁰⁰ m passes a positivity test) turns a
/// millimetre of difference into 10³⁰⁰ rad, whose square overflows the heading's variance
/// and leaves NaN behind; one far above it makes every turn nothing.
pub const TRACK_RANGE_M: (f64, f64) = (0.01, 100.0);

/// Checks a track `value` (named `what`) against [`TRACK_RANGE_M`].
pub fn check_track(what: &'static str, value: f64) -> Result<f64> {
    check_range(what, value, TRACK_RANGE_M.0, TRACK_RANGE_M.1)
}
