//! Sample types: one timestamped reading per struct, in SI units, body axes x forward,
//! y right, z down.

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::{GnssFix, Result, Validate, check_finite, check_range};

/// A two-axis magnetometer reading (any unit; calibration removes it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mag2Sample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// (mag_x, mag_y) in the sensor's unit. Level and heading ψ, ideal: (H cos ψ, −H sin ψ).
    pub mag: Vector2<f64>,
}

/// A three-axis magnetometer reading (any unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mag3Sample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// (mag_x, mag_y, mag_z) in the sensor's unit.
    pub mag: Vector3<f64>,
}

impl Mag2Sample {
    /// A reading of `mag_x`, `mag_y` at `t_s` seconds. Nothing is checked here: a calibrator
    /// checks each reading as it is pushed and refuses a non-finite one with a typed error.
    pub fn new(t_s: f64, mag_x: f64, mag_y: f64) -> Self {
        Self {
            t_s,
            mag: Vector2::new(mag_x, mag_y),
        }
    }
}

impl Mag3Sample {
    /// A reading of `mag_x`, `mag_y`, `mag_z` at `t_s` seconds (checked when pushed, as
    /// [`Mag2Sample::new`]).
    pub fn new(t_s: f64, mag_x: f64, mag_y: f64, mag_z: f64) -> Self {
        Self {
            t_s,
            mag: Vector3::new(mag_x, mag_y, mag_z),
        }
    }
}

/// A three-axis rate-gyro reading.
///
/// **Sample convention**: the simulator writes the instantaneous angular rate at `t_s`, and
/// the vehicle estimator and gyro integrators read it so, with the trapezoid rule between
/// consecutive samples (exact for a rate that changes linearly between them). A digital
/// MEMS gyro's output is closer to the mean over the interval ending at `t_s`; the
/// quaternion filter reads it that way by default and takes the convention as a parameter
/// (`truenorth_fusion::GyroTiming`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GyroSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Angular rate about x, y, z, rad/s. `gyr.z > 0` is a right turn.
    pub gyr_rps: Vector3<f64>,
}

/// A three-axis accelerometer reading (specific force).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Specific force, m/s². At rest and level it reads (0, 0, −g) with z down.
    pub acc_mps2: Vector3<f64>,
}

/// The readings of up to three sensors on the body axes x, y, z, any of which may be absent:
/// a two-axis magnetometer (x, y), the two accelerometers and two gyros of a reduced
/// orientation detector (the yaw + pitch variant of WO 00/36376), or a full triad.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Axes {
    /// Reading on the body x axis, if that sensor is fitted.
    pub x: Option<f64>,
    /// Reading on the body y axis, if that sensor is fitted.
    pub y: Option<f64>,
    /// Reading on the body z axis, if that sensor is fitted.
    pub z: Option<f64>,
}

impl Axes {
    /// No sensor on any axis.
    pub const NONE: Self = Self {
        x: None,
        y: None,
        z: None,
    };

    /// All three axes.
    pub fn xyz(v: Vector3<f64>) -> Self {
        Self {
            x: Some(v.x),
            y: Some(v.y),
            z: Some(v.z),
        }
    }

    /// The x and y axes only (a two-axis magnetometer or accelerometer).
    pub fn xy(v: Vector2<f64>) -> Self {
        Self {
            x: Some(v.x),
            y: Some(v.y),
            z: None,
        }
    }

    /// The three readings, if all three axes are present.
    pub fn as_xyz(&self) -> Option<Vector3<f64>> {
        Some(Vector3::new(self.x?, self.y?, self.z?))
    }

    /// The x and y readings, if both are present.
    pub fn as_xy(&self) -> Option<Vector2<f64>> {
        Some(Vector2::new(self.x?, self.y?))
    }

    /// How many axes are present.
    pub fn count(&self) -> usize {
        usize::from(self.x.is_some())
            + usize::from(self.y.is_some())
            + usize::from(self.z.is_some())
    }

    /// Whether no axis is present.
    pub fn is_empty(&self) -> bool {
        self.count() == 0
    }

    /// Checks that every present reading is finite.
    pub fn check_finite(&self, what: &'static str) -> Result<()> {
        for v in [self.x, self.y, self.z].into_iter().flatten() {
            check_finite(what, v)?;
        }
        Ok(())
    }
}

impl From<Vector3<f64>> for Axes {
    fn from(v: Vector3<f64>) -> Self {
        Self::xyz(v)
    }
}

