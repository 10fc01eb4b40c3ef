//! Forward model of a level two-axis magnetometer in a vehicle: truth (heading and horizontal
//! field) → raw reading with hard iron, soft iron, noise and transient disturbances.

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use truenorth_core::check_range;
use truenorth_core::{NoiseSource, Result, SensorModel, check_finite, check_finite2};

use crate::distortion::invert_distortion;
use crate::{CompassCalibration2d, Disturbance, Disturbances};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// What a level compass should see: the vehicle's heading and the earth's horizontal field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeadingTruth {
    /// True magnetic heading, radians clockwise from magnetic north.
    pub heading_rad: f64,
    /// Horizontal field strength, in the unit the readings should come out in.
    pub horizontal_field: f64,
}

impl HeadingTruth {
    /// The undistorted body-axis field `(H cos ψ, −H sin ψ)` (ARCHITECTURE.md "Frames and
    /// signs").
    pub fn body_field(&self) -> Vector2<f64> {
        let (s, c) = self.heading_rad.sin_cos();
        Vector2::new(self.horizontal_field * c, -self.horizontal_field * s)
    }

    fn check(&self) -> Result<()> {
        check_finite("true heading", self.heading_rad)?;
        check_finite("true horizontal field", self.horizontal_field).map(drop)
    }
}

/// A level two-axis magnetometer: `raw = soft_iron · (b + d(t)) + hard_iron + n`, with `b` the
/// earth's horizontal field in body axes, `d(t)` the horizontal part of any transient
/// disturbance (rotated into body axes), and `n` white Gaussian noise of standard deviation
/// `noise_sigma` on each axis.
///
/// `soft_iron` here is the *distortion* (any invertible matrix); the calibration that undoes
/// it, [`MagnetometerModel2d::true_calibration`], holds its inverse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MagnetometerModel2d {
    hard_iron: Vector2<f64>,
    soft_iron: Matrix2<f64>,
    inverse: Matrix2<f64>,
    noise_sigma: f64,
    disturbances: Disturbances,
    t_s: f64,
}

impl MagnetometerModel2d {
    /// A model with the given hard iron (offset), soft-iron distortion matrix and noise.
    ///
    /// Refuses non-finite values, a negative noise level and a singular (or nearly singular)
    /// distortion, which no calibration could undo.
    pub fn new(hard_iron: Vector2<f64>, soft_iron: Matrix2<f64>, noise_sigma: f64) -> Result<Self> {
        check_finite2("hard iron", &hard_iron)?;
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
    pub fn hard_iron(&self) -> Vector2<f64> {
        self.hard_iron
    }

    /// The soft-iron distortion matrix.
    pub fn soft_iron(&self) -> Matrix2<f64> {
        self.soft_iron
    }

    /// Noise standard deviation per axis, input unit.
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

    /// Sets the model time (e.g. back to 0 to replay a scenario).
    pub fn set_time_s(&mut self, t_s: f64) {
        self.t_s = t_s;
    }

    /// The calibration that exactly undoes this model's deterministic errors: corrected
    /// readings are the true body field, a circle of radius equal to the true horizontal field.
    pub fn true_calibration(&self) -> CompassCalibration2d {
        CompassCalibration2d {
            hard_iron: self.hard_iron,
            soft_iron: self.inverse,
        }
    }

    fn distort(&self, body: &Vector2<f64>) -> Vector2<f64> {
        self.soft_iron * body + self.hard_iron
    }
}

/// The horizontal (north, east) part of an NED vector, rotated into the body axes of a
/// vehicle at heading `heading_rad`: `(N cos ψ + E sin ψ, −N sin ψ + E cos ψ)`.
pub(crate) fn ned_to_level_body(n: f64, e: f64, heading_rad: f64) -> Vector2<f64> {
    let (s, c) = heading_rad.sin_cos();
    Vector2::new(n * c + e * s, -n * s + e * c)
}

pub(crate) fn check_noise(noise_sigma: f64) -> Result<()> {
    check_range("noise standard deviation", noise_sigma, 0.0, f64::INFINITY).map(drop)
}

impl SensorModel for MagnetometerModel2d {
    type Truth = HeadingTruth;
    type Reading = Vector2<f64>;

    fn ideal(&self, truth: &HeadingTruth) -> Result<Vector2<f64>> {
        truth.check()?;
        Ok(self.distort(&truth.body_field()))
    }

