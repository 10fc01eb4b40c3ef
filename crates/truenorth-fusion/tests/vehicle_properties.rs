//! Properties of the vehicle estimators on arbitrary input: no panic on any finite or
//! non-finite value, a typed refusal that changes nothing for a non-finite value or a
//! timestamp that does not increase, and finite estimates from every accepted sample —
//! satellite fixes with and without their course among the rows, odometry or not.

use nalgebra::Vector2;
use proptest::prelude::*;
use truenorth_core::{
    GnssFix, HeadingEstimator, NavEstimate, Validate, VehicleSample, WheelReading,
};
use truenorth_fusion::vehicle::{
    SeedGyroCompass, SeedGyroCompassConfig, SeedOdometerCompass, SeedOdometerCompassConfig,
    TwoPassConfig, TwoPassStart,
};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_odometer::{AckermannParams, OdometerWheels};

/// Any f64 at all, weighted towards the awkward ones.
fn any_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -1e3f64..1e3,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => any::<f64>(),
    ]
}

/// A sample built from plausible increments or, now and then, arbitrary values; each
/// sensor present or not, as rows of a log with sensors at their own rates come.
#[derive(Debug, Clone)]
struct Step {
    dt_s: f64,
    wheels: bool,
    dl_m: f64,
    dr_m: f64,
    gyro: Option<f64>,
    mag: Option<(f64, f64)>,
    fix: Option<Fix>,
}

/// A fix: north and east of the origin, m (turned into latitude and longitude), σ, and
/// speed and course over ground, or, now and then, arbitrary values.
type Fix = (f64, f64, f64, Option<(f64, f64)>);

fn fix() -> impl Strategy<Value = Option<Fix>> {
    proptest::option::weighted(
        0.2,
        (
            prop_oneof![8 => -500.0f64..500.0, 1 => any_value()],
            prop_oneof![8 => -500.0f64..500.0, 1 => any_value()],
            prop_oneof![8 => 0.5f64..10.0, 1 => any_value()],
            proptest::option::of((
                prop_oneof![8 => 0.0f64..30.0, 1 => any_value()],
                prop_oneof![8 => 0.0f64..360.0, 1 => any_value()],
            )),
        ),
    )
}

fn step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![8 => 0.001f64..0.5, 1 => any_value()],
        prop_oneof![3 => Just(true), 1 => Just(false)],
        prop_oneof![8 => -0.1f64..2.0, 1 => any_value()],
        prop_oneof![8 => -0.1f64..2.0, 1 => any_value()],
        proptest::option::of(prop_oneof![8 => -1.0f64..1.0, 1 => any_value()]),
        proptest::option::of((
            prop_oneof![8 => -60.0f64..60.0, 1 => any_value()],
            prop_oneof![8 => -60.0f64..60.0, 1 => any_value()],
        )),
        fix(),
    )
        .prop_map(|(dt_s, wheels, dl_m, dr_m, gyro, mag, fix)| Step {
            dt_s,
            wheels,
            dl_m,
            dr_m,
            gyro,
            mag,
            fix,
        })
}

fn samples(steps: &[Step]) -> Vec<VehicleSample> {
    let (mut t, mut l, mut r) = (0.0, 0.0, 0.0);
    steps
        .iter()
        .map(|s| {
            t += s.dt_s;
            l += s.dl_m;
            r += s.dr_m;
            VehicleSample {
                t_s: t,
                wheels: s.wheels.then_some(WheelReading {
                    dist_l_m: l,
                    dist_r_m: r,
                }),
                gyr_z_rps: s.gyro,
                mag: s.mag.map(|(x, y)| Vector2::new(x, y)),
                dist_m: None,
                // 52.5° N, 13.4° E plus the step's metres (1e-5° is about 1.1 m of
                // latitude): a fix's degrees as arbitrary as its metres.
                gnss: s.fix.map(|(n, e, sigma, velocity)| {
                    let fix = GnssFix::at(52.5 + n * 9e-6, 13.4 + e * 1.5e-5).with_sigma(sigma);
                    match velocity {
                        Some((v, c)) => fix.with_velocity(v, c),
                        None => fix,
                    }
                }),
            }
        })
        .collect()
}