/// One IMU sample: gyros, accelerometers and magnetometers, each on whichever body axes the
/// device has. A 6-D IMU has no magnetometer ([`Axes::NONE`]); a magnetometer slower than
/// the gyro is absent on the samples between its readings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImuSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Angular rate, rad/s.
    pub gyr_rps: Axes,
    /// Specific force, m/s². At rest and level, z reads −g (z down).
    pub acc_mps2: Axes,
    /// Magnetic field (any unit).
    pub mag: Axes,
}

impl ImuSample {
    /// A 9-axis sample (gyro, accelerometer and magnetometer triads).
    pub fn new_9d(
        t_s: f64,
        gyr_rps: Vector3<f64>,
        acc_mps2: Vector3<f64>,
        mag: Vector3<f64>,
    ) -> Self {
        Self {
            t_s,
            gyr_rps: Axes::xyz(gyr_rps),
            acc_mps2: Axes::xyz(acc_mps2),
            mag: Axes::xyz(mag),
        }
    }

    /// A 6-axis sample (gyro and accelerometer triads, no magnetometer).
    pub fn new_6d(t_s: f64, gyr_rps: Vector3<f64>, acc_mps2: Vector3<f64>) -> Self {
        Self {
            t_s,
            gyr_rps: Axes::xyz(gyr_rps),
            acc_mps2: Axes::xyz(acc_mps2),
            mag: Axes::NONE,
        }
    }

    /// Checks that the timestamp and every present reading are finite.
    pub fn check_finite(&self) -> Result<()> {
        check_finite("timestamp t_s", self.t_s)?;
        self.gyr_rps.check_finite("gyro reading")?;
        self.acc_mps2.check_finite("accelerometer reading")?;
        self.mag.check_finite("magnetometer reading")
    }
}

/// Cumulative distances of the left and right odometer wheels, as the odometer reports them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WheelSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Cumulative distance of the left wheel, metres.
    pub dist_l_m: f64,
    /// Cumulative distance of the right wheel, metres.
    pub dist_r_m: f64,
}

/// The cumulative distances of the left and right odometer wheels at one instant, as the
/// odometer reports them (what `DRIVE.csv`'s `dist_l_m`, `dist_r_m` hold).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WheelReading {
    /// Cumulative distance of the left odometer wheel, metres.
    pub dist_l_m: f64,
    /// Cumulative distance of the right odometer wheel, metres.
    pub dist_r_m: f64,
}

/// What a land vehicle's navigation sensors report at one instant (the `drive` CSV row).
///
/// Every reading is optional: sensors arrive at their own rates, so a row may carry the
/// wheels, the gyro, the compass or any subset of them. A vehicle whose odometer gives one
/// distance for the whole vehicle (a car's CAN vehicle speed integrated, a single odometer)
/// carries it as [`VehicleSample::dist_m`]: a distance with no left and right, which says
/// nothing about turning.
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth_core::VehicleSample;
///
/// let s = VehicleSample::at(1.5).with_wheels(10.2, 10.1).with_gyro(0.01);
/// assert_eq!(s.wheels.unwrap().dist_l_m, 10.2);
/// assert!(s.mag.is_none() && s.dist_m.is_none());
/// let m = VehicleSample::at(1.6).with_mag(Vector2::new(20.0, -3.0));
/// assert!(m.wheels.is_none() && m.gyr_z_rps.is_none());
/// let car = VehicleSample::at(1.7).with_distance(12.5).with_gyro(0.02);
/// assert_eq!(car.dist_m, Some(12.5));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Cumulative wheel distances, if the row carries them.
    pub wheels: Option<WheelReading>,
    /// Raw yaw rate (with the gyro's own bias and scale error), rad/s, if the row carries one.
    pub gyr_z_rps: Option<f64>,
    /// Raw, uncalibrated horizontal magnetometer reading, if the row carries one.
    pub mag: Option<Vector2<f64>>,
    /// Cumulative distance of the vehicle as one odometer reports it (no left and right:
    /// a vehicle speed integrated), metres, if the row carries one. It gives the distance
    /// travelled and nothing about the heading; a row with wheels too is read by its wheels.
    #[serde(default)]
    pub dist_m: Option<f64>,
    /// A satellite fix, if the row carries one.
    #[serde(default)]
    pub gnss: Option<GnssFix>,
}

