//! Satellite fixes in the vehicle estimator: the first fix sets a local tangent plane, the
//! fixes' course (or their displacement against the dead-reckoned one) refers heading and
//! track to true north and the plane, and from then each fix corrects the position — and,
//! through the position's correlation with the heading, the heading and every learned
//! sensor error — unless it is too far from the dead-reckoned position to be believed.
//!
//! A receiver's error is correlated over tens of seconds (the atmosphere's delays,
//! multipath), so fixes are taken at most once a second, each with its variance widened to
//! stand for the few independent fixes within [`super::config::GnssConfig::error_correlation_s`]
//! (treating 10 fixes a second as independent would shrink the track's uncertainty, and
//! the learned errors' with it, by a factor the data do not carry). Between fixes, and through
//! outages, the estimate is dead reckoning from the sensors as learned, its uncertainty
//! growing as their model says.

use serde::{Deserialize, Serialize};
use truenorth_core::{GnssFix, wrap_pi};
use truenorth_geomag::{Geodetic, LocalTangentPlane};

use super::estimator::VehicleEstimator;
use super::gnss_track::PlaneShift;
use super::innovation_line::{InnovationLine, LineFit};
use super::nav_filter::{EAST, NORTH, PSI};
use super::path_trail::PathSince;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The interval the fixes are used at, s: one a second.
const FIX_INTERVAL_S: f64 = 1.0;

/// How much shorter than [`FIX_INTERVAL_S`] two fixes' epochs may be and both be used, s: a
/// receiver at 1 Hz stamps its fixes a second apart within tens of milliseconds, and a
/// logger's stamps jitter by as much, so an exact second would skip every other fix; half
/// a 10 Hz receiver's step, so that its fixes are used a second apart, not 0.9 s.
const FIX_JITTER_S: f64 = 0.05;

/// How far before the last wheel reading a fix's epoch lies before the trail of the path
/// gives where the vehicle was, s: nearer, a line drawn back along the heading of then
/// strays from the path by half its length times the turn, 0.13 m at 20 m/s in a 0.2 rad/s
/// turn, well within a fix's error (and the default delay, 0.1 s, never reaches the trail).
const TRAIL_AFTER_S: f64 = 0.25;

/// Courses that must agree before they refer the heading to true north.
const ALIGNMENT_COURSES: u32 = 5;

/// Courses rejected one after another that, agreeing on one offset from the heading, refer
/// it to them again: twice the first referral's, as the heading they contradict had passed
/// the gates before.
const RELOCK_COURSES: u32 = 2 * ALIGNMENT_COURSES;

/// Displacement between two fixes, in their standard deviations, that gives a course to
/// refer the heading to true north when the receiver reports none (10: the course to
/// within 8°).
const ALIGNMENT_DISPLACEMENT_SIGMAS: f64 = 10.0;

/// Standard deviation of the angle between a vehicle's heading and its course over ground,
/// rad (2°): the sideslip of a car's rear axle in ordinary driving, a robot's creep.
const SIDESLIP_RAD: f64 = 2.0 * core::f64::consts::PI / 180.0;

/// What the fixes did over a drive.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GnssCounts {
    /// Fixes that corrected the estimate.
    pub used: u32,
    /// Fixes rejected as too far from the dead-reckoned position (multipath, a frozen or
    /// late fix).
    pub rejected: u32,
    /// Times the position started again from a fix after a run of rejections.
    pub restarts: u32,
}

impl VehicleEstimator {
    /// The tangent plane's origin (the first fix's latitude and longitude, degrees), once
    /// a fix has been seen.
    pub fn gnss_origin(&self) -> Option<(f64, f64)> {
        self.tracking.gnss.origin
    }

    /// Whether heading and track are referred to the fixes: the heading to true north (the
    /// published [`truenorth_core::NavEstimate::heading`] stays magnetic: add
    /// [`VehicleEstimator::gnss_declination_rad`]), the track to the plane at the first fix.
    pub fn gnss_aligned(&self) -> bool {
        self.tracking.gnss.aligned
    }

