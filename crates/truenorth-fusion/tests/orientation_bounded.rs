//! The quaternion filter's state stays a state on any sequence of finite samples, however
//! hostile (rates, accelerations and fields up to the bounds it accepts, gaps of any
//! length, readings missing): the attitude a unit quaternion, σ finite and at most that of
//! an uninformed attitude, in `f64` and in `f32`.

use nalgebra::Vector3;
use proptest::prelude::*;
use truenorth_core::{Persistent, Real};
use truenorth_fusion::attitude_uncertainty::UNINFORMED_VARIANCE_RAD2;
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

/// One sample: the step since the last, gyro, accelerometer and magnetometer.
type Sample = (f64, [f64; 3], Option<[f64; 3]>, Option<[f64; 3]>);

/// A value that is realistic (`typical` around 0) or anywhere up to `bound`.
fn value(typical: f64, bound: f64) -> impl Strategy<Value = f64> {
    prop_oneof![3 => -typical..typical, 1 => -bound..bound, 1 => Just(bound), 1 => Just(0.0)]
}

fn sample() -> impl Strategy<Value = Sample> {
    let step =
        prop_oneof![4 => Just(0.01), 2 => 1e-4f64..0.2, 1 => 0.2f64..10.0, 1 => 10.0f64..1e5];
    let triad = |typical: f64, bound: f64| proptest::array::uniform3(value(typical, bound));
    (
        step,
        triad(3.0, 1e4),
        proptest::option::weighted(0.9, triad(12.0, 1e6)),
        proptest::option::weighted(0.7, triad(60.0, 1e12)),
    )
}

/// Runs `samples` through a filter in `T` and checks every state it passes through.
/// `unit_tol` is how far from 1 the quaternion's norm may be: 1e-9 in `f64`; in `f32`,
/// a few of its ulps (2⁻²³ ≈ 1.2e-7) of the last normalisation.
fn stays_bounded<T: Real>(
    samples: &[Sample],
    use_mag: bool,
    unit_tol: f64,
) -> Result<(), TestCaseError> {
    let config = QuaternionFilterConfig {
        use_mag,
        ..QuaternionFilterConfig::default()
    };
    let mut f = QuaternionFilter::<T>::with_precision(config).unwrap();
    let sigma_max = UNINFORMED_VARIANCE_RAD2.sqrt();
    let v = |a: [f64; 3]| Vector3::new(T::of(a[0]), T::of(a[1]), T::of(a[2]));
    let mut t_s = 0.0;
    for (k, (dt_s, gyr, acc, mag)) in samples.iter().enumerate() {
        t_s += dt_s;
        // A refusal (an implausible time base) is allowed; it changes nothing.
        let _ = f.update_readings(t_s, v(*gyr), acc.map(v), mag.map(v));
        let q = f.attitude();
        let n = q
            .coords
            .iter()
            .map(|c| c.to_f64().powi(2))
            .sum::<f64>()
            .sqrt();
        prop_assert!((n - 1.0).abs() <= unit_tol, "sample {k}: |q| = {n}");
        for s in f.sigma_rad().expect("σ on").iter().map(|s| s.to_f64()) {
            prop_assert!(
                s.is_finite() && (0.0..=sigma_max * (1.0 + 1e-6)).contains(&s),
                "sample {k}: σ {s}"
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// In `f64`, and the state then restores (every number in it finite and valid).
    #[test]
    fn the_state_stays_finite_and_the_attitude_unit_f64(
        samples in proptest::collection::vec(sample(), 1..300), use_mag: bool,
    ) {
        stays_bounded::<f64>(&samples, use_mag, 1e-9)?;
        let mut f = QuaternionFilter::new(QuaternionFilterConfig { use_mag, ..QuaternionFilterConfig::default() }).unwrap();
        let mut t_s = 0.0;
        for (dt_s, g, a, m) in &samples {
            t_s += dt_s;
            let _ = f.update_readings(t_s, Vector3::from(*g), a.map(Vector3::from), m.map(Vector3::from));
        }
        prop_assert!(QuaternionFilter::from_state(f.state()).is_ok(), "{:?}", f.state());
    }

    /// In `f32`.
    #[test]
    fn the_state_stays_finite_and_the_attitude_unit_f32(
        samples in proptest::collection::vec(sample(), 1..300), use_mag: bool,
    ) {
        stays_bounded::<f32>(&samples, use_mag, 1e-6)?;
    }
}

/// The fuzzer's finding: after a restart, a shock of 80 g while the body spins at
/// 100 rad/s, then level readings. The low-passed force turned at first order by a
/// correction proportional to itself grew quadratically to infinity, and σ and the
/// attitude with it.
#[test]
fn a_shock_while_spinning_after_a_restart_leaves_a_state() {
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    let level = Some(Vector3::new(0.0, 0.0, -9.81));
    for k in 0..100 {
        f.update_readings(0.01 * f64::from(k), Vector3::zeros(), level, None)
            .unwrap();
    }
    let mut t_s = 3600.0;
    f.update_readings(t_s, Vector3::zeros(), level, None)
        .unwrap();
    let spin = Vector3::new(130.0, 150.0, -100.0);
    for k in 0..200 {
        t_s += 0.01;
        let acc = if k == 1 {
            Some(Vector3::new(549.0, 559.0, 190.0))
        } else {
            level
        };
        f.update_readings(t_s, if k < 20 { spin } else { Vector3::zeros() }, acc, None)
            .unwrap();
        assert!(
            f.attitude().coords.iter().all(|c| c.is_finite()),
            "sample {k}"
        );
        let sigma = f.sigma_rad().expect("σ on");
        assert!(
            sigma
                .iter()
                .all(|s| s.is_finite() && *s <= UNINFORMED_VARIANCE_RAD2.sqrt()),
            "sample {k}: {sigma:?}"
        );
    }
}
