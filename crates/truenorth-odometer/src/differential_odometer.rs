//! A differential odometer as a relative heading source: cumulative wheel distances in,
//! heading change and distance per step out (US 4,788,645 eqs. 2/8 and 3/14).

use serde::{Deserialize, Serialize};
use truenorth_core::{
    RelativeHeadingSource, RelativeStep, Result, TimeStep, Validate, WheelSample, check_finite,
};

use crate::differential::{check_speed_factor, curvature_ratio};
use crate::{EffectiveTrack, OdometerCalibration, OdometryStep, WheelDistances};

/// Settings of a [`DifferentialOdometer`] (the effective-track source, a built object, is
/// passed to [`DifferentialOdometer::new`] beside it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DifferentialOdometerConfig {
    /// Wheel calibration applied to every step. Default [`OdometerCalibration::IDENTITY`]:
    /// raw wheels, the plain heading change of eq. 1.
    pub calibration: OdometerCalibration,
}

impl Validate for DifferentialOdometerConfig {
    /// The calibration's gains positive and `a` finite.
    fn validate(&self) -> Result<()> {
        self.calibration.validate()
    }
}

/// What one step of a [`DifferentialOdometer`] found.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct OdometerStep {
    /// Time since the previous sample, s (> 0).
    pub dt_s: f64,
    /// Heading change, radians, positive for a right turn.
    pub heading_change_rad: f64,
    /// Mean distance of the two wheels after calibration (AD), m: the distance travelled by
    /// the midpoint between the odometer wheels (negative when reversing).
    pub mean_dist_m: f64,
    /// Mean speed of the two wheels over the step, m/s.
    pub wheel_speed_mps: f64,
    /// Curvature ratio ΔD/AD after the speed correction.
    pub ratio: f64,
    /// Effective track used, m.
    pub effective_track_m: f64,
}

impl From<OdometerStep> for RelativeStep {
    fn from(s: OdometerStep) -> Self {
        Self {
            dt_s: s.dt_s,
            heading_change_rad: s.heading_change_rad,
            distance_m: Some(s.mean_dist_m),
        }
    }
}

/// Heading change and distance from two wheels' cumulative distances.
///
/// Per step: differences of the cumulative distances → per-wheel scale removed → wheel speed
/// `V = |AD|/dt` → difference divided by `1 + aV²` (eq. 2/8) → ratio `c = ΔD/AD` → track
/// `T_E(c)` from `T` (fixed, patent formula, look-up table or exact geometry) → `Δθ = ΔD/T_E`.
///
/// The ratio is taken after the speed correction, so that the Ackermann geometry sees the
/// geometric ratio; the patent feeds it the raw ΔD/AD, which is the same when `a = 0`.
///
/// The distance reported ([`RelativeStep::distance_m`], [`OdometerStep::mean_dist_m`]) is
/// that of the midpoint between the odometer wheels. On a rear axle that is the rear-axle
/// centre, which moves along the heading. On Ackermann-steered front wheels it is the mean of
/// the front wheels' paths, which exceeds the rear-axle centre's by about `√(1 + (Bκ)²)` in a
/// turn of curvature κ (wheelbase B): for B = 2.7 m, 0.1 % on a 60 m rear-axle radius and
/// 14 % on a 5 m one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DifferentialOdometer<T> {
    track: T,
    config: DifferentialOdometerConfig,
    clock: TimeStep,
    last_m: Option<WheelDistances>,
    heading_rad: f64,
}