    /// How the track was put on the fixes' plane, while it is there (see [`PlaneShift`]).
    pub fn gnss_plane_shift(&self) -> Option<PlaneShift> {
        self.tracking
            .gnss
            .shift
            .filter(|_| self.tracking.gnss.aligned)
    }

    /// The declination at the first fix (WMM2025 at the configured date), rad, east
    /// positive: true heading = magnetic heading + it.
    pub fn gnss_declination_rad(&self) -> Option<f64> {
        self.tracking
            .gnss
            .origin
            .map(|_| self.tracking.gnss.declination_rad)
    }

    /// How many fixes were used and rejected so far.
    pub fn gnss_counts(&self) -> GnssCounts {
        let g = &self.tracking.gnss;
        GnssCounts {
            used: g.used,
            rejected: g.rejected,
            restarts: g.restarts,
        }
    }

    /// The difference between the heading frame and magnetic north, rad: the declination
    /// once the fixes refer the heading to true north, else zero.
    pub(super) fn frame_declination_rad(&self) -> f64 {
        if self.tracking.gnss.aligned {
            self.tracking.gnss.declination_rad
        } else {
            0.0
        }
    }

    /// Forgets the fixes' frame: the heading was lost, so the track can no longer be turned
    /// onto the plane by a heading offset alone.
    pub(super) fn forget_gnss_frame(&mut self) {
        let g = &mut self.tracking.gnss;
        g.aligned = false;
        g.course_only = false;
        g.line = InnovationLine::default();
        g.start = None;
    }

    /// Takes the fix a row carries at `t_s`.
    pub(super) fn gnss_step(&mut self, t_s: f64, fix: &GnssFix) {
        self.est.status.gnss_used = false;
        let Some(plane) = self.plane(fix) else {
            return;
        };
        let Ok(point) = Geodetic::from_degrees(fix.lat_deg, fix.lon_deg, 0.0) else {
            return;
        };
        let [north, east, _] = plane.from_geodetic(&point);
        // Where the vehicle was when the fix was computed (the time a fix is noted used at).
        let t_s = t_s - self.config.gnss.latency_s;
        if self
            .tracking
            .gnss
            .last_used_s
            .is_some_and(|t0| t_s - t0 < FIX_INTERVAL_S - FIX_JITTER_S)
        {
            return;
        }
        // Fixes say where the vehicle is; between them only odometry carries it there.
        // Without any, their course still says where it heads.
        if !self.est.status.position_known {
            self.course_without_odometry(t_s, fix);
            return;
        }
        let sigma = fix.sigma_m.unwrap_or(self.config.gnss.default_sigma_m);
        // What the delay's spread leaves unknown along the track.
        self.correct_with_speed(t_s, fix);
        let lag = self.config.gnss.latency_sigma_s * self.est.speed_mps;
        let sigma = (sigma * sigma + lag * lag).sqrt();
        if self.tracking.gnss.course_only {
            // The heading is on true north already; the track joins the plane here.
            self.tracking.gnss.course_only = false;
            self.restart_position(t_s, north, east, sigma);
            self.note_fix_used(t_s);
            self.anchor_plain();
            return;
        }
        if self.tracking.gnss.aligned {
            self.correct_with_fix(t_s, north, east, sigma);
            self.correct_with_course(t_s, fix);
        } else {
            self.align_to_fixes(t_s, north, east, sigma, fix);
        }
    }

