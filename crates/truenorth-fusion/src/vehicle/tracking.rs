//! The vehicle estimator's bookkeeping between samples, as one value: the gyro's and the
//! wheels' last steps, rest, the learning gates, the compass's alignment, outage and
//! averaging window, and the covariance steps not yet applied. The estimator holds it as
//! its state beside its configuration and the coefficients derived from it, so that saving
//! and restoring copy it whole (see ARCHITECTURE.md, "Persistence").

use serde::{Deserialize, Serialize};

use super::gnss_track::GnssTrack;
use super::heading_trig::HeadingTrig;
use super::innovation_line::InnovationLine;
use super::learning_gates::LearningGates;
use super::nav_filter::DIM;
use super::plain_baseline::PlainBaseline;
use super::step_batch::StepBatch;

/// The vehicle estimator's bookkeeping between samples (the gyro's and the wheels' last
/// steps, rest, the learning gates, the compass's alignment, outage and averaging window,
/// the covariance steps not yet applied); opaque beyond serde.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleTracking {
    pub(super) gyro: GyroTrack,
    pub(super) motion: Motion,
    pub(super) rest: Rest,
    /// Seconds of driving since the wheels were last compared with the gyro.
    pub(super) wheel_check_s: f64,
    pub(super) gates: LearningGates,
    pub(super) alignment: Alignment,
    pub(super) outage: Outage,
    pub(super) batch: StepBatch,
    pub(super) window: CompassWindow,
    /// Sine and cosine of the mid-step heading and of the predicted compass reading.
    pub(super) trig: HeadingTrig,
    pub(super) trig_compass: HeadingTrig,
    /// Time passed since the covariance was last carried forward, s: the calibration
    /// states' walk and the compass error's decay over it enter once, at the next epoch.
    pub(super) pending_time_s: f64,
    /// Rows taken since the last epoch.
    pub(super) rows_since_epoch: u32,
    /// When the undetermined states were last refreshed, s; `-inf` until the first refresh.
    #[serde(with = "truenorth_core::extended_float::scalar")]
    pub(super) unobserved_at_s: f64,
    /// Readings up to this time are not offered to the compass learner (it has them
    /// already: the estimator is replaying them); `-inf` unless it replays.
    #[serde(with = "truenorth_core::extended_float::scalar")]
    pub(super) learned_until_s: f64,
    /// Plain integration beside the fused estimate.
    #[serde(default)]
    pub(super) guard: PlainBaseline,
    /// The satellite fixes as used so far.
    #[serde(default)]
    pub(super) gnss: GnssTrack,
}

impl VehicleTracking {
    /// Nothing seen yet.
    pub(super) fn start() -> Self {
        Self {
            gyro: GyroTrack::default(),
            motion: Motion::default(),
            rest: Rest::default(),
            wheel_check_s: 0.0,
            gates: LearningGates::default(),
            alignment: Alignment::default(),
            outage: Outage::default(),
            batch: StepBatch::default(),
            window: CompassWindow::default(),
            trig: HeadingTrig::new(0.0),
            trig_compass: HeadingTrig::new(0.0),
            pending_time_s: 0.0,
            rows_since_epoch: 0,
            unobserved_at_s: f64::NEG_INFINITY,
            learned_until_s: f64::NEG_INFINITY,
            guard: PlainBaseline::default(),
            gnss: GnssTrack::default(),
        }
    }
}

/// The gyro between readings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct GyroTrack {
    /// The gyro carries the heading (a reading has been seen and the method uses it).
    pub active: bool,
    /// The gyro's states come from a stored calibration rather than the priors.
    pub restored: bool,
    /// The last reading and its time.
    pub last: Option<(f64, f64)>,
    /// The corrected rate, low-passed, rad/s: which way the vehicle turns, free of the
    /// sign flips of noise and vibration.
    pub smoothed_rps: f64,
    /// The wheels' heading at the last gyro reading, for a gap the wheels bridge.
    pub odo_at_last_rad: f64,
    /// The gyro's usual interval between readings, s (a running mean of the intervals not
    /// much longer than it).
    pub interval_s: f64,
    /// The corrected rate over the last interval, rad/s: the heading carries on at it
    /// until the next reading, so that a sensor read between two gyro readings is
    /// compared with the heading at its own time.
    pub rate_rps: f64,
    /// The distance travelled at the last reading, m: what a gap that nothing else bridges
    /// leaves the heading free to turn over.
    #[serde(default)]
    pub distance_at_last_m: f64,
}