impl<T: EffectiveTrack> DifferentialOdometer<T> {
    /// A differential odometer with effective-track source `track` and a validated `config`.
    pub fn new(track: T, config: DifferentialOdometerConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            track,
            config,
            clock: TimeStep::new(),
            last_m: None,
            heading_rad: 0.0,
        })
    }

    /// The effective-track source.
    pub fn track(&self) -> &T {
        &self.track
    }

    /// The settings in use.
    pub fn config(&self) -> &DifferentialOdometerConfig {
        &self.config
    }

    /// The wheel calibration in use.
    pub fn calibration(&self) -> &OdometerCalibration {
        &self.config.calibration
    }

    /// Replaces the calibration (e.g. with a refined `a`, US 4,788,645 eq. 2/8); from the next step.
    /// An invalid calibration is refused and the old one kept.
    pub fn set_calibration(&mut self, calibration: OdometerCalibration) -> Result<()> {
        calibration.validate()?;
        self.config.calibration = calibration;
        Ok(())
    }

    /// Heading change accumulated since construction or reset, radians, not wrapped.
    pub fn heading_rad(&self) -> f64 {
        self.heading_rad
    }

    /// Feeds one cumulative reading and returns what the step since the previous one gave
    /// (`None` for the first). On any error (non-finite value, time not increasing, a turn
    /// tighter than the track source covers, `1 + aV² ≤ 0`) nothing changes, so the next
    /// accepted sample covers the skipped interval too.
    pub fn push(&mut self, sample: &WheelSample) -> Result<Option<OdometerStep>> {
        let l = check_finite("dist_l_m", sample.dist_l_m)?;
        let r = check_finite("dist_r_m", sample.dist_r_m)?;
        let mut clock = self.clock;
        let dt = clock.dt_s(sample.t_s)?;
        let step = match (dt, self.last_m) {
            (Some(dt_s), Some(last)) => Some(self.compute_step(
                check_finite("left wheel step (distances too large)", l - last.left_m)?,
                check_finite("right wheel step (distances too large)", r - last.right_m)?,
                dt_s,
            )?),
            _ => None,
        };
        self.clock = clock;
        self.last_m = Some(WheelDistances {
            left_m: l,
            right_m: r,
        });
        if let Some(s) = step {
            self.heading_rad += s.heading_change_rad;
        }
        Ok(step)
    }

    fn compute_step(&self, raw_l_m: f64, raw_r_m: f64, dt_s: f64) -> Result<OdometerStep> {
        let calibration = &self.config.calibration;
        let u = calibration.unscale(raw_l_m, raw_r_m)?;
        // No floor on the speed factor: one that is not positive is refused below.
        let step = OdometryStep::new(
            &u,
            dt_s,
            calibration.speed_coeff_s2_per_m2,
            f64::NEG_INFINITY,
        );
        // The speed term leaves the mean alone, so the mean of the unscaled wheels is true.
        let mean = check_finite("mean wheel distance (distances too large)", step.mean_m)?;
        let wheel_speed_mps = check_finite("wheel speed", step.speed_mps)?;
        check_speed_factor(step.speed_factor)?;
        let diff = step.diff_m;
        let ratio = curvature_ratio(mean + 0.5 * diff, mean - 0.5 * diff)?;
        let effective_track_m = self.track.effective_track_m(ratio)?;
        Ok(OdometerStep {
            dt_s,
            heading_change_rad: check_finite(
                "heading change (distances too large)",
                step.turn(effective_track_m, 1.0).heading_change_rad,
            )?,
            mean_dist_m: mean,
            wheel_speed_mps,
            ratio,
            effective_track_m,
        })
    }
}

impl<T: EffectiveTrack> RelativeHeadingSource for DifferentialOdometer<T> {
    type Sample = WheelSample;

    /// See [`DifferentialOdometer::push`]; the step's `distance_m` is
    /// [`OdometerStep::mean_dist_m`].
    fn step(&mut self, sample: &WheelSample) -> Result<Option<RelativeStep>> {
        Ok(self.push(sample)?.map(RelativeStep::from))
    }

    fn reset(&mut self) {
        self.clock.reset();
        self.last_m = None;
        self.heading_rad = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        AckermannGeometry, AckermannParams, EffectiveTrackTable, FixedTrack, OdometerModel,
        OdometerParams, OdometerWheels, PatentAckermannTrack, WheelMotion,
    };
    use proptest::prelude::*;
    use truenorth_core::Error;

    const CAR: AckermannParams = AckermannParams {
        wheelbase_m: 2.7,
        track_m: 1.55,
        kingpin_offset_m: 0.10,
    };

    type Steps = Vec<(f64, f64, f64)>;

    fn config(calibration: OdometerCalibration) -> DifferentialOdometerConfig {
        DifferentialOdometerConfig { calibration }
    }

    /// Drives `model` through `steps` (dt, speed, curvature) and feeds `odo`; returns the
    /// true and the odometer's heading change.
    fn drive<T: EffectiveTrack>(
        model: &mut OdometerModel,
        odo: &mut DifferentialOdometer<T>,
        steps: &Steps,
    ) -> (f64, f64) {
        let mut t = 100.0;
        let first = model
            .sample_cumulative(t, &WheelMotion::default(), 1.0)
            .unwrap();
        assert_eq!(odo.push(&first).unwrap(), None);
        let mut truth = 0.0;
        for &(dt, v, k) in steps {
            t += dt;
            let m = WheelMotion {
                ds_m: v * dt,
                curvature_per_m: k,
                speed_mps: v,
                pivot_rad: 0.0,
            };
            truth += k * v * dt;
            let s = model.sample_cumulative(t, &m, dt).unwrap();
            let step = odo.step(&s).unwrap().unwrap();
            assert!((step.dt_s - dt).abs() < 1e-9);
            // With the true calibration the distance is the rear-axle centre's on rear wheels;
            // the front wheels' mean is at least that, in the same direction.
            let d = step.distance_m.unwrap();
            assert!(d.abs() >= (v * dt).abs() * (1.0 - 1e-9) - 1e-12 && d * v >= 0.0);
        }
        (truth, odo.heading_rad())
    }

