//! Drives as real logs come: in motion from the first row, rarely at rest, each sensor on
//! rows of its own at its own rate and latency, wheel data filtered and quantised by the
//! controller that sends it, the sensor sets real vehicles carry, and sensor errors over
//! their physical range. Everything is drawn from one seed and the truth is kept exactly:
//! the state at every row's stamp, the instant each reading measured, and every error.
//!
//! ```
//! use truenorth_sim::{LogDrive, LogDriveConfig, SensorSet, VehicleKind};
//!
//! // A car's CAN bus: the vehicle speed and the ESP's yaw rate.
//! let mut config = LogDriveConfig::new(7, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
//! config.motion.length_m = 500.0;
//! let drive = LogDrive::new(config)?;
//! // In motion from the first row, the speed and the yaw rate on rows of their own (a
//! // row is shared only where two stamps meet in the same millisecond).
//! assert!(drive.truth[0].speed_mps > 1.0);
//! let shared = drive.rows.iter().filter(|r| r.odometry.is_some() && r.gyr_z_rps.is_some());
//! assert!(shared.count() * 20 < drive.rows.len());
//! assert!(drive.to_csv().starts_with("t_s,speed_mps,gyr_z\n"));
//! // The truth at every row, and the instant behind every reading.
//! assert_eq!(drive.truth.len(), drive.rows.len());
//! let m = drive.measured.iter().find_map(|m| m.odometry_s).unwrap();
//! assert!(m < drive.rows.iter().find(|r| r.odometry.is_some()).unwrap().t_s);
//! # Ok::<(), truenorth_core::Error>(())
//! ```
//!
//! Each habit, the ranges it is drawn from and why, is in its module: [`motion`] (in motion
//! from the first row, rests, circling), [`timing`] (own rates, latency, jitter, lost
//! readings, stamps), [`wheel_controller`] (lag and quanta of wheel data), [`skid_ground`]
//! (a skid-steer's effective track), [`yaw_sensor`] (bias, scale, tilt and quantum of a
//! yaw-rate sensor), [`gnss_config`] (a GNSS receiver: time-correlated errors, a reported σ,
//! speed and course, outages, multipath jumps, frozen and late fixes, the lever arm; fixes as
//! WGS84 latitude and longitude in the [`LocalTangentPlane`] at its origin, where the compass
//! sees the World Magnetic Model's declination), [`body_tilt`] (the body's roll in turns,
//! pitch on grades and camber under a level-assumed compass, in the field with its vertical
//! part). [`Habit`] and [`LogDriveConfig::without`] leave one out at a time.

mod assemble;
pub mod body_tilt;
mod config;
pub mod gnss_config;
mod gnss_receiver;
mod gnss_truth;
pub mod motion;
mod row;
mod sensor_set;
pub mod skid_ground;
mod span;
mod streams;
pub mod timing;
pub mod wheel_controller;
pub mod yaw_sensor;

pub use body_tilt::{TiltConfig, TiltErrors};
pub use config::{CompassConfig, Habit, LogDriveConfig, RobotConfig};
pub use gnss_config::{Canyons, Episodes, GnssConfig, LateFixes, Origin};
pub use gnss_receiver::{GnssErrors, Jump};
pub use gnss_truth::{FixCondition, GnssFix, GnssTruth};
pub use motion::{MotionConfig, Rests, RouteShape};
pub use row::{LogRow, Measured, OdometryReading, drive_csv, vehicle_samples};
pub use sensor_set::{Odometry, SensorSet};
pub use skid_ground::{SkidGround, SkidSteerConfig};
pub use span::Span;
pub use timing::{Clock, RowLayout, SensorTiming, TimingConfig};
pub use wheel_controller::WheelConfig;
pub use yaw_sensor::{YawRateConfig, YawRateErrors};

use core::f64::consts::PI;

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use truenorth_compass::Disturbance;
use truenorth_core::{NoiseSource, Result, SplitMix64, Validate, VehicleSample, check_range};
use truenorth_odometer::{AckermannParams, OdometerParams, OdometerWheels};

use crate::LocalTangentPlane;
use crate::drive::{active_at, random_disturbances};
use crate::route::Route;
use crate::vehicle::{MAX_SAMPLES, VehicleTruth, simulate_at};
use crate::vehicle_kind::{RangeVehicle, VehicleKind};
use assemble::assemble;
use gnss_receiver::gnss_stream;
use streams::{Track, compass_stream, gyro_stream, odometry_stream};
use truenorth_geomag::field_at_deg;