    /// The tangent plane at the first fix (set now if this is it), or `None` if the fix
    /// cannot be placed.
    fn plane(&mut self, fix: &GnssFix) -> Option<LocalTangentPlane> {
        if let Some((lat, lon)) = self.tracking.gnss.origin {
            return LocalTangentPlane::new(lat, lon, 0.0).ok();
        }
        let plane = LocalTangentPlane::new(fix.lat_deg, fix.lon_deg, 0.0).ok()?;
        self.tracking.gnss.origin = Some((fix.lat_deg, fix.lon_deg));
        // Where the model has no answer (at the poles) the compass and the fixes are not
        // related, as without a place.
        self.tracking.gnss.declination_rad = truenorth_geomag::declination(
            fix.lat_deg.to_radians(),
            fix.lon_deg.to_radians(),
            0.0,
            self.config.gnss.decimal_year,
        )
        .map_or(0.0, |d| d.0);
        Some(plane)
    }

    /// The path driven since `t_s`, when `t_s` lies more than [`TRAIL_AFTER_S`] before the
    /// last wheel reading and within the trail kept; nearer, a line along the heading is as
    /// good.
    fn path_since(&self, t_s: f64) -> Option<PathSince> {
        let last = self.wheels.last_s()?;
        (last - t_s > TRAIL_AFTER_S)
            .then(|| self.tracking.gnss.trail.since(t_s, self.filter.x[PSI]))
            .flatten()
    }

    /// The heading at `t_s`: the heading now less the turns since, from the trail, or the
    /// gyro's rate carried to it.
    fn heading_then(&self, t_s: f64) -> f64 {
        self.path_since(t_s)
            .map_or_else(|| self.heading_at(t_s), |p| self.filter.x[PSI] - p.turn_rad)
    }

    /// The antenna's dead-reckoned position at `t_s`: the track's last point less the path
    /// driven since (from the trail), or carried on (or back) along the heading at the speed
    /// the wheels last showed; plus the lever arm turned with the heading.
    fn position_at(&self, t_s: f64) -> (f64, f64) {
        let [forward, right] = self.config.gnss.lever_arm_m;
        let x = &self.filter.x;
        let (north, east, heading, forward) = match self.path_since(t_s) {
            Some(p) => (
                x[NORTH] - p.north_m,
                x[EAST] - p.east_m,
                x[PSI] - p.turn_rad,
                forward,
            ),
            None => {
                let ahead_s = self.wheels.last_s().map_or(0.0, |t0| {
                    (t_s - t0).clamp(-self.config.max_gap_s, self.config.max_gap_s)
                });
                let travel = self.est.speed_mps * ahead_s + forward;
                (x[NORTH], x[EAST], self.heading_at(t_s), travel)
            }
        };
        let (s, c) = heading.sin_cos();
        (
            north + forward * c - right * s,
            east + forward * s + right * c,
        )
    }

    /// How the antenna's position moves with the heading, m/rad north and east: the lever
    /// arm turning.
    fn lever_arm_turn(&self, t_s: f64) -> (f64, f64) {
        let [forward, right] = self.config.gnss.lever_arm_m;
        let (s, c) = self.heading_then(t_s).sin_cos();
        (-forward * s - right * c, forward * c - right * s)
    }