fn valid(s: &VehicleSample, last_t: Option<f64>) -> bool {
    let finite = s.t_s.is_finite()
        && s.wheels
            .is_none_or(|w| w.dist_l_m.is_finite() && w.dist_r_m.is_finite())
        && s.gyr_z_rps.is_none_or(f64::is_finite)
        && s.mag.is_none_or(|m| m.x.is_finite() && m.y.is_finite())
        && s.gnss.is_none_or(|f| f.validate().is_ok());
    finite && last_t.is_none_or(|t0| s.t_s > t0)
}

fn finite_estimate(e: &NavEstimate) -> bool {
    e.north_m.is_finite()
        && e.east_m.is_finite()
        && e.heading.rad().is_finite()
        && e.distance_m.is_finite()
        // A σ may be infinite (heading not referred to north) or NaN where an estimator
        // reports none (the seed configurations), never negative.
        && e.heading_sigma_rad.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less)
}

/// Feeds `estimator` and checks the refusal contract on every sample.
fn check(
    mut estimator: Box<dyn HeadingEstimator>,
    input: &[VehicleSample],
) -> Result<(), TestCaseError> {
    let mut last_t = None;
    for s in input {
        let before = estimator.estimate();
        match estimator.update(s) {
            Ok(e) => {
                prop_assert!(valid(s, last_t), "accepted {s:?}");
                prop_assert!(finite_estimate(&e), "{e:?} from {s:?}");
                last_t = Some(s.t_s);
            }
            Err(err) => {
                prop_assert!(!err.to_string().is_empty());
                let after = estimator.estimate();
                prop_assert!(
                    format!("{before:?}") == format!("{after:?}"),
                    "a refused sample changed the estimate: {s:?}"
                );
            }
        }
    }
    Ok(())
}

/// Each kind of vehicle.
fn wheels(kind: usize) -> OdometerWheels {
    match kind % 4 {
        0 => OdometerWheels::Rear { track_m: 1.5 },
        1 => OdometerWheels::Front(AckermannParams::from_pitman_ratio(2.7, 1.5, 0.129)),
        2 => OdometerWheels::SkidSteer { track_m: 0.6 },
        _ => OdometerWheels::Differential { track_m: 0.4 },
    }
}

proptest! {
    #[test]
    fn the_fused_estimator_refuses_bad_samples_and_never_panics(
        steps in proptest::collection::vec(step(), 1..300),
        kind in 0usize..4,
    ) {
        let input = samples(&steps);
        let config = VehicleConfig { wheels: wheels(kind), ..VehicleConfig::default() };
        check(Box::new(VehicleEstimator::new(config).unwrap()), &input)?;
        // No odometry at all: the fixes' courses alone refer the heading.
        let no_odometry: Vec<VehicleSample> = input
            .iter()
            .map(|s| VehicleSample { wheels: None, ..*s })
            .collect();
        check(Box::new(VehicleEstimator::new(config).unwrap()), &no_odometry)?;
    }

    #[test]
    fn the_seed_configurations_refuse_bad_samples_and_never_panic(
        steps in proptest::collection::vec(step(), 1..300),
        kind in 0usize..4,
    ) {
        let input = samples(&steps);
        let a = SeedGyroCompass::new(SeedGyroCompassConfig { wheels: wheels(kind), ..Default::default() }).unwrap();
        check(Box::new(a), &input)?;
        let b = SeedOdometerCompass::new(SeedOdometerCompassConfig { wheels: wheels(kind), ..Default::default() }).unwrap();
        check(Box::new(b), &input)?;
    }

    /// The two-pass start emits exactly one row per accepted sample, in order, whatever the
    /// input.
    #[test]
    fn the_two_pass_start_emits_one_row_per_accepted_sample(
        steps in proptest::collection::vec(step(), 1..300),
    ) {
        let input = samples(&steps);
        let nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
        let mut two = TwoPassStart::new(nav, TwoPassConfig::default()).unwrap();
        let mut times = Vec::new();
        let mut accepted = 0usize;
        for s in &input {
            if two.push(s, |s, _, _| times.push(s.t_s)).is_ok() {
                accepted += 1;
            }
        }
        two.finish(|s, _, _| times.push(s.t_s)).unwrap();
        prop_assert_eq!(times.len(), accepted);
        prop_assert!(times.windows(2).all(|w| w[0] < w[1]));
    }
}
