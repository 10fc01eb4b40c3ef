//! The compass in the vehicle estimator: readings judged by the gates, offered to the
//! online calibration, averaged into heading corrections, and the first run of consistent
//! readings referring the heading and the track to north.

use nalgebra::{SMatrix, Vector2};
use truenorth_core::{VehicleSample, wrap_pi};

use super::compass_learning::Judged;
use super::compass_monitor::{CompassFix, Verdict};
use super::estimator::VehicleEstimator;
use super::heading_trig::small_atan2;
use super::innovation_line::InnovationLine;
use super::nav_filter::{BIAS, COMPASS_BIAS, DIM, EAST, NORTH, PSI, PSI_ODO, state};
use super::tracking::{CompassWindow, Outage};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Heading uncertainty beyond which a correction is no longer linear, rad (15°): the
/// heading is referred to north again from a run of consistent readings instead.
const RELOCK_SIGMA_RAD: f64 = 15.0 * core::f64::consts::PI / 180.0;

/// A compass rejected for this long while the vehicle turned through
/// [`SUSPECT_TURN_RAD`] is taken to say something about the estimator rather than about the
/// field, s: disturbances on the road are local and the vehicle leaves them, while a wrong
/// calibration, or a dead-reckoned heading that drifted off, disagrees everywhere.
const SUSPECT_AFTER_S: f64 = 60.0;

/// Turning that must accompany [`SUSPECT_AFTER_S`] of rejection, rad (90°).
const SUSPECT_TURN_RAD: f64 = core::f64::consts::FRAC_PI_2;

/// …or distance driven, m, where the wheels carry the heading: farther than a disturbance
/// on the road reaches (a parked car, a bridge's steel, a tram line's current: metres to a
/// few hundred). On a straight the readings cannot show a wrong calibration, which is a
/// function of the heading, but a field that disagrees with a wheels' heading by a steady
/// or steadily growing offset over half a kilometre is the wheels' drift, not the road's.
/// A gyro drifts too little over that for the same reading: there, a long disagreement on
/// a straight is left to the compass's gates.
const SUSPECT_DISTANCE_M: f64 = 500.0;

/// What a long rejection of the compass says.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Suspect {
    /// Nothing yet.
    None,
    /// The readings agree with one another through the turning, by a heading offset the
    /// same at every heading: the dead reckoning is wrong by it, rad.
    DeadReckoning {
        /// The offset at the last reading, rad.
        offset_rad: f64,
        /// Its standard deviation, rad.
        sigma_rad: f64,
    },
    /// They do not: the calibration in use is wrong.
    Calibration,
}

/// A judged reading as the outage counts it: its time, the heading and the distance driven
/// then, and its innovation, rad.
#[derive(Debug, Clone, Copy)]
struct Counted {
    t_s: f64,
    psi: f64,
    distance_m: f64,
    nu_rad: f64,
    /// The wheels carry the heading (no gyro): it drifts with their scale difference and
    /// the speeds' roundings, degrees a minute on a long straight.
    wheels_heading: bool,
}

impl Outage {
    /// Counts one judged `reading`; `noise_rad` is one reading's noise. After
    /// [`SUSPECT_AFTER_S`] of rejection with [`SUSPECT_TURN_RAD`] of turning or
    /// [`SUSPECT_DISTANCE_M`] driven it says what the rejection means: a field that is
    /// disturbed on the road is local and changes with place and heading, so readings that
    /// keep one offset (or drift steadily) from the dead reckoning mean that the dead
    /// reckoning is off, and readings that do not through a turn, that the calibration is.
    fn count(&mut self, reading: Counted, noise_rad: f64, used: bool) -> Suspect {
        let Counted {
            t_s,
            psi,
            distance_m,
            nu_rad,
            wheels_heading,
        } = reading;
        if let (Some((t0, psi0)), false) = (self.last, used) {
            self.rejected_s += t_s - t0;
            self.turned_rad += wrap_pi(psi - psi0).abs();
            self.travelled_m += (distance_m - self.last_distance_m).abs();
        }
        self.last = Some((t_s, psi));
        self.last_distance_m = distance_m;
        if used {
            self.restart();
            return Suspect::None;
        }
        self.line.push(t_s, nu_rad);
        let turned = self.turned_rad >= SUSPECT_TURN_RAD;
        if self.relearning
            || self.rejected_s < SUSPECT_AFTER_S
            || !(turned || (wheels_heading && self.travelled_m >= SUSPECT_DISTANCE_M))
        {
            return Suspect::None;
        }
        let fit = self.line.fit(noise_rad);
        self.restart();
        match fit {
            Some(f) if f.residual_rad <= 3.0 * noise_rad => Suspect::DeadReckoning {
                offset_rad: f.offset_rad,
                sigma_rad: f.sigma_rad,
            },
            // Readings that disagree among themselves through a turn: the calibration is
            // wrong. Without the turn they say nothing the road could not.
            _ if turned => {
                self.relearning = true;
                Suspect::Calibration
            }
            _ => Suspect::None,
        }
    }