    /// The fix at (`north`, `east`) of accuracy `sigma` against the dead-reckoned position:
    /// used if within the gate, else counted as rejected; a run of rejections longer than
    /// [`super::config::GnssConfig::rejoin_after_s`] starts the position again from it.
    fn correct_with_fix(&mut self, t_s: f64, north: f64, east: f64, sigma: f64) {
        self.flush();
        let (pn, pe) = self.position_at(t_s);
        let (nu_n, nu_e) = (north - pn, east - pe);
        let p = &self.filter.p;
        let var = sigma * sigma;
        let (a, b, d) = (p[NORTH][NORTH] + var, p[NORTH][EAST], p[EAST][EAST] + var);
        let det = a * d - b * b;
        let d2 = (d * nu_n * nu_n - 2.0 * b * nu_n * nu_e + a * nu_e * nu_e) / det;
        let gate = self.config.gnss.gate_sigma;
        if !(det > 0.0 && d2.is_finite()) || d2 > gate * gate {
            let g = &mut self.tracking.gnss;
            g.rejected += 1;
            let since = *g.rejected_since_s.get_or_insert(t_s);
            if t_s - since >= self.config.gnss.rejoin_after_s {
                g.restarts += 1;
                g.rejected_since_s = None;
                self.restart_position(t_s, north, east, sigma);
            }
            return;
        }
        // One fix of the few independent ones within the error's correlation time.
        let widened = var * (self.config.gnss.error_correlation_s / FIX_INTERVAL_S).max(1.0);
        let (dn, de) = self.lever_arm_turn(t_s);
        self.filter
            .update(&[(NORTH, 1.0), (PSI, dn)], nu_n, widened);
        let (_, pe) = self.position_at(t_s);
        self.filter
            .update(&[(EAST, 1.0), (PSI, de)], east - pe, widened);
        // The fixes' error changes slowly: a position learned from them is no better than
        // one fix, however many were averaged within its correlation time.
        for i in [NORTH, EAST] {
            self.filter.p[i][i] = self.filter.p[i][i].max(var);
        }
        let g = &mut self.tracking.gnss;
        g.rejected_since_s = None;
        g.last_used_s = Some(t_s);
        g.used += 1;
        self.est.status.gnss_used = true;
        self.anchor_plain();
    }

    /// The receiver's course on a drive with no odometry (yet): a vehicle with a gyro or a
    /// compass and no wheels, whose heading the courses refer to true north and correct
    /// (the fixes' positions cannot be carried between them, so the position stays
    /// unknown). Without odometry nothing tells a reversing vehicle: a course is taken as
    /// the vehicle's heading when the receiver's speed is at least
    /// [`super::config::GnssConfig::min_course_speed_mps`], which few vehicles reach in reverse;
    /// one that does is off by half a turn, fails the gate once the heading is referred, and
    /// courses that contradict a heading referred by such ones refer it again
    /// ([`RELOCK_COURSES`]).
    fn course_without_odometry(&mut self, t_s: f64, fix: &GnssFix) {
        if !self.tracking.gnss.aligned {
            let Some(course) = self.course_of(fix, None) else {
                return;
            };
            if let Some(f) = self.agreeing_courses(t_s, course) {
                let after_compass = self.tracking.alignment.done;
                let turn_rad = self.refer_heading_to_fixes(f.offset_rad, f.sigma_rad);
                // No track to move onto the plane: only the heading's turn.
                self.tracking.gnss.shift = Some(PlaneShift {
                    turn_rad,
                    after_compass,
                    north_m: 0.0,
                    east_m: 0.0,
                });
                self.tracking.gnss.course_only = true;
                self.note_fix_used(t_s);
            }
            return;
        }
        if self.correct_with_course(t_s, fix) {
            self.note_fix_used(t_s);
        }
    }

    /// Gathers a course (rad, and its standard deviation) at `t_s` against the heading; once
    /// [`ALIGNMENT_COURSES`] are gathered, their offset from the heading if they agree (the
    /// gathering starts again either way).
    fn agreeing_courses(&mut self, t_s: f64, (course, sigma): (f64, f64)) -> Option<LineFit> {
        let nu = wrap_pi(course - self.heading_then(t_s));
        let line = &mut self.tracking.gnss.line;
        line.push(t_s, nu);
        if line.len() < ALIGNMENT_COURSES {
            return None;
        }
        let fit = line.fit(sigma);
        self.tracking.gnss.line = InnovationLine::default();
        fit.filter(|f| f.residual_rad <= 3.0 * sigma)
    }

    /// Counts a fix used at `t_s`.
    fn note_fix_used(&mut self, t_s: f64) {
        let g = &mut self.tracking.gnss;
        g.last_used_s = Some(t_s);
        g.used += 1;
        self.est.status.gnss_used = true;
    }

