//! Dead reckoning between measurements: the gyro's and the wheels' readings moving the
//! heading and the track, each at its own time, the error couplings and process noise
//! they add, the gaps they cannot bridge, and the measurement epochs.

use truenorth_core::{STANDARD_GRAVITY_MPS2, WheelReading, wrap_pi};
use truenorth_gyro::YawIncrement;

use super::estimator::{ROW_JITTER_S, VehicleEstimator};
use super::nav_filter::{
    BIAS, COMPASS_BIAS, DIM, EAST, GAIN_NEG, GAIN_POS, NORTH, PSI, PSI_ODO, SPEED_COEFF,
    TRACK_SCALE, WHEEL_DIFF, WHEEL_LAG, WHEEL_SCALE,
};
use super::step_batch::Step;
use super::tracking::{Alignment, CompassWindow, Rest, SpeedHold};
use super::wheel_odometry::{WheelCalibration, WheelStep};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Seconds of motion between two comparisons of the wheels' heading with the gyro's.
const WHEEL_CHECK_S: f64 = 1.0;

/// Seconds of rest averaged into one bias measurement.
const REST_AVERAGE_S: f64 = 1.0;

/// Shortest rest that measures the bias when it ends before [`REST_AVERAGE_S`], s. Shorter
/// ones are the moment of stopping or starting: a car's body still rocks on its springs
/// (1–1.5 Hz) and its CAN speed reads zero while it creeps. Found by experiment on the
/// smartLoc drive (`tests/vehicle_smartloc.rs`): counting rests from 0.2 s took its track
/// from 28 to 77 m RMS; from 0.5 s it is 13.5 m.
const SHORT_REST_S: f64 = 0.5;

/// Weight of one interval in the gyro's running interval.
const INTERVAL_WEIGHT: f64 = 0.1;

/// Shortest silence of the gyro bridged by the wheels, s.
const MIN_BRIDGE_S: f64 = 0.05;

/// Slack on the freshness of the wheels' word that the vehicle stands still, s.
const REST_FRESH_S: f64 = 0.05;

/// Readings of a rest after which a reading is held to the rest's own mean.
const REST_MEAN_READINGS: u32 = 2;

/// Smallest bias-measurement noise at rest, rad/s (vibration of an idling engine).
const REST_NOISE_FLOOR_RPS: f64 = 2e-5;

/// Time constant of the low-passed turn rate that says which way the vehicle turns, s.
const TURN_SMOOTHING_S: f64 = 0.3;

/// Turn rate, above three standard deviations of the bias, from which a gyro reading is
/// counted against the gain of its turning direction, rad/s (1°/s). Below it the
/// direction is the sign of noise and vibration, which a per-direction gain would
/// rectify into a drift the gyro does not have; the gains' uncertainty there is heading
/// noise.
const GAIN_COUPLING_MIN_RATE_RPS: f64 = 1.0 * core::f64::consts::PI / 180.0;

/// Turn rate, above three standard deviations of the bias, from which a turn teaches the
/// gain (2°/s): below it a gain error cannot be told from the bias (on the straight real
/// drive of `truenorth-cli/tests/comma2k19.rs` vibration and an unlearned bias moved the
/// gains by 13 %).
const GAIN_LEARNING_MIN_RATE_RPS: f64 = 2.0 * core::f64::consts::PI / 180.0;

/// Gyro gain error not captured by the two gains (non-linearity), per radian turned.
const GYRO_GAIN_NOISE: f64 = 1e-3;

/// Correlation time of the wheels' slip, s: its variance enters as white noise of density
/// `2σ²τ` per unit of squared turn rate, which is the exact variance for turns longer than
/// τ and more than it for shorter ones.
const SLIP_TAU_S: f64 = 3.0;

/// Random walk of the calibration states, per √s: they may drift a little (tyre pressure,
/// temperature), so the filter never stops listening.
const GAIN_WALK: f64 = 1e-5;
const DIFF_WALK: f64 = 2e-7;
const SPEED_COEFF_WALK: f64 = 1e-8;
/// The wheels' delay, s/√s: a logger's buffering may change over a drive.
const LAG_WALK_S: f64 = 1e-4;

