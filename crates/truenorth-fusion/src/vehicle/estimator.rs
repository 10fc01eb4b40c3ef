//! The vehicle heading and dead-reckoning estimator: gyro, wheels and compass in one
//! error-state Kalman filter that calibrates all three while the vehicle drives.
//!
//! Per sample:
//! 1. **Wheels** ([`super::wheel_odometry`]): heading change and rear-axle distance under the
//!    current differential scale δ and speed coefficient `a`; no wheel movement for
//!    [`VehicleConfig::standstill_s`] means the vehicle stands still.
//! 2. **Heading** is carried by the gyro when one is fitted (trapezoid rule on the corrected
//!    rate `(ω − b)/(1 + s±)`, one gain per turning direction since cheap gyros differ), and
//!    by the wheels otherwise. At rest the heading is held (a car cannot turn without its
//!    wheels turning) and the raw rate measures the bias directly.
//! 3. **Wheels against gyro**: the heading integrated from the wheels alone is a second
//!    state; once a second their difference from the gyro's heading is a measurement. It
//!    depends only on the calibration states — bias (∝ time), gains (∝ turn), δ
//!    (∝ distance) and `a` (∝ turn × speed²) — which is what separates them: the wheels'
//!    error is bounded by one pulse, the gyro's grows.
//! 4. **Compass** ([`super::compass_monitor`]): calibrated online from the drive itself;
//!    once calibrated, a run of consistent readings refers the heading to magnetic north
//!    (the track so far is turned with it); after that, readings that pass the gates
//!    correct the heading, averaged a few at a time.
//! 5. **Position**: the rear-axle distance along the mid-step heading. Its covariance is
//!    carried by the filter (the heading's error turns into cross-track error), plus the
//!    odometer's unobservable mean scale as an along-track term.

use nalgebra::{Matrix2, SMatrix, Vector2};
use truenorth_core::{
    HeadingEstimator, MagneticHeading, NavEstimate, Result, TimeStep, Validate, VehicleSample,
    wrap_pi,
};

use super::compass_learning::{CompassLearner, Judged};
use super::compass_monitor::{CompassFix, CompassMonitor, Verdict};
use super::config::VehicleConfig;
use super::heading_trig::{HeadingTrig, small_atan2};
use super::innovation_line::InnovationLine;
use super::learned::VehicleCalibration;
use super::nav_filter::{
    BIAS, COMPASS_BIAS, DIM, EAST, GAIN_NEG, GAIN_POS, NORTH, NavFilter, PSI, PSI_ODO, SPEED_COEFF,
    TRACK_SCALE, WHEEL_DIFF,
};
use super::step_batch::{Step, StepBatch};
use super::wheel_odometry::{WheelCalibration, WheelOdometry};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Seconds of motion between two comparisons of the wheels' heading with the gyro's.
const WHEEL_CHECK_S: f64 = 1.0;

/// Seconds of rest averaged into one bias measurement.
const REST_AVERAGE_S: f64 = 1.0;

/// Gyro gain error not captured by the two gains (non-linearity), per radian turned.
const GYRO_GAIN_NOISE: f64 = 1e-3;

/// Turn rate above three standard deviations of the bias from which the gyro's readings
/// teach its gains, rad/s (2°/s). Below it a gain error cannot be told from the bias: on a
/// straight road vibration averages to no turn but a per-reading split by sign sees
/// degrees of each, and a bias not yet learned looks like a steady turn one way (on the
/// straight real drive of `truenorth-cli/tests/comma2k19.rs` both made the gains move by
/// 13 % and report themselves known to 2 %). There the gains' uncertainty is heading
/// noise instead; a gain error of a few percent costs under 0.06°/s at such rates.
const GAIN_LEARNING_MIN_RATE_RPS: f64 = 2.0 * core::f64::consts::PI / 180.0;

/// Wheel heading error not captured by δ and `a` (tyre deflection in a turn), per radian.
const WHEEL_TURN_NOISE: f64 = 5e-3;

