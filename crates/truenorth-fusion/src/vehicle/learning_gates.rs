//! Which calibration states a measurement may teach, how far the wheels are trusted against
//! the gyro, and whether the time base agrees with the motion.
//!
//! A measurement of the heading (the wheels against the gyro, or the compass) sees the sum
//! of every sensor error that moved the heading since the last one. A state is taught by it
//! only where the interval held the motion that separates that state from the others: a
//! gyro gain in a clear turn that way, the speed coefficient in a turn at speed, the
//! wheels' track in a turn. Elsewhere the state is only *considered* (its uncertainty is
//! carried into the measurement, [`super::nav_filter::NavFilter::update_some`]), so that a
//! steady circle, a straight road or a crawl cannot teach it what only their combination
//! shows.
//!
//! The wheels' trust adapts to what they do: if their comparisons with the gyro disagree
//! by more than the model allows (a skid-steer on a new ground, wheels spinning), the
//! wheels' slip noise is scaled up until the disagreement is what it predicts
//! (covariance matching, Mehra, "Approaches to adaptive filtering", IEEE Trans. AC 17(5),
//! 1972), and meanwhile the wheels teach the gyro nothing.

use truenorth_core::{Error, Result};

use super::nav_filter::{
    ALL_STATES, GAIN_NEG, GAIN_POS, SPEED_COEFF, StateSet, TRACK_SCALE, state,
};

/// Turning (rad) an interval must hold, of the kind that separates a state, before a
/// measurement at its end teaches that state (6°).
const MIN_SEPARATING_TURN_RAD: f64 = 0.1;

/// Speed above which a turn teaches the speed coefficient, m/s (15 mph, US 4,788,645's own
/// lower gate: below it `aV²` is under a tenth of a percent).
pub const SPEED_COEFF_MIN_SPEED_MPS: f64 = 6.7;

/// Weight of one comparison in the running mean of the normalised innovations (about the
/// last 20 comparisons).
const NIS_WEIGHT: f64 = 0.05;

/// Largest normalised innovation one comparison adds to the mean: one wheel spin must not
/// inflate the wheels' noise for minutes.
const NIS_CLAMP: f64 = 25.0;

/// Above this mean normalised innovation the wheels disagree with the gyro beyond their
/// model, and teach it nothing.
const NIS_DISTRUST: f64 = 3.0;

/// Largest factor on the wheels' slip variance.
const MAX_SLIP_SCALE2: f64 = 400.0;

/// What a measurement interval held.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Interval {
    /// Gyro turning in clear turns, right and left, rad.
    pub clear_turn_rad: [f64; 2],
    /// Wheel turning, rad.
    pub wheel_turn_rad: f64,
    /// Wheel turning at speed (≥ [`SPEED_COEFF_MIN_SPEED_MPS`]), rad.
    pub turn_at_speed_rad: f64,
}

impl Interval {
    /// The states a measurement at the end of this interval may correct.
    pub fn learnable(&self) -> StateSet {
        let mut set = ALL_STATES;
        for (k, s) in [(0, GAIN_POS), (1, GAIN_NEG)] {
            if self.clear_turn_rad[k] < MIN_SEPARATING_TURN_RAD {
                set &= !state(s);
            }
        }
        if self.turn_at_speed_rad < MIN_SEPARATING_TURN_RAD {
            set &= !state(SPEED_COEFF);
        }
        if self.wheel_turn_rad < MIN_SEPARATING_TURN_RAD {
            set &= !state(TRACK_SCALE);
        }
        set
    }
}

/// The intervals of both kinds of measurement, and the wheels' adaptive trust.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LearningGates {
    /// Since the last comparison of wheels and gyro.
    pub wheel_check: Interval,
    /// Since the last compass correction.
    pub compass: Interval,
    /// Running mean of the comparisons' normalised innovation squared.
    pub mean_nis: f64,
    /// Factor on the wheels' slip variance (≥ 1).
    pub slip_scale2: f64,
    time_base: TimeBase,
}

impl Default for LearningGates {
    fn default() -> Self {
        Self {
            wheel_check: Interval::default(),
            compass: Interval::default(),
            mean_nis: 1.0,
            slip_scale2: 1.0,
            time_base: TimeBase::default(),
        }
    }
}