/// Position noise per metre travelled, m²/m (lateral creep, bumps).
const POSITION_NOISE_M2_PER_M: f64 = 1e-6;

/// Share of the turn made in a gap that the path through it leaves unknown: the chord's
/// direction (for the track) and, for steered wheels, the effective track along it.
const GAP_TURN_SHARE: f64 = 0.3;

/// How far an unsensed heading may wander per metre driven, rad²/m: the variance added to
/// the heading where odometry moves the vehicle and nothing measures its turning (one
/// vehicle speed and no gyro, or a gyro gap a single distance cannot bridge). A random
/// walk of 0.22 rad/√m: after 10 m the heading is known to about 40°, after 50 m not at
/// all — a car's corner is 15–30 m of road, a robot's pivot a fraction of a metre.
const UNSENSED_TURN_RAD2_PER_M: f64 = 0.05;

/// Share of a steered axle's turn across a gap that the unknown path leaves unknown: the
/// effective track changes along the path by up to a tenth between straight and full lock
/// (`truenorth-odometer`'s table of the exact track).
const GAP_STEERED_SHARE: f64 = 0.05;

impl VehicleEstimator {
    /// Takes a gyro reading at `t_s`.
    pub(super) fn gyro_reading(&mut self, t_s: f64, raw: f64) {
        let Some((t0, raw0)) = self.tracking.gyro.last else {
            self.start_gyro(t_s, raw);
            return;
        };
        self.tracking.gyro.last = Some((t_s, raw));
        self.tracking.gyro.distance_at_last_m = self.est.distance_m;
        let dt = t_s - t0;
        let gap = dt > self.config.max_gap_s;
        let at_rest = self.resting_at(t_s, raw, dt);
        if !at_rest {
            self.tracking.gates.count_step(gap);
        }
        if self.tracking.gyro.interval_s == 0.0 {
            self.tracking.gyro.interval_s = dt.min(self.config.max_gap_s);
        } else if dt <= 1.5 * self.tracking.gyro.interval_s {
            self.tracking.gyro.interval_s += INTERVAL_WEIGHT * (dt - self.tracking.gyro.interval_s);
        }
        if gap || (self.wheels_fresh(t_s) && dt > self.gyro_bridge_s()) {
            self.bridge_gyro_gap(gap);
            return;
        }
        if at_rest {
            self.tracking.rest.sum_raw += raw;
            self.tracking.rest.n += 1;
            self.tracking.rest.span_s += dt;
            self.tracking.gyro.smoothed_rps = 0.0;
            self.tracking.gyro.rate_rps = 0.0;
            self.tracking.motion.heading_rate_rps = 0.0;
            self.tracking.gyro.odo_at_last_rad = self.filter.x[PSI_ODO];
            return;
        }
        let rest = core::mem::take(&mut self.tracking.rest);
        if rest.span_s >= SHORT_REST_S && rest.n >= REST_MEAN_READINGS {
            // The rest ended before a full average: what it measured still counts, with the
            // noise of its shorter span (a robot that stops for a moment between tasks).
            self.flush();
            self.measure_bias(&rest);
        }
        let trapezoid = YawIncrement::new(raw0, raw, dt);
        self.plain_gyro(trapezoid.angle_rad(), dt);
        let x = &self.filter.x;
        let increment = trapezoid.angle_rad() - x[BIAS] * dt;
        let alpha = dt / (dt + TURN_SMOOTHING_S);
        self.tracking.gyro.smoothed_rps +=
            alpha * (increment / dt - self.tracking.gyro.smoothed_rps);
        let turning = if self.tracking.gyro.smoothed_rps != 0.0 {
            self.tracking.gyro.smoothed_rps
        } else {
            increment
        };
        let gain_state = if turning >= 0.0 { GAIN_POS } else { GAIN_NEG };
        let gain = 1.0 + x[gain_state];
        let dpsi = increment / gain;
        self.tracking.gyro.rate_rps = dpsi / dt;
        self.tracking.motion.heading_rate_rps = dpsi / dt;
        let bias_sigma3 = 3.0 * self.filter.sigma(BIAS);
        let rate = self.tracking.gyro.smoothed_rps.abs();
        let mut step = Step::default();
        step.psi_from[0] = (BIAS, -dt / gain);
        // The trapezoid is exact for a rate that changes linearly between readings; a
        // rate that changes faster (a robot starting to pivot) can change anywhere in the
        // interval.
        let integration = trapezoid.error_variance_rad2();
        step.q[PSI] =
            self.coeffs.gyro_noise_rad2_per_s * dt + (GYRO_GAIN_NOISE * dpsi).powi(2) + integration;
        if rate > GAIN_COUPLING_MIN_RATE_RPS + bias_sigma3 {
            step.psi_from[1] = (gain_state, -dpsi / gain);
        } else {
            step.q[PSI] += (self.filter.sigma(gain_state) * dpsi).powi(2);
        }
        self.tracking
            .gates
            .gyro_step(dpsi, rate > GAIN_LEARNING_MIN_RATE_RPS + bias_sigma3);
        self.turn_heading(dpsi, &mut step);
        self.tracking.batch.add(&step);
        self.tracking.gyro.odo_at_last_rad = self.filter.x[PSI_ODO];
    }

