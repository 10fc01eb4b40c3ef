//! The satellite fixes' clock checked against the gyro's: a receiver's course over ground
//! turns when the vehicle turns, so the course's change between two fixes equals the gyro's
//! integrated turn over the same epochs — shifted by however late the fixes are stamped. A
//! receiver and logger delay a fix by 0.05–0.3 s; fixes stamped on another clock than the
//! sensors, or queued by a slow logger, can be seconds off, and an estimator that trusts the
//! stamps then learns the delay as a gyro bias (a car's fixes 5 s late taught one −0.14°/s
//! where the truth was 0). Nothing else in a drive shows it while the fixes pass their gate.
//!
//! Without a course (a `sensor_msgs/NavSatFix` alone) the chord between two fixes 0.5–2 s
//! apart stands for the course at their middle: a receiver's position error changes little
//! within a second (it is correlated over tens of seconds), so the chord's direction is good
//! to a few degrees at road speeds.
//!
//! For every lag from [`MIN_LAG_S`] to [`MAX_LAG_S`] the check fits the course changes of
//! pairs of fixes 0.5–2 s apart to the gyro's turns over the same epochs that lag earlier,
//! with the gyro's bias and scale error free (a raw yaw rate has both), and keeps each lag's
//! weighted squared residual; the lag that leaves the least is the fixes' delay, with a σ
//! from the residual's curvature there. Streaming, fixed-size: nothing grows with the log.
//!
//! What it finds is the delay less the lead an antenna ahead of the axle gives its course
//! in a turn (the lever arm over the speed: 0.04–0.24 s for 0.8–2.4 m at road speeds), which
//! moves the course as an earlier stamp would; `tests/course_lag_drives.rs` holds the found
//! delay within 4σ of the stamp delay less that lead on drives with a real receiver's habits.

use core::f64::consts::PI;

use truenorth_core::{GnssFix, VehicleSample, wrap_pi};

/// The heading is kept at this step, s.
const STEP_S: f64 = 0.05;
/// The earliest lag tried, s (negative: fixes stamped before the gyro saw the turn).
pub const MIN_LAG_S: f64 = -1.0;
/// The latest lag tried, s.
pub const MAX_LAG_S: f64 = 6.0;
/// Lags tried, one per [`STEP_S`].
const LAGS: usize = 141;
/// Two courses closer than this are not paired (a receiver's course is filtered over a few
/// epochs, so at 10 Hz neighbours share most of their error).
const MIN_PAIR_S: f64 = 0.5;
/// Two courses farther apart than this are not paired (a gap in the fixes).
const MAX_PAIR_S: f64 = 2.0;
/// Heading samples kept: the longest lag, the longest pair and the earliest lag's wait.
const HISTORY: usize = 200;
/// A gyro step longer than this breaks the heading's history (a gap in the log), s.
const MAX_GYRO_STEP_S: f64 = 0.5;
/// Course pairs waiting for the gyro to reach [`MIN_LAG_S`] past them.
const PENDING: usize = 16;
/// Slowest speed whose course is taken, m/s: below it the course is the receiver's noise.
const MIN_SPEED_MPS: f64 = 3.0;
/// The receiver's speed error, m/s: a course's error is about this over the speed.
const SPEED_SIGMA_MPS: f64 = 0.3;
/// What else parts a course change from the gyro's turn, rad (1°): the sideslip changing
/// between two fixes, a course rounded to a degree.
const OTHER_SIGMA_RAD: f64 = PI / 180.0;
/// Pairs needed before a delay is given.
pub const MIN_PAIRS: usize = 30;
/// How much a receiver's position error changes between two fixes a second or so apart, m:
/// the error of a chord's length, and so of its direction times its length.
const CHORD_SIGMA_M: f64 = 0.5;
/// A course change no vehicle makes between two fixes at most 2 s apart, rad (90°, 45°/s
/// at speed): a chord across a multipath jump, a course at a standstill, not a turn.
const MAX_COURSE_CHANGE_RAD: f64 = PI / 2.0;
/// Metres per radian of latitude (WGS84 equatorial radius): enough for a chord's direction.
const EARTH_RADIUS_M: f64 = 6_378_137.0;

