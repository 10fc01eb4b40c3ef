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
    check_finite, wrap_pi,
};

use super::compass_monitor::{CompassFix, CompassMonitor, Verdict};
use super::config::{VehicleConfig, VehicleMethod};
use super::nav_filter::{
    BIAS, Coupling, DIM, EAST, GAIN_NEG, GAIN_POS, NORTH, NavFilter, PSI, PSI_ODO, SPEED_COEFF,
    WHEEL_DIFF,
};
use super::wheel_odometry::WheelOdometry;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Seconds of motion between two comparisons of the wheels' heading with the gyro's.
const WHEEL_CHECK_S: f64 = 1.0;

/// Seconds of rest averaged into one bias measurement.
const REST_AVERAGE_S: f64 = 1.0;

/// Gyro gain error not captured by the two gains (non-linearity), per radian turned.
const GYRO_GAIN_NOISE: f64 = 1e-3;

/// Wheel heading error not captured by δ and `a` (tyre deflection in a turn), per radian.
const WHEEL_TURN_NOISE: f64 = 5e-3;

/// Random walk of the calibration states, per √s: they may drift a little (tyre pressure,
/// temperature), so the filter never stops listening.
const GAIN_WALK: f64 = 1e-5;
const DIFF_WALK: f64 = 2e-7;
const SPEED_COEFF_WALK: f64 = 1e-8;

/// Position noise per metre travelled, m²/m (lateral creep, bumps).
const POSITION_NOISE_M2_PER_M: f64 = 1e-6;

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
        }
    }
}

/// Gyro state between samples.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct GyroTrack {
    /// The gyro carries the heading (a reading has been seen and the method uses it).
    active: bool,
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

