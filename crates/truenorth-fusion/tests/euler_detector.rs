//! Properties of the Euler orientation detector (WO 00/36376): no panic on any input, the
//! still sensor's attitude, continuity through the vertical, the two-axis magnetometer with
//! the M_z reconstruction, the yaw + pitch variant, and gaps in time.

use nalgebra::{UnitQuaternion, Vector2, Vector3};
use proptest::prelude::*;
use truenorth_core::{Axes, Error, EulerZyx, ImuSample, OrientationEstimator};
use truenorth_fusion::{
    EulerDetector, EulerDetectorConfig, EulerVariant, GyroConditioning, StartupField,
    coefficient_table,
};
use truenorth_gyro::{HighPassConfig, HighPassCorrectionConfig, IirHighPassConfig};

const G: f64 = 9.81;

fn field_ned(incl_rad: f64) -> Vector3<f64> {
    Vector3::new(45.0 * incl_rad.cos(), 0.0, 45.0 * incl_rad.sin())
}

fn still(att: &EulerZyx, incl: f64) -> (Vector3<f64>, Vector3<f64>) {
    let q = att.to_quaternion();
    (
        q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -G)),
        q.inverse_transform_vector(&field_ned(incl)),
    )
}

fn any_conditioning() -> impl Strategy<Value = GyroConditioning> {
    prop_oneof![
        Just(GyroConditioning::None),
        Just(GyroConditioning::HighPass {
            filter: HighPassConfig::default(),
            correction: Some(HighPassCorrectionConfig::default()),
        }),
        Just(GyroConditioning::Iir(IirHighPassConfig::default())),
    ]
}