impl VehicleSample {
    /// A row at `t_s` with no reading yet.
    pub const fn at(t_s: f64) -> Self {
        Self {
            t_s,
            wheels: None,
            gyr_z_rps: None,
            mag: None,
            dist_m: None,
            gnss: None,
        }
    }

    /// The row with cumulative wheel distances, metres.
    pub const fn with_wheels(mut self, dist_l_m: f64, dist_r_m: f64) -> Self {
        self.wheels = Some(WheelReading { dist_l_m, dist_r_m });
        self
    }

    /// The row with a raw yaw rate, rad/s (positive turning right).
    pub const fn with_gyro(mut self, gyr_z_rps: f64) -> Self {
        self.gyr_z_rps = Some(gyr_z_rps);
        self
    }

    /// The row with a raw horizontal magnetometer reading (any unit).
    pub const fn with_mag(mut self, mag: Vector2<f64>) -> Self {
        self.mag = Some(mag);
        self
    }

    /// The row with the vehicle's cumulative distance from a single odometer, metres.
    pub const fn with_distance(mut self, dist_m: f64) -> Self {
        self.dist_m = Some(dist_m);
        self
    }

    /// The row with a satellite fix.
    pub const fn with_gnss(mut self, fix: GnssFix) -> Self {
        self.gnss = Some(fix);
        self
    }
}

/// Largest yaw rate a vehicle sample may carry, rad/s (2000°/s, the widest range of MEMS
/// rate gyros): a reading beyond it is a corrupted value, not a turn.
pub const MAX_YAW_RATE_RPS: f64 = 2000.0 * core::f64::consts::PI / 180.0;

impl Validate for VehicleSample {
    /// Checks that the timestamp and every present reading are finite, and the yaw rate
    /// within [`MAX_YAW_RATE_RPS`].
    fn validate(&self) -> Result<()> {
        check_finite("timestamp t_s", self.t_s)?;
        if let Some(w) = self.wheels {
            check_finite("dist_l_m", w.dist_l_m)?;
            check_finite("dist_r_m", w.dist_r_m)?;
        }
        if let Some(g) = self.gyr_z_rps {
            check_range("gyr_z (rad/s)", g, -MAX_YAW_RATE_RPS, MAX_YAW_RATE_RPS)?;
        }
        if let Some(m) = self.mag {
            check_finite("mag_x", m.x)?;
            check_finite("mag_y", m.y)?;
        }
        if let Some(d) = self.dist_m {
            check_finite("dist_m", d)?;
        }
        if let Some(g) = &self.gnss {
            g.validate()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn any_axis() -> impl Strategy<Value = Option<f64>> {
        prop_oneof![
            Just(None),
            any::<f64>().prop_map(Some),
            (-1e3f64..1e3).prop_map(Some),
        ]
    }

    proptest! {
        #[test]
        fn axes_report_exactly_what_is_present(x in any_axis(), y in any_axis(), z in any_axis()) {
            let a = Axes { x, y, z };
            prop_assert_eq!(a.as_xyz().is_some(), x.is_some() && y.is_some() && z.is_some());
            prop_assert_eq!(a.as_xy().is_some(), x.is_some() && y.is_some());
            prop_assert_eq!(a.count(), [x, y, z].iter().filter(|v| v.is_some()).count());
            prop_assert_eq!(a.is_empty(), a.count() == 0);
            let all_finite = [x, y, z].iter().flatten().all(|v| v.is_finite());
            prop_assert_eq!(a.check_finite("test").is_ok(), all_finite);
        }

        #[test]
        fn imu_sample_rejects_any_non_finite_value(
            t in any::<f64>(),
            g in proptest::array::uniform3(any::<f64>()),
            a in proptest::array::uniform3(-20.0f64..20.0),
            m in proptest::array::uniform3(any::<f64>()),
        ) {
            let s = ImuSample::new_9d(t, Vector3::from(g), Vector3::from(a), Vector3::from(m));
            let finite = t.is_finite() && g.iter().chain(&m).all(|v| v.is_finite());
            prop_assert_eq!(s.check_finite().is_ok(), finite);
            let six = ImuSample::new_6d(t, Vector3::from(g), Vector3::from(a));
            prop_assert!(six.mag.is_empty());
            prop_assert_eq!(
                six.check_finite().is_ok(),
                t.is_finite() && g.iter().all(|v| v.is_finite())
            );
        }
    }
}