    fn steps(k_max: f64) -> impl Strategy<Value = Steps> {
        proptest::collection::vec((0.01f64..1.0, -3.0f64..30.0, -k_max..k_max), 1..60)
    }

    proptest! {
        /// Rear wheels with scale errors and a speed term: with the true calibration the
        /// heading change is exact; without it, it is not (so the test can fail).
        #[test]
        fn rear_wheels_with_true_calibration_give_the_true_heading(
            sl in -0.05f64..0.05, sr in -0.05f64..0.05, a in 1e-5f64..1e-3, st in steps(0.2),
        ) {
            let p = OdometerParams {
                scale_error_l: sl, scale_error_r: sr, speed_coeff_s2_per_m2: a,
                ..OdometerParams::perfect(OdometerWheels::Rear { track_m: 1.5 })
            };
            let mut model = OdometerModel::new(p).unwrap();
            let mut odo = DifferentialOdometer::new(FixedTrack::new(1.5).unwrap(), config(model.true_calibration())).unwrap();
            let (truth, got) = drive(&mut model, &mut odo, &st);
            prop_assert!((got - truth).abs() < 1e-9 * (1.0 + truth.abs()), "{got} vs {truth}");
        }

        /// Front wheels: the exact geometry recovers the heading change exactly.
        #[test]
        fn front_wheels_with_exact_geometry_give_the_true_heading(
            a in 0.0f64..1e-3, sl in -0.03f64..0.03, st in steps(0.23),
        ) {
            let p = OdometerParams {
                scale_error_l: sl, speed_coeff_s2_per_m2: a, ..OdometerParams::perfect(OdometerWheels::Front(CAR))
            };
            let mut model = OdometerModel::new(p).unwrap();
            let g = AckermannGeometry::new(CAR).unwrap();
            let mut odo = DifferentialOdometer::new(g, config(model.true_calibration())).unwrap();
            let (truth, got) = drive(&mut model, &mut odo, &st);
            prop_assert!((got - truth).abs() < 1e-9 * (1.0 + truth.abs()), "{got} vs {truth}");
        }

        /// Front wheels through the patent's formula and its 256-entry table, on turns no
        /// tighter than a 5 m rear-axle radius (|κ| < 0.2/m): each step's heading is
        /// `ΔD/T_used` against the true `ΔD/T_E,exact`, so it is off by
        /// `T_E,exact(c)/T_used(c) − 1` of that step's turn. Both tracks fall with |c| (see
        /// `tests/patent_vs_exact.rs`), so on a cell `a ≤ |c| ≤ b` the ratio is at most
        /// `T_E,exact(a)/T_used(b) − 1`; a table value interpolates between the formula at its
        /// cell ends and is at least the formula at `b`. The bound is the largest such ratio
        /// over cells covering `0..c(0.2/m)`: 1024 fine cells for the formula, the table's own
        /// cells for the table.
        #[test]
        fn front_wheels_with_the_patent_formula_are_close(st in steps(0.2)) {
            let mut model = OdometerModel::new(OdometerParams::perfect(OdometerWheels::Front(CAR))).unwrap();
            let exact = AckermannGeometry::new(CAR).unwrap();
            let patent = PatentAckermannTrack::from_params(&CAR).unwrap();
            let mut odo = DifferentialOdometer::new(patent, config(OdometerCalibration::IDENTITY)).unwrap();
            let mut model2 = model;
            let table = EffectiveTrackTable::<256>::build(&patent, patent.max_ratio()).unwrap();
            let mut odo_t = DifferentialOdometer::new(table, config(OdometerCalibration::IDENTITY)).unwrap();
            let (truth, got) = drive(&mut model, &mut odo, &st);
            let (_, got_t) = drive(&mut model2, &mut odo_t, &st);
            let turned: f64 = st.iter().map(|&(dt, v, k)| (k * v * dt).abs()).sum();

            let c_hi = exact.ratio_at_curvature(0.2).unwrap();
            let cell_bound = |h: f64| {
                let cells = (c_hi / h).ceil() as usize;
                (0..cells)
                    .map(|i| {
                        let (a, b) = (h * i as f64, (h * (i + 1) as f64).min(patent.max_ratio()));
                        exact.effective_track_m(a).unwrap() / patent.effective_track_m(b).unwrap() - 1.0
                    })
                    .fold(0.0, f64::max)
            };
            let formula_bound = cell_bound(c_hi / 1024.0);
            let table_bound = cell_bound(table.step());
            // The bounds must say something: a few per cent at most here.
            prop_assert!(formula_bound < 0.01 && table_bound < 0.02, "{formula_bound} {table_bound}");
            // 1e-12: rounding of the per-step sums.
            prop_assert!((got - truth).abs() <= formula_bound * turned + 1e-12, "{got} vs {truth}");
            prop_assert!((got_t - truth).abs() <= table_bound * turned + 1e-12, "{got_t} vs {truth}");
        }

        #[test]
        fn bad_samples_are_typed_errors_and_change_nothing(
            t in proptest::num::f64::ANY, l in proptest::num::f64::ANY, r in proptest::num::f64::ANY,
        ) {
            let g = AckermannGeometry::new(CAR).unwrap();
            let mut odo = DifferentialOdometer::new(g, config(OdometerCalibration::IDENTITY)).unwrap();
            odo.push(&WheelSample { t_s: 0.0, dist_l_m: 0.0, dist_r_m: 0.0 }).unwrap();
            odo.push(&WheelSample { t_s: 1.0, dist_l_m: 1.0, dist_r_m: 0.99 }).unwrap();
            let before = odo;
            let res = odo.step(&WheelSample { t_s: t, dist_l_m: l, dist_r_m: r });
            match res {
                Ok(s) => {
                    let s = s.unwrap();
                    prop_assert!(s.heading_change_rad.is_finite() && s.dt_s > 0.0);
                    prop_assert!(s.distance_m.unwrap().is_finite());
                }
                Err(_) => prop_assert_eq!(odo, before),
            }
            if !(t.is_finite() && t > 1.0 && l.is_finite() && r.is_finite()) {
                prop_assert!(res.is_err());
            }
            if !(t.is_finite() && l.is_finite() && r.is_finite()) {
                let non_finite = matches!(res, Err(Error::NonFinite { .. }));
                prop_assert!(non_finite, "{res:?}");
            }
        }
    }