/// The fixes' delay found ([`CourseLagCheck::lag`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CourseLag {
    /// How long after the gyro saw a turn the fixes' course shows it by their stamps, s.
    pub lag_s: f64,
    /// Its 1σ, s.
    pub sigma_s: f64,
    /// Course pairs compared.
    pub pairs: usize,
    /// The least weighted squared residual per pair left free (a χ² over its degrees of
    /// freedom): about 1 when the course's and the gyro's errors are as modelled; far above
    /// it, no lag makes the fixes' course follow the gyro's turns.
    pub misfit: f64,
}

/// A course pair waiting for the gyro's heading past it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    t0_s: f64,
    t1_s: f64,
    course_change_rad: f64,
    variance: f64,
}

/// The running comparison of the fixes' course changes with the gyro's turns.
#[derive(Debug, Clone, PartialEq)]
pub struct CourseLagCheck {
    /// Integrated gyro heading at ticks of [`STEP_S`], a ring; the newest tick's index.
    heading: [f64; HISTORY],
    newest_tick: Option<i64>,
    ticks_kept: usize,
    /// The last gyro reading: time, rate, integrated heading.
    last_gyro: Option<(f64, f64, f64)>,
    /// The last course taken: time, course, its variance.
    last_course: Option<(f64, f64, f64)>,
    /// Whether any fix carried its course (then chords are not used).
    course_given: bool,
    /// The last fix a chord starts from: time, latitude and longitude, rad.
    last_position: Option<(f64, f64, f64)>,
    pending: [Option<Pair>; PENDING],
    /// Per lag: Σ w r², Σ w r Δt, Σ w r Δh, Σ w Δt², Σ w Δt Δh, Σ w Δh².
    sums: [[f64; 6]; LAGS],
    /// Pairs compared.
    pub pairs: usize,
}

impl Default for CourseLagCheck {
    fn default() -> Self {
        Self::new()
    }
}

impl CourseLagCheck {
    /// An empty check.
    pub fn new() -> Self {
        Self {
            heading: [0.0; HISTORY],
            newest_tick: None,
            ticks_kept: 0,
            last_gyro: None,
            last_course: None,
            course_given: false,
            last_position: None,
            pending: [None; PENDING],
            sums: [[0.0; 6]; LAGS],
            pairs: 0,
        }
    }

    /// Takes a row: its yaw rate (`gyr_z_rps`) and its fix's course and speed, if any; rows
    /// with neither, non-finite values or time going back are passed over.
    pub fn push(&mut self, sample: &VehicleSample) {
        let t = sample.t_s;
        if !t.is_finite() {
            return;
        }
        if let Some(rate) = sample.gyr_z_rps.filter(|r| r.is_finite()) {
            self.push_rate(t, rate);
        }
        let Some(fix) = &sample.gnss else {
            return;
        };
        if let (Some(speed), Some(course_deg)) = (fix.speed_mps, fix.course_deg)
            && speed.is_finite()
            && course_deg.is_finite()
        {
            self.course_given = true;
            if speed >= MIN_SPEED_MPS {
                let variance = (SPEED_SIGMA_MPS / speed).powi(2);
                self.push_course(t, course_deg.to_radians(), variance);
            }
        } else if !self.course_given && fix.lat_deg.is_finite() && fix.lon_deg.is_finite() {
            self.push_position(t, fix.lat_deg.to_radians(), fix.lon_deg.to_radians());
        }
    }

    /// Takes a row of columns, NaN where a reading is absent: the yaw rate (any unit), the
    /// fix's latitude and longitude, degrees, and its speed (m/s) and course (degrees) where
    /// the log has them — as [`CourseLagCheck::push`] takes a sample.
    pub fn push_columns(
        &mut self,
        t_s: f64,
        gyr_z: f64,
        lat_deg: f64,
        lon_deg: f64,
        velocity: Option<(f64, f64)>,
    ) {
        let mut s = VehicleSample::at(t_s);
        s.gyr_z_rps = gyr_z.is_finite().then_some(gyr_z);
        if lat_deg.is_finite() && lon_deg.is_finite() {
            let mut fix = GnssFix::at(lat_deg, lon_deg);
            if let Some((speed, course)) = velocity {
                (fix.speed_mps, fix.course_deg) = (Some(speed), Some(course));
            }
            s.gnss = Some(fix);
        }
        self.push(&s);
    }