/// Random walk of the calibration states, per √s: they may drift a little (tyre pressure,
/// temperature), so the filter never stops listening.
const GAIN_WALK: f64 = 1e-5;
const DIFF_WALK: f64 = 2e-7;
const SPEED_COEFF_WALK: f64 = 1e-8;

/// Most steps composed before the covariance is carried forward (it is carried forward at
/// every measurement too): keeps the reported uncertainty fresh without a compass.
const MAX_BATCH_STEPS: u32 = 20;

/// Position noise per metre travelled, m²/m (lateral creep, bumps).
const POSITION_NOISE_M2_PER_M: f64 = 1e-6;

/// Drift of the dead-reckoned heading that its variance may leave out, rad/s: while the
/// compass is rejected its gates widen by this rate times the outage's length, so that a
/// dead reckoning that drifted faster than its model says is corrected once the field is
/// clean again instead of being locked out for good (0.02°/s).
const OUTAGE_DRIFT_RPS: f64 = 0.02 * core::f64::consts::PI / 180.0;

/// A compass rejected for this long while the vehicle turned through
/// [`SUSPECT_TURN_RAD`] is taken to have a calibration that is wrong rather than a field
/// that is disturbed, s: disturbances on
/// the road are local and the vehicle leaves them, while a wrong calibration disagrees
/// everywhere.
const SUSPECT_AFTER_S: f64 = 120.0;

/// Turning that must accompany [`SUSPECT_AFTER_S`] of rejection, rad (90°).
const SUSPECT_TURN_RAD: f64 = core::f64::consts::FRAC_PI_2;

/// Smallest bias-measurement noise at rest, rad/s (vibration of an idling engine).
const REST_NOISE_FLOOR_RPS: f64 = 2e-5;

/// Coefficients derived from the configuration once.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Coefficients {
    gyro_noise_rad2_per_s: f64,
    bias_walk_rad2_per_s3: f64,
    wheel_noise_rad2_per_m: f64,
    /// Variance of the wheels' heading from the pulses at each end of a comparison, rad².
    wheel_quantisation_rad2: f64,
    /// Variance of the road's and the installation's share of the compass's systematic
    /// error, rad² (the calibration's share comes with each calibration).
    compass_floor_var: f64,
}

impl Coefficients {
    fn new(c: &VehicleConfig) -> Self {
        let p = &c.priors;
        let track = match c.wheels {
            truenorth_odometer::OdometerWheels::Rear { track_m } => track_m,
            truenorth_odometer::OdometerWheels::Front(f) => f.track_m,
        };
        let q = p.wheel_resolution_m / track;
        Self {
            gyro_noise_rad2_per_s: p.gyro_noise_dps_per_sqrt_hz.to_radians().powi(2),
            bias_walk_rad2_per_s3: p.gyro_bias_walk_dps_per_sqrt_s.to_radians().powi(2),
            wheel_noise_rad2_per_m: p.wheel_heading_noise_deg_per_sqrt_m.to_radians().powi(2),
            // Each wheel's reading is off by up to half a pulse, uniformly, at each end of
            // the comparison: 4 · q²/12 in the difference.
            wheel_quantisation_rad2: q * q / 3.0,
            compass_floor_var: c.compass.systematic_deg.to_radians().powi(2),
        }
    }
}

/// Gyro state between samples.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct GyroTrack {
    /// The gyro carries the heading (a reading has been seen and the method uses it).
    active: bool,
    /// The gyro's states come from a stored calibration rather than the priors.
    restored: bool,
    last_raw_rps: f64,
}

/// Rest detection and the bias average.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Rest {
    still_s: f64,
    sum_raw: f64,
    n: u32,
    span_s: f64,
}

/// How long the compass has been rejected, and how far the vehicle turned meanwhile.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Outage {
    rejected_s: f64,
    turned_rad: f64,
    last: Option<(f64, f64)>,
    /// The calibration in use was found wanting: a new one is being learned from readings
    /// the gates cannot judge.
    relearning: bool,
}