/// The true errors of one drive's sensors and clocks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LogErrors {
    /// The yaw-rate sensor.
    pub yaw_rate: YawRateErrors,
    /// The rear axle's odometer (a robot's sides: its rear wheels).
    pub rear: OdometerParams,
    /// The front axle's odometer (a robot's sides: its front wheels; none on a
    /// differential-drive robot).
    pub front: Option<OdometerParams>,
    /// Time constant of the speeds' lag, s.
    pub wheel_lag_s: f64,
    /// Quantum of a speed, m/s.
    pub speed_quantum_mps: f64,
    /// Quantum of the cumulative distance, m.
    pub dist_quantum_m: f64,
    /// Horizontal field, µT.
    pub field_ut: f64,
    /// Compass hard iron, µT.
    pub compass_hard_iron: Vector2<f64>,
    /// Compass soft iron (raw = soft · field + hard).
    pub compass_soft_iron: Matrix2<f64>,
    /// Compass noise per axis, µT.
    pub compass_noise_ut: f64,
    /// The declination the compass sees, rad east (magnetic = true − declination).
    pub declination_rad: f64,
    /// The field's dip, rad (with a level compass it does not matter).
    pub dip_rad: f64,
    /// How the body tilts under the compass (`None`: it stays level).
    pub tilt: Option<TiltErrors>,
    /// The gyro's clock.
    pub gyro_clock: Clock,
    /// The odometry's clock.
    pub odometry_clock: Clock,
    /// The compass's clock.
    pub compass_clock: Clock,
}

/// A drive as a real log gives it, with the whole truth behind it.
#[derive(Debug, Clone)]
pub struct LogDrive {
    /// What was asked for.
    pub config: LogDriveConfig,
    /// The vehicle drawn (its `wheels` are the odometer pair a `VEHICLE.json` describes:
    /// the rear wheels of a rear-wheel car, the steered front wheels of a front-wheel car,
    /// a robot's sides).
    pub vehicle: RangeVehicle,
    /// A car's front axle (both kinds of car have one; the four-wheel readings use it).
    pub front_axle: Option<AckermannParams>,
    /// The route driven.
    pub route: Route,
    /// The heading at the truth's start, rad.
    pub heading0_rad: f64,
    /// The rows of the log.
    pub rows: Vec<LogRow>,
    /// The truth at each row's stamp (its `t_s` on the log's clock).
    pub truth: Vec<VehicleTruth>,
    /// When each reading on each row was measured.
    pub measured: Vec<Measured>,
    /// Every true error.
    pub errors: LogErrors,
    /// A skid-steer's ground, patch by patch.
    pub ground: Option<SkidGround>,
    /// The magnetic disturbances, s on the log's clock.
    pub disturbances: Vec<Disturbance>,
    /// The GNSS receiver's errors (times s after the truth starts), if there is one.
    pub gnss: Option<GnssErrors>,
    /// The tangent plane the truth's north and east are in, at the GNSS origin, if there
    /// is a receiver.
    pub plane: Option<LocalTangentPlane>,
}

