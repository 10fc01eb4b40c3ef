//! Properties of the simulated sensor streams.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use proptest::prelude::*;
use truenorth_accel::AccelParams;
use truenorth_core::{Validate, angle_diff};
use truenorth_gyro::GyroAxisParams;
use truenorth_odometer::{OdometerParams, OdometerWheels};
use truenorth_sim::{
    HandheldParams, ImuSensorParams, RouteBuilder, VehicleSensorParams, handheld_motion,
    imu_streams, scenario, simulate, vehicle_accel_stream, vehicle_streams,
};

fn perfect_vehicle() -> VehicleSensorParams {
    VehicleSensorParams {
        gyro: GyroAxisParams::PERFECT,
        gyro_temp_c: 25.0,
        odometer: OdometerParams::perfect(OdometerWheels::Rear { track_m: 1.5 }),
        compass_hard_iron: Vector2::zeros(),
        compass_soft_iron: Matrix2::identity(),
        compass_noise: 0.0,
        horizontal_field: 20.0,
    }
}

#[test]
fn perfect_vehicle_sensors_reproduce_the_truth() {
    let truth = simulate(&scenario::city_blocks(3, 80.0).unwrap(), 0.7, 50.0).unwrap();
    let s = vehicle_streams(&truth, &perfect_vehicle(), 3).unwrap();
    assert_eq!(s.len(), truth.len());
    for k in 1..truth.len() {
        let (a, b) = (&truth[k - 1], &truth[k]);
        let dpsi = angle_diff(b.heading_rad, a.heading_rad);
        // Gyro: the instantaneous rate at the sample time.
        let g = s[k].gyr_z_rps.unwrap();
        assert_eq!(g, b.speed_mps * b.curvature_per_m);
        // Odometer (rear wheels): (D_L − D_R)/T is the heading change; the mean is the distance.
        let (wa, wb) = (s[k - 1].wheels.unwrap(), s[k].wheels.unwrap());
        let dl = wb.dist_l_m - wa.dist_l_m;
        let dr = wb.dist_r_m - wa.dist_r_m;
        assert!(((dl - dr) / 1.5 - dpsi).abs() < 1e-9);
        assert!((0.5 * (dl + dr) - (b.distance_m - a.distance_m)).abs() < 1e-9);
        // Compass: heading = atan2(−y, x).
        let m = s[k].mag.unwrap();
        assert!(angle_diff((-m.y).atan2(m.x), b.heading_rad).abs() < 1e-12);
    }
}

#[test]
fn perfect_imu_reproduces_the_truth() {
    let truth = handheld_motion(&HandheldParams {
        duration_s: 5.0,
        ..Default::default()
    })
    .unwrap();
    let p = ImuSensorParams {
        gyro: GyroAxisParams::PERFECT,
        accel: AccelParams::default(),
        mag_hard_iron: Vector3::zeros(),
        mag_soft_iron: Matrix3::identity(),
        mag_noise: 0.0,
        ..ImuSensorParams::typical()
    };
    let s = imu_streams(&truth, &p, 1).unwrap();
    for (t, m) in truth.iter().zip(&s) {
        assert!((m.gyr_rps.as_xyz().unwrap() - t.gyr_rps).norm() < 1e-12);
        assert!((m.acc_mps2.as_xyz().unwrap() - t.specific_force_mps2).norm() < 1e-9);
        // The field, rotated back to NED, is the earth's field.
        let ned = t.attitude * m.mag.as_xyz().unwrap();
        let expect = Vector3::new(
            50.0 * 60f64.to_radians().cos(),
            0.0,
            50.0 * 60f64.to_radians().sin(),
        );
        assert!((ned - expect).norm() < 1e-9, "{ned} vs {expect}");
    }
}

#[test]
fn typical_compass_is_undone_by_its_true_calibration() {
    let truth = simulate(
        &scenario::calibration_circle(10.0, 5.0, 1.0).unwrap(),
        0.0,
        20.0,
    )
    .unwrap();
    let p = VehicleSensorParams {
        compass_noise: 0.0,
        ..VehicleSensorParams::typical()
    };
    let s = vehicle_streams(&truth, &p, 9).unwrap();
    let cal = truenorth_compass::CompassCalibration2d {
        hard_iron: p.compass_hard_iron,
        soft_iron: p.compass_soft_iron.try_inverse().unwrap(),
    };
    for (t, m) in truth.iter().zip(&s) {
        assert!(angle_diff(cal.heading_rad(&m.mag.unwrap()), t.heading_rad).abs() < 1e-9);
    }
}

