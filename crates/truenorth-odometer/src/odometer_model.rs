//! Forward model of a two-wheel odometer: exact wheel geometry (rear axle, or Ackermann front
//! wheels with kingpin offset), the speed-dependent differential error `(1 + aV²)`
//! (US 4,788,645 eq. 2/8), per-wheel scale error and pulse quantisation.
//!
//! Order of the errors for one step (true motion of the rear-axle centre → raw distances):
//! 1. geometry: true path lengths `D_L, D_R` of the two wheels;
//! 2. speed term: mean kept, difference times `1 + aV²`, V the mean speed of the two wheels;
//! 3. scale: each wheel times `1 + scale_error`;
//! 4. (sample only) quantisation: the wheel's accumulated distance is reported in whole pulses.
//!
//! Steps 1-3 are [`SensorModel::ideal`]; [`OdometerModel::true_calibration`] undoes 2-3 and
//! [`crate::WheelGeometry::motion_from_paths`] undoes 1.

use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{
    NoiseSource, Result, SensorModel, Validate, WheelSample, check_dt, check_finite,
    check_positive, check_range,
};

use crate::differential::speed_factor;
use crate::{OdometerCalibration, OdometerWheels, WheelDistances, WheelGeometry, WheelMotion};

/// Smallest accepted scale error (a gain of 0.001; ≤ 0 could not be inverted).
pub const MIN_SCALE_ERROR: f64 = -0.999;

/// The odometer's true error parameters (and its wheel geometry).
///
/// A forward model's parameters are called `*Params` (not `*Config`): they describe the
/// sensor's actual errors, which a calibration estimates, rather than options a user picks.
/// They are validated like every config ([`Validate`]) and [`OdometerModel::new`] refuses
/// invalid ones.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OdometerParams {
    /// Which wheels, and their geometry.
    pub wheels: OdometerWheels,
    /// Relative scale error of the left wheel (e.g. 0.01: reads 1 % long).
    pub scale_error_l: f64,
    /// Relative scale error of the right wheel.
    pub scale_error_r: f64,
    /// The `a` of `1 + aV²`, s²/m²: how much the wheels' difference is inflated at speed V.
    pub speed_coeff_s2_per_m2: f64,
    /// Distance per odometer pulse, m; `None` for a continuous reading.
    pub dist_per_pulse_m: Option<f64>,
}

impl OdometerParams {
    /// An error-free odometer on `wheels`.
    pub fn perfect(wheels: OdometerWheels) -> Self {
        Self {
            wheels,
            scale_error_l: 0.0,
            scale_error_r: 0.0,
            speed_coeff_s2_per_m2: 0.0,
            dist_per_pulse_m: None,
        }
    }
}

impl Validate for OdometerParams {
    /// The geometry valid (see [`OdometerWheels`]), scale errors ≥ [`MIN_SCALE_ERROR`], `a`
    /// finite, and the pulse length, if any, positive.
    fn validate(&self) -> Result<()> {
        self.wheels.validate()?;
        check_range(
            "odometer scale_error_l",
            self.scale_error_l,
            MIN_SCALE_ERROR,
            f64::MAX,
        )?;
        check_range(
            "odometer scale_error_r",
            self.scale_error_r,
            MIN_SCALE_ERROR,
            f64::MAX,
        )?;
        check_finite("speed coefficient a (s²/m²)", self.speed_coeff_s2_per_m2)?;
        if let Some(d) = self.dist_per_pulse_m {
            check_positive("dist_per_pulse_m", d)?;
        }
        Ok(())
    }
}

/// Quantities derived from [`OdometerParams`] once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometerCoefficients {
    /// The built wheel geometry.
    pub geometry: WheelGeometry,
    /// Left gain, `1 + scale_error_l`.
    pub gain_l: f64,
    /// Right gain, `1 + scale_error_r`.
    pub gain_r: f64,
}

