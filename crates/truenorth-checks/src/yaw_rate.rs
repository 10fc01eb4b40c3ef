//! A vehicle's yaw gyro checked against its wheels: over each second in which the vehicle
//! turns, the odometer wheels' distance difference over the track turns the vehicle by as
//! much as the gyro integrates (within the few percent of a gyro's scale error and the
//! 1.5–2.5 times of a skid-steer's wheel slip). A gyro in deg/s read as rad/s turns 57
//! times too far, one whose sign is flipped turns the other way; neither comes near one.
//! Streaming: it keeps a few sums, so a log of any length is checked as it is read.

use truenorth_core::{Fixed, VehicleSample};

use crate::finding::{Finding, Fix};
use crate::units::GyroUnit;

/// Length of a comparison window, s.
const WINDOW_S: f64 = 1.0;
/// A window counts when the wheels turned the vehicle by at least this, rad (3°): a
/// corner, not the wheels' noise.
const MIN_WINDOW_TURN_RAD: f64 = 0.05;
/// A step longer than this drops the window (a gap in the log).
const MAX_STEP_S: f64 = 0.5;
/// Turning windows needed before the gyro is judged.
pub const MIN_WINDOWS: usize = 10;
/// The wheels' turn per gyro turn a vehicle can show: a car's is 1 within the gyro's gain
/// error and the track's uncertainty, a skid-steer's up to 2.5 (its effective track is
/// 1.5-2.5 times the physical one); outside this the unit of a column or `track_m` is wrong.
const PLAUSIBLE_RATIO: (f64, f64) = (0.5, 3.0);
/// How close (as a factor) a ratio must come to a unit's factor to be named as it.
const UNIT_TOLERANCE: f64 = 1.15;

/// The share of the wheels' turns the gyro must explain (squared correlation) before its
/// scale or sign is judged: below it the two do not see the same motion at all.
pub const MIN_R2: f64 = 0.5;

/// The running comparison of the gyro's turns with the wheels'.
#[derive(Debug, Clone, PartialEq)]
pub struct YawRateCheck {
    track_m: f64,
    /// Start of the open window, s.
    start_s: Option<f64>,
    /// The wheels' and the gyro's turns in the open window, rad; whether it is still whole.
    window: (f64, f64, bool),
    last_wheels: Option<[f64; 2]>,
    last_gyro: Option<(f64, f64)>,
    /// The time the gyro's turn is integrated to, s: every row's, so that a row without
    /// a gyro reading does not add the last rate's turn since its reading again.
    gyro_to_s: f64,
    /// Σ wheels·gyro, Σ gyro², Σ wheels² over the turning windows.
    sums: [f64; 3],
    /// The number of turning windows.
    pub windows: usize,
    /// The row given with the last reading ([`YawRateCheck::push_at`]).
    row: Option<usize>,
    /// The row at which the last turning window needed for a judgement closed: where the
    /// evidence became clear.
    pub judged_at_row: Option<usize>,
}

impl YawRateCheck {
    /// A check for wheels `track_m` apart.
    pub fn new(track_m: f64) -> Self {
        Self {
            track_m,
            start_s: None,
            window: (0.0, 0.0, true),
            last_wheels: None,
            last_gyro: None,
            gyro_to_s: f64::NEG_INFINITY,
            sums: [0.0; 3],
            windows: 0,
            row: None,
            judged_at_row: None,
        }
    }

    /// The track the wheels' turns are computed with, m.
    pub fn track_m(&self) -> f64 {
        self.track_m
    }

    /// [`YawRateCheck::push`] of the reading on `row` of the input (1-based, a header is
    /// row 1), so that a finding can name the row where its evidence became clear.
    pub fn push_at(&mut self, sample: &VehicleSample, row: usize) {
        self.row = Some(row);
        self.push(sample);
    }

    /// Takes one row of the log (the gyro already in rad/s as declared).
    pub fn push(&mut self, sample: &VehicleSample) {
        let t = sample.t_s;
        let start = *self.start_s.get_or_insert(t);
        if let Some((t0, g0)) = self.last_gyro {
            self.window.1 += g0 * (t - self.gyro_to_s.max(t0));
            self.window.2 &= t - t0 <= MAX_STEP_S;
        }
        self.gyro_to_s = t;
        if let Some(g) = sample.gyr_z_rps.filter(|g| g.is_finite()) {
            self.last_gyro = Some((t, g));
        }
        if let Some(w) = sample.wheels {
            let now = [w.dist_l_m, w.dist_r_m];
            if let Some([l, r]) = self.last_wheels {
                // A right turn takes the left wheel further.
                self.window.0 += ((now[0] - l) - (now[1] - r)) / self.track_m;
            }
            self.last_wheels = Some(now);
        }
        if t - start >= WINDOW_S {
            self.close_window(t);
        }
    }