    /// The receiver's course against the heading, once referred to true north: used when
    /// the vehicle moves fast enough for the course to mean its direction. Whether it was.
    fn correct_with_course(&mut self, t_s: f64, fix: &GnssFix) -> bool {
        let odometer_speed = self.est.status.position_known.then_some(self.est.speed_mps);
        let Some((course, sigma)) = self.course_of(fix, odometer_speed) else {
            return false;
        };
        let nu = wrap_pi(course - self.heading_then(t_s));
        let lag = self.config.gnss.latency_sigma_s * self.tracking.gyro.rate_rps;
        let sigma = (sigma * sigma + lag * lag).sqrt();
        let s = self.filter.p[PSI][PSI] + sigma * sigma;
        let gate = self.config.gnss.gate_sigma;
        if nu * nu > gate * gate * s {
            self.course_rejected(t_s, nu, sigma);
            return false;
        }
        self.tracking.gnss.line = InnovationLine::default();
        self.flush();
        self.filter.update(&[(PSI, 1.0)], nu, sigma * sigma);
        true
    }

    /// A course the gate rejected, at `t_s` with innovation `nu` and standard deviation
    /// `sigma`. A course is the vehicle's direction within its sideslip whatever the fix's
    /// position error (a multipath jump moves the position, not the course), so
    /// [`RELOCK_COURSES`] rejected in a row that agree on one offset say the heading is what
    /// is wrong — referred once by courses taken while reversing, or drifted beyond its σ
    /// — and it is referred to them again.
    fn course_rejected(&mut self, t_s: f64, nu: f64, sigma: f64) {
        let line = &mut self.tracking.gnss.line;
        line.push(t_s, nu);
        if line.len() < RELOCK_COURSES {
            return;
        }
        let fit = line.fit(sigma);
        self.tracking.gnss.line = InnovationLine::default();
        if let Some(f) = fit.filter(|f| f.residual_rad <= 3.0 * sigma) {
            self.relock(f.offset_rad, f.sigma_rad);
        }
    }

    /// The direction the vehicle heads by the fix's course (rad, true north), and its
    /// standard deviation, when the receiver reports one at a speed that makes it mean the
    /// vehicle's direction: one the odometer's speed (`None`: no odometry) bears out
    /// (reversing: the course less half a turn).
    fn course_of(&self, fix: &GnssFix, odometer_speed: Option<f64>) -> Option<(f64, f64)> {
        let (speed, course_deg) = (fix.speed_mps?, fix.course_deg?);
        let cfg = &self.config.gnss;
        let moving = odometer_speed.unwrap_or(speed);
        if speed < cfg.min_course_speed_mps || moving.abs() < 0.5 * speed {
            return None;
        }
        let reversing = moving < 0.0;
        let course = course_deg.to_radians()
            + if reversing {
                core::f64::consts::PI
            } else {
                0.0
            };
        let sigma = ((cfg.speed_sigma_mps / speed).powi(2) + SIDESLIP_RAD * SIDESLIP_RAD).sqrt();
        Some((wrap_pi(course), sigma))
    }

    /// Before the heading is referred to the fixes: gathers the courses' differences from
    /// the heading (or, with no course, waits for a displacement long enough to give one),
    /// and once they agree turns heading and track onto true north and the plane.
    fn align_to_fixes(&mut self, t_s: f64, north: f64, east: f64, sigma: f64, fix: &GnssFix) {
        let (pn, pe) = self.position_at(t_s);
        if let Some(course) = self.course_of(fix, Some(self.est.speed_mps)) {
            if let Some(f) = self.agreeing_courses(t_s, course) {
                self.refer_to_fixes(t_s, north, east, sigma, f.offset_rad, f.sigma_rad);
            }
            return;
        }
        let Some([n0, e0, pn0, pe0]) = self.tracking.gnss.start else {
            self.tracking.gnss.start = Some([north, east, pn, pe]);
            return;
        };
        let (fn_, fe) = (north - n0, east - e0);
        let (dn, de) = (pn - pn0, pe - pe0);
        let fixed = fn_.hypot(fe);
        if fixed < ALIGNMENT_DISPLACEMENT_SIGMAS * sigma {
            return;
        }
        self.tracking.gnss.start = Some([north, east, pn, pe]);
        // The two displacements are chords of one path: one in the plane, the other in the
        // dead reckoning's frame, turned from it by the offset sought.
        let reckoned = dn.hypot(de);
        if reckoned < 0.5 * fixed || reckoned > 2.0 * fixed {
            return;
        }
        let offset = wrap_pi(fe.atan2(fn_) - de.atan2(dn));
        self.refer_to_fixes(
            t_s,
            north,
            east,
            sigma,
            offset,
            core::f64::consts::SQRT_2 * sigma / fixed,
        );
    }