/// Alignment: the first run of consistent compass readings.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Alignment {
    done: bool,
    sin_sum: f64,
    cos_sum: f64,
    n: u32,
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
    initial_fix: Option<CompassFix>,
    clock: TimeStep,
    gyro: GyroTrack,
    rest: Rest,
    wheel_check_s: f64,
    alignment: Alignment,
    est: NavEstimate,
}

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
        let filter = NavFilter::new(x, sigma);
        Ok(Self {
            coeffs: Coefficients::new(&config),
            initial: filter,
            filter,
            wheels: WheelOdometry::new(config.wheels)?,
            compass: CompassMonitor::new(config.compass)?,
            initial_fix: None,
            clock: TimeStep::new(),
            gyro: GyroTrack::default(),
            rest: Rest::default(),
            wheel_check_s: 0.0,
            alignment: Alignment::default(),
            est: NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY),
            config,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &VehicleConfig {
        &self.config
    }

    /// The filter's nominal state and covariance (indices in [`super::nav_filter`]).
    pub fn filter(&self) -> &NavFilter {
        &self.filter
    }

    /// The compass calibration in use, if any.
    pub fn compass_fix(&self) -> Option<&CompassFix> {
        self.compass.fix()
    }

    fn check(sample: &VehicleSample) -> Result<()> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite("dist_l_m", sample.dist_l_m)?;
        check_finite("dist_r_m", sample.dist_r_m)?;
        if let Some(g) = sample.gyr_z_rps {
            check_finite("gyr_z", g)?;
        }
        if let Some(m) = sample.mag {
            check_finite("mag_x", m.x)?;
            check_finite("mag_y", m.y)?;
        }
        Ok(())
    }

    fn step(&mut self, sample: &VehicleSample, dt: f64) {
        let x = self.filter.x;
        let Some(wheel) = self.wheels.step(
            sample.dist_l_m,
            sample.dist_r_m,
            dt,
            x[WHEEL_DIFF],
            x[SPEED_COEFF],
        ) else {
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

        let mut couplings: [Coupling; 6] = [(0, 0, 0.0); 6];
        let mut q = [0.0; DIM];
        let c = &self.coeffs;
        let dpsi = self.heading_change(&wheel, raw, dt, at_rest);
        // Position first: it is coupled from the heading, whose own couplings follow.
        let (s, co) = (x[PSI] + 0.5 * dpsi).sin_cos();
        couplings[0] = (NORTH, PSI, -wheel.ds_m * s);
        couplings[1] = (EAST, PSI, wheel.ds_m * co);
        q[NORTH] = POSITION_NOISE_M2_PER_M * wheel.ds_m.abs();
        q[EAST] = q[NORTH];
        let wheel_q = c.wheel_noise_rad2_per_m * wheel.ds_m.abs()
            + (WHEEL_TURN_NOISE * wheel.heading_change_rad).powi(2);
        if self.gyro.active {
            if !at_rest {
                let increment = 0.5 * (self.gyro.last_raw_rps + raw) * dt - x[BIAS] * dt;
                let gain_state = if increment >= 0.0 { GAIN_POS } else { GAIN_NEG };
                let gain = 1.0 + x[gain_state];
                couplings[2] = (PSI, BIAS, -dt / gain);
                couplings[3] = (PSI, gain_state, -dpsi / gain);
                q[PSI] = c.gyro_noise_rad2_per_s * dt + (GYRO_GAIN_NOISE * dpsi).powi(2);
            }
            couplings[4] = (PSI_ODO, WHEEL_DIFF, wheel.d_heading_d_diff);
            couplings[5] = (PSI_ODO, SPEED_COEFF, wheel.d_heading_d_speed_coeff);
            q[PSI_ODO] = wheel_q;
            q[BIAS] = c.bias_walk_rad2_per_s3 * dt;
            q[GAIN_POS] = GAIN_WALK * GAIN_WALK * dt;
            q[GAIN_NEG] = q[GAIN_POS];
            self.filter.x[PSI_ODO] += wheel.heading_change_rad;
        } else {
            couplings[2] = (PSI, WHEEL_DIFF, wheel.d_heading_d_diff);
            couplings[3] = (PSI, SPEED_COEFF, wheel.d_heading_d_speed_coeff);
            q[PSI] = wheel_q;
        }
        if self.learns_wheels() {
            q[WHEEL_DIFF] = DIFF_WALK * DIFF_WALK * dt;
            q[SPEED_COEFF] = SPEED_COEFF_WALK * SPEED_COEFF_WALK * dt;
        }
        self.filter.x[NORTH] += wheel.ds_m * co;
        self.filter.x[EAST] += wheel.ds_m * s;
        self.filter.x[PSI] += dpsi;
        self.filter.predict(&couplings, &q);

        if self.gyro.active {
            self.rest_update(at_rest, raw, dt);
            if !at_rest {
                self.wheel_check_s += dt;
                if self.wheel_check_s >= WHEEL_CHECK_S {
                    self.wheel_check_s = 0.0;
                    self.wheels_against_gyro();
                }
            }
            self.gyro.last_raw_rps = raw;
        }
        self.est.speed_mps = wheel.speed_mps;
        self.est.distance_m += wheel.ds_m.abs();
        self.est.status.at_rest = at_rest;
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

    fn learns_wheels(&self) -> bool {
        matches!(self.config.method, VehicleMethod::Fused)
    }

    /// Switches the heading to the gyro at its first reading (when the method uses one):
    /// the wheels' heading starts equal to it, fully correlated.
    fn start_gyro(&mut self, sample: &VehicleSample) {
        let Some(raw) = sample.gyr_z_rps else {
            return;
        };
        if self.gyro.active || !self.config.method.uses_gyro() {
            return;
        }
        self.gyro = GyroTrack {
            active: true,
            last_raw_rps: raw,
        };
        let p = &self.config.priors;
        self.filter
            .reset_state(BIAS, p.gyro_bias_sigma_dps.to_radians());
        self.filter.reset_state(GAIN_POS, p.gyro_gain_sigma);
        self.filter.reset_state(GAIN_NEG, p.gyro_gain_sigma);
        self.filter.x[PSI_ODO] = self.filter.x[PSI];
        for k in 0..DIM {
            self.filter.p[PSI_ODO][k] = self.filter.p[PSI][k];
            self.filter.p[k][PSI_ODO] = self.filter.p[k][PSI];
        }
        self.filter.p[PSI_ODO][PSI_ODO] = self.filter.p[PSI][PSI];
    }

    /// At rest the raw rate is the bias plus noise: averaged a second at a time, it
    /// measures the bias directly (EP 0640207 claims 8-9 do the same once, before the turn).
    fn rest_update(&mut self, at_rest: bool, raw: f64, dt: f64) {
        if !at_rest {
            self.rest.sum_raw = 0.0;
            self.rest.n = 0;
            self.rest.span_s = 0.0;
            return;
        }
        self.rest.sum_raw += raw;
        self.rest.n += 1;
        self.rest.span_s += dt;
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
    }

    /// The wheels' heading minus the gyro's, measured against zero.
    fn wheels_against_gyro(&mut self) {
        if !self.learns_wheels() {
            return;
        }
        let nu = self.filter.x[PSI_ODO] - self.filter.x[PSI];
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
        let trusted = match reading {
            Some((heading, ratio)) if self.alignment.done => {
                let nu = wrap_pi(heading - self.filter.x[PSI]);
                let verdict = self
                    .compass
                    .judge(sample.t_s, nu, ratio, self.filter.p[PSI][PSI]);
                if let Verdict::Correct {
                    innovation_rad,
                    variance_rad2,
                } = verdict
                {
                    // The average of the innovations was taken against headings that the
                    // filter has since moved on from by no more than its own updates.
                    self.filter
                        .update(&[(PSI, 1.0)], innovation_rad, variance_rad2);
                    self.est.status.compass_used = true;
                }
                matches!(verdict, Verdict::Taken | Verdict::Correct { .. })
            }
            Some((heading, ratio)) => {
                if self.compass.field_ok(ratio) {
                    self.align_step(heading);
                }
                true
            }
            None => true,
        };
        if trusted {
            self.compass.offer(&raw, sample.t_s, self.filter.x[PSI]);
        }
        self.est.status.compass_calibrated = self.compass.fix().is_some();
        self.est.status.compass_disturbed = self.compass.disturbed();
    }

    /// Gathers consistent readings and, once there are enough, refers the heading to north.
    fn align_step(&mut self, heading: f64) {
        let Some(fix) = self.compass.fix().copied() else {
            return;
        };
        let nu = wrap_pi(heading - self.filter.x[PSI]);
        let a = &mut self.alignment;
        a.sin_sum += nu.sin();
        a.cos_sum += nu.cos();
        a.n += 1;
        if a.n < self.config.compass.alignment_readings {
            return;
        }
        let n = f64::from(a.n);
        let resultant = (a.sin_sum.hypot(a.cos_sum) / n).min(1.0);
        let spread = (-2.0 * resultant.ln()).sqrt();
        let floor = self.config.compass.systematic_floor_deg.to_radians();
        let offset = a.sin_sum.atan2(a.cos_sum);
        *a = Alignment::default();
        if spread > 3.0 * (fix.noise_rad + floor) {
            // Not consistent (a disturbance, or the calibration is off): gather again.
            return;
        }
        self.align(
            offset,
            (fix.noise_rad * fix.noise_rad / n + floor * floor).sqrt(),
        );
    }

    /// Refers the heading to north: turns heading, wheel heading and track by `offset`,
    /// measured with standard deviation `sigma`.
    ///
    /// The offset is a measurement of the start heading, which was unknown (infinite
    /// variance): conditioning on it leaves the heading with the measurement's error alone,
    /// uncorrelated with the calibration states, and the track turned about the start by the
    /// same error. The wheels' heading keeps its difference from the gyro's.
    fn align(&mut self, offset: f64, sigma: f64) {
        let f = &mut self.filter;
        f.x[PSI] += offset;
        f.x[PSI_ODO] += offset;
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
        self.alignment.done = true;
        self.compass.restart_gates();
    }

    fn publish(&mut self, t_s: f64) -> NavEstimate {
        let f = &self.filter;
        let e = &mut self.est;
        e.t_s = t_s;
        e.north_m = f.x[NORTH];
        e.east_m = f.x[EAST];
        e.heading = MagneticHeading::new(wrap_pi(f.x[PSI]));
        e.heading_sigma_rad = if self.alignment.done {
            f.sigma(PSI)
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
        Self::check(sample)?;
        match self.clock.dt_s(sample.t_s)? {
            None => {
                self.wheels
                    .step(sample.dist_l_m, sample.dist_r_m, 1.0, 0.0, 0.0);
                self.start_gyro(sample);
            }
            Some(dt) => self.step(sample, dt),
        }
        self.compass_step(sample);
        Ok(self.publish(sample.t_s))
    }

    fn estimate(&self) -> NavEstimate {
        self.est
    }

    fn reset(&mut self) {
        self.filter = self.initial;
        self.wheels.reset();
        self.compass.reset();
        self.compass = self.compass.clone().with_fix(self.initial_fix);
        self.clock.reset();
        self.gyro = GyroTrack::default();
        self.rest = Rest::default();
        self.wheel_check_s = 0.0;
        self.alignment = Alignment::default();
        self.est = NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY);
    }
}