    /// A fix without course: the chord from the last one, 0.5–2 s before, is a course at
    /// their middle.
    fn push_position(&mut self, t: f64, lat: f64, lon: f64) {
        match self.last_position {
            Some((t0, ..)) if t - t0 < MIN_PAIR_S && t >= t0 => return,
            // Time going back starts the chords again.
            Some((t0, lat0, lon0)) if t > t0 && t - t0 <= MAX_PAIR_S => {
                let north = (lat - lat0) * EARTH_RADIUS_M;
                let east = wrap_pi(lon - lon0) * EARTH_RADIUS_M * lat0.cos();
                let chord = north.hypot(east);
                if chord >= MIN_SPEED_MPS * (t - t0) {
                    let variance = (CHORD_SIGMA_M / chord).powi(2);
                    self.push_course(0.5 * (t0 + t), east.atan2(north), variance);
                }
            }
            _ => {}
        }
        self.last_position = Some((t, lat, lon));
    }

    fn tick_time(k: i64) -> f64 {
        k as f64 * STEP_S
    }

    fn push_rate(&mut self, t: f64, rate: f64) {
        match self.last_gyro {
            Some((t0, r0, h0)) if t > t0 && t - t0 <= MAX_GYRO_STEP_S => {
                // Trapezoids between the readings, at every tick they span.
                let dt = t - t0;
                let mut k = self
                    .newest_tick
                    .map_or((t0 / STEP_S).ceil() as i64, |k| k + 1);
                while Self::tick_time(k) <= t {
                    let s = Self::tick_time(k) - t0;
                    let h = h0 + s * (r0 + (rate - r0) * s / (2.0 * dt));
                    self.heading[k.rem_euclid(HISTORY as i64) as usize] = h;
                    self.newest_tick = Some(k);
                    self.ticks_kept = (self.ticks_kept + 1).min(HISTORY);
                    k += 1;
                }
                self.last_gyro = Some((t, rate, h0 + dt * 0.5 * (r0 + rate)));
                self.evaluate_pending();
            }
            Some((t0, ..)) if t <= t0 => {}
            _ => {
                // The first reading, or after a gap: the history starts again.
                self.last_gyro = Some((t, rate, 0.0));
                self.newest_tick = None;
                self.ticks_kept = 0;
            }
        }
    }

    fn push_course(&mut self, t: f64, course_rad: f64, variance: f64) {
        match self.last_course {
            Some((t0, ..)) if t - t0 < MIN_PAIR_S && t >= t0 => return,
            Some((t0, c0, v0)) if t > t0 && t - t0 <= MAX_PAIR_S => {
                let change = wrap_pi(course_rad - c0);
                if change.abs() <= MAX_COURSE_CHANGE_RAD {
                    self.wait(Pair {
                        t0_s: t0,
                        t1_s: t,
                        course_change_rad: change,
                        variance: v0 + variance + OTHER_SIGMA_RAD.powi(2),
                    });
                }
            }
            _ => {}
        }
        self.last_course = Some((t, course_rad, variance));
    }

    /// Keeps `pair` until the gyro has passed it; the oldest waiting gives way if the gyro
    /// has stopped.
    fn wait(&mut self, pair: Pair) {
        let slot = self
            .pending
            .iter()
            .position(Option::is_none)
            .unwrap_or_else(|| {
                self.pending.rotate_left(1);
                PENDING - 1
            });
        self.pending[slot] = Some(pair);
    }

