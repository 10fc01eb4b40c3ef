//! Forward model of a three-axis magnetometer on a tilted body: truth (attitude and the
//! earth's field, inclination included) → raw reading with hard iron, full soft iron, noise and
//! transient disturbances.

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{EulerZyx, NoiseSource, Result, SensorModel, check_finite, check_finite3};

use crate::distortion::invert_distortion;
use crate::model2d::check_noise;
use crate::{CompassCalibration3d, Disturbance, Disturbances};
use truenorth_core::check_range;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The earth's field in the local-level frame of magnetic north (north, east, down) from its
/// total strength and inclination (dip, positive when the field points down, as in the northern
/// hemisphere): `(F cos I, 0, F sin I)`.
pub fn earth_field_ned(total: f64, inclination_rad: f64) -> Vector3<f64> {
    let (s, c) = inclination_rad.sin_cos();
    Vector3::new(total * c, 0.0, total * s)
}

/// What a body-mounted magnetometer should see: the body's attitude and the earth's field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AttitudeTruth {
    /// Attitude of the body, body → NED (yaw = magnetic heading when `field_ned` is given in
    /// the frame of magnetic north, as [`earth_field_ned`] gives it).
    pub attitude: EulerZyx,
    /// The earth's field, NED.
    pub field_ned: Vector3<f64>,
}

impl AttitudeTruth {
    /// The undistorted field in body axes, `Rᵀ · field_ned`.
    pub fn body_field(&self) -> Vector3<f64> {
        ned_to_body(&self.attitude, &self.field_ned)
    }

    fn check(&self) -> Result<()> {
        check_finite("true yaw", self.attitude.yaw_rad)?;
        check_finite("true pitch", self.attitude.pitch_rad)?;
        check_finite("true roll", self.attitude.roll_rad)?;
        check_finite3("true field", &self.field_ned)
    }
}

/// Rotates an NED vector into body axes: `Rᵀ v` with `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
pub(crate) fn ned_to_body(att: &EulerZyx, v: &Vector3<f64>) -> Vector3<f64> {
    Rotation3::from_euler_angles(att.roll_rad, att.pitch_rad, att.yaw_rad)
        .inverse_transform_vector(v)
}

/// A three-axis magnetometer: `raw = soft_iron · (Rᵀ (f + d(t))) + hard_iron + n`, with `f`
/// the earth's field and `d(t)` any transient disturbance (both NED), `R` the attitude, and `n`
/// white Gaussian noise of standard deviation `noise_sigma` per axis.
///
/// `soft_iron` is the distortion (any invertible matrix); [`Self::true_calibration`] holds its
/// inverse. A two-axis sensor on a tilted body is this model's `x` and `y` outputs: take
/// `reading.xy()`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MagnetometerModel3d {
    hard_iron: Vector3<f64>,
    soft_iron: Matrix3<f64>,
    inverse: Matrix3<f64>,
    noise_sigma: f64,
    disturbances: Disturbances,
    t_s: f64,
}

impl MagnetometerModel3d {
    /// A model with the given hard iron, soft-iron distortion matrix and noise. Refuses
    /// non-finite values, negative noise and a (nearly) singular distortion.
    pub fn new(hard_iron: Vector3<f64>, soft_iron: Matrix3<f64>, noise_sigma: f64) -> Result<Self> {
        check_finite3("hard iron", &hard_iron)?;
        check_noise(noise_sigma)?;
        let inverse = invert_distortion(&soft_iron)?;
        Ok(Self {
            hard_iron,
            soft_iron,
            inverse,
            noise_sigma,
            disturbances: Disturbances::new(),
            t_s: 0.0,
        })
    }

    /// Adds a transient disturbance (builder style).
    pub fn with_disturbance(mut self, d: Disturbance) -> Result<Self> {
        self.disturbances.add(d)?;
        Ok(self)
    }

    /// The hard iron, input unit.
    pub fn hard_iron(&self) -> Vector3<f64> {
        self.hard_iron
    }

    /// The soft-iron distortion matrix.
    pub fn soft_iron(&self) -> Matrix3<f64> {
        self.soft_iron
    }

    /// Noise standard deviation per axis.
    pub fn noise_sigma(&self) -> f64 {
        self.noise_sigma
    }

    /// The transient disturbances.
    pub fn disturbances(&self) -> &Disturbances {
        &self.disturbances
    }

    /// Model time, seconds: the sum of the `dt_s` passed to [`SensorModel::sample`].
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// Sets the model time.
    pub fn set_time_s(&mut self, t_s: f64) {
        self.t_s = t_s;
    }

    /// The calibration that exactly undoes the deterministic errors: corrected readings are
    /// the true body field (a sphere of radius equal to the total field).
    pub fn true_calibration(&self) -> CompassCalibration3d {
        CompassCalibration3d {
            hard_iron: self.hard_iron,
            soft_iron: self.inverse,
        }
    }
}

impl SensorModel for MagnetometerModel3d {
    type Truth = AttitudeTruth;
    type Reading = Vector3<f64>;

