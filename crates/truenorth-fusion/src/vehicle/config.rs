//! The configuration of the [`crate::VehicleEstimator`]: the vehicle, the method, what the
//! sensors are believed to do before anything is learned, and the compass gates. Angles in
//! the serde form are degrees (they are edited by hand in files); everything else SI.

use serde::{Deserialize, Serialize};
use truenorth_calib::OnlineEllipseConfig;
use truenorth_core::{Result, Validate, check_positive, check_range};
use truenorth_odometer::OdometerWheels;

/// What the sensors are believed to do before anything is learned: the filter's prior and
/// process noise. Each learned state's prior is a physical range, not a tuning: it says what
/// a sensor of its kind does out of the box, so that data which cannot separate two states
/// leave each where physics puts it.
///
/// [`SensorPriors::for_wheels`] gives the defaults for a kind of vehicle; a
/// [`VehicleConfig`] without `priors` uses them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorPriors {
    /// Gyro white noise (angle random walk), °/s/√Hz (0.05: the noisier consumer MEMS
    /// yaw gyros; automotive parts are near 0.01).
    pub gyro_noise_dps_per_sqrt_hz: f64,
    /// Gyro bias random walk, °/s/√s (0.01): how fast the bias may wander with temperature.
    pub gyro_bias_walk_dps_per_sqrt_s: f64,
    /// Standard deviation of the gyro bias before it is measured, °/s (3: consumer MEMS
    /// gyros specify a zero-rate offset of up to ±5 °/s, a uniform spread of σ 2.9).
    pub gyro_bias_sigma_dps: f64,
    /// Standard deviation of each gyro gain error before it is learned (0.03: MEMS
    /// sensitivity tolerances of ±2–5 %).
    pub gyro_gain_sigma: f64,
    /// Standard deviation of the differential wheel scale δ before it is learned (0.01:
    /// tyres of one axle differ by tenths of a percent, ±2 % with a soft tyre).
    pub wheel_diff_sigma: f64,
    /// Standard deviation of the odometer's mean scale error before it is learned (0.003 for
    /// a car's ABS odometer, whose tyres' rolling radius is known to a few tenths of a
    /// percent; 0.012 for a robot's wheels). Only satellite fixes measure it; without them
    /// it makes the along-track uncertainty.
    pub wheel_scale_sigma: f64,
    /// The wheels' effective track over the physical one before it is learned (1 for
    /// rolling wheels; 1.9 for a skid-steer, whose sides slide in a turn).
    pub track_factor: f64,
    /// Standard deviation of the relative error ε of the wheels' effective track before it
    /// is learned (0.02 for rolling wheels, whose contact patches sit within a few cm of
    /// the nominal track; 0.3 for a skid-steer, whose factor lies between 1.5 and 2.5).
    pub wheel_track_sigma: f64,
    /// How far the wheels' readings trail the gyro's before it is learned, s (0.1), and the
    /// spread of that, s (0.1): sensors on their own rows reach a log 50–150 ms apart, and
    /// wheel speeds come through a controller's filter of 20–100 ms (a car's ABS unit) to
    /// 50–300 ms (a robot's motor controller).
    pub wheel_lag_s: f64,
    /// See [`SensorPriors::wheel_lag_s`].
    pub wheel_lag_sigma_s: f64,
    /// The quantum of the wheel speeds the wheel distances were integrated from, m/s (0:
    /// the wheels are read as distances, from counters). A controller sends speeds rounded
    /// (a car's CAN 0.01 km/h, a robot's motor controller 1 mm/s); while the speeds hold
    /// steady each wheel's rounding error holds too, and the heading drifts.
    #[serde(default)]
    pub wheel_speed_quantum_mps: f64,
    /// Initial speed coefficient `a`, s²/m² (1e-4 for a car; 0 for a robot, which never
    /// goes fast enough for it to show).
    pub speed_coeff_s2_per_m2: f64,
    /// Standard deviation of `a` before it is learned, s²/m² (1e-4: the range 0–3·10⁻⁴
    /// that lateral load transfer gives road cars; 0 where it is not learned). `a` is
    /// never negative: a wheel pair's difference only grows with speed.
    pub speed_coeff_sigma: f64,
    /// Heading noise of the wheels per square-root metre travelled, °/√m (0.01): bumps and
    /// the quantisation of short steps.
    pub wheel_heading_noise_deg_per_sqrt_m: f64,
    /// Standard deviation of the relative error of the wheels' turn that slip leaves at
    /// no lateral acceleration (0.003 for a car; 0.1 for a skid-steer, whose effective
    /// track changes with the ground; 0.015 for a differential-drive robot).
    pub wheel_slip: f64,
    /// Its growth per g of lateral acceleration (0.02 for a car: what load transfer does to
    /// the rolling radii beyond the `aV²` law, which varies with the road and the tyres;
    /// 0 for a robot).
    pub wheel_slip_per_g: f64,
    /// Its growth with the square of the turn ratio c = ΔD/D of steered front wheels
    /// (0.2: the effective track's sensitivity to the steering geometry grows as (Bκ)²,
    /// about 3c², and a described Pitman ratio or wheelbase is rarely better than a few
    /// percent; 0 for unsteered wheels).
    pub wheel_slip_per_c2: f64,
    /// Resolution of the wheel distances, m (0.02: ABS pulses; a few mm for integrated CAN
    /// wheel speeds, a fraction of a mm for a robot's encoders). Sets the noise of the
    /// wheels' heading against the gyro's.
    pub wheel_resolution_m: f64,
    /// Standard deviation of the heading error the ground's tilt adds to a level two-axis
    /// compass beyond [`CompassGates::systematic_deg`], degrees (6 for a robot; 0 for a
    /// car, whose road that already covers). A robot crosses kerbs, lawns and ramps: its
    /// body follows a grade of σ 1–4 % that changes within tens of metres, and the field's
    /// vertical part leaks into a level compass by tan(dip) times the tilt — at a dip of
    /// 70° (tan 2.75) and a tilt of 2.3° (4 %), 6°.
    #[serde(default)]
    pub compass_ground_tilt_deg: f64,
    /// Distance over which the compass's systematic error changes as the ground under the
    /// vehicle does, m (30 for a robot, whose ground's tilt changes over 10–50 m; 0: only
    /// with time and turning, as [`CompassGates`] says — a road's grade changes slowly
    /// enough for that).
    #[serde(default)]
    pub compass_ground_length_m: f64,
}

