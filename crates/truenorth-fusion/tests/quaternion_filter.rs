//! The quaternion filter through its public interface: convergence from a still sensor
//! with a gyro bias, a unit attitude and finite σ on any input, invalid parameters refused.

use nalgebra::Vector3;
use proptest::prelude::*;
use truenorth_core::{EulerZyx, ImuSample, OrientationEstimator, Persistent};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

fn field_ned() -> Vector3<f64> {
    Vector3::new(20.0, 0.0, 45.0)
}

proptest! {
    #[test]
    fn still_sensor_with_constant_bias_converges(
        yaw in -3.1f64..3.1, pitch in -1.2f64..1.2, roll in -3.1f64..3.1,
        bias in proptest::array::uniform3(-0.1f64..0.1),
    ) {
        let truth = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll }.to_quaternion();
        let acc = truth.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81));
        let mag = truth.inverse_transform_vector(&field_ned());
        // |bias| ≤ 0.17 rad/s drifts the attitude for `rest.min_time_s` (1.5 s) before
        // rest is recognised and for about `bias_tau_rest_s` (2 s) more while the bias
        // estimate settles: at most 0.17 · 3.5 ≈ 0.6 rad, which then decays with the
        // slowest correction, `tau_mag_s`, from t ≈ 5.5 s.
        let cfg = QuaternionFilterConfig::default();
        let t_end = 120.0;
        let bound_deg = (0.6 * (-(t_end - 5.5) / cfg.tau_mag_s).exp()).to_degrees().max(0.01);
        let mut f = QuaternionFilter::new(cfg).unwrap();
        for k in 0..(t_end * 100.0) as usize {
            f.update(&ImuSample::new_9d(0.01 * k as f64, Vector3::from(bias), acc, mag)).unwrap();
        }
        let e = f.estimate();
        let err_deg = e.attitude.angle_to(&truth).to_degrees();
        let bias_err_dps = (e.gyro_bias_rps - Vector3::from(bias)).norm().to_degrees();
        prop_assert!(err_deg < bound_deg && bias_err_dps < 0.01, "attitude {err_deg}° (bound {bound_deg}), bias {bias_err_dps}°/s");
    }

    #[test]
    fn no_panic_and_unit_norm_on_any_input(
        vals in proptest::collection::vec(proptest::array::uniform10(proptest::num::f64::ANY), 1..40)
    ) {
        let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
        for v in vals {
            let s = ImuSample::new_9d(v[0], Vector3::new(v[1], v[2], v[3]), Vector3::new(v[4], v[5], v[6]), Vector3::new(v[7], v[8], v[9]));
            let before = f.estimate();
            match f.update(&s) {
                Ok(e) => {
                    prop_assert!((e.attitude.norm() - 1.0).abs() < 1e-9);
                    let sigma = e.sigma_rad.unwrap();
                    prop_assert!(sigma.iter().all(|v| v.is_finite() && *v >= 0.0), "{sigma:?}");
                }
                Err(_) => prop_assert_eq!(format!("{:?}", f.estimate()), format!("{before:?}")),
            }
        }
    }
}

#[test]
fn invalid_configs_are_refused() {
    for c in [
        QuaternionFilterConfig {
            tau_acc_s: 0.0,
            ..Default::default()
        },
        QuaternionFilterConfig {
            tau_mag_s: f64::NAN,
            ..Default::default()
        },
        QuaternionFilterConfig {
            bias_tau_motion_s: 1.0,
            ..Default::default()
        },
        QuaternionFilterConfig {
            initial_attitude: Some([0.0; 4]),
            ..Default::default()
        },
        QuaternionFilterConfig {
            max_gap_s: 0.0,
            ..Default::default()
        },
        QuaternionFilterConfig {
            uncertainty: truenorth_fusion::AttitudeUncertaintyConfig {
                gyro_scale_rel: -0.01,
                ..Default::default()
            },
            ..Default::default()
        },
    ] {
        assert!(QuaternionFilter::new(c).is_err());
    }
}

#[test]
fn the_default_filter_is_the_default_configuration() {
    let d = QuaternionFilter::default();
    let n = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    assert_eq!(
        serde_json::to_string(&d.state()).unwrap(),
        serde_json::to_string(&n.state()).unwrap()
    );
}