    fn ideal(&self, truth: &AttitudeTruth) -> Result<Vector3<f64>> {
        truth.check()?;
        Ok(self.soft_iron * truth.body_field() + self.hard_iron)
    }

    /// Advances model time by `dt_s` (zero is allowed: a second reading at the same
    /// instant), then reads the earth field plus any disturbance active at the new time,
    /// plus noise. A non-finite truth or a negative or non-finite `dt_s` is an error and
    /// leaves the model time unchanged.
    fn sample(
        &mut self,
        truth: &AttitudeTruth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Vector3<f64>> {
        truth.check()?;
        check_range("time step dt_s", dt_s, 0.0, f64::MAX)?;
        self.t_s += dt_s;
        let total = truth.field_ned + self.disturbances.field_at(self.t_s);
        let body = ned_to_body(&truth.attitude, &total);
        let s = self.noise_sigma;
        let n = Vector3::new(noise.normal(s), noise.normal(s), noise.normal(s));
        Ok(self.soft_iron * body + self.hard_iron + n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DisturbanceShape, heading_from_horizontal};
    use proptest::prelude::*;
    use truenorth_core::{Error, ZeroNoise, angle_diff};

    fn any_distortion() -> impl Strategy<Value = Matrix3<f64>> {
        proptest::array::uniform9(-0.3f64..0.3)
            .prop_map(|a| Matrix3::identity() + Matrix3::from_row_slice(&a))
    }

    proptest! {
        #[test]
        fn true_calibration_inverts_the_model(
            h in proptest::array::uniform3(-50.0f64..50.0),
            s in any_distortion(),
            yaw in -3.1f64..3.1, pitch in -1.4f64..1.4, roll in -3.1f64..3.1,
            total in 20.0f64..60.0, incl in -1.4f64..1.4,
        ) {
            prop_assume!(s.determinant().abs() > 0.05);
            let m = MagnetometerModel3d::new(Vector3::from(h), s, 0.0).unwrap();
            let truth = AttitudeTruth {
                attitude: EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll },
                field_ned: earth_field_ned(total, incl),
            };
            let back = m.true_calibration().correct(&m.ideal(&truth).unwrap());
            prop_assert!((back - truth.body_field()).norm() < 1e-9 * total);
            prop_assert!((back.norm() - total).abs() < 1e-9 * total);
        }

        #[test]
        fn level_body_sees_the_2d_convention(yaw in -3.1f64..3.1, incl in -1.4f64..1.4) {
            let truth = AttitudeTruth {
                attitude: EulerZyx { yaw_rad: yaw, pitch_rad: 0.0, roll_rad: 0.0 },
                field_ned: earth_field_ned(50.0, incl),
            };
            let b = truth.body_field();
            // Level: mag_x = H cos ψ, mag_y = −H sin ψ, mag_z = vertical field.
            prop_assert!(angle_diff(heading_from_horizontal(&b.xy()), yaw).abs() < 1e-9);
            prop_assert!((b.z - 50.0 * incl.sin()).abs() < 1e-9);
        }
    }

    #[test]
    fn nose_up_pitch_brings_the_down_field_onto_x() {
        // Heading north, pitched 90° nose up: body x points up, so a purely downward field
        // reads negative on x.
        let truth = AttitudeTruth {
            attitude: EulerZyx {
                yaw_rad: 0.0,
                pitch_rad: core::f64::consts::FRAC_PI_2,
                roll_rad: 0.0,
            },
            field_ned: Vector3::new(0.0, 0.0, 10.0),
        };
        assert!((truth.body_field() - Vector3::new(-10.0, 0.0, 0.0)).norm() < 1e-9);
    }

    #[test]
    fn disturbance_window() {
        let mut m = MagnetometerModel3d::new(Vector3::zeros(), Matrix3::identity(), 0.0)
            .unwrap()
            .with_disturbance(Disturbance {
                start_s: 0.0,
                duration_s: 2.0,
                field_ned: Vector3::new(0.0, 0.0, 7.0),
                shape: DisturbanceShape::RaisedCosine,
            })
            .unwrap();
        let truth = AttitudeTruth {
            attitude: EulerZyx::default(),
            field_ned: earth_field_ned(30.0, 1.0),
        };
        let peak = m.sample(&truth, 1.0, &mut ZeroNoise).unwrap();
        assert!((peak - m.ideal(&truth).unwrap() - Vector3::new(0.0, 0.0, 7.0)).norm() < 1e-9);
        let after = m.sample(&truth, 1.5, &mut ZeroNoise).unwrap();
        assert!((after - m.ideal(&truth).unwrap()).norm() < 1e-12);
    }

    #[test]
    fn singular_is_refused() {
        let mut s = Matrix3::identity();
        s[(2, 2)] = 0.0;
        assert!(matches!(
            MagnetometerModel3d::new(Vector3::zeros(), s, 0.0),
            Err(Error::Degenerate { .. })
        ));
    }
}