impl Default for SensorPriors {
    /// A car on its rear wheels.
    fn default() -> Self {
        Self::for_wheels(&OdometerWheels::Rear { track_m: 1.55 })
    }
}

impl SensorPriors {
    /// The priors of the kind of vehicle `wheels` describes.
    pub fn for_wheels(wheels: &OdometerWheels) -> Self {
        let car = Self {
            gyro_noise_dps_per_sqrt_hz: 0.05,
            gyro_bias_walk_dps_per_sqrt_s: 0.01,
            gyro_bias_sigma_dps: 3.0,
            gyro_gain_sigma: 0.03,
            wheel_diff_sigma: 0.01,
            wheel_scale_sigma: 0.003,
            track_factor: 1.0,
            wheel_track_sigma: 0.02,
            wheel_lag_s: 0.1,
            wheel_lag_sigma_s: 0.1,
            wheel_speed_quantum_mps: 0.0,
            speed_coeff_s2_per_m2: 1e-4,
            speed_coeff_sigma: 1e-4,
            wheel_heading_noise_deg_per_sqrt_m: 0.01,
            wheel_slip: 0.003,
            wheel_slip_per_g: 0.02,
            wheel_slip_per_c2: 0.0,
            wheel_resolution_m: 0.02,
            compass_ground_tilt_deg: 0.0,
            compass_ground_length_m: 0.0,
        };
        let robot = Self {
            wheel_scale_sigma: 0.012,
            speed_coeff_s2_per_m2: 0.0,
            speed_coeff_sigma: 0.0,
            wheel_slip_per_g: 0.0,
            wheel_resolution_m: 1e-3,
            compass_ground_tilt_deg: 6.0,
            compass_ground_length_m: 30.0,
            ..car
        };
        match wheels {
            OdometerWheels::Rear { .. } => car,
            OdometerWheels::Front(_) => Self {
                wheel_slip_per_c2: 0.2,
                ..car
            },
            OdometerWheels::SkidSteer { .. } => Self {
                track_factor: 1.9,
                wheel_track_sigma: 0.3,
                wheel_slip: 0.1,
                ..robot
            },
            OdometerWheels::Differential { .. } => Self {
                wheel_slip: 0.015,
                ..robot
            },
        }
    }
}