proptest! {
    /// After a gap longer than `max_gap_s` (the body turned meanwhile) the detector starts
    /// again from the sample's static angles, with any gyro conditioning, and says so; a
    /// millisecond time base, every step a gap, is refused by its second step.
    #[test]
    fn a_gap_restarts_from_the_static_angles(
        yaw in -3.1f64..3.1, pitch in -1.2f64..1.2, roll in -1.2f64..1.2,
        gap_s in 0.6f64..1e5, gyro in any_conditioning(),
    ) {
        let cfg = EulerDetectorConfig { gyro, ..Default::default() };
        let level = EulerZyx::default();
        let turned = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
        let mut d = EulerDetector::new(cfg).unwrap();
        let (a, m) = still(&level, 1.0);
        for k in 0..300 {
            prop_assert!(!d.update(&ImuSample::new_9d(0.01 * k as f64, Vector3::zeros(), a, m)).unwrap().status.gap);
        }
        let (a, m) = still(&turned, 1.0);
        let e = d.update(&ImuSample::new_9d(2.99 + gap_s, Vector3::zeros(), a, m)).unwrap();
        prop_assert!(e.status.gap);
        prop_assert!(e.attitude.angle_to(&turned.to_quaternion()) < 1e-6);
        prop_assert!(!d.update(&ImuSample::new_9d(3.0 + gap_s, Vector3::zeros(), a, m)).unwrap().status.gap);

        let mut d = EulerDetector::new(cfg).unwrap();
        let ms = |k: usize| ImuSample::new_9d(10.0 * k as f64, Vector3::zeros(), a, m);
        d.update(&ms(0)).unwrap();
        prop_assert!(d.update(&ms(1)).unwrap().status.gap);
        let refused = matches!(d.update(&ms(2)), Err(Error::Implausible { .. }));
        prop_assert!(refused);
    }

    /// Held still in any upright attitude, the detector reads pitch, roll and magnetic
    /// heading from the accelerometer and magnetometer at once and keeps them.
    #[test]
    fn still_sensor_keeps_its_attitude(
        yaw in -3.1f64..3.1, pitch in -1.2f64..1.2, roll in -1.2f64..1.2, incl in -1.2f64..1.2,
    ) {
        let att = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
        let (a, m) = still(&att, incl);
        let mut d = EulerDetector::new(EulerDetectorConfig::default()).unwrap();
        for k in 0..300 {
            d.update(&ImuSample::new_9d(0.01 * k as f64, Vector3::zeros(), a, m)).unwrap();
        }
        let err = d.estimate().attitude.angle_to(&att.to_quaternion());
        prop_assert!(err < 1e-6, "{err}");
    }

    /// A rotation about the body y axis through pitch +90° and on: the integrated angles
    /// continue (re-expressed past the vertical) and match the truth.
    #[test]
    fn integration_continues_through_the_vertical(rate in 0.5f64..3.0) {
        let cfg = EulerDetectorConfig { tau_s: [1e9; 3], use_mag: false, ..Default::default() };
        let mut d = EulerDetector::new(cfg).unwrap();
        let dt = 0.001;
        let n = (2.5 / rate / dt) as usize; // 2.5 rad, past the vertical
        let mut truth = UnitQuaternion::identity();
        for k in 0..=n {
            let gyr = Vector3::new(0.0, rate, 0.0);
            if k > 0 {
                truth *= UnitQuaternion::from_scaled_axis(gyr * dt);
            }
            let a = truth.inverse_transform_vector(&Vector3::new(0.0, 0.0, -G));
            d.update(&ImuSample::new_6d(k as f64 * dt, gyr, a)).unwrap();
        }
        let err = d.estimate().attitude.angle_to(&truth);
        prop_assert!(err < 0.01, "{err}");
    }

    /// No input panics; a rejected sample changes nothing.
    #[test]
    fn no_panic_on_any_input(
        vals in proptest::collection::vec(proptest::array::uniform10(proptest::num::f64::ANY), 1..30),
        conditioning in any_conditioning(),
        two_d in any::<bool>(),
    ) {
        let cfg = EulerDetectorConfig {
            gyro: conditioning,
            variant: if two_d { EulerVariant::YawPitch } else { EulerVariant::Full },
            ..Default::default()
        };
        let mut d = EulerDetector::new(cfg).unwrap();
        for v in vals {
            let s = ImuSample::new_9d(v[0], Vector3::new(v[1], v[2], v[3]), Vector3::new(v[4], v[5], v[6]), Vector3::new(v[7], v[8], v[9]));
            let before = format!("{:?}", d.estimate());
            match d.update(&s) {
                Ok(e) => prop_assert!((e.attitude.norm() - 1.0).abs() < 1e-9),
                Err(_) => prop_assert_eq!(format!("{:?}", d.estimate()), before),
            }
        }
    }

    /// Two magnetometers and the start-up field give the same heading as three, for an
    /// upright sensor away from the attitudes where M_z changes sign.
    #[test]
    fn two_axis_magnetometer_with_reconstruction(
        yaw in -3.1f64..3.1, pitch in -0.6f64..0.6, roll in -0.6f64..0.6,
    ) {
        let incl = 1.1;
        let att = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
        let (a, m) = still(&att, incl);
        let cfg = EulerDetectorConfig {
            startup_field: Some(StartupField { total: 45.0, inclination_rad: incl }),
            ..Default::default()
        };
        let mut d = EulerDetector::new(cfg).unwrap();
        for k in 0..300 {
            let s = ImuSample { mag: Axes::xy(Vector2::new(m.x, m.y)), ..ImuSample::new_9d(0.01 * k as f64, Vector3::zeros(), a, m) };
            d.update(&s).unwrap();
        }
        let e = EulerZyx::from_quaternion(&d.estimate().attitude);
        prop_assert!(truenorth_core::angle_diff(e.yaw_rad, yaw).abs() < 1e-6, "{} vs {yaw}", e.yaw_rad);
    }
}

