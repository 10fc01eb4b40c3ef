//! The quaternion filter's gaps and σ through its public interface: a gap longer than
//! `max_gap_s` restarts the attitude from the sensors, a millisecond time base is refused,
//! σ settles at rest where the error model puts the sensors' floor and grows where heading
//! is not observed.

use nalgebra::{UnitQuaternion, Vector3};
use proptest::prelude::*;
use truenorth_core::{Error, EulerZyx, ImuSample, OrientationEstimator, STANDARD_GRAVITY_MPS2};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

fn field_ned() -> Vector3<f64> {
    Vector3::new(20.0, 0.0, 45.0)
}

proptest! {
    /// After a gap longer than `max_gap_s` the attitude is the one the sensors give
    /// (the body turned during the gap), flagged, with σ widened; the next sample is no
    /// gap.
    #[test]
    fn a_gap_restarts_from_the_sensors(
        yaw in -3.1f64..3.1, pitch in -1.2f64..1.2, roll in -3.1f64..3.1,
        gap_s in 0.6f64..1e5,
    ) {
        let level = EulerZyx::default().to_quaternion();
        let turned = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll }.to_quaternion();
        let reading = |q: &UnitQuaternion<f64>, t: f64| ImuSample::new_9d(
            t,
            Vector3::zeros(),
            q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81)),
            q.inverse_transform_vector(&field_ned()),
        );
        let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
        for k in 0..1000 {
            let e = f.update(&reading(&level, 0.01 * k as f64)).unwrap();
            prop_assert!(!e.status.gap);
        }
        let settled = f.estimate().sigma_rad.unwrap();
        let t = 9.99 + gap_s;
        let e = f.update(&reading(&turned, t)).unwrap();
        prop_assert!(e.status.gap);
        prop_assert!(e.attitude.angle_to(&turned) < 1e-6, "{}°", e.attitude.angle_to(&turned).to_degrees());
        let widened = e.sigma_rad.unwrap();
        prop_assert!(widened.iter().zip(settled.iter()).all(|(w, s)| w > s), "{settled:?} → {widened:?}");
        prop_assert!(!f.update(&reading(&turned, t + 0.01)).unwrap().status.gap);
    }

    /// A time column in milliseconds read as seconds makes every step a gap: refused by
    /// the second step, with nothing changed.
    #[test]
    fn a_millisecond_time_base_is_refused(rate_hz in 10.0f64..1500.0, t0 in 0.0f64..1e6) {
        let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
        let s = |k: usize| ImuSample::new_9d(t0 + 1000.0 * k as f64 / rate_hz, Vector3::zeros(), Vector3::new(0.0, 0.0, -9.81), field_ned());
        f.update(&s(0)).unwrap();
        prop_assert!(f.update(&s(1)).unwrap().status.gap);
        let before = format!("{:?}", f.estimate());
        let refused = matches!(f.update(&s(2)), Err(Error::Implausible { .. }));
        prop_assert!(refused);
        prop_assert_eq!(format!("{:?}", f.estimate()), before);
    }
}

/// At rest the σ settles where the error model puts the sensors' floor: inclination at
/// the accelerometer bias's tilt, heading at the magnetometer's calibration error and
/// the inclination error about north turned by the dip.
#[test]
fn sigma_at_rest_settles_on_the_sensors_floor() {
    let cfg = QuaternionFilterConfig::default();
    let u = cfg.uncertainty;
    let mut f = QuaternionFilter::new(cfg).unwrap();
    for k in 0..30_000 {
        f.update(&ImuSample::new_9d(
            0.01 * k as f64,
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, -9.81),
            field_ned(),
        ))
        .unwrap();
    }
    let sigma = f.estimate().sigma_rad.unwrap();
    let tilt = u.accel_bias_mps2 / STANDARD_GRAVITY_MPS2;
    let tan_dip = field_ned().z / field_ned().x;
    let heading = (u.mag_heading_rad.powi(2) + (tan_dip * tilt).powi(2)).sqrt();
    // The white-noise and bias-floor terms add well under 1 % at rest.
    for (got, want) in [(sigma.x, tilt), (sigma.y, tilt), (sigma.z, heading)] {
        assert!(got >= want && got < 1.01 * want, "σ {got} against {want}");
    }
}

/// Where the model cannot explain the sensors, σ grows: while the field is rejected as
/// disturbed, heading σ grows with the gyro's uncertainty (here its scale error on a
/// steady turn) while inclination σ, still corrected, does not; without a magnetometer heading σ grows
/// without bound.
#[test]
fn sigma_grows_where_heading_is_not_observed() {
    // Turning about the vertical at 0.2 rad/s, the field scaled by `gain`.
    let turning = |k: usize, gain: f64| {
        let q = EulerZyx {
            yaw_rad: 0.002 * k as f64,
            ..Default::default()
        }
        .to_quaternion();
        ImuSample::new_9d(
            0.01 * k as f64,
            Vector3::new(0.0, 0.0, 0.2),
            q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81)),
            q.inverse_transform_vector(&(gain * field_ned())),
        )
    };
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    for k in 0..3000 {
        f.update(&turning(k, 1.0)).unwrap();
    }
    let before = f.estimate().sigma_rad.unwrap();
    // A magnet doubles the field: rejected from the first reading.
    for k in 3000..9000 {
        let e = f.update(&turning(k, 2.0)).unwrap();
        assert!(e.status.mag_disturbed);
    }
    let after = f.estimate().sigma_rad.unwrap();
    assert!(
        after.z > 2.0 * before.z && after.x <= before.x,
        "{before:?} → {after:?}"
    );

    let mut six = QuaternionFilter::new(QuaternionFilterConfig {
        use_mag: false,
        ..Default::default()
    })
    .unwrap();
    let mut last = 0.0;
    for k in 0..6000 {
        // Turning about the vertical at 0.5 rad/s.
        let yaw = EulerZyx {
            yaw_rad: 0.005 * k as f64,
            ..Default::default()
        }
        .to_quaternion();
        let e = six
            .update(&ImuSample::new_6d(
                0.01 * k as f64,
                Vector3::new(0.0, 0.0, 0.5),
                yaw.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81)),
            ))
            .unwrap();
        let z = e.sigma_rad.unwrap().z;
        if k > 0 {
            assert!(z > last, "heading σ {z} after {last} at sample {k}");
        }
        last = z;
    }
}