impl SensorPriors {
    /// The priors of the kind of vehicle `wheels` describes when its wheels are read as
    /// speeds from a controller and integrated: sent in quanta (0.01 km/h, the commonest
    /// scaling of a car's CAN wheel-speed signal; the mm/s of a robot's motor controller)
    /// and delayed by the controller's speed filter besides the bus (a car's ABS unit filters
    /// over 20–100 ms, a robot's motor controller over 50–300 ms; with the rows' 50–150 ms:
    /// 0.15 ± 0.1 s and 0.25 ± 0.12 s).
    pub fn for_wheel_speeds(wheels: &OdometerWheels) -> Self {
        let robot = wheels.can_pivot();
        Self {
            wheel_speed_quantum_mps: if robot { 0.001 } else { 0.01 / 3.6 },
            wheel_lag_s: if robot { 0.25 } else { 0.15 },
            wheel_lag_sigma_s: if robot { 0.12 } else { 0.1 },
            ..Self::for_wheels(wheels)
        }
    }
}

impl Validate for SensorPriors {
    fn validate(&self) -> Result<()> {
        check_positive(
            "gyro_noise_dps_per_sqrt_hz",
            self.gyro_noise_dps_per_sqrt_hz,
        )?;
        check_positive(
            "gyro_bias_walk_dps_per_sqrt_s",
            self.gyro_bias_walk_dps_per_sqrt_s,
        )?;
        check_range("gyro_bias_sigma_dps", self.gyro_bias_sigma_dps, 1e-6, 100.0)?;
        check_range("gyro_gain_sigma", self.gyro_gain_sigma, 1e-9, 0.5)?;
        check_range("wheel_diff_sigma", self.wheel_diff_sigma, 1e-9, 0.2)?;
        check_range("wheel_scale_sigma", self.wheel_scale_sigma, 0.0, 0.5)?;
        check_range("track_factor", self.track_factor, 0.5, 5.0)?;
        check_range("wheel_track_sigma", self.wheel_track_sigma, 1e-9, 2.0)?;
        check_range("wheel_lag_s", self.wheel_lag_s, 0.0, 2.0)?;
        check_range("wheel_lag_sigma_s", self.wheel_lag_sigma_s, 0.0, 2.0)?;
        check_range(
            "wheel_speed_quantum_mps",
            self.wheel_speed_quantum_mps,
            0.0,
            1.0,
        )?;
        check_range(
            "speed_coeff_s2_per_m2",
            self.speed_coeff_s2_per_m2,
            0.0,
            1e-2,
        )?;
        check_range("speed_coeff_sigma", self.speed_coeff_sigma, 0.0, 1e-2)?;
        check_positive(
            "wheel_heading_noise_deg_per_sqrt_m",
            self.wheel_heading_noise_deg_per_sqrt_m,
        )?;
        check_range("wheel_slip", self.wheel_slip, 0.0, 1.0)?;
        check_range("wheel_slip_per_g", self.wheel_slip_per_g, 0.0, 1.0)?;
        check_range(
            "compass_ground_tilt_deg",
            self.compass_ground_tilt_deg,
            0.0,
            45.0,
        )?;
        check_range(
            "compass_ground_length_m",
            self.compass_ground_length_m,
            0.0,
            1e5,
        )?;
        check_range("wheel_slip_per_c2", self.wheel_slip_per_c2, 0.0, 10.0)?;
        check_range("wheel_resolution_m", self.wheel_resolution_m, 1e-6, 1.0)?;
        Ok(())
    }
}