    /// Advances model time by `dt_s` (zero is allowed: a second reading at the same
    /// instant), then reads the earth field plus any disturbance active at the new time,
    /// plus noise. A non-finite truth or a negative or non-finite `dt_s` is an error and
    /// leaves the model time unchanged.
    fn sample(
        &mut self,
        truth: &HeadingTruth,
        dt_s: f64,
        noise: &mut dyn NoiseSource,
    ) -> Result<Vector2<f64>> {
        truth.check()?;
        check_range("time step dt_s", dt_s, 0.0, f64::MAX)?;
        self.t_s += dt_s;
        let d = self.disturbances.field_at(self.t_s);
        let body = truth.body_field() + ned_to_level_body(d.x, d.y, truth.heading_rad);
        let n = Vector2::new(
            noise.normal(self.noise_sigma),
            noise.normal(self.noise_sigma),
        );
        Ok(self.distort(&body) + n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DisturbanceShape, soft_iron_from_axes};
    use nalgebra::Vector3;
    use proptest::prelude::*;
    use truenorth_core::{Error, SplitMix64, ZeroNoise, angle_diff};

    fn any_distortion() -> impl Strategy<Value = Matrix2<f64>> {
        (0.5f64..2.0, 0.5f64..2.0, -3.2f64..3.2, -0.3f64..0.3).prop_map(|(g1, g2, a, skew)| {
            // Symmetric part plus a small rotation: a general invertible distortion.
            let (s, c) = skew.sin_cos();
            Matrix2::new(c, -s, s, c) * soft_iron_from_axes(g1, g2, a)
        })
    }

    proptest! {
        #[test]
        fn true_calibration_inverts_the_model(
            hx in -50.0f64..50.0, hy in -50.0f64..50.0,
            s in any_distortion(),
            heading in -3.2f64..3.2, h in 1.0f64..60.0,
        ) {
            let m = MagnetometerModel2d::new(Vector2::new(hx, hy), s, 0.0).unwrap();
            let truth = HeadingTruth { heading_rad: heading, horizontal_field: h };
            let cal = m.true_calibration();
            let back = cal.correct(&m.ideal(&truth).unwrap());
            prop_assert!((back - truth.body_field()).norm() < 1e-9 * h.max(1.0));
            prop_assert!(angle_diff(cal.heading_rad(&m.ideal(&truth).unwrap()), heading).abs() < 1e-9);
        }

        #[test]
        fn zero_noise_sample_equals_ideal(heading in -3.2f64..3.2, dt in 0.0f64..1.0) {
            let mut m = MagnetometerModel2d::new(
                Vector2::new(3.0, -2.0), soft_iron_from_axes(1.3, 1.0, 0.5), 0.5).unwrap();
            let truth = HeadingTruth { heading_rad: heading, horizontal_field: 20.0 };
            prop_assert_eq!(m.sample(&truth, dt, &mut ZeroNoise).unwrap(), m.ideal(&truth).unwrap());
        }
    }

    #[test]
    fn noise_has_the_stated_sigma() {
        let mut m = MagnetometerModel2d::new(Vector2::zeros(), Matrix2::identity(), 0.3).unwrap();
        let truth = HeadingTruth {
            heading_rad: 0.4,
            horizontal_field: 10.0,
        };
        let ideal = m.ideal(&truth).unwrap();
        let mut rng = SplitMix64::new(3);
        let n = 20_000;
        let ss: f64 = (0..n)
            .map(|_| (m.sample(&truth, 0.01, &mut rng).unwrap() - ideal).norm_squared())
            .sum();
        let sigma = (ss / (2.0 * n as f64)).sqrt();
        assert!((sigma - 0.3).abs() < 0.01, "{sigma}");
    }

    #[test]
    fn disturbance_adds_a_world_fixed_field_in_its_window() {
        let d = Disturbance {
            start_s: 1.0,
            duration_s: 1.0,
            field_ned: Vector3::new(0.0, 5.0, 0.0), // 5 units towards east
            shape: DisturbanceShape::Step,
        };
        let mut m = MagnetometerModel2d::new(Vector2::zeros(), Matrix2::identity(), 0.0)
            .unwrap()
            .with_disturbance(d)
            .unwrap();
        // Heading east: the east field lies along body x.
        let truth = HeadingTruth {
            heading_rad: core::f64::consts::FRAC_PI_2,
            horizontal_field: 10.0,
        };
        let before = m.sample(&truth, 0.5, &mut ZeroNoise).unwrap();
        let during = m.sample(&truth, 1.0, &mut ZeroNoise).unwrap();
        let after = m.sample(&truth, 1.0, &mut ZeroNoise).unwrap();
        assert!((during - before - Vector2::new(5.0, 0.0)).norm() < 1e-9);
        assert!((after - before).norm() < 1e-12);
        assert_eq!(m.time_s(), 2.5);
    }

    #[test]
    fn singular_or_bad_inputs_are_refused() {
        let z = Vector2::zeros();
        assert!(matches!(
            MagnetometerModel2d::new(z, Matrix2::new(1.0, 2.0, 2.0, 4.0), 0.0),
            Err(Error::Degenerate { .. })
        ));
        assert!(MagnetometerModel2d::new(z, Matrix2::identity(), -1.0).is_err());
        assert!(
            MagnetometerModel2d::new(Vector2::new(f64::NAN, 0.0), Matrix2::identity(), 0.0)
                .is_err()
        );
        assert!(MagnetometerModel2d::new(z, Matrix2::identity() * f64::INFINITY, 0.0).is_err());
    }
}