    /// Whether the vehicle stands still at `t_s`, as far as a gyro reading `raw` taken
    /// `dt` after the last can be held to it: the wheels said so at their last reading,
    /// that reading is fresh (within two of their intervals), and the gyro does not
    /// contradict it (a rate beyond five standard deviations of the bias and the reading's
    /// noise is a turn the wheels missed: a skid-steer pivoting while its wheel readings
    /// drop out). Once a few readings of this rest are in, the rate is held to their mean
    /// rather than to the bias: a gyro at rest reads its bias, whatever the bias is, so a
    /// reading that leaves the rest's mean by more than its noise is a turn even while the
    /// bias is still unknown (a car creeping round a corner below the speed a CAN bus
    /// reports as anything but zero).
    fn resting_at(&self, t_s: f64, raw: f64, dt: f64) -> bool {
        if !self.tracking.motion.at_rest {
            return false;
        }
        let fresh = self.wheels.last_s().is_some_and(|t0| {
            t_s - t0 <= 2.0 * self.tracking.motion.wheel_interval_s + REST_FRESH_S
        });
        let rest = &self.tracking.rest;
        let (reference, reference_var) = if rest.n >= REST_MEAN_READINGS {
            let mean = rest.sum_raw / f64::from(rest.n);
            (
                mean,
                self.coeffs.gyro_noise_rad2_per_s / rest.span_s.max(dt),
            )
        } else {
            (self.filter.x[BIAS], self.filter.p[BIAS][BIAS])
        };
        let spread = (reference_var + self.coeffs.gyro_noise_rad2_per_s / dt)
            .sqrt()
            .max(REST_NOISE_FLOOR_RPS);
        fresh && (raw - reference).abs() <= 5.0 * spread
    }

    /// Switches the heading to the gyro at its first reading: the wheels' heading starts
    /// equal to it, fully correlated.
    fn start_gyro(&mut self, t_s: f64, raw: f64) {
        self.tracking.gyro.active = true;
        self.tracking.gyro.last = Some((t_s, raw));
        if !self.tracking.gyro.restored {
            let s = &self.coeffs.prior_sigma;
            self.filter.reset_state(BIAS, s[BIAS]);
            self.filter.reset_state(GAIN_POS, s[GAIN_POS]);
            self.filter.reset_state(GAIN_NEG, s[GAIN_NEG]);
        }
        self.restart_wheel_heading();
    }