    fn close_window(&mut self, t: f64) {
        let (wheels, gyro, whole) = self.window;
        let seen = self.last_gyro.is_some() && self.last_wheels.is_some();
        if whole && seen && wheels.abs() >= MIN_WINDOW_TURN_RAD && wheels.is_finite() {
            self.sums[0] += wheels * gyro;
            self.sums[1] += gyro * gyro;
            self.sums[2] += wheels * wheels;
            self.windows += 1;
            if self.windows == MIN_WINDOWS {
                self.judged_at_row = self.row;
            }
        }
        self.window = (0.0, 0.0, true);
        self.start_s = Some(t);
    }

    /// The wheels' turn per turn of the gyro (least squares over the turning windows) and
    /// the squared correlation; `None` before [`MIN_WINDOWS`] turning windows.
    pub fn ratio(&self) -> Option<(f64, f64)> {
        let [wg, gg, ww] = self.sums;
        (self.windows >= MIN_WINDOWS && gg > 0.0 && ww > 0.0)
            .then(|| (wg / gg, wg * wg / (gg * ww)))
    }

    /// [`YawRateCheck::ratio`] once the gyro and the wheels see the same motion (their
    /// squared correlation at least [`MIN_R2`]).
    pub fn agreeing_ratio(&self) -> Option<(f64, f64)> {
        self.ratio().filter(|(_, r2)| *r2 >= MIN_R2)
    }

    /// What the size of the wheels' turns against the gyro's says is wrong when it is
    /// neither one nor 57 (the gyro's unit, [`YawRateCheck::findings`]): wheel speeds in
    /// km/h (3.6 times), distances in km or mm (1000 times), or else `track_m` (the turns
    /// give the track). `wheels` names the wheel columns as read (`dist_l_m, dist_r_m`),
    /// `speeds` whether they are speeds, `vehicle` where the track came from (the vehicle
    /// file's name).
    pub fn wheel_scale_finding(
        &self,
        wheels: &str,
        speeds: bool,
        vehicle: &str,
    ) -> Option<Finding> {
        let (ratio, r2) = self.agreeing_ratio()?;
        let turns = Turns {
            ratio,
            r2,
            windows: self.windows,
            row: self.judged_at_row,
            track_m: self.track_m,
        };
        turns.wheel_scale_finding(wheels, speeds, vehicle)
    }

    /// What contradicts the declared gyro unit or sign.
    pub fn findings(&self, declared: GyroUnit) -> Vec<Finding> {
        let Some((ratio, r2)) = self.agreeing_ratio() else {
            return Vec::new();
        };
        let mut findings = Vec::new();
        let other = declared.other();
        let factor = other.to_rad_per_s() / declared.to_rad_per_s();
        // Within a factor of three of the other unit's ratio (57 apart from this one's).
        if (ratio.abs() / factor).ln().abs() < 3f64.ln() {
            findings.push(
                Finding::units(
                    format!(
                        "gyr_z turns {} times as far as the wheels over {} turning seconds (r² {}): it is in {}, not the declared unit",
                        Fixed(1.0 / ratio.abs(), 3),
                        self.windows,
                        Fixed(r2, 2),
                        other.name()
                    ),
                    Fix::GyroUnit(other),
                )
                .at_row(self.judged_at_row),
            );
        }
        if ratio < 0.0 {
            findings.push(
                Finding::axes(
                    format!(
                        "gyr_z turns against the wheels over {} turning seconds (wheels per gyro {}, r² {}): its sign is flipped (a right turn must read positive)",
                        self.windows,
                        Fixed(ratio, 2),
                        Fixed(r2, 2),
                    ),
                    Fix::GyroZSign,
                )
                .at_row(self.judged_at_row),
            );
        }
        findings
    }
}

/// A comparison of the wheels' turns with the gyro's over turning windows, however the
/// windows were chosen: the least-squares ratio, its squared correlation, the windows, the
/// row where the judgement became possible and the track the wheels' turns assume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turns {
    /// Wheels' turn per gyro turn.
    pub ratio: f64,
    /// Squared correlation.
    pub r2: f64,
    /// Turning windows behind it.
    pub windows: usize,
    /// Row where the evidence became clear.
    pub row: Option<usize>,
    /// Track assumed, m.
    pub track_m: f64,
}