impl LearningGates {
    /// Counts a gyro step that turned `dpsi` (rad); `clear` when the turn is clear of the
    /// bias's uncertainty.
    pub fn gyro_step(&mut self, dpsi: f64, clear: bool) {
        if clear {
            let k = usize::from(dpsi < 0.0);
            self.wheel_check.clear_turn_rad[k] += dpsi.abs();
            self.compass.clear_turn_rad[k] += dpsi.abs();
        }
        self.time_base.gyro_rad += dpsi;
    }

    /// Counts a wheel step that turned `dpsi` (rad) at `speed_mps`; `compared` when the
    /// gyro integrated the same interval (the time base is judged only there).
    pub fn wheel_step(&mut self, dpsi: f64, speed_mps: f64, compared: bool) {
        for i in [&mut self.wheel_check, &mut self.compass] {
            i.wheel_turn_rad += dpsi.abs();
            if speed_mps >= SPEED_COEFF_MIN_SPEED_MPS {
                i.turn_at_speed_rad += dpsi.abs();
            }
        }
        if compared {
            self.time_base.wheels_rad += dpsi;
        }
    }

    /// The states the comparison of wheels and gyro may correct now: as
    /// [`Interval::learnable`], and no gyro gain while the wheels disagree beyond their
    /// model.
    pub fn wheel_check_learnable(&self) -> StateSet {
        let mut set = self.wheel_check.learnable();
        if self.mean_nis > NIS_DISTRUST || self.slip_scale2 > NIS_DISTRUST {
            set &= !(state(GAIN_POS) | state(GAIN_NEG));
        }
        set
    }

    /// Takes a comparison's normalised innovation squared and starts a new interval: the
    /// running mean moves towards it, and the slip scale follows the mean (a tenth at a
    /// time, so that it settles where the innovations are as large as predicted).
    pub fn wheel_check_done(&mut self, nis: f64) {
        self.wheel_check = Interval::default();
        if !nis.is_finite() {
            return;
        }
        self.mean_nis += NIS_WEIGHT * (nis.min(NIS_CLAMP) - self.mean_nis);
        self.slip_scale2 =
            (self.slip_scale2 * self.mean_nis.clamp(0.9, 1.1)).clamp(1.0, MAX_SLIP_SCALE2);
    }

    /// Starts a new compass interval.
    pub fn compass_done(&mut self) {
        self.compass = Interval::default();
    }

    /// Closes a time-base window at a comparison of wheels and gyro (the turning of both
    /// since the last one), and counts a sensor step that was `gap` while moving.
    pub fn time_base_window(&mut self) {
        self.time_base.close_window();
    }

    /// Counts one step of a sensor while the vehicle moved; `gap` if it was longer than
    /// the estimator bridges.
    pub fn count_step(&mut self, gap: bool) {
        self.time_base.count_step(gap);
    }

    /// An error if the evidence so far says the time base or the gyro's unit is not what
    /// the input declares.
    pub fn check_time_base(&self) -> Result<()> {
        self.time_base.check()
    }
}

/// Comparison windows with at least this much wheel turning count towards the time-base
/// check, rad (6°: a turn of 6°/s, against which an unlearned bias of up to 5°/s still
/// leaves the ratio within its range).
const TIME_BASE_WINDOW_TURN_RAD: f64 = 0.1;

/// Windows needed before the turn ratio is judged.
const TIME_BASE_WINDOWS: u32 = 5;

/// Sensor steps while moving needed before the share of gaps is judged.
const TIME_BASE_STEPS: u32 = 20;

/// The evidence on the time base: how far the gyro turns against the wheels, and how many
/// steps are gaps.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
struct TimeBase {
    gyro_rad: f64,
    wheels_rad: f64,
    sum_gyro: f64,
    sum_wheels: f64,
    windows: u32,
    steps: u32,
    gaps: u32,
}

impl TimeBase {
    fn close_window(&mut self) {
        if self.wheels_rad.abs() >= TIME_BASE_WINDOW_TURN_RAD && self.windows < u32::MAX {
            self.sum_gyro += self.gyro_rad.abs();
            self.sum_wheels += self.wheels_rad.abs();
            self.windows += 1;
        }
        self.gyro_rad = 0.0;
        self.wheels_rad = 0.0;
    }

    fn count_step(&mut self, gap: bool) {
        if self.steps < TIME_BASE_STEPS {
            self.steps += 1;
            self.gaps += u32::from(gap);
        }
    }