    /// Starts the wheels' heading again from the gyro's: equal to it, fully correlated.
    pub(super) fn restart_wheel_heading(&mut self) {
        self.flush();
        let f = &mut self.filter;
        f.x[PSI_ODO] = f.x[PSI];
        for k in 0..DIM {
            f.p[PSI_ODO][k] = f.p[PSI][k];
            f.p[k][PSI_ODO] = f.p[k][PSI];
        }
        f.p[PSI_ODO][PSI_ODO] = f.p[PSI][PSI];
        self.tracking.gyro.odo_at_last_rad = f.x[PSI_ODO];
    }

    /// Longest silence of the gyro its readings are integrated across while the wheels can
    /// bridge it instead, s: three of its intervals (the trapezoid rule over a longer silence
    /// misses a turn made inside it — a robot pivots through 90° in a second), within
    /// [`super::VehicleConfig::max_gap_s`].
    pub(super) fn gyro_bridge_s(&self) -> f64 {
        (3.0 * self.tracking.gyro.interval_s).clamp(MIN_BRIDGE_S, self.config.max_gap_s)
    }

    /// Whether the wheels read recently enough to carry the heading at `t_s` (and say how
    /// the vehicle turns at all).
    fn wheels_fresh(&self, t_s: f64) -> bool {
        self.est.status.position_known
            && self.tracking.motion.wheels_turn
            && self.wheels.last_s().is_some_and(|t0| {
                t_s - t0 <= 2.0 * self.tracking.motion.wheel_interval_s + REST_FRESH_S
            })
    }

    /// The gyro was silent for longer than it can be integrated across (`gap`: longer than
    /// the estimator follows at all). The wheels, if any, carried the heading through most
    /// of the silence; what they turned since the last gyro reading that nothing has yet
    /// counted is added with a share of it as noise. Without wheels the heading is lost
    /// until the compass refers it to north again.
    fn bridge_gyro_gap(&mut self, gap: bool) {
        self.est.status.gap |= gap;
        self.tracking.gyro.smoothed_rps = 0.0;
        self.tracking.gyro.rate_rps = 0.0;
        if self.est.status.position_known && !self.tracking.motion.wheels_turn {
            // One distance carried the vehicle through the gap and says nothing of how it
            // turned: the heading is widened by what it may have turned over that distance.
            let ds = self.est.distance_m - self.tracking.gyro.distance_at_last_m;
            let mut step = Step::default();
            step.q[PSI] = UNSENSED_TURN_RAD2_PER_M * ds.abs();
            self.tracking.batch.add(&step);
            self.tracking.gyro.distance_at_last_m = self.est.distance_m;
        } else if self.est.status.position_known {
            let turned = wrap_pi(self.filter.x[PSI_ODO] - self.tracking.gyro.odo_at_last_rad);
            let mut step = Step::default();
            step.q[PSI] = (GAP_TURN_SHARE * turned).powi(2);
            self.turn_heading(turned, &mut step);
            self.tracking.batch.add(&step);
            self.tracking.gyro.odo_at_last_rad = self.filter.x[PSI_ODO];
        } else {
            self.flush();
            self.filter
                .reset_state(PSI, super::estimator::UNKNOWN_HEADING_SIGMA_RAD);
            self.tracking.alignment = Alignment::default();
            self.forget_gnss_frame();
            self.tracking.window = CompassWindow::default();
            self.restart_wheel_heading();
        }
        self.anchor_plain();
    }

    /// Moves the heading by `dpsi` in `step` (which carries its couplings), with the
    /// compass error's growth as the heading turns, keeping it in (−π, π].
    fn turn_heading(&mut self, dpsi: f64, step: &mut Step) {
        // The compass error is a function of the heading: turning decorrelates it.
        self.decorrelate_compass(dpsi.abs() / self.config.compass.systematic_turn_rad, step);
        let x = &mut self.filter.x;
        // Heading kept in (−π, π]: differences of headings stay in range, and the wheels'
        // heading and the heading at the last wheel reading are wrapped with it so that
        // their differences keep their meaning.
        let wrapped = wrap_pi(x[PSI] + dpsi);
        let shift = wrapped - (x[PSI] + dpsi);
        self.tracking.gnss.trail.turn(dpsi);
        x[PSI_ODO] += shift;
        self.tracking.motion.psi_at_wheels_rad += shift;
        self.tracking.gyro.odo_at_last_rad += shift;
        x[PSI] = wrapped;
    }

