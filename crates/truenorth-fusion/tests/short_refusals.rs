//! A refusal names the number that was wrong in a form that reads at a glance: a timestamp
//! of 1e308 shows as `1e308`, not as 309 digits.

use nalgebra::{Vector2, Vector3};
use truenorth_core::{HeadingEstimator, ImuSample, OrientationEstimator, VehicleSample};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig, VehicleConfig, VehicleEstimator};

fn short(m: &str) {
    println!("{m}");
    assert!(m.len() < 300 && !m.contains("0000000000"), "{m}");
}

#[test]
fn a_refusal_of_1e308_is_short() {
    let mut named = 0;
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    let imu = |t_s: f64| {
        ImuSample::new_9d(
            t_s,
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, -9.81),
            Vector3::new(20.0, 0.0, 40.0),
        )
    };
    let mut v = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let car = |t_s: f64| {
        VehicleSample::at(t_s)
            .with_wheels(1.0, 1.0)
            .with_gyro(0.0)
            .with_mag(Vector2::new(20.0, 0.0))
    };
    for t_s in [0.0, 1e308, 1.0] {
        if let Err(e) = f.update(&imu(t_s)) {
            short(&e.to_string());
            named += usize::from(e.to_string().contains("1e308"));
        }
        if let Err(e) = v.update(&car(t_s)) {
            short(&e.to_string());
            named += usize::from(e.to_string().contains("1e308"));
        }
    }
    assert!(named > 0);
}
