//! The vehicle heading and dead-reckoning estimator: gyro, wheels and compass in one
//! error-state Kalman filter that calibrates all three while the vehicle drives.
//!
//! Each sensor is taken when it reads, at its own rate; a row may carry any of them
//! ([`truenorth_core::VehicleSample`]):
//! 1. **Gyro** ([`super::dead_reckoning`]): the heading moves by the corrected rate
//!    `(ω − b)/(1 + s±)` integrated by the trapezoid rule between two readings, one gain
//!    per turning direction since cheap gyros differ. At rest (the wheels stand still) the
//!    heading is held and the raw rate measures the bias.
//! 2. **Wheels** ([`super::wheel_odometry`]): the rear-axle distance, drawn along the
//!    heading half-way between two wheel readings, and the wheels' own heading change
//!    under the current differential scale δ, speed coefficient `a` and track scale ε —
//!    integrated as a second heading that is compared with the gyro's once a second of
//!    driving. Their difference depends only on the calibration states — bias (∝ time),
//!    gains (∝ turn), δ (∝ distance), `a` (∝ turn × speed²), ε (∝ turn) — which is what
//!    separates them, as far as the motion allows ([`super::learning_gates`]). Without a
//!    gyro the wheels carry the heading.
//! 3. **Compass** ([`super::compass_fusion`]): calibrated online from the drive itself;
//!    once calibrated, a run of consistent readings refers the heading to magnetic north
//!    (the track so far is turned with it); after that, readings that pass the gates
//!    correct the heading, averaged a few at a time.
//! 4. **Time**: a sensor silent for longer than [`VehicleConfig::max_gap_s`] is not
//!    bridged by guesswork: the heading crosses the gap on the wheels (or is lost without
//!    them), the track's uncertainty grows with the distance covered, and the status says
//!    so.
//! 5. **Satellite fixes** ([`super::gnss_fusion`]): once they refer heading and track to
//!    true north and their plane, each corrects the position and, through its
//!    correlations, the heading and the learned errors; their speeds over ground measure
//!    the odometer's mean scale `k` ([`super::gnss_speed`]), which nothing else separates.
//!
//! Every learned state starts from its kind of vehicle's physical prior
//! ([`super::SensorPriors::for_wheels`]); the speed coefficient is kept non-negative.

use nalgebra::Matrix2;
use truenorth_core::{
    HeadingEstimator, MagneticHeading, NavEstimate, Result, TimeStep, Unobserved, Validate,
    VehicleSample, WheelReading, wrap_pi,
};

use super::compass_learning::CompassLearner;
use super::compass_monitor::{CompassFix, CompassMonitor};
use super::config::{SensorPriors, VehicleConfig};
use super::learned::VehicleCalibration;
use super::nav_filter::{
    BIAS, DIM, GAIN_NEG, GAIN_POS, NavFilter, PSI, SPEED_COEFF, TRACK_SCALE, WHEEL_DIFF, WHEEL_LAG,
    WHEEL_SCALE,
};
use super::observability::unobserved;
use super::tracking::{GyroTrack, VehicleTracking};
use super::wheel_odometry::{TrackModel, WheelOdometry};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Most rows taken before the covariance is carried forward (it is carried forward at
/// every measurement too): keeps the reported uncertainty fresh without a compass.
const MAX_BATCH_ROWS: u32 = 20;

/// Seconds between two refreshes of which states are not yet determined.
const UNOBSERVED_REFRESH_S: f64 = 1.0;

/// Standard deviation of a heading uniform on the circle, π/√3: the most a heading's
/// uncertainty can honestly be.
pub(super) const UNKNOWN_HEADING_SIGMA_RAD: f64 = 1.813_799_364_234_217_8;

/// Heading uncertainty beyond which its effect on the track is no longer linear, rad (30°).
const LINEAR_HEADING_SIGMA_RAD: f64 = 0.5;

/// Coefficients derived from the configuration once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Coefficients {
    /// The priors in use.
    pub priors: SensorPriors,
    pub gyro_noise_rad2_per_s: f64,
    pub bias_walk_rad2_per_s3: f64,
    pub wheel_noise_rad2_per_m: f64,
    /// Variance of the wheels' heading from the pulses at each end of a comparison, rad².
    pub wheel_quantisation_rad2: f64,
    /// Variance of the road's, the ground's and the installation's share of the compass's
    /// systematic error, rad² (the calibration's share comes with each calibration).
    pub compass_floor_var: f64,
    /// The prior standard deviation of each state (0 where the state is not learned).
    pub prior_sigma: [f64; DIM],
}

