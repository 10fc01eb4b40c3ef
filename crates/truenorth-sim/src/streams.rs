//! Sensor streams: ground truth run through the sensor crates' forward models.
//!
//! Gyro convention (the one [`truenorth_core::GyroSample`] documents and every integrator
//! assumes): each gyro sample is the instantaneous true rate at its timestamp, plus the
//! sensor's errors. A sample holding the mean rate over the preceding step would, when
//! integrated by the trapezoid rule, lag the truth by half a sample.

use nalgebra::{Matrix2, Matrix3, Rotation2, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_accel::{AccelModel, AccelParams, AccelTruth};
use truenorth_compass::{
    AttitudeTruth, Disturbance, HeadingTruth, MagnetometerModel2d, MagnetometerModel3d,
    earth_field_ned,
};
use truenorth_core::{
    AccelSample, EulerZyx, ImuSample, Result, SensorModel, SplitMix64, Validate, VehicleSample,
    angle_diff, check_finite, check_finite2, check_finite3, check_positive, check_range,
};
use truenorth_gyro::{
    Gyro3Model, Gyro3Params, GyroAxisModel, GyroAxisParams, Rate3Truth, RateTruth,
};
use truenorth_odometer::{OdometerModel, OdometerParams, OdometerWheels, WheelMotion};

use crate::{MotionTruth, VehicleTruth};

/// The true errors of a land vehicle's navigation sensors (`*Params`, like every forward
/// model's: what the sensors actually do, which the calibrators must find).
///
/// The simulated heading is the magnetic heading (declination zero): add a declination at the
/// edge if a scenario needs true north.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleSensorParams {
    /// Yaw-rate gyro.
    pub gyro: GyroAxisParams,
    /// Gyro temperature during the drive, °C.
    pub gyro_temp_c: f64,
    /// Wheel odometer.
    pub odometer: OdometerParams,
    /// Compass hard iron (offset), µT.
    pub compass_hard_iron: Vector2<f64>,
    /// Compass soft-iron distortion (raw = soft · field + hard).
    pub compass_soft_iron: Matrix2<f64>,
    /// Compass noise, µT per axis (1 σ).
    pub compass_noise: f64,
    /// Earth's horizontal field, µT.
    pub horizontal_field: f64,
}

impl Validate for VehicleSensorParams {
    /// Each sensor's parameters valid; temperature and compass terms finite, noise ≥ 0 and
    /// the field positive. (A singular soft iron is refused when the streams are made.)
    fn validate(&self) -> Result<()> {
        self.gyro.validate()?;
        check_finite("gyro_temp_c", self.gyro_temp_c)?;
        self.odometer.validate()?;
        check_finite2("compass_hard_iron", &self.compass_hard_iron)?;
        for &x in self.compass_soft_iron.iter() {
            check_finite("compass_soft_iron entry", x)?;
        }
        check_range("compass_noise", self.compass_noise, 0.0, f64::MAX)?;
        check_positive("horizontal_field", self.horizontal_field)?;
        Ok(())
    }
}

/// A soft-iron distortion with principal gains `major` and `minor` whose major axis is rotated
/// by `angle_rad` from the x axis: `R(θ) · diag(major, minor) · R(θ)ᵀ`.
pub fn rotated_soft_iron(major: f64, minor: f64, angle_rad: f64) -> Matrix2<f64> {
    let r = Rotation2::new(angle_rad).into_inner();
    r * Matrix2::new(major, 0.0, 0.0, minor) * r.transpose()
}

impl VehicleSensorParams {
    /// Errors of a typical low-cost installation: a MEMS yaw gyro with 0.5 °/s bias and
    /// 1.5 % / 0.5 % right/left scale error, rear-wheel ABS odometry with 0.3 % / −0.2 %
    /// wheel-size errors and 2 cm pulses, and a roof compass with hard iron of half the field
    /// and a 1.3 : 1 soft iron rotated 30°, on a 20 µT horizontal field.
    pub fn typical() -> Self {
        Self {
            gyro: GyroAxisParams {
                bias_rps: 0.5f64.to_radians(),
                bias_walk_rps_per_sqrt_s: 0.002f64.to_radians(),
                scale_error_pos: 0.015,
                scale_error_neg: 0.005,
                noise_density_rps_per_sqrt_hz: 0.015f64.to_radians(),
                ..GyroAxisParams::PERFECT
            },
            gyro_temp_c: 25.0,
            odometer: OdometerParams {
                wheels: OdometerWheels::Rear { track_m: 1.55 },
                scale_error_l: 0.003,
                scale_error_r: -0.002,
                speed_coeff_s2_per_m2: 0.0,
                dist_per_pulse_m: Some(0.02),
            },
            compass_hard_iron: Vector2::new(8.0, -6.0),
            compass_soft_iron: rotated_soft_iron(1.3, 1.0, 30f64.to_radians()),
            compass_noise: 0.2,
            horizontal_field: 20.0,
        }
    }
}