    /// The integrated heading at `t`, interpolated between ticks kept.
    fn heading_at(&self, t: f64) -> Option<f64> {
        let newest = self.newest_tick?;
        let oldest = newest - self.ticks_kept as i64 + 1;
        let x = t / STEP_S;
        let k = x.floor() as i64;
        if k < oldest || k + 1 > newest {
            return None;
        }
        let at = |k: i64| self.heading[k.rem_euclid(HISTORY as i64) as usize];
        let w = x - k as f64;
        Some(at(k) * (1.0 - w) + at(k + 1) * w)
    }

    fn evaluate_pending(&mut self) {
        let Some(newest) = self.newest_tick else {
            return;
        };
        let now = Self::tick_time(newest);
        for slot in 0..PENDING {
            let Some(p) = self.pending[slot] else {
                continue;
            };
            // Interpolation needs the tick after the latest time read.
            if p.t1_s - MIN_LAG_S + STEP_S > now {
                continue;
            }
            self.pending[slot] = None;
            let mut changes = [0.0; LAGS];
            let mut whole = true;
            for (i, change) in changes.iter_mut().enumerate() {
                let lag = MIN_LAG_S + i as f64 * STEP_S;
                match (self.heading_at(p.t1_s - lag), self.heading_at(p.t0_s - lag)) {
                    (Some(h1), Some(h0)) => *change = h1 - h0,
                    _ => {
                        whole = false;
                        break;
                    }
                }
            }
            if !whole {
                continue;
            }
            let w = 1.0 / p.variance;
            let dt = p.t1_s - p.t0_s;
            for (s, dh) in self.sums.iter_mut().zip(changes) {
                // Not wrapped: the gyro's turn is in its own unit (a rate in °/s read as
                // rad/s turns 57 times too far), which the fitted scale takes out.
                let r = p.course_change_rad - dh;
                let terms = [r * r, r * dt, r * dh, dt * dt, dt * dh, dh * dh];
                for (s, x) in s.iter_mut().zip(terms) {
                    *s += w * x;
                }
            }
            self.pairs += 1;
        }
    }

    /// The weighted squared residual left at lag index `i` with the gyro's bias and scale
    /// fitted (only the bias where the turns cannot separate the scale).
    fn cost(&self, i: usize) -> f64 {
        let [rr, rt, rh, tt, th, hh] = self.sums[i];
        let det = tt * hh - th * th;
        if det > 1e-9 * tt * hh && det > 0.0 {
            rr - (hh * rt * rt - 2.0 * th * rt * rh + tt * rh * rh) / det
        } else if tt > 0.0 {
            rr - rt * rt / tt
        } else {
            rr
        }
    }

    /// The fixes' delay, once [`MIN_PAIRS`] pairs have been compared and the turns make
    /// one lag stand out (`None` on a straight drive, where every lag fits alike).
    pub fn lag(&self) -> Option<CourseLag> {
        if self.pairs < MIN_PAIRS {
            return None;
        }
        let costs: [f64; LAGS] = core::array::from_fn(|i| self.cost(i));
        let (best, &least) = costs.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
        if !least.is_finite() || best == 0 || best == LAGS - 1 {
            return None;
        }
        // The parabola through the least and its neighbours: its vertex and curvature.
        let (a, b, c) = (costs[best - 1], least, costs[best + 1]);
        let curvature = (a - 2.0 * b + c) / (STEP_S * STEP_S);
        if curvature.is_nan() || curvature <= 0.0 {
            return None;
        }
        let offset = 0.5 * (a - c) / (a - 2.0 * b + c) * STEP_S;
        Some(CourseLag {
            lag_s: MIN_LAG_S + best as f64 * STEP_S + offset,
            sigma_s: (2.0 / curvature).sqrt(),
            pairs: self.pairs,
            misfit: least / (self.pairs as f64 - 3.0),
        })
    }