    /// Takes a wheel reading at `t_s`; `turns`: the reading says how the vehicle turns (two
    /// wheels that have differed), else it gives the distance only.
    pub(super) fn wheel_reading(&mut self, t_s: f64, reading: WheelReading, turns: bool) {
        let x = self.filter.x;
        let cal = WheelCalibration {
            diff: x[WHEEL_DIFF],
            speed_coeff: x[SPEED_COEFF],
            track_scale: x[TRACK_SCALE],
        };
        let Some(wheel) = self.wheels.step(t_s, reading, &cal) else {
            self.est.status.position_known = true;
            self.tracking.motion.psi_at_wheels_rad = self.heading_at(t_s);
            return;
        };
        let dt = wheel.dt_s;
        let gap = dt > self.config.max_gap_s;
        self.tracking.motion.still_s = if wheel.moved {
            0.0
        } else {
            self.tracking.motion.still_s + dt
        };
        self.tracking.motion.at_rest = self.tracking.motion.still_s >= self.config.standstill_s
            && self.tracking.motion.still_s > 0.0;
        self.tracking.motion.wheel_interval_s = dt;
        if wheel.moved {
            self.tracking.gates.count_step(gap);
            self.est.status.gap |= gap;
        }
        let wheel_q = self.wheel_noise(&wheel, gap) + self.held_speeds_noise(&wheel, turns);
        let wheel_from = [
            (WHEEL_DIFF, wheel.d_heading_d_diff),
            (SPEED_COEFF, wheel.d_heading_d_speed_coeff),
            (TRACK_SCALE, wheel.d_heading_d_track_scale),
        ];
        let turned = if turns { wheel.heading_change_rad } else { 0.0 };
        let mut step = Step::default();
        let gyro_silent = self
            .tracking
            .gyro
            .last
            .is_some_and(|(t0, _)| t_s - t0 > self.gyro_bridge_s());
        if !turns {
            // The distance only: the gyro, if it reads, carries the heading; if not, the
            // heading is free to wander over the distance driven.
            if !self.tracking.gyro.active {
                step.q[PSI] = UNSENSED_TURN_RAD2_PER_M * wheel.ds_m.abs();
            }
        } else if self.tracking.gyro.active {
            step.odo_from = wheel_from;
            step.q[PSI_ODO] = wheel_q;
            self.filter.x[PSI_ODO] += turned;
            if gyro_silent {
                // The gyro is in a gap: the wheels carry the heading across it.
                step.psi_from = wheel_from;
                step.q[PSI] = wheel_q;
                self.turn_heading(turned, &mut step);
                self.tracking.motion.heading_rate_rps = turned / dt.max(1e-3);
                self.tracking.gyro.odo_at_last_rad = self.filter.x[PSI_ODO];
                self.tracking.guard.anchored = false;
            } else if !self.tracking.motion.at_rest && wheel.moved {
                self.tracking.wheel_check_s += dt;
            }
        } else {
            step.psi_from = wheel_from;
            step.q[PSI] = wheel_q;
            self.turn_heading(turned, &mut step);
            self.tracking.motion.heading_rate_rps = turned / dt.max(1e-3);
        }
        if wheel.moved {
            let compared = turns && self.tracking.gyro.active && !gyro_silent;
            self.tracking
                .gates
                .wheel_step(turned, wheel.speed_mps, compared);
        }
        let scale = 1.0 + self.filter.x[WHEEL_SCALE];
        self.advance_track(t_s, &wheel, gap, &mut step);
        self.tracking.batch.add(&step);
        self.tracking.motion.odometer_m += wheel.ds_m.abs();
        self.tracking
            .gnss
            .odometer
            .push(t_s, self.tracking.motion.odometer_m);
        self.est.speed_mps = wheel.speed_mps * scale;
        self.est.distance_m += (wheel.ds_m * scale).abs();
        self.est.status.at_rest = self.tracking.motion.at_rest;
    }