/// Runs `truth` through the vehicle's sensor models. One sample per truth sample; random
/// errors drawn from `seed`, so the same inputs always give the same stream.
///
/// The gyro reads the instantaneous yaw rate at each sample time (speed × curvature there),
/// the odometer the wheels' travel over each step, and the compass the field at each sample
/// time.
pub fn vehicle_streams(
    truth: &[VehicleTruth],
    params: &VehicleSensorParams,
    seed: u64,
) -> Result<Vec<VehicleSample>> {
    vehicle_streams_disturbed(truth, params, &[], seed)
}

/// [`vehicle_streams`] with magnetic `disturbances` added to the field the compass sees
/// (world-fixed fields in time windows, at most
/// [`truenorth_compass::MAX_DISTURBANCES`]).
pub fn vehicle_streams_disturbed(
    truth: &[VehicleTruth],
    params: &VehicleSensorParams,
    disturbances: &[Disturbance],
    seed: u64,
) -> Result<Vec<VehicleSample>> {
    params.validate()?;
    let mut rng = SplitMix64::new(seed);
    let mut gyro = GyroAxisModel::new(params.gyro)?;
    let mut odo = OdometerModel::new(params.odometer)?;
    let mut compass = MagnetometerModel2d::new(
        params.compass_hard_iron,
        params.compass_soft_iron,
        params.compass_noise,
    )?;
    for d in disturbances {
        compass = compass.with_disturbance(*d)?;
    }
    let mut out = Vec::with_capacity(truth.len());
    let mut prev: Option<&VehicleTruth> = None;
    for s in truth {
        let heading = HeadingTruth {
            heading_rad: s.heading_rad,
            horizontal_field: params.horizontal_field,
        };
        let rate = RateTruth {
            rate_rps: s.yaw_rate_rps,
            temp_c: params.gyro_temp_c,
        };
        let (gyr, mag, dist) = match prev {
            None => {
                compass.set_time_s(s.t_s);
                (
                    gyro.ideal(&rate)?,
                    compass.ideal(&heading)?,
                    odo.cumulative_m(),
                )
            }
            Some(p) => {
                let dt = s.t_s - p.t_s;
                let ds = s.distance_m - p.distance_m;
                let dpsi = angle_diff(s.heading_rad, p.heading_rad);
                // The wheels measure distance travelled, an integral over the step: the
                // step's mean curvature makes them agree with the truth's heading change
                // exactly, whatever happened inside the step.
                let motion = WheelMotion {
                    ds_m: ds,
                    curvature_per_m: if ds > 0.0 { dpsi / ds } else { 0.0 },
                    speed_mps: ds / dt,
                    pivot_rad: if ds > 0.0 { 0.0 } else { dpsi },
                };
                odo.sample(&motion, dt, &mut rng)?;
                let g = gyro.sample(&rate, dt, &mut rng)?;
                let m = compass.sample(&heading, dt, &mut rng)?;
                (g, m, odo.cumulative_m())
            }
        };
        out.push(
            VehicleSample::at(s.t_s)
                .with_wheels(dist.left_m, dist.right_m)
                .with_gyro(gyr)
                .with_mag(mag),
        );
        prev = Some(s);
    }
    Ok(out)
}

/// Runs `truth` through an accelerometer fixed level in the vehicle (x forward, y right,
/// z down). The vehicle's own acceleration is the rear-axle point's: `dv/dt` forward and
/// `v²κ` to the right (centripetal, towards the centre of a right turn), so a level sensor
/// reads `(dv/dt, v²κ, −g)` plus its errors. Random errors drawn from `seed`.
pub fn vehicle_accel_stream(
    truth: &[VehicleTruth],
    params: &AccelParams,
    seed: u64,
) -> Result<Vec<AccelSample>> {
    let mut rng = SplitMix64::new(seed);
    let mut accel = AccelModel::new(*params)?;
    let mut out = Vec::with_capacity(truth.len());
    let mut prev_t: Option<f64> = None;
    for s in truth {
        let forward = s.accel_mps2;
        let right = s.speed_mps * s.speed_mps * s.curvature_per_m;
        let (sin, cos) = s.heading_rad.sin_cos();
        let a = AccelTruth {
            attitude: EulerZyx {
                yaw_rad: s.heading_rad,
                ..EulerZyx::default()
            }
            .to_quaternion(),
            accel_ned_mps2: Vector3::new(
                forward * cos - right * sin,
                forward * sin + right * cos,
                0.0,
            ),
        };
        let reading = match prev_t {
            None => accel.ideal(&a)?,
            Some(p) => accel.sample(&a, s.t_s - p, &mut rng)?,
        };
        out.push(AccelSample {
            t_s: s.t_s,
            acc_mps2: reading,
        });
        prev_t = Some(s.t_s);
    }
    Ok(out)
}