impl Coefficients {
    pub(super) fn new(c: &VehicleConfig) -> Self {
        let p = c.priors();
        let q = p.wheel_resolution_m / c.wheels.track_m();
        let mut prior_sigma = [0.0; DIM];
        prior_sigma[BIAS] = p.gyro_bias_sigma_dps.to_radians();
        prior_sigma[GAIN_POS] = p.gyro_gain_sigma;
        prior_sigma[GAIN_NEG] = p.gyro_gain_sigma;
        prior_sigma[WHEEL_DIFF] = p.wheel_diff_sigma;
        prior_sigma[SPEED_COEFF] = p.speed_coeff_sigma;
        prior_sigma[TRACK_SCALE] = p.wheel_track_sigma;
        prior_sigma[WHEEL_SCALE] = p.wheel_scale_sigma;
        prior_sigma[WHEEL_LAG] = p.wheel_lag_sigma_s;
        Self {
            priors: p,
            gyro_noise_rad2_per_s: p.gyro_noise_dps_per_sqrt_hz.to_radians().powi(2),
            bias_walk_rad2_per_s3: p.gyro_bias_walk_dps_per_sqrt_s.to_radians().powi(2),
            wheel_noise_rad2_per_m: p.wheel_heading_noise_deg_per_sqrt_m.to_radians().powi(2),
            // Each wheel's reading is off by up to half a pulse, uniformly, at each end of
            // the comparison: 4 · q²/12 in the difference.
            wheel_quantisation_rad2: q * q / 3.0,
            compass_floor_var: c.compass.systematic_deg.to_radians().powi(2)
                + p.compass_ground_tilt_deg.to_radians().powi(2),
            prior_sigma,
        }
    }

    /// The nominal state before anything is learned: the priors' values of the learned
    /// states, zero heading and track.
    pub(super) fn prior_x(&self) -> [f64; DIM] {
        let mut x = [0.0; DIM];
        x[SPEED_COEFF] = self.priors.speed_coeff_s2_per_m2;
        x[TRACK_SCALE] = self.priors.track_factor - 1.0;
        x[WHEEL_LAG] = self.priors.wheel_lag_s;
        x
    }
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
    pub(super) config: VehicleConfig,
    pub(super) coeffs: Coefficients,
    pub(super) initial: NavFilter,
    pub(super) filter: NavFilter,
    pub(super) wheels: WheelOdometry,
    pub(super) compass: CompassMonitor,
    /// The compass calibration the estimator started with (restored), if any.
    pub(super) initial_fix: Option<CompassFix>,
    pub(super) learner: CompassLearner,
    pub(super) clock: TimeStep,
    /// The bookkeeping between samples.
    pub(super) tracking: VehicleTracking,
    pub(super) est: NavEstimate,
}

