//! What the vehicle estimator keeps of the satellite fixes between samples (see
//! [`super::gnss_fusion`]): the tangent plane's origin, whether heading and track are
//! referred to the fixes, the counts, the courses gathered to refer them, and the last fix
//! whose speed over ground starts a comparison with the odometer.

use serde::{Deserialize, Serialize};

use super::innovation_line::InnovationLine;
use super::odometer_history::OdometerHistory;
use super::path_trail::PathTrail;

/// The fixes as the estimator has used them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub(super) struct GnssTrack {
    /// The first fix, latitude and longitude in degrees: the tangent plane's origin.
    pub origin: Option<(f64, f64)>,
    /// Declination at the origin, rad (east positive).
    pub declination_rad: f64,
    /// Heading and track are referred to the fixes: the heading to true north, the track
    /// to the plane.
    pub aligned: bool,
    /// When the last fix was used, s.
    pub last_used_s: Option<f64>,
    /// When the current run of rejected fixes began, s.
    pub rejected_since_s: Option<f64>,
    /// Fixes used, rejected, and restarts of the position from a fix after a run of
    /// rejections.
    pub used: u32,
    pub rejected: u32,
    pub restarts: u32,
    /// The courses' differences from the heading, while they are gathered to refer it to
    /// true north.
    pub line: InnovationLine,
    /// Where a displacement to refer the heading to true north started: the fix's north
    /// and east, and the dead-reckoned position's, m.
    pub start: Option<[f64; 4]>,
    /// How the track was put on the plane when the fixes referred it there: see
    /// [`PlaneShift`].
    pub shift: Option<PlaneShift>,
    /// The heading was referred to true north by courses taken with no odometry, and the
    /// track is not on the plane yet: it is put there at the first fix after the odometry
    /// starts, and its position is not published before.
    pub course_only: bool,
    /// The last fix with a speed over ground that can start a comparison of distances
    /// with the odometer.
    pub speed_mark: Option<SpeedMark>,
    /// The odometer's last readings, for its distance at a fix's epoch.
    pub odometer: OdometerHistory,
    /// The dead-reckoned path's last seconds, for where the vehicle was at the epoch of a
    /// fix stamped long after it.
    pub trail: PathTrail,
}

/// How the fixes put the track on their plane: turned about the start by `turn_rad` (the
/// offset that referred a heading relative to the start to true north, or, when the compass
/// had referred it to magnetic north, the declination), then shifted by `north_m`,
/// `east_m`. Estimates made before join the plane by the same.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PlaneShift {
    /// The turn about the start, rad.
    pub turn_rad: f64,
    /// Whether the compass had referred the heading to magnetic north before (the turn is
    /// then the declination, and the published magnetic heading does not change).
    pub after_compass: bool,
    /// The shift after the turn, m.
    pub north_m: f64,
    /// See `north_m`.
    pub east_m: f64,
}

/// One end of a comparison: a fix with a speed over ground.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct SpeedMark {
    /// The fix's epoch (its stamp less the receiver's delay), s.
    pub t_s: f64,
    /// The receiver's speed over ground, m/s.
    pub fix_mps: f64,
    /// The odometer's distance at the epoch, before its scale, m.
    pub odometer_m: f64,
}