impl Outage {
    /// Counts one judged reading at time `t_s` and heading `psi`; returns whether the
    /// calibration in use should now be taken as wrong.
    fn count(&mut self, t_s: f64, psi: f64, used: bool) -> bool {
        if let (Some((t0, psi0)), false) = (self.last, used) {
            self.rejected_s += t_s - t0;
            self.turned_rad += wrap_pi(psi - psi0).abs();
        }
        self.last = Some((t_s, psi));
        if used {
            self.rejected_s = 0.0;
            self.turned_rad = 0.0;
        }
        if !self.relearning
            && self.rejected_s >= SUSPECT_AFTER_S
            && self.turned_rad >= SUSPECT_TURN_RAD
        {
            self.relearning = true;
            return true;
        }
        false
    }
}

/// Compass readings taken since the last heading correction, averaged into one.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CompassWindow {
    n: u32,
    sum_nu: f64,
    /// Σ over the readings of the heading's accumulated couplings `A_k` at each reading,
    /// counted from the start of the current batch.
    sum_psi_from: [f64; DIM],
    variance_rad2: f64,
}

impl Default for CompassWindow {
    fn default() -> Self {
        Self {
            n: 0,
            sum_nu: 0.0,
            sum_psi_from: [0.0; DIM],
            variance_rad2: 0.0,
        }
    }
}

/// Alignment: the first run of consistent compass readings.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Alignment {
    done: bool,
    /// The turn applied to heading and track when they were referred to north, rad.
    offset_rad: f64,
    line: InnovationLine,
}

/// The fused vehicle estimator. See the module documentation.
///
/// ```
/// use truenorth_core::HeadingEstimator;
/// use truenorth_fusion::{VehicleConfig, VehicleEstimator};
/// use truenorth_sim::{DriveSpec, SimulatedDrive};
///
/// let drive = SimulatedDrive::new(DriveSpec { length_m: 1500.0, ..DriveSpec::new(1) })?;
/// let mut nav = VehicleEstimator::new(VehicleConfig::default())?;
/// for s in &drive.samples {
///     nav.update(s)?;
/// }
/// let est = nav.estimate();
/// assert!(est.status.heading_absolute); // the opening turn calibrated the compass
/// let truth = drive.truth.last().unwrap();
/// let error_m = (est.north_m - truth.north_m).hypot(est.east_m - truth.east_m);
/// assert!(error_m < 0.02 * drive.distance_m());
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct VehicleEstimator {
    config: VehicleConfig,
    coeffs: Coefficients,
    initial: NavFilter,
    filter: NavFilter,
    wheels: WheelOdometry,
    compass: CompassMonitor,
    /// The compass calibration the estimator started with (restored), if any.
    initial_fix: Option<CompassFix>,
    learner: CompassLearner,
    clock: TimeStep,
    gyro: GyroTrack,
    rest: Rest,
    wheel_check_s: f64,
    alignment: Alignment,
    outage: Outage,
    batch: StepBatch,
    window: CompassWindow,
    /// Sine and cosine of the mid-step heading and of the predicted compass reading.
    trig: HeadingTrig,
    trig_compass: HeadingTrig,
    /// The last step length and the compass error's decay over it (an `exp` saved per
    /// sample when the rate is steady).
    decay_cache: (f64, f64),
    /// Readings up to this time are not offered to the compass learner (it has them
    /// already: the estimator is replaying them).
    learned_until_s: f64,
    est: NavEstimate,
}

/// Factor by which a restored calibration's sigmas are widened: between drives the sensors
/// drift, and a replay must not count the same readings' information twice.
const RESTORE_WIDEN: f64 = 2.0;