    /// Variance of the wheels' heading change over `wheel`: bumps and pulses per metre,
    /// and slip, which grows with lateral acceleration, with the turn ratio of steered
    /// wheels, and with the wheels' observed disagreement.
    fn wheel_noise(&self, wheel: &WheelStep, gap: bool) -> f64 {
        let p = &self.coeffs.priors;
        let turned = wheel.heading_change_rad;
        let rate = turned / wheel.dt_s;
        let lateral_g = (wheel.speed_mps * rate).abs() / STANDARD_GRAVITY_MPS2;
        let slip = self.tracking.gates.slip_scale2.sqrt()
            * (p.wheel_slip
                + p.wheel_slip_per_g * lateral_g
                + p.wheel_slip_per_c2 * wheel.ratio * wheel.ratio);
        let mut q = self.coeffs.wheel_noise_rad2_per_m * wheel.ds_m.abs()
            + 2.0 * slip * slip * SLIP_TAU_S * rate * turned;
        if gap && p.wheel_slip_per_c2 > 0.0 {
            q += (GAP_STEERED_SHARE * turned).powi(2);
        }
        q
    }

    /// Variance the wheels' heading gains from speeds read in quanta `q` and integrated: each
    /// wheel's rounding error holds while its speed moves by less than a quantum, and their
    /// difference turns the heading at a rate of standard deviation `q/(√6·T)` (two uniform
    /// roundings, track T) for as long as it holds — an error growing with the hold's length,
    /// `σ²h²`, not with its square root; the increments here sum to that over each hold. Zero
    /// for distances read from counters (`wheel_speed_quantum_mps` 0).
    fn held_speeds_noise(&mut self, wheel: &WheelStep, turns: bool) -> f64 {
        let quantum = self.coeffs.priors.wheel_speed_quantum_mps;
        if quantum <= 0.0 || !turns || !wheel.moved {
            return 0.0;
        }
        let hold = &mut self.tracking.motion.speed_hold;
        // A step's speed is the mean of two readings: one quantum in a reading is half here.
        let renewed = hold
            .speeds_mps
            .iter()
            .zip(wheel.side_speeds_mps)
            .any(|(a, b)| (a - b).abs() >= 0.5 * quantum);
        if renewed {
            *hold = SpeedHold {
                speeds_mps: wheel.side_speeds_mps,
                held_s: 0.0,
            };
        }
        let sigma_rate = quantum / (6f64.sqrt() * wheel.effective_track_m);
        let (h0, h1) = (hold.held_s, hold.held_s + wheel.dt_s);
        hold.held_s = h1;
        sigma_rate * sigma_rate * (h1 * h1 - h0 * h0)
    }

    /// Lets the compass's systematic error change by `e`-foldings in `step`, towards its
    /// stationary spread.
    fn decorrelate_compass(&mut self, foldings: f64, step: &mut Step) {
        let decay = (-foldings).exp();
        step.compass_decay *= decay;
        step.q[COMPASS_BIAS] += self.compass_bias_var() * (1.0 - decay * decay);
        self.filter.x[COMPASS_BIAS] *= decay;
    }