    /// Turns heading and track onto true north by `offset` (standard deviation
    /// `offset_sigma`) and starts the position at the fix. A heading already referred to
    /// magnetic north by the compass is turned by the declination instead, which is known:
    /// the courses then correct it as measurements.
    fn refer_to_fixes(
        &mut self,
        t_s: f64,
        north: f64,
        east: f64,
        sigma: f64,
        offset: f64,
        offset_sigma: f64,
    ) {
        let after_compass = self.tracking.alignment.done;
        let turn_rad = self.refer_heading_to_fixes(offset, offset_sigma);
        self.flush();
        let (pn, pe) = self.position_at(t_s);
        self.tracking.gnss.shift = Some(PlaneShift {
            turn_rad,
            after_compass,
            north_m: north - pn,
            east_m: east - pe,
        });
        self.restart_position(t_s, north, east, sigma);
        let g = &mut self.tracking.gnss;
        g.last_used_s = Some(t_s);
        g.used += 1;
        self.est.status.gnss_used = true;
        self.anchor_plain();
    }

    /// Refers the heading to true north: by the declination if the compass referred it to
    /// magnetic north already, else by `offset` (standard deviation `offset_sigma`) found
    /// from the fixes. The angle turned.
    fn refer_heading_to_fixes(&mut self, offset: f64, offset_sigma: f64) -> f64 {
        let after_compass = self.tracking.alignment.done;
        let turn_rad = if after_compass {
            self.tracking.gnss.declination_rad
        } else {
            offset
        };
        if after_compass {
            self.turn_known(turn_rad);
        } else {
            self.turn_frame(offset, offset_sigma);
            self.tracking.alignment.done = true;
            self.compass.restart_gates();
        }
        self.tracking.gnss.aligned = true;
        turn_rad
    }

    /// Turns heading, wheel heading and track about the start by an exactly known angle.
    fn turn_known(&mut self, angle: f64) {
        self.refer_heading(angle);
        let f = &mut self.filter;
        let (s, c) = angle.sin_cos();
        let (n, e) = (f.x[NORTH], f.x[EAST]);
        f.x[NORTH] = n * c - e * s;
        f.x[EAST] = n * s + e * c;
        for k in 0..super::nav_filter::DIM {
            let (pn, pe) = (f.p[NORTH][k], f.p[EAST][k]);
            f.p[NORTH][k] = c * pn - s * pe;
            f.p[EAST][k] = s * pn + c * pe;
        }
        for k in 0..super::nav_filter::DIM {
            let (pn, pe) = (f.p[k][NORTH], f.p[k][EAST]);
            f.p[k][NORTH] = c * pn - s * pe;
            f.p[k][EAST] = s * pn + c * pe;
        }
    }