impl VehicleEstimator {
    /// An estimator that knows nothing yet beyond `config`'s priors.
    pub fn new(config: VehicleConfig) -> Result<Self> {
        config.validate()?;
        let p = &config.priors;
        let mut x = [0.0; DIM];
        x[SPEED_COEFF] = p.speed_coeff_s2_per_m2;
        let mut sigma = [0.0; DIM];
        sigma[WHEEL_DIFF] = p.wheel_diff_sigma;
        sigma[SPEED_COEFF] = p.speed_coeff_sigma;
        sigma[TRACK_SCALE] = p.wheel_track_sigma;
        let filter = NavFilter::new(x, sigma);
        Ok(Self {
            coeffs: Coefficients::new(&config),
            initial: filter,
            filter,
            wheels: WheelOdometry::new(config.wheels)?,
            compass: CompassMonitor::new(config.compass),
            initial_fix: None,
            learner: CompassLearner::new(config.compass)?,
            clock: TimeStep::new(),
            gyro: GyroTrack::default(),
            rest: Rest::default(),
            wheel_check_s: 0.0,
            alignment: Alignment::default(),
            outage: Outage::default(),
            batch: StepBatch::default(),
            window: CompassWindow::default(),
            trig: HeadingTrig::new(0.0),
            trig_compass: HeadingTrig::new(0.0),
            decay_cache: (f64::NAN, 1.0),
            learned_until_s: f64::NEG_INFINITY,
            est: NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY),
            config,
        })
    }

    /// An estimator that starts from what an earlier drive learned (see
    /// [`VehicleEstimator::calibration`]): the compass calibrated, the gyro and wheels
    /// with their learned errors (sigmas widened by 2, for drift since). A calibration
    /// with a non-finite value, a gain or scale beyond ±50 % or a singular soft iron is
    /// refused.
    pub fn with_calibration(
        config: VehicleConfig,
        calibration: &VehicleCalibration,
    ) -> Result<Self> {
        calibration.validate()?;
        let mut e = Self::new(config)?;
        calibration.to_filter(&mut e.filter, RESTORE_WIDEN);
        e.initial = e.filter;
        e.gyro.restored = calibration.gyro_bias_rps.sigma > 0.0;
        e.initial_fix = calibration.compass_fix();
        if let Some(fix) = e.initial_fix {
            e.compass.set_fix(fix);
        }
        Ok(e)
    }

    /// The turn applied to the heading and the track when they were referred to north
    /// (`None` before): estimates made before then are relative to the start heading and
    /// become absolute when turned by it.
    pub fn alignment_offset_rad(&self) -> Option<f64> {
        self.alignment.done.then_some(self.alignment.offset_rad)
    }

    /// What the estimator has learned about its sensors so far, to store and give back to
    /// [`VehicleEstimator::with_calibration`] at the next start.
    pub fn calibration(&self) -> VehicleCalibration {
        VehicleCalibration::from_filter(&self.filter, self.compass.fix())
    }

    /// A fresh start at the beginning of the samples this estimator has seen, knowing what
    /// it has learned: the two-pass start replays the head of a drive through it. The
    /// compass learner carries on from where this one is, and is not offered the readings
    /// again.
    pub(crate) fn replay_start(&self) -> Result<Self> {
        let mut e = Self::with_calibration(self.config, &self.calibration())?;
        e.learner = self.learner.clone();
        e.learned_until_s = self.est.t_s;
        Ok(e)
    }

    /// The configuration in use.
    pub fn config(&self) -> &VehicleConfig {
        &self.config
    }

    /// The filter's nominal state and covariance (indices in [`super::nav_filter`]).
    pub fn filter(&self) -> &NavFilter {
        &self.filter
    }

    /// The compass monitor (calibration in use and gates).
    pub fn compass(&self) -> &CompassMonitor {
        &self.compass
    }

    /// The compass calibrators.
    pub fn compass_learner(&self) -> &CompassLearner {
        &self.learner
    }

    /// The compass calibration in use, if any.
    pub fn compass_fix(&self) -> Option<&CompassFix> {
        self.compass.fix()
    }

    fn step(&mut self, sample: &VehicleSample, dt: f64) {
        let x = self.filter.x;
        let cal = WheelCalibration {
            diff: x[WHEEL_DIFF],
            speed_coeff: x[SPEED_COEFF],
            track_scale: x[TRACK_SCALE],
        };
        let Some(wheel) = self.wheels.step(sample.dist_l_m, sample.dist_r_m, dt, &cal) else {
            return;
        };
        self.rest.still_s = if wheel.moved {
            0.0
        } else {
            self.rest.still_s + dt
        };
        let at_rest = self.rest.still_s >= self.config.standstill_s && self.rest.still_s > 0.0;
        self.start_gyro(sample);
        let raw = sample.gyr_z_rps.unwrap_or(self.gyro.last_raw_rps);

        let dpsi = self.heading_change(&wheel, raw, dt, at_rest);
        let (s, co) = self.trig.at(x[PSI] + 0.5 * dpsi);
        let c = &self.coeffs;
        let mut step = Step {
            north_from_psi: -wheel.ds_m * s,
            east_from_psi: wheel.ds_m * co,
            ..Step::default()
        };
        let q = &mut step.q;
        q[NORTH] = POSITION_NOISE_M2_PER_M * wheel.ds_m.abs();
        q[EAST] = q[NORTH];
        let wheel_q = c.wheel_noise_rad2_per_m * wheel.ds_m.abs()
            + (WHEEL_TURN_NOISE * wheel.heading_change_rad).powi(2);
        let wheel_from = [
            (WHEEL_DIFF, wheel.d_heading_d_diff),
            (SPEED_COEFF, wheel.d_heading_d_speed_coeff),
            (TRACK_SCALE, wheel.d_heading_d_track_scale),
        ];
        if self.gyro.active {
            if !at_rest {
                let increment = 0.5 * (self.gyro.last_raw_rps + raw) * dt - x[BIAS] * dt;
                let gain_state = if increment >= 0.0 { GAIN_POS } else { GAIN_NEG };
                let gain = 1.0 + x[gain_state];
                step.psi_from[0] = (BIAS, -dt / gain);
                q[PSI] = c.gyro_noise_rad2_per_s * dt + (GYRO_GAIN_NOISE * dpsi).powi(2);
                let clear_turn = increment.abs()
                    > (GAIN_LEARNING_MIN_RATE_RPS + 3.0 * self.filter.sigma(BIAS)) * dt;
                if clear_turn {
                    step.psi_from[1] = (gain_state, -dpsi / gain);
                } else {
                    q[PSI] += (self.filter.sigma(gain_state) * dpsi).powi(2);
                }
            }
            step.odo_from = wheel_from;
            q[PSI_ODO] = wheel_q;
            q[BIAS] = c.bias_walk_rad2_per_s3 * dt;
            q[GAIN_POS] = GAIN_WALK * GAIN_WALK * dt;
            q[GAIN_NEG] = q[GAIN_POS];
            self.filter.x[PSI_ODO] += wheel.heading_change_rad;
        } else {
            step.psi_from = wheel_from;
            q[PSI] = wheel_q;
        }
        let decay = self.compass_decay(dt);
        step.compass_decay = decay;
        // A calibration's error depends on the heading: turning changes it by up to its
        // size per radian (the slope of a one-cycle error A·sin ψ is at most A).
        let cal_sigma = self.compass.fix().map_or(0.0, |f| f.calibration_sigma_rad);
        let q = &mut step.q;
        q[COMPASS_BIAS] =
            self.compass_bias_var() * (1.0 - decay * decay) + (cal_sigma * dpsi).powi(2);
        q[WHEEL_DIFF] = DIFF_WALK * DIFF_WALK * dt;
        q[SPEED_COEFF] = SPEED_COEFF_WALK * SPEED_COEFF_WALK * dt;
        q[TRACK_SCALE] = GAIN_WALK * GAIN_WALK * dt;
        self.filter.x[COMPASS_BIAS] *= decay;
        self.filter.x[NORTH] += wheel.ds_m * co;
        self.filter.x[EAST] += wheel.ds_m * s;
        // Heading kept in (−π, π]: differences of headings stay in range, and the wheels'
        // heading is wrapped with it so that their difference keeps its meaning.
        let wrapped = wrap_pi(self.filter.x[PSI] + dpsi);
        self.filter.x[PSI_ODO] += wrapped - (self.filter.x[PSI] + dpsi);
        self.filter.x[PSI] = wrapped;
        self.batch.add(&step);

        if self.gyro.active {
            self.rest_accumulate(at_rest, raw, dt);
            if !at_rest {
                self.wheel_check_s += dt;
            }
            self.gyro.last_raw_rps = raw;
        }
        self.est.speed_mps = wheel.speed_mps;
        self.est.distance_m += wheel.ds_m.abs();
        self.est.status.at_rest = at_rest;
    }

    /// Carries the covariance forward through the steps composed so far: before any
    /// measurement or change of the covariance.
    fn flush(&mut self) {
        // The window's readings are tied to the heading through the couplings accumulated
        // since the batch began; the next batch begins now, so refer them to now:
        // A_k − A_now for each reading.
        let n = f64::from(self.window.n);
        for (s, a) in self
            .window
            .sum_psi_from
            .iter_mut()
            .zip(self.batch.psi_from())
        {
            *s -= n * a;
        }
        self.batch.apply(&mut self.filter);
    }

    /// `exp(−dt/τ)` for the compass error, recomputed only when the step length changes.
    fn compass_decay(&mut self, dt: f64) -> f64 {
        if self.decay_cache.0 != dt {
            self.decay_cache = (dt, (-dt / self.config.compass.systematic_tau_s).exp());
        }
        self.decay_cache.1
    }

    /// The heading change of this step from the sensor that carries the heading.
    fn heading_change(
        &self,
        wheel: &super::wheel_odometry::WheelStep,
        raw: f64,
        dt: f64,
        at_rest: bool,
    ) -> f64 {
        if !self.gyro.active {
            return wheel.heading_change_rad;
        }
        if at_rest {
            return 0.0;
        }
        let x = &self.filter.x;
        let increment = 0.5 * (self.gyro.last_raw_rps + raw) * dt - x[BIAS] * dt;
        let gain = 1.0
            + if increment >= 0.0 {
                x[GAIN_POS]
            } else {
                x[GAIN_NEG]
            };
        increment / gain
    }

    /// Switches the heading to the gyro at its first reading:
    /// the wheels' heading starts equal to it, fully correlated.
    fn start_gyro(&mut self, sample: &VehicleSample) {
        let Some(raw) = sample.gyr_z_rps else {
            return;
        };
        if self.gyro.active {
            return;
        }
        self.gyro.active = true;
        self.gyro.last_raw_rps = raw;
        if !self.gyro.restored {
            let p = &self.config.priors;
            self.filter
                .reset_state(BIAS, p.gyro_bias_sigma_dps.to_radians());
            self.filter.reset_state(GAIN_POS, p.gyro_gain_sigma);
            self.filter.reset_state(GAIN_NEG, p.gyro_gain_sigma);
        }
        self.filter.x[PSI_ODO] = self.filter.x[PSI];
        for k in 0..DIM {
            self.filter.p[PSI_ODO][k] = self.filter.p[PSI][k];
            self.filter.p[k][PSI_ODO] = self.filter.p[k][PSI];
        }
        self.filter.p[PSI_ODO][PSI_ODO] = self.filter.p[PSI][PSI];
    }

    /// At rest the raw rate is the bias plus noise: averaged a second at a time, it
    /// measures the bias directly (EP 0640207 claims 8-9 do the same once, before the turn).
    fn rest_accumulate(&mut self, at_rest: bool, raw: f64, dt: f64) {
        if at_rest {
            self.rest.sum_raw += raw;
            self.rest.n += 1;
            self.rest.span_s += dt;
        } else {
            self.rest.sum_raw = 0.0;
            self.rest.n = 0;
            self.rest.span_s = 0.0;
        }
    }

    /// A measurement epoch: the covariance is carried forward once, then every measurement
    /// that is due corrects the state — the compass's averaged readings, the wheels'
    /// heading against the gyro's once a second of driving, the bias once a second of rest.
    fn epoch(&mut self) {
        self.flush();
        if self.rest.span_s >= REST_AVERAGE_S {
            let mean = self.rest.sum_raw / f64::from(self.rest.n);
            let r = self.coeffs.gyro_noise_rad2_per_s / self.rest.span_s
                + REST_NOISE_FLOOR_RPS * REST_NOISE_FLOOR_RPS;
            self.filter
                .update(&[(BIAS, 1.0)], mean - self.filter.x[BIAS], r);
            self.rest.sum_raw = 0.0;
            self.rest.n = 0;
            self.rest.span_s = 0.0;
        }
        if self.wheel_check_s >= WHEEL_CHECK_S {
            self.wheel_check_s = 0.0;
            self.wheels_against_gyro();
        }
        if self.window.n >= self.config.compass.readings_per_update {
            self.correct_with_compass();
        }
    }

    /// The wheels' heading minus the gyro's, measured against zero.
    fn wheels_against_gyro(&mut self) {
        let nu = wrap_pi(self.filter.x[PSI_ODO] - self.filter.x[PSI]);
        self.filter.update(
            &[(PSI, 1.0), (PSI_ODO, -1.0)],
            nu,
            self.coeffs.wheel_quantisation_rad2,
        );
    }

    fn compass_step(&mut self, sample: &VehicleSample) {
        self.est.status.compass_used = false;
        let Some(raw) = sample.mag else {
            return;
        };
        let reading = self.compass.measure(&raw);
        let judged = match reading {
            Some((u, ratio)) if self.alignment.done => {
                // Innovation: the angle from the predicted reading's direction to the
                // reading's, without an arctangent per reading when it is small.
                let f = &self.filter;
                let (sp, cp) = self.trig_compass.at(f.x[PSI] + f.x[COMPASS_BIAS]);
                let nu = small_atan2(-u.y * cp - u.x * sp, u.x * cp - u.y * sp);
                let drift = OUTAGE_DRIFT_RPS * self.outage.rejected_s;
                let p_nu = f.p[PSI][PSI]
                    + 2.0 * f.p[PSI][COMPASS_BIAS]
                    + f.p[COMPASS_BIAS][COMPASS_BIAS]
                    + self.batch.psi_noise()
                    + drift * drift;
                let verdict = self.compass.judge(sample.t_s, nu, ratio, p_nu);
                let used = matches!(verdict, Verdict::Use { .. });
                if let Verdict::Use { variance_rad2 } = verdict {
                    self.take_compass(nu, variance_rad2);
                }
                if self.outage.count(sample.t_s, self.filter.x[PSI], used) {
                    self.learner.relearn();
                }

                match (self.outage.relearning, used) {
                    (true, _) => Judged::Unjudged,
                    (false, true) => Judged::Gated,
                    (false, false) => Judged::Rejected,
                }
            }
            Some((u, ratio)) => {
                if self.compass.field_ok(ratio) {
                    self.align_step(sample.t_s, (-u.y).atan2(u.x));
                }
                Judged::Unjudged
            }
            None => Judged::Unjudged,
        };
        let learn = sample.t_s > self.learned_until_s;
        if let Some(s) = learn
            .then(|| {
                self.learner
                    .offer(&raw, sample.t_s, self.filter.x[PSI], judged)
            })
            .flatten()
        {
            self.compass.set_fix(CompassFix::from_solution(&s));
            self.outage = Outage::default();
            // A new calibration makes a new systematic error, and the averaged
            // innovations were taken against the old one.
            self.compass.restart_gates();
            self.flush();
            self.window = CompassWindow::default();
            self.filter.x[COMPASS_BIAS] = 0.0;
            self.filter
                .reset_state(COMPASS_BIAS, self.compass_bias_var().sqrt());
        }
        self.est.status.compass_calibrated = self.compass.fix().is_some();
        self.est.status.compass_disturbed = self.compass.disturbed();
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
        let w = &mut self.window;
        w.n += 1;
        w.sum_nu += nu;
        w.variance_rad2 = variance_rad2;
        for (s, a) in w.sum_psi_from.iter_mut().zip(self.batch.psi_from()) {
            *s += a;
        }
    }

    /// Corrects the heading with the window's readings, right after the covariance was
    /// carried forward to now (so `A_now = 0` and each reading's row is `−A_k` on the
    /// calibration states).
    fn correct_with_compass(&mut self) {
        let w = self.window;
        self.window = CompassWindow::default();
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
        self.filter
            .update(&h[..len], w.sum_nu / n, w.variance_rad2 / n);
        self.est.status.compass_used = true;
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
        let line = &mut self.alignment.line;
        line.push(t_s, wrap_pi(heading - self.filter.x[PSI]));
        if line.len() < self.config.compass.alignment_readings {
            return;
        }
        let fit = line.fit(fix.noise_rad);
        *line = InnovationLine::default();
        match fit {
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
        self.alignment.offset_rad = offset;
        self.flush();
        self.window = CompassWindow::default();
        let bias_var = self.compass_bias_var();
        let f = &mut self.filter;
        let turned = wrap_pi(f.x[PSI] + offset);
        f.x[PSI_ODO] += turned - f.x[PSI];
        f.x[PSI] = turned;
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
        if self.gyro.active {
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
        g[PSI_ODO] = if self.gyro.active { 1.0 } else { 0.0 };
        g[NORTH] = -f.x[EAST];
        g[EAST] = f.x[NORTH];
        f.add_common_error(&g, sigma);
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
        self.alignment.done = true;
        self.compass.restart_gates();
    }

    /// Stationary variance of the compass's systematic error: the road's floor plus what
    /// the calibration in use leaves, rad².
    fn compass_bias_var(&self) -> f64 {
        let cal = self.compass.fix().map_or(0.0, |f| f.calibration_sigma_rad);
        self.coeffs.compass_floor_var + cal * cal
    }

    fn publish(&mut self, t_s: f64) -> NavEstimate {
        let f = &self.filter;
        let e = &mut self.est;
        e.t_s = t_s;
        e.north_m = f.x[NORTH];
        e.east_m = f.x[EAST];
        e.heading = MagneticHeading::new(wrap_pi(f.x[PSI]));
        e.heading_sigma_rad = if self.alignment.done {
            // The covariance is carried forward a few times a second; the noise since then
            // is added here, the calibration states' share waits for the next time.
            (f.p[PSI][PSI] + self.batch.psi_noise()).max(0.0).sqrt()
        } else {
            f64::INFINITY
        };
        let p = Vector2::new(f.x[NORTH], f.x[EAST]);
        let scale = self.config.priors.wheel_scale_sigma;
        e.position_cov_m2 = Matrix2::new(
            f.p[NORTH][NORTH],
            f.p[NORTH][EAST],
            f.p[EAST][NORTH],
            f.p[EAST][EAST],
        ) + scale * scale * p * p.transpose();
        e.status.heading_absolute = self.alignment.done;
        *e
    }
}

impl HeadingEstimator for VehicleEstimator {
    /// Takes one sample. A non-finite value or a timestamp that does not increase is a
    /// typed error and changes nothing; a missing gyro or compass reading (`None`) is
    /// allowed on any sample (the last gyro reading is held).
    fn update(&mut self, sample: &VehicleSample) -> Result<NavEstimate> {
        sample.validate()?;
        self.wheels.check_speed(sample, self.clock.last_s())?;
        match self.clock.dt_s(sample.t_s)? {
            None => {
                self.wheels.step(
                    sample.dist_l_m,
                    sample.dist_r_m,
                    1.0,
                    &WheelCalibration::default(),
                );
                self.start_gyro(sample);
            }
            Some(dt) => self.step(sample, dt),
        }
        self.compass_step(sample);
        if self.window.n >= self.config.compass.readings_per_update
            || self.batch.steps() >= MAX_BATCH_STEPS
        {
            self.epoch();
        }
        Ok(self.publish(sample.t_s))
    }

    fn estimate(&self) -> NavEstimate {
        self.est
    }

    fn reset(&mut self) {
        self.filter = self.initial;
        self.wheels.reset();
        self.compass = CompassMonitor::new(self.config.compass);
        if let Some(fix) = self.initial_fix {
            self.compass.set_fix(fix);
        }
        self.learner.reset();
        self.learned_until_s = f64::NEG_INFINITY;
        self.clock.reset();
        self.gyro = GyroTrack {
            restored: self.gyro.restored,
            ..GyroTrack::default()
        };
        self.rest = Rest::default();
        self.wheel_check_s = 0.0;
        self.alignment = Alignment::default();
        self.outage = Outage::default();
        self.batch = StepBatch::default();
        self.window = CompassWindow::default();
        self.est = NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY);
    }
}