    /// Draws the track along the heading half-way between this wheel reading and the last.
    fn advance_track(&mut self, t_s: f64, wheel: &WheelStep, gap: bool, step: &mut Step) {
        let psi = self.heading_at(t_s);
        let change = wrap_pi(psi - self.tracking.motion.psi_at_wheels_rad);
        let (s, c) = self
            .tracking
            .trig
            .at(self.tracking.motion.psi_at_wheels_rad + 0.5 * change);
        self.tracking.motion.psi_at_wheels_rad = psi;
        let ds = wheel.ds_m * (1.0 + self.filter.x[WHEEL_SCALE]);
        step.north_from_psi = -ds * s;
        step.east_from_psi = ds * c;
        step.north_from_scale = wheel.ds_m * c;
        step.east_from_scale = wheel.ds_m * s;
        // The ground's tilt changes along the way (one state carries every share of the
        // compass's systematic error, so all of it is let go: the cautious side).
        let ground_m = self.coeffs.priors.compass_ground_length_m;
        if ground_m > 0.0 {
            self.decorrelate_compass(ds.abs() / ground_m, step);
        }
        let mut q = POSITION_NOISE_M2_PER_M * ds.abs();
        if gap {
            // The path through a gap is unknown: the chord may lie anywhere between the
            // turn made first and made last.
            q += (GAP_TURN_SHARE * ds * change).powi(2);
        }
        step.q[NORTH] += q;
        step.q[EAST] += q;
        self.filter.x[NORTH] += ds * c;
        self.filter.x[EAST] += ds * s;
        self.tracking.gnss.trail.step(t_s, ds);
        self.plain_odometry(wheel.ds_m);
    }

    /// The passage of the time since the last epoch: the compass error's decay and the
    /// calibration states' random walk, composed into the batch as one step (they couple
    /// to nothing within it).
    fn time_passes(&mut self) {
        let dt = core::mem::take(&mut self.tracking.pending_time_s);
        if dt <= 0.0 {
            return;
        }
        let decay = (-dt / self.config.compass.systematic_tau_s).exp();
        let mut step = Step {
            compass_decay: decay,
            ..Step::default()
        };
        let q = &mut step.q;
        q[COMPASS_BIAS] = self.compass_bias_var() * (1.0 - decay * decay);
        if self.tracking.gyro.active {
            q[BIAS] = self.coeffs.bias_walk_rad2_per_s3 * dt;
            q[GAIN_POS] = GAIN_WALK * GAIN_WALK * dt;
            q[GAIN_NEG] = q[GAIN_POS];
        }
        q[WHEEL_DIFF] = DIFF_WALK * DIFF_WALK * dt;
        if self.coeffs.prior_sigma[SPEED_COEFF] > 0.0 {
            q[SPEED_COEFF] = SPEED_COEFF_WALK * SPEED_COEFF_WALK * dt;
        }
        q[TRACK_SCALE] = GAIN_WALK * GAIN_WALK * dt;
        // A tyre's rolling radius follows its pressure and temperature over a drive.
        q[WHEEL_SCALE] = GAIN_WALK * GAIN_WALK * dt;
        q[WHEEL_LAG] = LAG_WALK_S * LAG_WALK_S * dt;
        self.filter.x[COMPASS_BIAS] *= decay;
        self.tracking.batch.add(&step);
    }

    /// Carries the covariance forward through the steps composed so far: before any
    /// measurement or change of the covariance.
    pub(super) fn flush(&mut self) {
        self.time_passes();
        // The window's readings are tied to the heading through the couplings accumulated
        // since the batch began; the next batch begins now, so refer them to now:
        // A_k − A_now for each reading.
        let n = f64::from(self.tracking.window.n);
        let w = &mut self.tracking.window;
        for (s, a) in w
            .sum_psi_from
            .iter_mut()
            .zip(self.tracking.batch.psi_from())
        {
            *s -= n * a;
        }
        w.noise_after += n * self.tracking.batch.psi_noise() - w.sum_noise_at;
        w.sum_noise_at = 0.0;
        self.tracking.batch.apply(&mut self.filter);
    }

    /// A measurement epoch: the covariance is carried forward once, then every measurement
    /// that is due corrects the state — the compass's averaged readings, the wheels'
    /// heading against the gyro's once a second of driving, the bias once a second of rest.
    pub(super) fn epoch(&mut self) {
        self.tracking.rows_since_epoch = 0;
        self.flush();
        if self.tracking.rest.span_s >= REST_AVERAGE_S {
            let rest = core::mem::take(&mut self.tracking.rest);
            self.measure_bias(&rest);
        }
        if self.tracking.wheel_check_s >= WHEEL_CHECK_S {
            self.tracking.wheel_check_s = 0.0;
            self.wheels_against_gyro();
        }
        if self.tracking.window.n >= self.config.compass.readings_per_update {
            self.correct_with_compass();
        }
        // A wheel pair's difference only grows with speed: `a` is never negative; and the
        // wheels cannot read before the motion.
        self.filter.project_at_least(SPEED_COEFF, 0.0);
        self.filter.project_at_least(WHEEL_LAG, 0.0);
        self.guard_against_plain();
    }