/// The true errors of a 9-axis IMU (`*Params`, like every forward model's).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImuSensorParams {
    /// Each gyro axis.
    pub gyro: GyroAxisParams,
    /// Gyro temperature, °C.
    pub gyro_temp_c: f64,
    /// Accelerometer.
    pub accel: AccelParams,
    /// Magnetometer hard iron, µT.
    pub mag_hard_iron: Vector3<f64>,
    /// Magnetometer soft-iron distortion.
    pub mag_soft_iron: Matrix3<f64>,
    /// Magnetometer noise, µT per axis (1 σ).
    pub mag_noise: f64,
    /// Earth's total field, µT.
    pub field_total: f64,
    /// Inclination (dip), radians, positive down.
    pub inclination_rad: f64,
}

impl ImuSensorParams {
    /// A consumer MEMS IMU: gyro bias 0.3 °/s, accelerometer bias 0.05 m/s², a calibrated
    /// magnetometer with 0.3 µT noise, in a 50 µT field dipping 60°.
    pub fn typical() -> Self {
        Self {
            gyro: GyroAxisParams {
                bias_rps: 0.3f64.to_radians(),
                noise_density_rps_per_sqrt_hz: 0.01f64.to_radians(),
                ..GyroAxisParams::PERFECT
            },
            gyro_temp_c: 25.0,
            accel: AccelParams {
                bias_mps2: Vector3::new(0.05, -0.03, 0.04),
                noise_density_mps2_per_sqrt_hz: 0.002,
                ..AccelParams::default()
            },
            mag_hard_iron: Vector3::zeros(),
            mag_soft_iron: Matrix3::identity(),
            mag_noise: 0.3,
            field_total: 50.0,
            inclination_rad: 60f64.to_radians(),
        }
    }
}

impl Validate for ImuSensorParams {
    /// Each sensor's parameters valid; temperature, magnetometer terms and inclination
    /// finite, noise ≥ 0 and the field positive. (A singular soft iron is refused when the
    /// streams are made.)
    fn validate(&self) -> Result<()> {
        self.gyro.validate()?;
        check_finite("gyro_temp_c", self.gyro_temp_c)?;
        self.accel.validate()?;
        check_finite3("mag_hard_iron", &self.mag_hard_iron)?;
        for &x in self.mag_soft_iron.iter() {
            check_finite("mag_soft_iron entry", x)?;
        }
        check_range("mag_noise", self.mag_noise, 0.0, f64::MAX)?;
        check_positive("field_total", self.field_total)?;
        check_finite("inclination_rad", self.inclination_rad)?;
        Ok(())
    }
}

/// Runs hand-held motion truth through a 9-axis IMU model. Random errors drawn from `seed`.
///
/// The gyros read the instantaneous body rate at each sample time
/// ([`MotionTruth::gyr_rps`]), the accelerometers and magnetometers the specific force and
/// field there.
pub fn imu_streams(
    truth: &[MotionTruth],
    params: &ImuSensorParams,
    seed: u64,
) -> Result<Vec<ImuSample>> {
    params.validate()?;
    let mut rng = SplitMix64::new(seed);
    let mut gyro = Gyro3Model::new(Gyro3Params::uniform(params.gyro))?;
    let mut accel = AccelModel::new(params.accel)?;
    let mut mag =
        MagnetometerModel3d::new(params.mag_hard_iron, params.mag_soft_iron, params.mag_noise)?;
    let field_ned = earth_field_ned(params.field_total, params.inclination_rad);
    let mut out = Vec::with_capacity(truth.len());
    let mut prev_t: Option<f64> = None;
    for s in truth {
        let rate = Rate3Truth {
            rate_rps: s.gyr_rps,
            temp_c: params.gyro_temp_c,
        };
        let acc_truth = AccelTruth {
            attitude: s.attitude,
            accel_ned_mps2: s.accel_ned_mps2,
        };
        let att = AttitudeTruth {
            attitude: EulerZyx::from_quaternion(&s.attitude),
            field_ned,
        };
        let (g, a, m) = match prev_t {
            None => {
                mag.set_time_s(s.t_s);
                (
                    gyro.ideal(&rate)?,
                    accel.ideal(&acc_truth)?,
                    mag.ideal(&att)?,
                )
            }
            Some(p) => {
                let dt = s.t_s - p;
                (
                    gyro.sample(&rate, dt, &mut rng)?,
                    accel.sample(&acc_truth, dt, &mut rng)?,
                    mag.sample(&att, dt, &mut rng)?,
                )
            }
        };
        out.push(ImuSample::new_9d(s.t_s, g, a, m));
        prev_t = Some(s.t_s);
    }
    Ok(out)
}