impl VehicleEstimator {
    /// An estimator that knows nothing yet beyond `config`'s priors.
    pub fn new(config: VehicleConfig) -> Result<Self> {
        config.validate()?;
        let coeffs = Coefficients::new(&config);
        let x = coeffs.prior_x();
        let mut sigma = [0.0; DIM];
        for i in [WHEEL_DIFF, SPEED_COEFF, TRACK_SCALE, WHEEL_SCALE, WHEEL_LAG] {
            sigma[i] = coeffs.prior_sigma[i];
        }
        let filter = NavFilter::new(x, sigma);
        let mut est = NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), 0.0);
        est.position_cov_m2 = Matrix2::from_element(f64::INFINITY);
        Ok(Self {
            coeffs,
            initial: filter,
            filter,
            wheels: WheelOdometry::new(config.wheels, TrackModel::Exact)?,
            compass: CompassMonitor::new(config.compass)?,
            initial_fix: None,
            learner: CompassLearner::new(config.compass)?,
            clock: TimeStep::new(),
            tracking: VehicleTracking::start(),
            est,
            config,
        })
    }

    /// An estimator that starts from what an earlier drive learned (see
    /// [`VehicleEstimator::calibration`]): the compass calibrated, the gyro and wheels
    /// with their learned errors, each widened by what it may drift between drives and
    /// never beyond its prior ([`VehicleCalibration::to_filter`]). A calibration with a
    /// non-finite value, a gain or scale beyond its physical range or a singular soft iron
    /// is refused.
    pub fn with_calibration(
        config: VehicleConfig,
        calibration: &VehicleCalibration,
    ) -> Result<Self> {
        calibration.validate()?;
        let mut e = Self::new(config)?;
        calibration.to_filter(&mut e.filter, &e.coeffs.prior_sigma);
        e.initial = e.filter;
        e.tracking.gyro.restored = calibration.gyro_bias_rps.sigma > 0.0;
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
        self.tracking
            .alignment
            .done
            .then_some(self.tracking.alignment.offset_rad)
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
        e.tracking.learned_until_s = self.est.t_s;
        Ok(e)
    }

    /// How many times the fused estimate has fallen back to plain integration (the raw gyro
    /// less its last rest's bias, along the odometry) because it departed from it beyond both
    /// their uncertainties; see [`truenorth_core::NavStatus::fell_back`].
    pub fn fallbacks(&self) -> u32 {
        self.tracking.guard.fallbacks
    }

    /// Whether plain integration runs beside the fused estimate now, able to catch it: the
    /// gyro's bias has been measured at a rest and nothing since has moved the fused
    /// estimate by what plain integration cannot follow.
    pub fn plain_guard_active(&self) -> bool {
        self.tracking.guard.anchored
    }

    /// The configuration in use.
    pub fn config(&self) -> &VehicleConfig {
        &self.config
    }

    /// The priors in use (the configuration's, or its kind of vehicle's).
    pub fn priors(&self) -> &SensorPriors {
        &self.coeffs.priors
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

    /// The factor on the wheels' slip variance that their disagreement with the gyro has
    /// set (1: the wheels behave as their model says).
    pub fn wheel_distrust(&self) -> f64 {
        self.tracking.gates.slip_scale2
    }

    /// The mean square of the wheels' delay behind the motion as the filter knows it, s²: its
    /// learned value squared plus its variance — what it may be where it is not modelled.
    pub(super) fn wheel_delay_s2(&self) -> f64 {
        self.filter.x[WHEEL_LAG].powi(2) + self.filter.p[WHEEL_LAG][WHEEL_LAG].max(0.0)
    }

    /// The estimate at `t_s`: the heading carried on from the gyro's last reading and the
    /// track from the wheels' last reading at the speed they last showed, so that a row
    /// that carries only another sensor reports where the vehicle is at its own time.
    fn publish(&mut self, t_s: f64) -> NavEstimate {
        // A reading reaches its row some 50–150 ms after the motion it measures (a sensor's
        // filter, a bus, a logger): the heading at the row's time trails by the turn made
        // meanwhile, the rate times the delay, an error no heading state carries and that
        // vanishes when the turn ends. Where the wheels carry the heading their delay is a
        // state (its prior, with no gyro to learn it against): its mean and spread are
        // published as the heading's. A gyro's own delay is not known to anything here.
        let rate = self.tracking.motion.heading_rate_rps;
        let delay_s = if !self.tracking.gyro.active && self.tracking.motion.wheels_turn {
            (self.wheel_delay_s2() + ROW_JITTER_S.powi(2)).sqrt()
        } else {
            READING_DELAY_S
        };
        let trailing = delay_s * rate;
        let psi = self.heading_at(t_s);
        let declination = self.frame_declination_rad();
        let ahead_s = self
            .wheels
            .last_s()
            .map_or(0.0, |t0| (t_s - t0).clamp(0.0, self.config.max_gap_s));
        let travel = self.est.speed_mps * ahead_s;
        let f = &self.filter;
        let e = &mut self.est;
        e.t_s = t_s;
        e.north_m = f.x[super::nav_filter::NORTH] + travel * psi.cos();
        e.east_m = f.x[super::nav_filter::EAST] + travel * psi.sin();
        // Referred to the fixes the heading is true; the estimate's heading is magnetic.
        e.heading = MagneticHeading::new(wrap_pi(psi - declination));
        // The covariance is carried forward a few times a second; what the steps since
        // then added is composed here, and the delay's share (above) with the heading.
        let sigma = (self.tracking.batch.psi_variance(f).max(0.0) + trailing * trailing).sqrt();
        // A heading known to no better than the whole circle is uniform on it: π/√3.
        e.heading_sigma_rad = sigma.min(UNKNOWN_HEADING_SIGMA_RAD);
        e.position_cov_m2 = if e.status.position_known {
            let (n, ea) = (super::nav_filter::NORTH, super::nav_filter::EAST);
            // The wheels' last reading is off by up to a pulse (uniform: q²/12 per wheel,
            // half of it on their mean), and the track carried on to now at a speed that
            // may have changed by a tenth and that the last step's pulses gave to within
            // q²/12 over its interval squared (both ends quantised, two wheels averaged).
            let resolution = self.coeffs.priors.wheel_resolution_m;
            let speed_quantum = resolution / self.tracking.motion.wheel_interval_s.max(1e-3);
            let floor = resolution * resolution / 24.0
                + (0.1 * travel).powi(2)
                + (ahead_s * speed_quantum).powi(2) / 12.0;
            let cov = Matrix2::new(f.p[n][n], f.p[n][ea], f.p[ea][n], f.p[ea][ea])
                + Matrix2::identity() * floor;
            if sigma > LINEAR_HEADING_SIGMA_RAD {
                // The heading is too uncertain for its error to move the track along one
                // direction only: the error may lie in any direction, as far as the
                // linearised spread reaches along its longest axis.
                let (a, b, c) = (cov[(0, 0)], cov[(0, 1)], cov[(1, 1)]);
                let largest = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt();
                Matrix2::identity() * largest
            } else {
                cov
            }
        } else {
            Matrix2::from_element(f64::INFINITY)
        };
        e.status.heading_absolute = self.tracking.alignment.done;
        e.status.gnss_frame = self.tracking.gnss.aligned;
        let mut out = *e;
        if self.tracking.gnss.course_only {
            // A track not yet on the fixes' plane has no place in it.
            out.status.position_known = false;
            out.position_cov_m2 = Matrix2::from_element(f64::INFINITY);
        }
        out
    }

    /// The heading at `t_s`: the gyro's carried on at its last rate from its last reading
    /// (a turn at 30°/s moves it 3° in the 0.1 s between two readings of a 10 Hz gyro),
    /// or the heading as it stands when the wheels carry it.
    pub(super) fn heading_at(&self, t_s: f64) -> f64 {
        let psi = self.filter.x[PSI];
        match self.tracking.gyro.last {
            Some((t0, _)) if self.tracking.gyro.active && t_s - t0 <= self.gyro_bridge_s() => {
                psi + self.tracking.gyro.rate_rps * (t_s - t0)
            }
            _ => psi,
        }
    }

    /// The odometry of `sample` as the wheel path takes it, and whether it says how the
    /// vehicle turns: two wheels as they are once they have differed on any row; one
    /// distance (`dist_m`, a CAN vehicle speed integrated) as two equal wheels that say
    /// nothing of turning — read only while no row has carried two wheels, whose counters
    /// it would otherwise mix with. Two wheels equal on every row so far are one speed
    /// written twice, and carry no more.
    fn odometry_of(&self, sample: &VehicleSample) -> Option<(WheelReading, bool)> {
        let motion = &self.tracking.motion;
        match (sample.wheels, sample.dist_m) {
            (Some(w), _) => Some((w, motion.wheels_turn || w.dist_l_m != w.dist_r_m)),
            (None, Some(d)) if motion.single_distance || !self.est.status.position_known => Some((
                WheelReading {
                    dist_l_m: d,
                    dist_r_m: d,
                },
                false,
            )),
            _ => None,
        }
    }

    /// Keeps what the odometry has shown: the first time two wheels differ after the
    /// vehicle has moved, their heading starts from the gyro's, since over that distance
    /// they were not compared with it (equal wheels at a standstill were a true "no turn").
    fn note_odometry(&mut self, turns: bool, single: bool) {
        let first_row = !self.est.status.position_known;
        let motion = &mut self.tracking.motion;
        if first_row {
            motion.single_distance = single;
        }
        if turns && !motion.wheels_turn {
            motion.wheels_turn = true;
            motion.single_distance = false;
            if self.tracking.gyro.active && self.est.distance_m > 0.0 {
                self.restart_wheel_heading();
            }
        }
    }

    /// Refreshes which learned states the data have not yet separated (at each epoch: it
    /// reads the covariance, which only changes then).
    pub(super) fn refresh_unobserved(&mut self) {
        let u = unobserved(&self.filter, &self.coeffs.prior_sigma);
        self.est.status.unobserved = Unobserved {
            gyro_bias: self.tracking.gyro.active && u.gyro_bias,
            gyro_gain_right: self.tracking.gyro.active && u.gyro_gain_right,
            gyro_gain_left: self.tracking.gyro.active && u.gyro_gain_left,
            wheel_diff: self.tracking.motion.wheels_turn && u.wheel_diff,
            track_scale: self.tracking.motion.wheels_turn && u.track_scale,
            speed_coeff: self.tracking.motion.wheels_turn && u.speed_coeff,
            // Only fixes measure distance apart from the odometer itself.
            wheel_scale: self.tracking.gnss.used > 0 && u.wheel_scale,
            // Only a gyro's turns set the wheels' delay apart.
            wheel_lag: self.tracking.gyro.active && self.tracking.motion.wheels_turn && u.wheel_lag,
        };
    }
}