    /// The gyro's mean reading over `rest` measures its bias, to the noise of the rest's
    /// span (the covariance carried forward to now by the caller).
    fn measure_bias(&mut self, rest: &Rest) {
        let mean = rest.sum_raw / f64::from(rest.n);
        let r = self.coeffs.gyro_noise_rad2_per_s / rest.span_s
            + REST_NOISE_FLOOR_RPS * REST_NOISE_FLOOR_RPS;
        self.filter
            .update(&[(BIAS, 1.0)], mean - self.filter.x[BIAS], r);
        self.plain_rest(mean, r);
    }

    /// The wheels' heading minus the gyro's, measured against zero. A comparison far
    /// outside what the model allows (a wheel that spun or slid) corrects nothing: the
    /// wheels' heading starts again from the gyro's, and the disagreement lowers the
    /// wheels' trust.
    fn wheels_against_gyro(&mut self) {
        self.tracking.gates.time_base_window();
        let t_wheels = self.wheels.last_s().unwrap_or(f64::NAN);
        let ahead = self.heading_at(t_wheels) - self.filter.x[PSI];
        // The wheels' and the gyro's readings reach the log with different delays (their
        // own rows and clocks, a motor controller's or an ABS unit's filtering): in a turn
        // the wheels' heading trails the gyro's by the rate times the delay, which is
        // learned (it vanishes when the turn ends, where a gain's error stays). It shows
        // only in a turn the gyro is known to make: while the bias is uncertain a straight
        // reads as a turn at the bias's rate, whose product with the delay is no turn at
        // all — the delay is then only noise, as large as it may be.
        let rate = self.tracking.gyro.rate_rps;
        let known_turn = rate.abs() > GAIN_LEARNING_MIN_RATE_RPS + 3.0 * self.filter.sigma(BIAS);
        let (lag, lag_h) = if known_turn {
            (self.filter.x[WHEEL_LAG], -rate)
        } else {
            (0.0, 0.0)
        };
        let nu = wrap_pi(self.filter.x[PSI_ODO] - self.filter.x[PSI] - ahead + lag * rate);
        let h = [(PSI, 1.0), (PSI_ODO, -1.0), (WHEEL_LAG, lag_h)];
        // What the delay does beyond what is modelled: the rows' jitter, and in a turn not
        // known the whole delay.
        let unmodelled = if known_turn {
            ROW_JITTER_S * ROW_JITTER_S
        } else {
            self.wheel_delay_s2()
        };
        let r = self.coeffs.wheel_quantisation_rad2 + unmodelled * rate * rate;
        let f = &self.filter;
        let s = f.p[PSI][PSI] - 2.0 * f.p[PSI][PSI_ODO]
            + f.p[PSI_ODO][PSI_ODO]
            + lag_h * lag_h * f.p[WHEEL_LAG][WHEEL_LAG]
            + 2.0 * lag_h * (f.p[PSI][WHEEL_LAG] - f.p[PSI_ODO][WHEEL_LAG])
            + r;
        let nis = nu * nu / s;
        let learn = self.tracking.gates.wheel_check_learnable();
        self.tracking.gates.wheel_check_done(nis);
        if nis > OUTLIER_NIS || !nis.is_finite() {
            self.restart_wheel_heading();
            return;
        }
        self.filter.update_some(&h, nu, r, learn);
    }
}

/// A comparison whose normalised innovation squared exceeds this (5σ) is an outlier.
const OUTLIER_NIS: f64 = 25.0;