    /// Starts the position again at the fix (`north`, `east`) of accuracy `sigma`: the
    /// track's last point placed where the fix says the vehicle was, less the way it went
    /// since the wheels last read.
    fn restart_position(&mut self, t_s: f64, north: f64, east: f64, sigma: f64) {
        self.flush();
        let (pn, pe) = self.position_at(t_s);
        let f = &mut self.filter;
        f.x[NORTH] += north - pn;
        f.x[EAST] += east - pe;
        f.reset_state(NORTH, sigma);
        f.reset_state(EAST, sigma);
        self.tracking.gnss.rejected_since_s = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::VehicleConfig;
    use truenorth_core::{HeadingEstimator, VehicleSample};

    /// Due east at 10 m/s for 60 s with an exact fix of the antenna, 2 m ahead of the axle,
    /// each second (with its course): where the axle ends, m off, for a configured lever arm.
    fn end_error(lever_arm_m: [f64; 2]) -> f64 {
        let plane = LocalTangentPlane::new(52.5, 13.4, 0.0).unwrap();
        let mut config = VehicleConfig::default();
        config.gnss.lever_arm_m = lever_arm_m;
        config.gnss.latency_s = 0.0;
        let mut nav = VehicleEstimator::new(config).unwrap();
        let mut last = None;
        for k in 0..=600 {
            let t = 0.1 * f64::from(k);
            let mut s = VehicleSample::at(t).with_distance(10.0 * t).with_gyro(0.0);
            if k % 10 == 0 {
                let g = plane.to_geodetic(0.0, 10.0 * t + 2.0, 0.0).unwrap();
                let fix = GnssFix::at(g.lat_rad().to_degrees(), g.lon_rad().to_degrees())
                    .with_sigma(0.5)
                    .with_velocity(10.0, 90.0);
                s = s.with_gnss(fix);
            }
            last = Some(nav.update(&s).unwrap());
        }
        let e = last.unwrap();
        assert!(e.status.gnss_frame);
        let (lat, lon) = nav.gnss_origin().unwrap();
        let ours = LocalTangentPlane::new(lat, lon, 0.0).unwrap();
        let g = ours.to_geodetic(e.north_m, e.east_m, 0.0).unwrap();
        let [n, east, _] = plane.from_geodetic(&g);
        n.hypot(east - 600.0)
    }

    #[test]
    fn the_lever_arm_puts_the_track_on_the_axle() {
        let known = end_error([2.0, 0.0]);
        let unknown = end_error([0.0, 0.0]);
        assert!(known < 0.3, "{known:.2} m with the lever arm");
        assert!((unknown - 2.0).abs() < 0.3, "{unknown:.2} m without it");
    }

    /// A car without odometry heading east at 10 m/s, whose first fixes report the
    /// opposite course (as when reversing at that speed): the courses refer its heading half
    /// a turn off, and the courses after, rejected by the gate one after another, refer it
    /// again.
    #[test]
    fn courses_rejected_in_a_row_refer_the_heading_again() {
        let plane = LocalTangentPlane::new(52.5, 13.4, 0.0).unwrap();
        let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
        let mut last = None;
        let mut wrong_at_10_s = f64::NAN;
        for k in 0..=600 {
            let t = 0.1 * f64::from(k);
            let mut s = VehicleSample::at(t).with_gyro(0.0);
            if k % 10 == 0 {
                let course = if t < 8.0 { 270.0 } else { 90.0 };
                let g = plane.to_geodetic(0.0, 10.0 * t, 0.0).unwrap();
                let fix = GnssFix::at(g.lat_rad().to_degrees(), g.lon_rad().to_degrees())
                    .with_sigma(2.0)
                    .with_velocity(10.0, course);
                s = s.with_gnss(fix);
            }
            let e = nav.update(&s).unwrap();
            let true_heading = e.heading.rad() + nav.gnss_declination_rad().unwrap_or(0.0);
            if k == 100 {
                wrong_at_10_s = wrap_pi(true_heading - core::f64::consts::FRAC_PI_2).abs();
            }
            last = Some((e, true_heading));
        }
        let (e, true_heading) = last.unwrap();
        assert!(e.status.gnss_frame);
        assert!(
            wrong_at_10_s > 3.0,
            "referred to the reversed courses: {wrong_at_10_s}"
        );
        let off = wrap_pi(true_heading - core::f64::consts::FRAC_PI_2).abs();
        assert!(off < 2f64.to_radians(), "{:.1}° off", off.to_degrees());
    }
}