impl LogDrive {
    /// Draws the drive `config` describes; a typed error for a configuration out of its
    /// documented ranges or a sensor set the vehicle cannot carry.
    pub fn new(config: LogDriveConfig) -> Result<Self> {
        config.validate()?;
        let mut master = SplitMix64::new(config.seed);
        let mut stream = || SplitMix64::new(master.next_u64());
        let (mut motion_rng, mut error_rng, mut clock_rng) = (stream(), stream(), stream());
        // Each sensor draws its noise and its arrivals from a stream of its own, so that a
        // sensor's rows do not change with the other sensors fitted.
        let (mut gyro_rng, mut wheel_rng, mut compass_rng) = (stream(), stream(), stream());
        let mut gnss_rng = stream();

        let (vehicle, front_axle) = draw_vehicle(config.kind, &config.robot, &mut motion_rng);
        let route = config.motion.route(&vehicle, &mut motion_rng)?;
        let heading0_rad = PI * (2.0 * motion_rng.uniform() - 1.0);
        let duration_s = route.duration_s();
        let fastest = [
            &config.timing.gyro.rate_hz,
            &config.timing.odometry.rate_hz,
            &config.timing.compass.rate_hz,
        ]
        .iter()
        .chain(config.gnss.as_ref().map(|g| &g.timing.rate_hz).as_ref())
        .fold(config.wheels.loop_hz, |m, r| m.max(r.hi));
        check_range(
            "readings of the drive (duration × fastest rate)",
            duration_s * fastest,
            0.0,
            MAX_SAMPLES,
        )?;

        let plane = config
            .gnss
            .map(|g| LocalTangentPlane::new(g.origin.lat_deg, g.origin.lon_deg, g.origin.height_m))
            .transpose()?;
        let declination_deg = match (config.compass.declination_deg, config.gnss) {
            (Some(d), _) => d,
            (None, Some(g)) => {
                let o = g.origin;
                field_at_deg(o.lat_deg, o.lon_deg, o.height_m / 1e3, g.year)?.declination_deg()
            }
            (None, None) => 0.0,
        };
        let mut errors = draw_errors(
            &config,
            &vehicle,
            front_axle,
            &mut error_rng,
            &mut clock_rng,
        );
        errors.declination_rad = declination_deg.to_radians();
        let disturbances = if config.sensors.compass && config.compass.disturbances {
            random_disturbances(&mut error_rng, duration_s, errors.field_ut)
        } else {
            Vec::new()
        };
        if let Some(t) = &config.tilt {
            errors.tilt = Some(TiltErrors::draw(t, &mut error_rng));
            errors.dip_rad = match &config.gnss {
                Some(g) => {
                    let o = g.origin;
                    field_at_deg(o.lat_deg, o.lon_deg, o.height_m / 1e3, g.year)?.inclination_rad
                }
                None => body_tilt::drawn_dip_rad(t, errors.field_ut, &mut error_rng),
            };
        }
        let track = Track {
            route: &route,
            heading0_rad,
            duration_s,
            timing: &config.timing,
        };
        let mut streams = Vec::new();
        let mut ground = None;
        if config.sensors.odometry != Odometry::None {
            let (stream, skid) =
                odometry_stream(&track, &config, &vehicle, &errors, &mut wheel_rng)?;
            streams.push(stream);
            ground = skid;
        }
        if config.sensors.gyro {
            streams.push(gyro_stream(&track, &errors, &mut gyro_rng)?);
        }
        if config.sensors.compass {
            streams.push(compass_stream(
                &track,
                &errors,
                &disturbances,
                &mut compass_rng,
            )?);
        }
        let mut gnss = None;
        if let (Some(g), Some(plane)) = (&config.gnss, &plane) {
            let e = GnssErrors::draw(g, duration_s, &mut gnss_rng);
            streams.push(gnss_stream(&track, g, &e, plane, &mut gnss_rng)?);
            gnss = Some(e);
        }
        let (route_times, rows, measured) =
            assemble(streams, &config.timing, &mut clock_rng, duration_s);
        let mut truth = simulate_at(&route, heading0_rad, &route_times)?;
        for (s, r) in truth.iter_mut().zip(&rows) {
            s.t_s = r.t_s;
        }
        let disturbances = disturbances
            .into_iter()
            .map(|d| Disturbance {
                start_s: d.start_s + config.timing.start_s,
                ..d
            })
            .collect();
        Ok(Self {
            config,
            vehicle,
            front_axle,
            route,
            heading0_rad,
            rows,
            truth,
            measured,
            errors,
            ground,
            disturbances,
            gnss,
            plane,
        })
    }

    /// The drive as a `DRIVE.csv` for the `drive` command.
    pub fn to_csv(&self) -> String {
        drive_csv(&self.rows)
    }

    /// The rows as the core's samples, one per row (see [`vehicle_samples`]).
    pub fn vehicle_samples(&self) -> Vec<VehicleSample> {
        vehicle_samples(&self.rows, self.vehicle.kind)
    }

    /// The rows as the core's samples with every fix stamped `late_s` later than the receiver
    /// stamped it (moved onto the first row at or after: there is one every few hundredths
    /// of a second), as a logger's queue or a receiver on another clock would stamp it.
    pub fn samples_with_fixes_late(&self, late_s: f64) -> Vec<VehicleSample> {
        let samples = self.vehicle_samples();
        let mut out: Vec<VehicleSample> = samples
            .iter()
            .map(|s| VehicleSample { gnss: None, ..*s })
            .collect();
        let mut j = 0;
        for s in &samples {
            let Some(fix) = s.gnss else { continue };
            while j < out.len() && out[j].t_s < s.t_s + late_s {
                j += 1;
            }
            if let Some(row) = out.get_mut(j) {
                row.gnss = Some(fix);
            }
        }
        out
    }

    /// Distance driven by the end of the last row, m.
    pub fn distance_m(&self) -> f64 {
        self.truth.last().map_or(0.0, |t| t.distance_m)
    }

    /// Whether a magnetic disturbance is active at `t_s` (the log's clock).
    pub fn disturbed_at(&self, t_s: f64) -> bool {
        active_at(&self.disturbances, t_s)
    }