    /// How much worse than the best lag `lag_s` fits: the rise of the weighted squared
    /// residual, over the misfit where that is above 1 (the course's errors larger than
    /// modelled) — a χ² with one degree of freedom where `lag_s` is the true delay, so
    /// beyond 25 `lag_s` is refuted at 5σ. `None` before [`MIN_PAIRS`] or outside the lags
    /// tried.
    pub fn excess_at(&self, lag_s: f64) -> Option<f64> {
        if self.pairs < MIN_PAIRS || !(MIN_LAG_S..=MAX_LAG_S).contains(&lag_s) {
            return None;
        }
        let x = (lag_s - MIN_LAG_S) / STEP_S;
        let i = (x.floor() as usize).min(LAGS - 2);
        let w = x - i as f64;
        let at = self.cost(i) * (1.0 - w) + self.cost(i + 1) * w;
        let least = (0..LAGS)
            .map(|i| self.cost(i))
            .fold(f64::INFINITY, f64::min);
        let misfit = least / (self.pairs as f64 - 3.0);
        Some((at - least) / misfit.max(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::GnssFix;

    /// A car at 12 m/s turning as a sum of slow sines (up to 0.3 rad/s), its raw gyro at
    /// 50 Hz reading `scale` × the rate + 0.02 rad/s, its fixes at 5 Hz stamped `lag_s`
    /// after the epoch whose course they carry (course noise 0.5°); `turning` false: straight;
    /// `chords`: positions only (an error wandering 0.1 m a fix, and 0.2 m of noise).
    fn drive(lag_s: f64, scale: f64, turning: bool, seconds: f64) -> CourseLagCheck {
        drive_with(lag_s, scale, turning, seconds, false)
    }

    fn drive_with(
        lag_s: f64,
        scale: f64,
        turning: bool,
        seconds: f64,
        chords: bool,
    ) -> CourseLagCheck {
        let rate = |t: f64| {
            if turning {
                0.2 * (0.21 * t).sin() + 0.1 * (0.67 * t + 1.0).sin()
            } else {
                0.0
            }
        };
        let heading = |t: f64| {
            if turning {
                -0.2 / 0.21 * (0.21 * t).cos() - 0.1 / 0.67 * (0.67 * t + 1.0).cos()
            } else {
                0.3
            }
        };
        let mut noise = 12345u64;
        let mut normal = move || {
            // Twelve uniforms less six: near enough normal for a test.
            (0..12)
                .map(|_| {
                    noise = noise
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (noise >> 11) as f64 / (1u64 << 53) as f64
                })
                .sum::<f64>()
                - 6.0
        };
        let mut check = CourseLagCheck::new();
        let mut rows: Vec<VehicleSample> = Vec::new();
        let n = (seconds * 50.0) as usize;
        // The track at every step (north, east, m), and the receiver's wandering error.
        let mut track = Vec::with_capacity(n);
        let (mut north, mut east) = (0.0, 0.0);
        for k in 0..n {
            track.push((north, east));
            let h = heading(k as f64 * 0.02);
            (north, east) = (north + 12.0 * 0.02 * h.cos(), east + 12.0 * 0.02 * h.sin());
        }
        let mut wander = (0.0, 0.0);
        for k in 0..n {
            let t = k as f64 * 0.02;
            rows.push(VehicleSample::at(t).with_gyro(scale * rate(t) + 0.02));
            if k % 10 == 0 && t >= lag_s.max(0.0) {
                let epoch = t - lag_s;
                let fix = if chords {
                    let (n, e) = track[(epoch / 0.02).round() as usize];
                    wander = (wander.0 + 0.1 * normal(), wander.1 + 0.1 * normal());
                    let (n, e) = (n + wander.0 + 0.2 * normal(), e + wander.1 + 0.2 * normal());
                    let m_per_deg = EARTH_RADIUS_M.to_radians();
                    GnssFix::at(
                        52.5 + n / m_per_deg,
                        13.4 + e / (m_per_deg * 52.5f64.to_radians().cos()),
                    )
                } else {
                    let course = (heading(epoch) + 0.5f64.to_radians() * normal()).to_degrees();
                    GnssFix::at(52.5, 13.4).with_velocity(12.0, course.rem_euclid(360.0))
                };
                rows.push(VehicleSample::at(t).with_gnss(fix));
            }
        }
        for r in &rows {
            check.push(r);
        }
        check
    }

    /// The delay the fixes were given is found within 3σ (and σ under 0.1 s) whatever it is
    /// within the lags tried, with the gyro's bias and a 6 % scale error left in; the
    /// configured 0.1 s is refuted when the fixes are late by a second or more, and not
    /// when they are 0.1 s late.
    #[test]
    fn the_fixes_delay_is_found_from_the_turns() {
        for lag in [-0.5, 0.1, 0.8, 2.5, 5.0] {
            let check = drive(lag, 1.06, true, 300.0);
            let found = check.lag().expect("a delay after five minutes of turns");
            assert!(
                (found.lag_s - lag).abs() < 3.0 * found.sigma_s.max(0.01) && found.sigma_s < 0.1,
                "lag {lag}: found {found:?}"
            );
            assert!(found.misfit < 2.0, "lag {lag}: {found:?}");
            let excess = check.excess_at(0.1).unwrap();
            if (lag - 0.1f64).abs() >= 0.7 {
                assert!(excess > 25.0, "lag {lag}: 0.1 s only {excess:.1} worse");
            } else if lag == 0.1 {
                assert!(excess < 9.0, "the true lag refuted: {excess:.1}");
            }
        }
    }

    /// Positions alone: the chords between fixes find the delay as the course does.
    #[test]
    fn the_chords_between_fixes_find_it_without_a_course() {
        for lag in [0.1, 2.5] {
            let check = drive_with(lag, 1.06, true, 300.0, true);
            let found = check.lag().expect("a delay from the chords");
            assert!(
                (found.lag_s - lag).abs() < 3.0 * found.sigma_s.max(0.01) && found.sigma_s < 0.2,
                "lag {lag}: found {found:?}"
            );
            let excess = check.excess_at(0.1).unwrap();
            assert_eq!(excess > 25.0, lag > 1.0, "lag {lag}: {excess:.1}");
        }
    }

    /// The gyro's unit and sign do not matter: a rate in °/s, its axis flipped, finds the
    /// same delay (the fitted scale takes them out).
    #[test]
    fn any_gyro_unit_and_sign_find_it() {
        let check = drive(2.5, -1.06f64.to_degrees(), true, 300.0);
        let found = check.lag().expect("a delay");
        assert!(
            (found.lag_s - 2.5).abs() < 3.0 * found.sigma_s && found.sigma_s < 0.1,
            "{found:?}"
        );
    }

    /// A straight drive shows no delay: every lag fits alike.
    #[test]
    fn a_straight_drive_tells_no_delay() {
        let check = drive(2.0, 1.0, false, 300.0);
        assert!(check.pairs >= MIN_PAIRS);
        let excess = check.excess_at(0.1).unwrap();
        assert!(excess < 9.0, "{excess}");
        if let Some(found) = check.lag() {
            assert!(found.sigma_s > 1.0, "{found:?}");
        }
    }

    proptest! {
        /// Any rows (non-finite values, time going back, gaps) leave the check usable: no
        /// panic, a delay (if any) within the lags tried with a positive σ.
        #[test]
        fn any_rows_leave_it_usable(
            rows in proptest::collection::vec(
                (
                    -1.0f64..50.0,
                    proptest::option::of(proptest::num::f64::ANY),
                    proptest::option::of((proptest::num::f64::ANY, proptest::num::f64::ANY)),
                ),
                0..200,
            )
        ) {
            let mut check = CourseLagCheck::new();
            let mut sorted = rows.clone();
            sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (t, gyro, fix) in rows.iter().chain(&sorted) {
                let mut s = VehicleSample::at(*t);
                s.gyr_z_rps = *gyro;
                if let Some((speed, course)) = fix {
                    let mut f = GnssFix::at(0.0, 0.0);
                    (f.speed_mps, f.course_deg) = (Some(*speed), Some(*course));
                    s.gnss = Some(f);
                }
                check.push(&s);
            }
            if let Some(found) = check.lag() {
                prop_assert!((MIN_LAG_S..=MAX_LAG_S).contains(&found.lag_s));
                prop_assert!(found.sigma_s > 0.0);
            }
            let _ = check.excess_at(0.1);
        }
    }
}