/// How compass readings are calibrated, judged and used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompassGates {
    /// The online least-squares calibrators the compass learns its hard and soft iron with
    /// (defaults as [`OnlineEllipseConfig`], but refreshed every 64 readings taken: a
    /// vehicle's calibration changes slowly, and a refresh costs as much as a few hundred
    /// samples' filtering).
    pub calibrator: OnlineEllipseConfig,
    /// A reading goes to the calibrator once the heading has moved this far since the last
    /// one it took, degrees (2): even coverage, and a small per-sample cost on straights.
    pub calibrator_spacing_deg: f64,
    /// …or once this long has passed, s (10).
    pub calibrator_interval_s: f64,
    /// Largest relative departure of the calibrated field magnitude from the fitted one
    /// before a reading is taken as disturbed (0.1).
    pub field_tolerance: f64,
    /// A reading whose innovation exceeds this many standard deviations is rejected (3.5).
    pub innovation_gate_sigma: f64,
    /// Time constant of the averaged innovation that catches slow disturbances, s (1.5):
    /// longer averages less noise but lags a drifting field by more.
    pub slow_gate_tau_s: f64,
    /// The compass counts as disturbed while the averaged innovation exceeds this many of
    /// its standard deviations (3).
    pub slow_gate_sigma: f64,
    /// Standard deviation of the heading error that the installation and the road (a
    /// compass mounted a little askew, grade and camber tilting it) leave in every reading
    /// alike, degrees (3): the filter carries it, with the calibration's own error, as a
    /// state, so that it is not averaged away as if it were noise. A level two-axis compass
    /// tilted by θ reads the heading wrong by up to tan(dip)·θ, since the field's vertical
    /// part leaks into the horizontal axes: a road's grade and camber of 1–3 % (0.6–1.7°)
    /// at a dip of 50–75° (most of the inhabited world) make 1–6°, and a car's roll in a
    /// bend adds as much; 3° is one standard deviation of that spread. A robot's rougher
    /// ground adds [`SensorPriors::compass_ground_tilt_deg`].
    pub systematic_deg: f64,
    /// Correlation time of that error while driving straight, s (300): a road's grade and
    /// camber last for hundreds of metres, and the calibration's error does not change at
    /// all while the heading holds.
    pub systematic_tau_s: f64,
    /// Turn over which the compass error changes, rad (0.7): what a calibration leaves is
    /// a function of the heading, one and two cycles per turn (a residual hard iron, a
    /// residual soft iron), which decorrelates over a radian or less of turning.
    pub systematic_turn_rad: f64,
    /// Readings averaged into one heading correction (5): the covariance is carried
    /// forward once per correction rather than at every sample.
    pub readings_per_update: u32,
    /// Readings that must agree before the heading is first referred to north (20).
    pub alignment_readings: u32,
}

impl Default for CompassGates {
    fn default() -> Self {
        Self {
            calibrator: OnlineEllipseConfig {
                refresh_interval_samples: 64,
                ..OnlineEllipseConfig::default()
            },
            calibrator_spacing_deg: 2.0,
            calibrator_interval_s: 10.0,
            field_tolerance: 0.1,
            innovation_gate_sigma: 3.5,
            slow_gate_tau_s: 1.5,
            slow_gate_sigma: 3.0,
            systematic_deg: 3.0,
            systematic_tau_s: 300.0,
            systematic_turn_rad: 0.7,
            readings_per_update: 10,
            alignment_readings: 20,
        }
    }
}