/// The model's running state: what each wheel has accumulated.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OdometerState {
    /// Accumulated raw (scaled, unquantised) distance, m.
    pub raw_l_m: f64,
    /// Accumulated raw right distance, m.
    pub raw_r_m: f64,
    /// Whole pulses reported so far, left (an integer; a float so that it cannot overflow).
    pub pulses_l: f64,
    /// Whole pulses reported so far, right.
    pub pulses_r: f64,
}

/// Forward model of a two-wheel odometer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometerModel {
    params: OdometerParams,
    coeffs: OdometerCoefficients,
    state: OdometerState,
}

impl OdometerModel {
    /// Validates the parameters and builds the model (all accumulators at zero).
    pub fn new(params: OdometerParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            coeffs: OdometerCoefficients {
                geometry: WheelGeometry::new(params.wheels)?,
                gain_l: 1.0 + params.scale_error_l,
                gain_r: 1.0 + params.scale_error_r,
            },
            state: OdometerState::default(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &OdometerParams {
        &self.params
    }

    /// The derived coefficients.
    pub fn coefficients(&self) -> &OdometerCoefficients {
        &self.coeffs
    }

    /// The wheel geometry.
    pub fn geometry(&self) -> &WheelGeometry {
        &self.coeffs.geometry
    }

    /// The running state.
    pub fn state(&self) -> &OdometerState {
        &self.state
    }

    /// Sets every accumulator back to zero.
    pub fn reset_state(&mut self) {
        self.state = OdometerState::default();
    }

    /// The model's true inverse of its deterministic errors (gains and `a`).
    pub fn true_calibration(&self) -> OdometerCalibration {
        OdometerCalibration {
            gain_l: self.coeffs.gain_l,
            gain_r: self.coeffs.gain_r,
            speed_coeff_s2_per_m2: self.params.speed_coeff_s2_per_m2,
        }
    }

    /// Mean speed of the two odometer wheels, m/s: `|speed_mps|·(f_L + f_R)/2`, where `f` is
    /// a wheel's path per metre of rear-axle travel (1 for rear wheels). This is the V of
    /// `1 + aV²`, and what `|AD|/dt` measures.
    pub fn wheel_speed_mps(&self, truth: &WheelMotion) -> Result<f64> {
        let v = check_finite("speed_mps", truth.speed_mps)?;
        let f = self
            .coeffs
            .geometry
            .wheel_paths_m(1.0, truth.curvature_per_m)?;
        Ok(v.abs() * 0.5 * (f.left_m + f.right_m))
    }

    /// Geometry, speed term and scale, no quantisation (see [`SensorModel::ideal`]).
    fn deterministic(&self, truth: &WheelMotion) -> Result<WheelDistances> {
        truth.check_finite()?;
        let rolled = self
            .coeffs
            .geometry
            .wheel_paths_m(truth.ds_m, truth.curvature_per_m)?;
        let pivot = self.coeffs.geometry.pivot_paths_m(truth.pivot_rad)?;
        let paths = WheelDistances {
            left_m: rolled.left_m + pivot.left_m,
            right_m: rolled.right_m + pivot.right_m,
        };
        let factor = speed_factor(
            self.params.speed_coeff_s2_per_m2,
            self.wheel_speed_mps(truth)?,
        )?;
        let mean = 0.5 * (paths.left_m + paths.right_m);
        let half_diff = 0.5 * (paths.left_m - paths.right_m) * factor;
        // Huge finite inputs can overflow; a typed error instead of an infinite reading.
        Ok(WheelDistances {
            left_m: check_finite(
                "left odometer reading (inputs too large)",
                self.coeffs.gain_l * (mean + half_diff),
            )?,
            right_m: check_finite(
                "right odometer reading (inputs too large)",
                self.coeffs.gain_r * (mean - half_diff),
            )?,
        })
    }

    /// One quantised step (see [`SensorModel::sample`]); on error the state is unchanged.
    fn advance(&mut self, truth: &WheelMotion, dt_s: f64) -> Result<WheelDistances> {
        let d = self.deterministic(truth)?;
        check_dt(dt_s)?;
        let raw_l = check_finite("accumulated left distance", self.state.raw_l_m + d.left_m)?;
        let raw_r = check_finite("accumulated right distance", self.state.raw_r_m + d.right_m)?;
        let Some(dpp) = self.params.dist_per_pulse_m else {
            self.state.raw_l_m = raw_l;
            self.state.raw_r_m = raw_r;
            return Ok(d);
        };
        // Pulses counted so far = whole pulses in the accumulated distance (floor, so that
        // reversing counts down the same way).
        let pulses_l = (raw_l / dpp).floor();
        let pulses_r = (raw_r / dpp).floor();
        let out = WheelDistances {
            left_m: check_finite("left pulse step", (pulses_l - self.state.pulses_l) * dpp)?,
            right_m: check_finite("right pulse step", (pulses_r - self.state.pulses_r) * dpp)?,
        };
        self.state = OdometerState {
            raw_l_m: raw_l,
            raw_r_m: raw_r,
            pulses_l,
            pulses_r,
        };
        Ok(out)
    }

    /// What the odometer reports in total so far (left, right), m: whole pulses times the
    /// distance per pulse, or the raw accumulated distance without quantisation.
    pub fn cumulative_m(&self) -> WheelDistances {
        match self.params.dist_per_pulse_m {
            Some(dpp) => WheelDistances {
                left_m: self.state.pulses_l * dpp,
                right_m: self.state.pulses_r * dpp,
            },
            None => WheelDistances {
                left_m: self.state.raw_l_m,
                right_m: self.state.raw_r_m,
            },
        }
    }

    /// Advances the model by one step and returns the cumulative reading at `t_s` as the
    /// core [`WheelSample`] (what `DRIVE.csv`'s `dist_l_m`, `dist_r_m` hold).
    pub fn sample_cumulative(
        &mut self,
        t_s: f64,
        truth: &WheelMotion,
        dt_s: f64,
    ) -> Result<WheelSample> {
        check_finite("timestamp t_s", t_s)?;
        self.advance(truth, dt_s)?;
        let c = self.cumulative_m();
        Ok(WheelSample {
            t_s,
            dist_l_m: c.left_m,
            dist_r_m: c.right_m,
        })
    }
}

impl SensorModel for OdometerModel {
    type Truth = WheelMotion;
    type Reading = WheelDistances;

    /// Raw distances of one step: geometry, speed term and scale, no quantisation. A typed
    /// error for a non-finite truth, a curvature the geometry cannot make, `1 + aV² ≤ 0`, or
    /// a reading too large to represent.
    fn ideal(&self, truth: &WheelMotion) -> Result<WheelDistances> {
        self.deterministic(truth)
    }

    /// One step's raw distances after pulse quantisation (each a whole number of pulses; the
    /// remainder carries over to the next step). The odometer has no random error of its own
    /// here (random slip belongs to the vehicle simulation), so `noise` is not drawn from.
    /// On error (as for [`SensorModel::ideal`], or `dt_s` not positive and finite) the state
    /// is unchanged.
    fn sample(
        &mut self,
        truth: &WheelMotion,
        dt_s: f64,
        _noise: &mut dyn NoiseSource,
    ) -> Result<WheelDistances> {
        self.advance(truth, dt_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AckermannParams;
    use proptest::prelude::*;
    use truenorth_core::{Calibration, Error, ZeroNoise};

    use crate::OdometerRaw;

    fn wheels() -> impl Strategy<Value = OdometerWheels> {
        prop_oneof![
            (1.2f64..1.9).prop_map(|t| OdometerWheels::Rear { track_m: t }),
            (2.0f64..3.5, 1.2f64..1.9, 0.0f64..0.2).prop_map(|(b, t, p)| {
                OdometerWheels::Front(AckermannParams {
                    wheelbase_m: b,
                    track_m: t,
                    kingpin_offset_m: p,
                })
            }),
        ]
    }

    fn params() -> impl Strategy<Value = OdometerParams> {
        (wheels(), -0.05f64..0.05, -0.05f64..0.05, 0.0f64..2e-3).prop_map(|(w, sl, sr, a)| {
            OdometerParams {
                wheels: w,
                scale_error_l: sl,
                scale_error_r: sr,
                speed_coeff_s2_per_m2: a,
                dist_per_pulse_m: None,
            }
        })
    }

    /// Largest curvature the inverse covers for this geometry.
    fn k_max(m: &OdometerModel) -> f64 {
        match m.geometry() {
            WheelGeometry::Rear { .. } => 0.5,
            WheelGeometry::Front(g) => g.peak_curvature_per_m(),
        }
    }

    proptest! {
        /// truth → model.ideal → true calibration → geometry inverse gives back the truth.
        #[test]
        fn ideal_then_true_inverse_gives_the_motion(
            p in params(), u in -0.999f64..0.999, ds in -5.0f64..5.0, v in 0.0f64..40.0,
        ) {
            let m = OdometerModel::new(p).unwrap();
            let truth = WheelMotion { ds_m: ds, curvature_per_m: u * k_max(&m), speed_mps: v, pivot_rad: 0.0 };
            let raw = m.ideal(&truth).unwrap();
            let raw = OdometerRaw {
                dist_l_m: raw.left_m,
                dist_r_m: raw.right_m,
                wheel_speed_mps: m.wheel_speed_mps(&truth).unwrap(),
            };
            let paths = m.true_calibration().apply(&raw).unwrap();
            let want = m.geometry().wheel_paths_m(ds, truth.curvature_per_m).unwrap();
            prop_assert!((paths.left_m - want.left_m).abs() < 1e-12 * (1.0 + ds.abs()));
            prop_assert!((paths.right_m - want.right_m).abs() < 1e-12 * (1.0 + ds.abs()));
            let back = m.geometry().motion_from_paths(paths.left_m, paths.right_m).unwrap();
            prop_assert!((back.ds_m - ds).abs() < 1e-9 * (1.0 + ds.abs()));
            prop_assert!((back.heading_change_rad - truth.curvature_per_m * ds).abs()
                < 1e-9 * (1.0 + ds.abs()));
        }

        /// The speed term inflates the difference by exactly 1 + aV² and keeps the mean.
        #[test]
        fn speed_term_inflates_the_difference(
            w in wheels(), a in 1e-5f64..2e-3, v in 0.0f64..40.0, u in 0.01f64..0.9,
        ) {
            let with = OdometerModel::new(OdometerParams { speed_coeff_s2_per_m2: a, ..OdometerParams::perfect(w) }).unwrap();
            let without = OdometerModel::new(OdometerParams::perfect(w)).unwrap();
            let truth = WheelMotion { ds_m: 1.0, curvature_per_m: u * k_max(&with), speed_mps: v, pivot_rad: 0.0 };
            let (d1, d0) = (with.ideal(&truth).unwrap(), without.ideal(&truth).unwrap());
            let vw = with.wheel_speed_mps(&truth).unwrap();
            let ratio = (d1.left_m - d1.right_m) / (d0.left_m - d0.right_m);
            prop_assert!((ratio - (1.0 + a * vw * vw)).abs() < 1e-9);
            prop_assert!((d1.left_m + d1.right_m - d0.left_m - d0.right_m).abs() < 1e-12);
        }

        /// Quantised steps are whole pulses; the reported total never runs ahead of the raw
        /// distance and never lags it by a pulse or more.
        #[test]
        fn quantisation_reports_whole_pulses(
            dpp in 0.01f64..0.5,
            steps in proptest::collection::vec((-1.0f64..3.0, -0.1f64..0.1), 1..200),
        ) {
            let mut m = OdometerModel::new(OdometerParams {
                dist_per_pulse_m: Some(dpp),
                scale_error_l: 0.02,
                ..OdometerParams::perfect(OdometerWheels::Rear { track_m: 1.5 })
            }).unwrap();
            let (mut sum_l, mut sum_r) = (0.0, 0.0);
            for (ds, k) in steps {
                let d = m.sample(&WheelMotion { ds_m: ds, curvature_per_m: k, speed_mps: 10.0, pivot_rad: 0.0 }, 0.1, &mut ZeroNoise).unwrap();
                for x in [d.left_m, d.right_m] {
                    let n = x / dpp;
                    prop_assert!((n - n.round()).abs() < 1e-6, "{x} is not whole pulses of {dpp}");
                }
                sum_l += d.left_m;
                sum_r += d.right_m;
                let c = m.cumulative_m();
                prop_assert!((c.left_m - sum_l).abs() < 1e-9 && (c.right_m - sum_r).abs() < 1e-9);
                let s = m.state();
                for (rep, raw) in [(c.left_m, s.raw_l_m), (c.right_m, s.raw_r_m)] {
                    prop_assert!(rep <= raw + 1e-9 && raw - rep < dpp + 1e-9, "{rep} vs {raw}");
                }
            }
        }

        #[test]
        fn no_panic_and_typed_errors_on_any_input(
            ds in proptest::num::f64::ANY, k in proptest::num::f64::ANY,
            v in proptest::num::f64::ANY, dt in proptest::num::f64::ANY, front in any::<bool>(),
        ) {
            let w = if front {
                OdometerWheels::Front(AckermannParams { wheelbase_m: 2.7, track_m: 1.55, kingpin_offset_m: 0.1 })
            } else {
                OdometerWheels::Rear { track_m: 1.5 }
            };
            let mut m = OdometerModel::new(OdometerParams {
                dist_per_pulse_m: Some(0.02), speed_coeff_s2_per_m2: 1e-3, ..OdometerParams::perfect(w)
            }).unwrap();
            let before = m;
            let truth = WheelMotion { ds_m: ds, curvature_per_m: k, speed_mps: v, pivot_rad: 0.0 };
            let finite = ds.is_finite() && k.is_finite() && v.is_finite();
            let r = m.sample(&truth, dt, &mut ZeroNoise);
            if !(finite && dt.is_finite() && dt > 0.0) {
                prop_assert!(r.is_err());
            }
            if !finite {
                let non_finite = matches!(r, Err(Error::NonFinite { .. }));
                prop_assert!(non_finite, "{r:?}");
                let non_finite = matches!(m.ideal(&truth), Err(Error::NonFinite { .. }));
                prop_assert!(non_finite);
            }
            match r {
                Ok(d) => prop_assert!(d.left_m.is_finite() && d.right_m.is_finite()),
                Err(_) => prop_assert_eq!(m, before),
            }
            if let Ok(d) = m.ideal(&truth) {
                prop_assert!(d.left_m.is_finite() && d.right_m.is_finite());
            }
            let before = m;
            match m.sample_cumulative(dt, &truth, 0.1) {
                Ok(s) => prop_assert!(s.dist_l_m.is_finite() && s.dist_r_m.is_finite()),
                Err(_) => prop_assert_eq!(m, before),
            }
            let _ = OdometerModel::new(OdometerParams { dist_per_pulse_m: Some(ds), ..OdometerParams::perfect(w) });
        }
    }

    #[test]
    fn invalid_params_are_rejected() {
        let rear = OdometerParams::perfect(OdometerWheels::Rear { track_m: 1.5 });
        for bad in [
            OdometerParams {
                scale_error_l: -1.0,
                ..rear
            },
            OdometerParams {
                speed_coeff_s2_per_m2: f64::NAN,
                ..rear
            },
            OdometerParams {
                dist_per_pulse_m: Some(0.0),
                ..rear
            },
            OdometerParams::perfect(OdometerWheels::Rear { track_m: 0.0 }),
        ] {
            assert!(OdometerModel::new(bad).is_err(), "{bad:?}");
        }
        // A negative a that makes 1 + aV² vanish is refused per sample, not turned into NaN.
        let m = OdometerModel::new(OdometerParams {
            speed_coeff_s2_per_m2: -0.01,
            ..rear
        })
        .unwrap();
        let fast = WheelMotion {
            ds_m: 1.0,
            curvature_per_m: 0.1,
            speed_mps: 20.0,
            pivot_rad: 0.0,
        };
        assert!(matches!(m.ideal(&fast), Err(Error::OutOfRange { .. })));
    }
}