    #[test]
    fn a_turn_tighter_than_the_formula_is_out_of_range_then_merged() {
        let patent = PatentAckermannTrack::from_params(&CAR).unwrap();
        let mut odo =
            DifferentialOdometer::new(patent, config(OdometerCalibration::IDENTITY)).unwrap();
        odo.push(&WheelSample {
            t_s: 0.0,
            dist_l_m: 0.0,
            dist_r_m: 0.0,
        })
        .unwrap();
        // ΔD/AD = 0.4: beyond c_max ≈ 0.284.
        let tight = WheelSample {
            t_s: 1.0,
            dist_l_m: 1.2,
            dist_r_m: 0.8,
        };
        assert!(matches!(odo.push(&tight), Err(Error::OutOfRange { .. })));
        // The next sample covers both steps: 1.4 + 1.1 vs 0.8 + 1.1 → ratio ≈ 0.2.
        let s = odo
            .push(&WheelSample {
                t_s: 2.0,
                dist_l_m: 2.3,
                dist_r_m: 1.9,
            })
            .unwrap()
            .unwrap();
        assert_eq!(s.dt_s, 2.0);
        assert!((s.ratio - 0.4 / 2.1).abs() < 1e-12);
        assert!(s.heading_change_rad.is_finite());
    }

    #[test]
    fn standing_still_is_no_turn() {
        let mut odo = DifferentialOdometer::new(
            FixedTrack::new(1.5).unwrap(),
            DifferentialOdometerConfig::default(),
        )
        .unwrap();
        for t in 0..5 {
            let s = WheelSample {
                t_s: t as f64,
                dist_l_m: 3.0,
                dist_r_m: 3.0,
            };
            let step = odo.step(&s).unwrap();
            if t == 0 {
                assert_eq!(step, None);
            } else {
                let step = step.unwrap();
                assert_eq!((step.heading_change_rad, step.distance_m), (0.0, Some(0.0)));
            }
        }
        odo.reset();
        assert_eq!(odo.heading_rad(), 0.0);
    }
}