    /// The odometer pair's mean scale (`1 +` the mean of its two wheels' scale errors):
    /// what no sensor on board can see.
    pub fn mean_wheel_scale(&self) -> f64 {
        let o = if self.vehicle.kind == VehicleKind::FrontWheelCar {
            self.errors.front.unwrap_or(self.errors.rear)
        } else {
            self.errors.rear
        };
        1.0 + 0.5 * (o.scale_error_l + o.scale_error_r)
    }
}

/// A vehicle of `kind` from its physical range; a car with both axles' geometry.
fn draw_vehicle(
    kind: VehicleKind,
    robot: &RobotConfig,
    rng: &mut SplitMix64,
) -> (RangeVehicle, Option<AckermannParams>) {
    if !kind.is_car() {
        let mut v = RangeVehicle::draw(kind, rng);
        if let Some(track) = robot.track_m.map(|t| t.draw(rng)) {
            v.wheels = match v.wheels {
                OdometerWheels::Differential { .. } => {
                    OdometerWheels::Differential { track_m: track }
                }
                _ => OdometerWheels::SkidSteer { track_m: track },
            };
        }
        if let Some(speed) = robot.speed_mps {
            v.speed_range_mps = (speed.lo, speed.hi);
        }
        return (v, None);
    }
    let front = RangeVehicle::draw(VehicleKind::FrontWheelCar, rng);
    let OdometerWheels::Front(axle) = front.wheels else {
        return (front, None);
    };
    let vehicle = if kind == VehicleKind::RearWheelCar {
        RangeVehicle {
            kind,
            wheels: OdometerWheels::Rear {
                track_m: axle.track_m,
            },
            ..front
        }
    } else {
        front
    };
    (vehicle, Some(axle))
}

/// Every error of the installation, and every clock.
fn draw_errors(
    config: &LogDriveConfig,
    v: &RangeVehicle,
    front_axle: Option<AckermannParams>,
    rng: &mut SplitMix64,
    clock_rng: &mut SplitMix64,
) -> LogErrors {
    let w = &config.wheels;
    let mean = w.scale_error * (2.0 * rng.uniform() - 1.0);
    let mut wheel = || mean + 0.5 * w.scale_difference * (2.0 * rng.uniform() - 1.0);
    let scales = [wheel(), wheel(), wheel(), wheel()];
    let a = w.speed_coeff_s2_per_m2.draw(rng);
    let tick = w.tick_m.draw_log(rng);
    let axle = |wheels: OdometerWheels, l: f64, r: f64| OdometerParams {
        wheels,
        scale_error_l: l,
        scale_error_r: r,
        speed_coeff_s2_per_m2: a,
        dist_per_pulse_m: Some(tick),
    };
    let rear_wheels = match v.wheels {
        OdometerWheels::Front(g) => OdometerWheels::Rear { track_m: g.track_m },
        other => other,
    };
    let rear = axle(rear_wheels, scales[2], scales[3]);
    let front = match (front_axle, v.kind) {
        (Some(g), _) => Some(axle(OdometerWheels::Front(g), scales[0], scales[1])),
        (None, VehicleKind::SkidSteer) => Some(axle(v.wheels, scales[0], scales[1])),
        _ => None,
    };
    let wheel_lag_s = w.lag_s.draw(rng);
    let yaw_rate = YawRateErrors::draw(&config.yaw_rate, rng);
    let field_ut = config.compass.field_ut.draw(rng);
    let compass = config.compass.ranges().draw(field_ut, rng);
    let t = &config.timing;
    let odometry_clock = Clock::draw(&t.odometry, clock_rng);
    let mut gyro_clock = Clock::draw(&t.gyro, clock_rng);
    let mut compass_clock = Clock::draw(&t.compass, clock_rng);
    if t.common_clock {
        for c in [&mut gyro_clock, &mut compass_clock] {
            c.rate_hz = odometry_clock.rate_hz;
            c.phase_s = odometry_clock.phase_s;
        }
    }
    LogErrors {
        yaw_rate,
        rear,
        front,
        wheel_lag_s,
        speed_quantum_mps: w.speed_quantum_mps,
        dist_quantum_m: w.dist_quantum_m,
        field_ut,
        compass_hard_iron: compass.hard_iron,
        compass_soft_iron: compass.soft_iron,
        compass_noise_ut: compass.noise,
        declination_rad: 0.0,
        dip_rad: 0.0,
        tilt: None,
        gyro_clock,
        odometry_clock,
        compass_clock,
    }
}