impl HeadingEstimator for VehicleEstimator {
    /// Takes one row: whatever readings it carries (wheels, gyro, compass, or any subset)
    /// are used at its time. A non-finite value, a timestamp that does not increase, a
    /// wheel counter that jumps, or a time base the motion contradicts (a gyro in °/s, a
    /// time in milliseconds) is a typed error and changes nothing.
    fn update(&mut self, sample: &VehicleSample) -> Result<NavEstimate> {
        sample.validate()?;
        self.tracking.gates.check_time_base()?;
        let odometry = self.odometry_of(sample);
        if let Some((w, _)) = &odometry {
            self.wheels.check_speed(sample.t_s, w)?;
        }
        let dt = self.clock.dt_s(sample.t_s)?;
        self.est.status.gap = false;
        self.est.status.fell_back = false;
        self.est.status.gnss_used = false;
        if let Some(dt) = dt {
            self.tracking.pending_time_s += dt;
        }
        if let Some(g) = sample.gyr_z_rps {
            self.gyro_reading(sample.t_s, g);
        }
        if let Some((w, turns)) = odometry {
            self.note_odometry(turns, sample.wheels.is_none());
            self.wheel_reading(sample.t_s, w, turns);
        }
        self.compass_step(sample);
        if let Some(fix) = &sample.gnss {
            self.gnss_step(sample.t_s, fix);
        }
        self.tracking.rows_since_epoch += 1;
        if self.tracking.window.n >= self.config.compass.readings_per_update
            || self.tracking.rows_since_epoch >= MAX_BATCH_ROWS
        {
            self.epoch();
            if sample.t_s - self.tracking.unobserved_at_s >= UNOBSERVED_REFRESH_S {
                self.tracking.unobserved_at_s = sample.t_s;
                self.refresh_unobserved();
            }
        }
        Ok(self.publish(sample.t_s))
    }