    /// The gyro turns 0.1–10 times what the wheels turn on any vehicle (a skid-steer's
    /// wheels turn 1.5–2.5 times the vehicle, a gyro's scale is off by a few percent): a
    /// ratio of 57 is a gyro in °/s, one of 1000 a time base in milliseconds. And a vehicle
    /// whose sensors are gaps apart on nearly every step cannot be followed: a time base in
    /// milliseconds makes every step of a 10 Hz log 100 s long.
    fn check(&self) -> Result<()> {
        if self.windows >= TIME_BASE_WINDOWS && self.sum_wheels > 0.0 {
            let ratio = self.sum_gyro / self.sum_wheels;
            if !(0.1..=10.0).contains(&ratio) {
                return Err(Error::Implausible {
                    what: "the gyro's turn over the wheels' turn in the same turns",
                    value: ratio,
                    min: 0.1,
                    max: 10.0,
                    hint: "near 57: gyr_z is in deg/s, not rad/s; near 1000: t_s is in milliseconds, not seconds; near 0.0175: gyr_z is in rad/s scaled as deg/s; otherwise check the wheel distances' unit and the track",
                });
            }
        }
        if self.steps >= TIME_BASE_STEPS && self.gaps * 5 >= self.steps * 4 {
            return Err(Error::Implausible {
                what: "share of sensor steps longer than max_gap_s while the vehicle moves",
                value: f64::from(self.gaps) / f64::from(self.steps),
                min: 0.0,
                max: 0.8,
                hint: "t_s is probably not in seconds (milliseconds?); a log this sparse needs a larger max_gap_s",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_is_learnable_only_after_the_motion_that_separates_it() {
        let mut g = LearningGates::default();
        let none = g.wheel_check_learnable();
        for s in [GAIN_POS, GAIN_NEG, SPEED_COEFF, TRACK_SCALE] {
            assert_eq!(none & state(s), 0);
        }
        g.gyro_step(0.2, true);
        g.wheel_step(0.2, 3.0, true);
        let set = g.wheel_check_learnable();
        assert_ne!(set & state(GAIN_POS), 0);
        assert_eq!(set & state(GAIN_NEG), 0);
        assert_ne!(set & state(TRACK_SCALE), 0);
        // The turn was slow: the speed coefficient cannot show in it.
        assert_eq!(set & state(SPEED_COEFF), 0);
        g.wheel_step(0.2, 20.0, true);
        assert_ne!(g.wheel_check_learnable() & state(SPEED_COEFF), 0);
        g.wheel_check_done(1.0);
        assert_eq!(g.wheel_check_learnable() & state(GAIN_POS), 0);
        // The compass interval runs on its own.
        assert_ne!(g.compass.learnable() & state(GAIN_POS), 0);
    }

    #[test]
    fn wheels_that_disagree_are_trusted_less_and_teach_no_gain() {
        let mut g = LearningGates::default();
        for _ in 0..200 {
            g.gyro_step(0.3, true);
            g.wheel_step(0.3, 2.0, true);
            assert!(g.slip_scale2 >= 1.0);
            g.wheel_check_done(20.0);
        }
        assert!(g.slip_scale2 > 10.0, "{}", g.slip_scale2);
        g.gyro_step(0.3, true);
        assert_eq!(g.wheel_check_learnable() & state(GAIN_POS), 0);
        // Agreement brings the trust back.
        for _ in 0..2000 {
            g.wheel_check_done(0.5);
        }
        assert_eq!(g.slip_scale2, 1.0);
    }

    #[test]
    fn a_gyro_in_degrees_or_a_time_base_in_milliseconds_is_named() {
        for (ratio, ok) in [(1.0, true), (0.45, true), (57.3, false), (1000.0, false)] {
            let mut g = LearningGates::default();
            for _ in 0..TIME_BASE_WINDOWS {
                g.gyro_step(0.5 * ratio, false);
                g.wheel_step(0.5, 5.0, true);
                g.time_base_window();
            }
            assert_eq!(g.check_time_base().is_ok(), ok, "{ratio}");
        }
        let mut g = LearningGates::default();
        for k in 0..TIME_BASE_STEPS {
            g.count_step(k % 10 != 0);
        }
        assert!(matches!(
            g.check_time_base(),
            Err(Error::Implausible { .. })
        ));
    }
}