impl Validate for CompassGates {
    fn validate(&self) -> Result<()> {
        self.calibrator.validate()?;
        check_range(
            "calibrator_spacing_deg",
            self.calibrator_spacing_deg,
            0.0,
            90.0,
        )?;
        check_positive("calibrator_interval_s", self.calibrator_interval_s)?;
        check_range("field_tolerance", self.field_tolerance, 1e-3, 1.0)?;
        check_range(
            "innovation_gate_sigma",
            self.innovation_gate_sigma,
            1.0,
            100.0,
        )?;
        check_positive("slow_gate_tau_s", self.slow_gate_tau_s)?;
        check_range("slow_gate_sigma", self.slow_gate_sigma, 1.0, 100.0)?;
        check_range("systematic_deg", self.systematic_deg, 1e-3, 45.0)?;
        check_positive("systematic_tau_s", self.systematic_tau_s)?;
        check_range("systematic_turn_rad", self.systematic_turn_rad, 0.01, 100.0)?;
        check_range(
            "readings_per_update",
            f64::from(self.readings_per_update),
            1.0,
            100.0,
        )?;
        check_range(
            "alignment_readings",
            f64::from(self.alignment_readings),
            1.0,
            1e4,
        )?;
        Ok(())
    }
}

/// Configuration of the [`crate::VehicleEstimator`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VehicleConfig {
    /// Which wheels carry the odometer, on what kind of vehicle, and its dimensions
    /// (default: a car's rear wheels, track 1.55 m).
    pub wheels: OdometerWheels,
    /// Prior beliefs about the sensors; `None` (the default) takes those of the kind of
    /// vehicle `wheels` describes ([`SensorPriors::for_wheels`]).
    pub priors: Option<SensorPriors>,
    /// Compass calibration and gates.
    pub compass: CompassGates,
    /// The wheels must stand still this long before the vehicle counts as at rest, s (0.5).
    pub standstill_s: f64,
    /// Longest interval between two readings of one sensor that the estimator follows, s
    /// (2): across a longer one it cannot integrate the gyro or draw the track, so it
    /// widens what the gap left unknown (the heading without wheels, the track, the gyro
    /// bias) and says so in the status.
    pub max_gap_s: f64,
    /// Run plain integration (the raw gyro less its last rest's bias, along the odometry)
    /// beside the fused estimate and fall back to it where the two part by more than both
    /// their uncertainties allow (true). Off, the fused estimate is trusted whatever it
    /// learned: for comparing the two, not for use.
    pub plain_guard: bool,
    /// How satellite fixes are used.
    pub gnss: GnssConfig,
}

/// How satellite fixes correct the vehicle estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GnssConfig {
    /// A fix's 1σ horizontal accuracy where the receiver reports none, m (5: a consumer
    /// receiver under open sky reports 1.5–3 m, in a town 3–10 m).
    pub default_sigma_m: f64,
    /// How long a fix's error stays the same, s (20): a receiver's error comes from the
    /// atmosphere's delays and multipath, which change over tens of seconds, so fixes a
    /// second apart are not independent. At most one fix per second is used, with its
    /// variance widened as if it were one of the few independent fixes within this time.
    pub error_correlation_s: f64,
    /// A fix whose distance from the dead-reckoned position exceeds this many standard
    /// deviations of their difference is rejected (4): a multipath jump, a frozen fix.
    pub gate_sigma: f64,
    /// Fixes rejected for this long in a row, s (15), mean the dead-reckoned position is
    /// what is wrong (a wheel that spun, an outage longer than the sensors' model): the
    /// position starts again from the next fix.
    pub rejoin_after_s: f64,
    /// Speed over ground below which the receiver's course is not used, m/s (3): at walking
    /// pace the course is the receiver's noise.
    pub min_course_speed_mps: f64,
    /// Standard deviation of the receiver's speed over ground, m/s (0.3): the course's
    /// error is about this over the speed.
    pub speed_sigma_mps: f64,
    /// How long after its epoch a fix reaches the log, s (0.1), and the spread of that
    /// delay, s (0.15): a receiver sends a fix some 20–100 ms after its epoch and a logger
    /// adds tens of milliseconds, a slow one more, so at 20 m/s a fix stamped on arrival lies
    /// metres behind the vehicle. The fix is compared with where the vehicle was that long
    /// before its stamp, and the spread, times the speed (and the turn rate, for the
    /// course), widens it. 0.25 s, the earlier default, put a real car's track 1–2.4 m ahead
    /// of its reference once the odometer's scale was learned from the fixes (the comma2k19
    /// RAV4's u-blox fixes: 2.10 m RMS against 0.70 m with 0.1 s, `truenorth-cli` test
    /// `comma2k19_gnss`).
    pub latency_s: f64,
    /// The spread of [`GnssConfig::latency_s`], s.
    pub latency_sigma_s: f64,
    /// Where the antenna is from the point the track follows (the rear-axle centre, or a
    /// robot's centre between its sides), m forward and to the right ([0, 0]): a roof
    /// antenna a metre or two ahead of a car's rear axle is that far off the track, in a
    /// direction that turns with the heading.
    pub lever_arm_m: [f64; 2],
    /// The date the drive was made, decimal year (2026.0), for the declination at the
    /// first fix (WMM2025, valid 2025.0–2030.0) that relates the compass's magnetic north to
    /// the fixes' true north.
    pub decimal_year: f64,
}