/// The yaw + pitch variant with gyros on y and z and one accelerometer on x follows a
/// turning, pitching sensor (no roll).
#[test]
fn yaw_pitch_variant_follows_yaw_and_pitch() {
    let cfg = EulerDetectorConfig {
        variant: EulerVariant::YawPitch,
        ..Default::default()
    };
    let mut d = EulerDetector::new(cfg).unwrap();
    let dt = 0.01;
    let mut worst: f64 = 0.0;
    for k in 0..3000 {
        let t = k as f64 * dt;
        let (yaw, pitch) = (0.3 * t, 0.4 * (0.5 * t).sin());
        let (yaw_rate, pitch_rate) = (0.3, 0.2 * (0.5 * t).cos());
        // Body rates of Rz(ψ)Ry(θ) (no roll): q = θ', r = ψ' cos θ, p = −ψ' sin θ.
        let gyr = Vector3::new(-yaw_rate * pitch.sin(), pitch_rate, yaw_rate * pitch.cos());
        let att = EulerZyx {
            yaw_rad: yaw,
            pitch_rad: pitch,
            roll_rad: 0.0,
        };
        let (a, m) = still(&att, 1.0);
        let s = ImuSample {
            t_s: t,
            gyr_rps: Axes {
                x: None,
                y: Some(gyr.y),
                z: Some(gyr.z),
            },
            acc_mps2: Axes {
                x: Some(a.x),
                y: None,
                z: None,
            },
            mag: Axes::xyz(m),
        };
        let e = d.update(&s).unwrap();
        if t > 1.0 {
            worst = worst.max(e.attitude.angle_to(&att.to_quaternion()));
        }
    }
    assert!(worst < 0.01, "worst {worst}");
}

#[test]
fn coefficient_table_bands() {
    let d = |x: f64| x.to_radians();
    assert_eq!(coefficient_table(d(10.0), d(10.0)), [1.0, 1.0, 1.0]);
    assert_eq!(coefficient_table(d(65.0), d(10.0)), [1.0, 0.7, 0.7]);
    assert_eq!(coefficient_table(d(80.0), d(75.0)), [0.3, 0.3, 0.3]);
    assert_eq!(coefficient_table(d(10.0), d(-65.0)), [0.7, 1.0, 0.7]);
    // Upside down (roll 170°) is 10° from the vertical.
    assert_eq!(coefficient_table(d(10.0), d(170.0)), [1.0, 1.0, 1.0]);
}

#[test]
fn missing_sensors_are_refused() {
    let mut d = EulerDetector::new(EulerDetectorConfig::default()).unwrap();
    let s = ImuSample {
        gyr_rps: Axes::xy(Vector2::new(0.0, 0.0)),
        ..ImuSample::new_6d(0.0, Vector3::zeros(), Vector3::new(0.0, 0.0, -G))
    };
    assert!(d.update(&s).is_err());
    // A two-axis magnetometer without the start-up field.
    let s = ImuSample {
        mag: Axes::xy(Vector2::new(20.0, 0.0)),
        ..ImuSample::new_6d(0.0, Vector3::zeros(), Vector3::new(0.0, 0.0, -G))
    };
    assert!(d.update(&s).is_err());
    assert!(
        EulerDetector::new(EulerDetectorConfig {
            tau_s: [0.0, 1.0, 1.0],
            ..Default::default()
        })
        .is_err()
    );
}

/// The detector corrects heading inside the same angles as tilt, so it has no gyro +
/// accelerometer attitude to report apart from its 9-D one: `attitude_6d` is `None`
/// before, at and after the first sample.
#[test]
fn no_6d_attitude_is_claimed() {
    let mut d = EulerDetector::new(EulerDetectorConfig::default()).unwrap();
    assert!(d.estimate().attitude_6d.is_none());
    let (acc, mag) = still(&EulerZyx::default(), 1.0);
    for k in 0..10 {
        let e = d
            .update(&ImuSample::new_9d(
                0.01 * k as f64,
                Vector3::zeros(),
                acc,
                mag,
            ))
            .unwrap();
        assert!(e.attitude_6d.is_none());
    }
}