    /// Starts counting a rejection afresh (the last reading is kept).
    fn restart(&mut self) {
        self.rejected_s = 0.0;
        self.turned_rad = 0.0;
        self.travelled_m = 0.0;
        self.line = InnovationLine::default();
    }
}

impl VehicleEstimator {
    pub(super) fn compass_step(&mut self, sample: &VehicleSample) {
        self.est.status.compass_used = false;
        let Some(raw) = sample.mag else {
            return;
        };
        let reading = self.compass.measure(&raw);
        if self.tracking.alignment.done && self.filter.sigma(PSI) > RELOCK_SIGMA_RAD {
            self.tracking.alignment.relocking = true;
        }
        let judged = match reading {
            Some((u, ratio))
                if self.tracking.alignment.done && !self.tracking.alignment.relocking =>
            {
                self.judge_reading(sample.t_s, &u, ratio)
            }
            Some((u, ratio)) => {
                if self.compass.field_ok(ratio) {
                    let ahead = self.heading_at(sample.t_s) - self.filter.x[PSI];
                    self.align_step(sample.t_s, (-u.y).atan2(u.x) - ahead);
                }
                Judged::Unjudged
            }
            None => Judged::Unjudged,
        };
        if sample.t_s > self.tracking.learned_until_s {
            self.learn_compass(&raw, sample.t_s, judged);
        }
        self.est.status.compass_calibrated = self.compass.fix().is_some();
        self.est.status.compass_disturbed = self.compass.disturbed();
    }

    /// A calibrated reading `u` (field ratio `ratio`) at `t_s`, once the heading is referred
    /// to north: its innovation judged by the gates, used if they pass it, counted against
    /// the outage; returns what the gates said, for the learner.
    fn judge_reading(&mut self, t_s: f64, u: &Vector2<f64>, ratio: f64) -> Judged {
        // Innovation: the angle from the predicted reading's direction to the
        // reading's, without an arctangent per reading when it is small.
        let f = &self.filter;
        let (sp, cp) = self
            .tracking
            .trig_compass
            .at(self.heading_at(t_s) - self.frame_declination_rad() + f.x[COMPASS_BIAS]);
        let nu = small_atan2(-u.y * cp - u.x * sp, u.x * cp - u.y * sp);
        let p_nu = f.p[PSI][PSI]
            + 2.0 * f.p[PSI][COMPASS_BIAS]
            + f.p[COMPASS_BIAS][COMPASS_BIAS]
            + self.tracking.batch.psi_noise();
        let verdict = self.compass.judge(t_s, nu, ratio, p_nu);
        let used = matches!(verdict, Verdict::Use { .. });
        if let Verdict::Use { variance_rad2 } = verdict {
            self.take_compass(nu, variance_rad2);
        }
        let noise = self.compass.fix().map_or(0.0, |f| f.noise_rad);
        let reading = Counted {
            t_s,
            psi: self.filter.x[PSI],
            distance_m: self.est.distance_m,
            nu_rad: nu,
            wheels_heading: !self.tracking.gyro.active,
        };
        match self.tracking.outage.count(reading, noise, used) {
            Suspect::None => {}
            Suspect::Calibration => self.learner.relearn(),
            Suspect::DeadReckoning {
                offset_rad,
                sigma_rad,
            } => self.relock(offset_rad, sigma_rad),
        }

        match (self.tracking.outage.relearning, used) {
            (true, _) => Judged::Unjudged,
            (false, true) => Judged::Gated,
            (false, false) => Judged::Rejected,
        }
    }

    /// Offers the raw reading to the compass learner; a new calibration from it replaces
    /// the one in use and starts the compass's gates and bias over.
    fn learn_compass(&mut self, raw: &Vector2<f64>, t_s: f64, judged: Judged) {
        let Some(s) = self.learner.offer(raw, t_s, self.filter.x[PSI], judged) else {
            return;
        };
        self.compass.set_fix(CompassFix::from_solution(&s));
        self.tracking.outage = Outage::default();
        // A new calibration makes a new systematic error, and the averaged
        // innovations were taken against the old one.
        self.compass.restart_gates();
        self.flush();
        self.tracking.window = CompassWindow::default();
        self.filter.x[COMPASS_BIAS] = 0.0;
        self.filter
            .reset_state(COMPASS_BIAS, self.compass_bias_var().sqrt());
    }

