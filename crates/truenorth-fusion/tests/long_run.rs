//! The quaternion filter's attitude stays a unit quaternion over long runs of vigorous
//! motion with every correction active: 10⁵ updates in the suite, 10⁷ as a release-mode
//! command (`cargo test --release -p truenorth-fusion --test long_run -- --ignored
//! --nocapture`, about 2 s).

use nalgebra::{UnitQuaternion, Vector3};
use truenorth_core::{ImuSample, NoiseSource, OrientationEstimator, SplitMix64};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

/// Runs `n` updates of a tumbling sensor (rates up to ±10 rad/s on each axis, changing
/// every second; readings of the true attitude with noise, a magnet attached for a while)
/// and returns the largest |‖q‖ − 1| of the 9-D and 6-D attitudes.
fn worst_norm_error(n: usize, seed: u64) -> f64 {
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    let mut rng = SplitMix64::new(seed);
    let dt = 0.005;
    let mut truth = UnitQuaternion::identity();
    let mut rate = Vector3::zeros();
    let field = Vector3::new(20.0, 0.0, 45.0);
    let mut worst: f64 = 0.0;
    for k in 0..n {
        if k % 200 == 0 {
            rate = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 20.0
                - Vector3::repeat(10.0);
        }
        truth *= UnitQuaternion::from_scaled_axis(rate * dt);
        let noise =
            Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()) - Vector3::repeat(0.5);
        let acc = truth.inverse_transform_vector(&Vector3::new(0.0, 0.0, -9.81)) + noise;
        let magnet = if (k / 50_000) % 3 == 1 {
            Vector3::new(5.0, -3.0, 30.0)
        } else {
            Vector3::zeros()
        };
        let mag = truth.inverse_transform_vector(&field) + magnet + noise;
        let e = f
            .update(&ImuSample::new_9d(
                k as f64 * dt,
                rate + noise * 0.01,
                acc,
                mag,
            ))
            .unwrap();
        worst = worst
            .max((e.attitude.as_ref().norm() - 1.0).abs())
            .max((e.attitude_6d.unwrap().as_ref().norm() - 1.0).abs());
    }
    worst
}

#[test]
fn unit_norm_over_a_hundred_thousand_updates() {
    let w = worst_norm_error(100_000, 1);
    assert!(w < 1e-12, "{w:e}");
}

#[test]
#[ignore = "release-mode measurement: 10^7 updates"]
fn unit_norm_over_ten_million_updates() {
    let w = worst_norm_error(10_000_000, 2);
    println!("largest |norm - 1| over 10^7 updates: {w:e}");
    assert!(w < 1e-12, "{w:e}");
}