/// How the vehicle moves, from the wheels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Motion {
    /// Time the wheels have stood still, s.
    pub still_s: f64,
    /// Stood still for [`VehicleConfig::standstill_s`](super::VehicleConfig::standstill_s).
    pub at_rest: bool,
    /// The heading at the last wheel reading (for the mid-step heading of the track).
    pub psi_at_wheels_rad: f64,
    /// The interval between the last two wheel readings, s.
    pub wheel_interval_s: f64,
    /// The odometry says how the vehicle turns: two wheels (or sides) that have differed.
    /// A single distance (`dist_m`), or a left and a right equal on every row so far (one
    /// speed written twice), carries the distance and nothing about turning.
    #[serde(default)]
    pub wheels_turn: bool,
    /// The odometry read so far is one distance, not two wheels.
    #[serde(default)]
    pub single_distance: bool,
    /// The rate the heading last turned at, from whichever sensor carried it, rad/s.
    #[serde(default)]
    pub heading_rate_rps: f64,
    /// The odometer's distance so far before its scale is applied (forward and back
    /// alike), m.
    #[serde(default)]
    pub odometer_m: f64,
    /// Wheel speeds held within a quantum: since when, and at what.
    #[serde(default)]
    pub speed_hold: SpeedHold,
}

/// Quantised wheel speeds held steady: each wheel's rounding error stays the same until its
/// speed moves by a quantum, so their difference turns the wheels' heading at a constant
/// rate for as long as the hold lasts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SpeedHold {
    /// The speeds when the hold began (left, right), m/s.
    pub speeds_mps: [f64; 2],
    /// How long they have held, s.
    pub held_s: f64,
}

/// Rest and the bias average.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Rest {
    pub sum_raw: f64,
    pub n: u32,
    pub span_s: f64,
}

/// How long the compass has been rejected, and how far the vehicle turned and drove
/// meanwhile.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Outage {
    pub rejected_s: f64,
    pub turned_rad: f64,
    /// Distance driven while rejected, m.
    #[serde(default)]
    pub travelled_m: f64,
    /// Time and heading at the last reading.
    pub last: Option<(f64, f64)>,
    /// Distance driven at the last reading, m.
    #[serde(default)]
    pub last_distance_m: f64,
    /// The calibration in use was found wanting: a new one is being learned from readings
    /// the gates cannot judge.
    pub relearning: bool,
    /// The rejected readings' innovations in time.
    pub line: InnovationLine,
}

/// Compass readings taken since the last heading correction, averaged into one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct CompassWindow {
    pub n: u32,
    pub sum_nu: f64,
    /// Σ over the readings of the heading's accumulated couplings `A_k` at each reading,
    /// counted from the start of the current batch.
    pub sum_psi_from: [f64; DIM],
    /// Σ over the readings of the heading noise the current batch had added by each.
    pub sum_noise_at: f64,
    /// Σ over the readings of the heading noise added after each, up to the batch start:
    /// the reading did not see it, so the window's mean carries a share of it as noise.
    pub noise_after: f64,
    pub variance_rad2: f64,
}

impl Default for CompassWindow {
    fn default() -> Self {
        Self {
            n: 0,
            sum_nu: 0.0,
            sum_psi_from: [0.0; DIM],
            sum_noise_at: 0.0,
            noise_after: 0.0,
            variance_rad2: 0.0,
        }
    }
}

/// Alignment: the first run of consistent compass readings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Alignment {
    pub done: bool,
    /// The heading, though referred to north, is too uncertain for a linear correction:
    /// it is being referred to north again from a run of consistent readings.
    pub relocking: bool,
    /// The turn applied to heading and track when they were referred to north, rad.
    pub offset_rad: f64,
    pub line: InnovationLine,
}