    /// Adds a reading's innovation to the window; a full window corrects the heading once.
    ///
    /// Reading `k` was taken against the heading then, whose error differs from the error
    /// now by the steps since: `e_k = e_now − (A_now − A_k)·cal`, with `A` the heading's
    /// accumulated couplings to the calibration states. So the window's mean innovation
    /// measures `e_now − (A_now − mean A_k)·cal + b_c`, which is the measurement row used —
    /// averaging while the heading drifts (uncalibrated wheels turn it by degrees a
    /// second) biases nothing.
    fn take_compass(&mut self, nu: f64, variance_rad2: f64) {
        let w = &mut self.tracking.window;
        w.n += 1;
        w.sum_nu += nu;
        w.variance_rad2 = variance_rad2;
        for (s, a) in w
            .sum_psi_from
            .iter_mut()
            .zip(self.tracking.batch.psi_from())
        {
            *s += a;
        }
        w.sum_noise_at += self.tracking.batch.psi_noise();
    }

    /// Corrects the heading with the window's readings, right after the covariance was
    /// carried forward to now (so `A_now = 0` and each reading's row is `−A_k` on the
    /// calibration states).
    pub(super) fn correct_with_compass(&mut self) {
        let w = self.tracking.window;
        self.tracking.window = CompassWindow::default();
        let n = f64::from(w.n);
        let mut h = [(0, 0.0); DIM];
        h[0] = (PSI, 1.0);
        h[1] = (COMPASS_BIAS, 1.0);
        let mut len = 2;
        for (j, s) in w.sum_psi_from.iter().enumerate() {
            if *s != 0.0 {
                h[len] = (j, s / n);
                len += 1;
            }
        }
        let mut learn = self.tracking.gates.compass.learnable();
        if !self.compass.steady() {
            // A field that turns slowly (30-90 s of steel alongside) starts as a trend in
            // the averaged innovation, well before the slow gate rejects it, and a trend
            // is just what a change of the gyro's bias would show: while one is under way
            // the compass cannot tell them apart, and a bias learned from it would turn
            // the heading on long after the field is clean again. The compass still
            // corrects the heading, and the bias's uncertainty still reaches it.
            learn &= !state(BIAS);
        }
        self.tracking.gates.compass_done();
        // Each reading missed the heading noise added after it; the mean of those is an
        // upper bound on the variance it adds to the window's mean (the noises are nested,
        // so positively correlated).
        let r = w.variance_rad2 / n + w.noise_after / n;
        self.filter.update_some(&h[..len], w.sum_nu / n, r, learn);
        self.est.status.compass_used = true;
        self.anchor_plain();
    }

    /// Gathers consistent readings and, once there are enough, refers the heading to north.
    ///
    /// The dead-reckoned heading may drift while the readings are gathered (wheels whose
    /// scales are not known yet turn the heading by up to a few degrees a second), so the
    /// innovations are fitted with a straight line in time and the offset is taken where
    /// the line ends, at the last reading; the line's residuals say whether the readings
    /// agree.
    fn align_step(&mut self, t_s: f64, heading: f64) {
        let Some(fix) = self.compass.fix().copied() else {
            return;
        };
        let heading = heading + self.frame_declination_rad();
        let line = &mut self.tracking.alignment.line;
        line.push(t_s, wrap_pi(heading - self.filter.x[PSI]));
        if line.len() < self.config.compass.alignment_readings {
            return;
        }
        let fit = line.fit(fix.noise_rad);
        *line = InnovationLine::default();
        match fit {
            Some(f)
                if f.residual_rad <= 3.0 * fix.noise_rad && self.tracking.alignment.relocking =>
            {
                self.relock(f.offset_rad, f.sigma_rad);
            }
            Some(f) if f.residual_rad <= 3.0 * fix.noise_rad => {
                self.align(f.offset_rad, f.sigma_rad);
            }
            // Not consistent (a disturbance, or the calibration is off): gather again.
            _ => {}
        }
    }