impl Turns {
    /// See [`YawRateCheck::wheel_scale_finding`].
    pub fn wheel_scale_finding(
        &self,
        wheels: &str,
        speeds: bool,
        vehicle: &str,
    ) -> Option<Finding> {
        let (r, r2) = (self.ratio.abs(), self.r2);
        if r2 < MIN_R2 {
            return None;
        }
        let near = |factor: f64| (r / factor).ln().abs() < UNIT_TOLERANCE.ln();
        let gyro_unit = (r * 1f64.to_degrees()).ln().abs() < 3f64.ln();
        if gyro_unit || (PLAUSIBLE_RATIO.0..=PLAUSIBLE_RATIO.1).contains(&r) {
            return None;
        }
        let seen = format!(
            "the wheels ({wheels}) turn the vehicle {} times as far as gyr_z over {} turning seconds (r² {})",
            Fixed(r, 4),
            self.windows,
            Fixed(r2, 2)
        );
        let advice = if speeds && near(3.6) {
            "the wheel speeds are in km/h, not m/s: divide them by 3.6 (speed_l_mps, speed_r_mps are metres per second)".to_string()
        } else if near(1e-3) || (r / 1e-3).ln().abs() < 3f64.ln() {
            format!(
                "the wheels' {} are in kilometres, not metres: multiply them by 1000",
                if speeds { "speeds" } else { "distances" }
            )
        } else if (r / 1e3).ln().abs() < 3f64.ln() {
            format!(
                "the wheels' {} are in millimetres, not metres: divide them by 1000",
                if speeds { "speeds" } else { "distances" }
            )
        } else {
            format!(
                "track_m = {} m in {vehicle} does not fit the turns, which give a track of {} m: check track_m (metres, between the odometer wheels' centres) or the wheel columns' unit",
                self.track_m,
                Fixed(self.track_m * r, 2)
            )
        };
        Some(Finding::units(seen, Fix::Advice(advice)).at_row(self.row))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vehicle weaving at up to 0.3 rad/s, its gyro reading `gain` times the truth.
    fn weave(gain: f64) -> YawRateCheck {
        let mut check = YawRateCheck::new(1.5);
        let (mut heading, mut l, mut r) = (0.0f64, 0.0, 0.0);
        for k in 0..3000 {
            let t = k as f64 * 0.02;
            let rate = 0.3 * (0.5 * t).sin();
            heading += rate * 0.02;
            l += (10.0 + 0.75 * rate) * 0.02;
            r += (10.0 - 0.75 * rate) * 0.02;
            check.push(
                &VehicleSample::at(t)
                    .with_wheels(l, r)
                    .with_gyro(gain * rate),
            );
        }
        assert!(heading.is_finite());
        check
    }

    #[test]
    fn a_gyro_that_agrees_with_the_wheels_passes_and_others_are_named() {
        let good = weave(1.0);
        let (ratio, r2) = good.ratio().unwrap();
        assert!((ratio - 1.0).abs() < 0.05 && r2 > 0.99, "{ratio} {r2}");
        assert!(good.findings(GyroUnit::RadPerS).is_empty());
        let degrees = weave(1f64.to_degrees()).findings(GyroUnit::RadPerS);
        assert_eq!(degrees.len(), 1);
        assert_eq!(
            degrees[0].fix,
            Fix::GyroUnit(GyroUnit::DegPerS),
            "{degrees:?}"
        );
        let flipped = weave(-1.0).findings(GyroUnit::RadPerS);
        assert_eq!(flipped.len(), 1);
        assert_eq!(flipped[0].fix, Fix::GyroZSign, "{flipped:?}");
    }

    /// A ratio of the wheels' turns to the gyro's is named for the unit it fits (3.6 only
    /// for speeds), else for the track it implies; a plausible one, or the gyro's 1/57, is
    /// left to the other checks.
    #[test]
    fn the_wheels_scale_is_named_for_the_unit_or_the_track_it_fits() {
        let at = |ratio: f64, speeds: bool| {
            Turns {
                ratio,
                r2: 0.99,
                windows: 20,
                row: Some(7),
                track_m: 1.5,
            }
            .wheel_scale_finding("l, r", speeds, "car.json")
            .map(|f| match f.fix {
                Fix::Advice(a) => format!("{}: {a}", f.seen),
                other => panic!("{other:?}"),
            })
        };
        assert!(at(1e-3, false).unwrap().contains("kilometres"));
        assert!(at(3.6, true).unwrap().contains("km/h"));
        let track = at(3.6, false).unwrap();
        assert!(
            track.contains("track of 5.40 m") && track.contains("car.json"),
            "{track}"
        );
        assert!(at(1e3, false).unwrap().contains("millimetres"));
        assert!(at(-0.1, false).unwrap().contains("track of 0.15 m"));
        for quiet in [1.0, 0.6, 2.5, 1.0 / 57.3] {
            assert_eq!(at(quiet, false), None, "{quiet}");
        }
    }
}