    fn estimate(&self) -> NavEstimate {
        self.est
    }

    fn reset(&mut self) {
        self.filter = self.initial;
        self.wheels.reset();
        self.compass.reset();
        if let Some(fix) = self.initial_fix {
            self.compass.set_fix(fix);
        }
        self.learner.reset();
        self.clock.reset();
        let t = &self.tracking;
        self.tracking = VehicleTracking {
            gyro: GyroTrack {
                restored: t.gyro.restored,
                ..GyroTrack::default()
            },
            // The sine-cosine caches are not learned state: they carry on from the angle
            // they were last asked for.
            trig: t.trig,
            trig_compass: t.trig_compass,
            ..VehicleTracking::start()
        };
        let mut est = NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), 0.0);
        est.position_cov_m2 = Matrix2::from_element(f64::INFINITY);
        self.est = est;
    }
}

/// How far a reading's row trails the motion it measures, s (0.1): sensors on their own
/// rows and clocks reach a log 50–150 ms after the motion (the simulator's real-log habit,
/// `truenorth_sim::log_drive`, draws the same).
const READING_DELAY_S: f64 = 0.1;

/// How much a reading's delay varies from one row to the next around its mean, s (0.02):
/// a logger's jitter.
pub(super) const ROW_JITTER_S: f64 = 0.02;