    /// Refers the heading to north: turns heading, wheel heading and track by `offset`,
    /// measured with standard deviation `sigma`.
    ///
    /// The offset is a measurement of the start heading, which was unknown (infinite
    /// variance): conditioning on it leaves the heading with the measurement's error alone,
    /// uncorrelated with the calibration states, and the track turned about the start by the
    /// same error. The wheels' heading keeps its difference from the gyro's.
    fn align(&mut self, offset: f64, sigma: f64) {
        let g = self.turn_frame(offset, sigma);
        let bias_var = self.compass_bias_var();
        let f = &mut self.filter;
        // The readings the offset came from carried the compass's systematic error too:
        // the heading's error is minus it, until the filter learns otherwise.
        f.reset_state(COMPASS_BIAS, bias_var.sqrt());
        for (k, gk) in g.iter().enumerate() {
            f.p[COMPASS_BIAS][k] -= bias_var * gk;
            f.p[k][COMPASS_BIAS] -= bias_var * gk;
        }
        f.p[COMPASS_BIAS][COMPASS_BIAS] = bias_var;
        for (i, gi) in g.iter().enumerate() {
            for (j, gj) in g.iter().enumerate() {
                f.p[i][j] += bias_var * gi * gj;
            }
        }
        self.tracking.alignment.done = true;
        self.compass.restart_gates();
        self.anchor_plain();
    }

    /// Turns heading, wheel heading and track about the start by `offset`, a measurement of
    /// the start heading (unknown until now) with standard deviation `sigma`: conditioning
    /// on it leaves the heading with the measurement's error alone, uncorrelated with the
    /// calibration states, and the track turned about the start by the same error. Returns
    /// how that error enters each state.
    pub(super) fn turn_frame(&mut self, offset: f64, sigma: f64) -> [f64; DIM] {
        self.tracking.alignment.offset_rad = offset;
        self.refer_heading(offset);
        let f = &mut self.filter;
        let (s, c) = offset.sin_cos();
        let (n, e) = (f.x[NORTH], f.x[EAST]);
        f.x[NORTH] = n * c - e * s;
        f.x[EAST] = n * s + e * c;
        // New errors as combinations of the old: P ← T P Tᵀ.
        let mut t = SMatrix::<f64, DIM, DIM>::identity();
        t[(NORTH, NORTH)] = c;
        t[(NORTH, EAST)] = -s;
        t[(EAST, NORTH)] = s;
        t[(EAST, EAST)] = c;
        t[(PSI, PSI)] = 0.0;
        if self.tracking.gyro.active {
            t[(PSI_ODO, PSI)] = -1.0;
        }
        let p = SMatrix::<f64, DIM, DIM>::from_fn(|i, j| f.p[i][j]);
        let turned = t * p * t.transpose();
        for (i, row) in f.p.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = turned[(i, j)];
            }
        }
        let mut g = [0.0; DIM];
        g[PSI] = 1.0;
        g[PSI_ODO] = if self.tracking.gyro.active { 1.0 } else { 0.0 };
        g[NORTH] = -f.x[EAST];
        g[EAST] = f.x[NORTH];
        f.add_common_error(&g, sigma);
        g
    }

    /// Refers a heading that was lost to north again: the heading (and the wheels' heading
    /// with it) turns by `offset`, measured with standard deviation `sigma` plus the
    /// compass's systematic error; the track already drawn stays as it is.
    pub(super) fn relock(&mut self, offset: f64, sigma: f64) {
        let bias_var = self.refer_heading(offset);
        let f = &mut self.filter;
        f.x[COMPASS_BIAS] = 0.0;
        f.reset_state(COMPASS_BIAS, bias_var.sqrt());
        f.reset_state(PSI, (sigma * sigma + bias_var).sqrt());
        if self.tracking.gyro.active {
            // The comparison with the wheels starts again from the new heading.
            f.x[PSI_ODO] = f.x[PSI];
            for k in 0..DIM {
                f.p[PSI_ODO][k] = f.p[PSI][k];
                f.p[k][PSI_ODO] = f.p[k][PSI];
            }
        }
        self.tracking.alignment.relocking = false;
        self.compass.restart_gates();
        self.anchor_plain();
    }

    /// Closes the open steps and the compass window, then turns the heading (and the
    /// wheels' heading with it) by `offset`; returns the compass's stationary systematic
    /// variance, which both a first alignment and a relock start the compass error from.
    pub(super) fn refer_heading(&mut self, offset: f64) -> f64 {
        self.flush();
        self.tracking.window = CompassWindow::default();
        let f = &mut self.filter;
        let turned = wrap_pi(f.x[PSI] + offset);
        f.x[PSI_ODO] += turned - f.x[PSI];
        f.x[PSI] = turned;
        self.compass_bias_var()
    }

    /// Stationary variance of the compass's systematic error: the road's floor plus what
    /// the calibration in use leaves, rad².
    pub(super) fn compass_bias_var(&self) -> f64 {
        let cal = self.compass.fix().map_or(0.0, |f| f.calibration_sigma_rad);
        self.coeffs.compass_floor_var + cal * cal
    }
}