impl Default for GnssConfig {
    fn default() -> Self {
        Self {
            default_sigma_m: 5.0,
            error_correlation_s: 20.0,
            gate_sigma: 4.0,
            rejoin_after_s: 15.0,
            min_course_speed_mps: 3.0,
            speed_sigma_mps: 0.3,
            latency_s: 0.1,
            latency_sigma_s: 0.15,
            lever_arm_m: [0.0; 2],
            decimal_year: 2026.0,
        }
    }
}

impl Validate for GnssConfig {
    fn validate(&self) -> Result<()> {
        check_range(
            "gnss default_sigma_m",
            self.default_sigma_m,
            1e-3,
            truenorth_core::MAX_GNSS_SIGMA_M,
        )?;
        check_range(
            "gnss error_correlation_s",
            self.error_correlation_s,
            0.0,
            3600.0,
        )?;
        check_range("gnss gate_sigma", self.gate_sigma, 1.0, 100.0)?;
        check_range("gnss rejoin_after_s", self.rejoin_after_s, 0.0, 3600.0)?;
        check_range(
            "gnss min_course_speed_mps",
            self.min_course_speed_mps,
            0.0,
            100.0,
        )?;
        check_range("gnss speed_sigma_mps", self.speed_sigma_mps, 1e-3, 10.0)?;
        check_range("gnss latency_s", self.latency_s, 0.0, 10.0)?;
        check_range("gnss latency_sigma_s", self.latency_sigma_s, 0.0, 10.0)?;
        for l in self.lever_arm_m {
            check_range("gnss lever_arm_m (forward, right)", l, -50.0, 50.0)?;
        }
        check_range(
            "gnss decimal_year (WMM2025 holds 2025.0-2030.0)",
            self.decimal_year,
            2025.0,
            2030.0,
        )?;
        Ok(())
    }
}

impl Default for VehicleConfig {
    fn default() -> Self {
        Self {
            wheels: OdometerWheels::Rear { track_m: 1.55 },
            priors: None,
            compass: CompassGates::default(),
            standstill_s: 0.5,
            max_gap_s: 2.0,
            plain_guard: true,
            gnss: GnssConfig::default(),
        }
    }
}

impl VehicleConfig {
    /// The priors in use: the given ones, or the kind of vehicle's.
    pub fn priors(&self) -> SensorPriors {
        self.priors
            .unwrap_or_else(|| SensorPriors::for_wheels(&self.wheels))
    }
}

impl Validate for VehicleConfig {
    fn validate(&self) -> Result<()> {
        self.wheels.validate()?;
        self.priors().validate()?;
        self.compass.validate()?;
        check_range("standstill_s", self.standstill_s, 0.0, 60.0)?;
        check_range("max_gap_s", self.max_gap_s, 0.01, 3600.0)?;
        self.gnss.validate()?;
        Ok(())
    }
}