/// Invalid sensor parameters are refused before any stream is made.
#[test]
fn invalid_sensor_params_are_typed_errors() {
    let truth = simulate(&scenario::parking().unwrap(), 0.0, 20.0).unwrap();
    let bad = [
        VehicleSensorParams {
            gyro_temp_c: f64::NAN,
            ..VehicleSensorParams::typical()
        },
        VehicleSensorParams {
            compass_noise: -1.0,
            ..VehicleSensorParams::typical()
        },
        VehicleSensorParams {
            horizontal_field: f64::INFINITY,
            ..VehicleSensorParams::typical()
        },
    ];
    for p in bad {
        assert!(p.validate().is_err(), "{p:?}");
        assert!(vehicle_streams(&truth, &p, 1).is_err(), "{p:?}");
    }
    let motion = handheld_motion(&HandheldParams {
        duration_s: 1.0,
        ..Default::default()
    })
    .unwrap();
    let p = ImuSensorParams {
        inclination_rad: f64::NAN,
        ..ImuSensorParams::typical()
    };
    assert!(matches!(
        imu_streams(&motion, &p, 1),
        Err(truenorth_core::Error::NonFinite { .. })
    ));
    let nan_amplitude = HandheldParams {
        rate_amplitude_rps: f64::NAN,
        ..Default::default()
    };
    assert!(handheld_motion(&nan_amplitude).is_err());
}

#[test]
fn perfect_vehicle_accelerometer_reads_forward_and_centripetal_acceleration() {
    let truth = simulate(&scenario::city_blocks(3, 80.0).unwrap(), 1.1, 50.0).unwrap();
    let acc = vehicle_accel_stream(&truth, &AccelParams::default(), 5).unwrap();
    assert_eq!(acc.len(), truth.len());
    let g = truenorth_core::STANDARD_GRAVITY_MPS2;
    for (t, a) in truth.iter().zip(&acc) {
        let want = Vector3::new(
            t.accel_mps2,
            t.speed_mps * t.speed_mps * t.curvature_per_m,
            -g,
        );
        assert!(
            (a.acc_mps2 - want).norm() < 1e-9,
            "{} vs {want}",
            a.acc_mps2
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn circle_at_steady_speed_reads_v_squared_over_r(
        speed in 1.0f64..30.0, radius in 5.0f64..200.0, left in any::<bool>(),
    ) {
        let angle = if left { -3.0 } else { 3.0 };
        let route = RouteBuilder::at_speed(speed).unwrap().turn(angle, radius).unwrap().build();
        let truth = simulate(&route, 0.0, 20.0).unwrap();
        let acc = vehicle_accel_stream(&truth, &AccelParams::default(), 1).unwrap();
        let lateral = angle.signum() * speed * speed / radius;
        for a in &acc {
            prop_assert!((a.acc_mps2.y - lateral).abs() < 1e-9 * lateral.abs().max(1.0));
            prop_assert!(a.acc_mps2.x.abs() < 1e-12);
        }
    }

    #[test]
    fn streams_are_deterministic_by_seed(seed in any::<u64>()) {
        let truth = simulate(&scenario::parking().unwrap(), 0.0, 20.0).unwrap();
        let p = VehicleSensorParams::typical();
        let a = vehicle_streams(&truth, &p, seed).unwrap();
        let b = vehicle_streams(&truth, &p, seed).unwrap();
        prop_assert_eq!(&a, &b);
        let c = vehicle_streams(&truth, &p, seed ^ 1).unwrap();
        prop_assert!(a != c);

        let motion = handheld_motion(&HandheldParams { duration_s: 1.0, seed, ..Default::default() }).unwrap();
        let i1 = imu_streams(&motion, &ImuSensorParams::typical(), seed).unwrap();
        let i2 = imu_streams(&motion, &ImuSensorParams::typical(), seed).unwrap();
        prop_assert_eq!(i1, i2);
    }
}
