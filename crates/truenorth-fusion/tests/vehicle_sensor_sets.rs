//! The sensor sets real vehicles have, each as the estimator takes it: one vehicle speed
//! (a cumulative `dist_m`) with a yaw rate, as a car's CAN bus gives them; the same speed
//! written twice as left and right wheels; one speed alone.

use truenorth_core::{HeadingEstimator, NavEstimate, VehicleSample};
use truenorth_fusion::vehicle::nav_filter::BIAS;
use truenorth_fusion::{VehicleConfig, VehicleEstimator};

/// A car at 10 m/s turning right at 0.1 rad/s for 60 s, its gyro reading `bias` more, at
/// 10 Hz; the odometry as `row` writes the distance.
fn turning(bias: f64, row: impl Fn(VehicleSample, f64) -> VehicleSample) -> Vec<VehicleSample> {
    (0..=600)
        .map(|k| {
            let t = 0.1 * k as f64;
            row(VehicleSample::at(t).with_gyro(0.1 + bias), 10.0 * t)
        })
        .collect()
}

fn run(samples: &[VehicleSample]) -> (VehicleEstimator, Vec<NavEstimate>) {
    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let out = samples.iter().map(|s| nav.update(s).unwrap()).collect();
    (nav, out)
}

/// One speed and a yaw rate: the track is drawn along the gyro's heading, and the gyro's
/// bias is not learned from a distance that says nothing about turning.
#[test]
fn speed_and_yaw_rate_draw_the_track_and_learn_no_bias_from_the_speed() {
    let bias = 0.2f64.to_radians();
    let (nav, out) = run(&turning(bias, |s, d| s.with_distance(d)));
    let e = out.last().unwrap();
    assert!(e.status.position_known);
    // 60 s at 0.1 rad/s plus the bias: the heading turned 6 rad and a little more.
    let turned = 6.0 + bias * 60.0;
    let error = truenorth_core::angle_diff(e.heading.rad(), turned);
    assert!(error.abs() < 0.01, "{error}");
    // Along the heading the gyro gives (its bias unknown): an arc of 600 m and radius
    // 600/turned.
    let r = 600.0 / turned;
    let (n, east) = (r * turned.sin(), r * (1.0 - turned.cos()));
    assert!(
        (e.north_m - n).hypot(e.east_m - east) < 5.0,
        "{} {}",
        e.north_m,
        e.east_m
    );
    assert!(
        nav.filter().x[BIAS].abs() < 1e-9,
        "bias learned from nothing"
    );
    assert!(e.status.unobserved.gyro_bias);
}

/// The same speed written as two equal wheels is the same information: the estimator does
/// not read "not turning" from it and learn the gyro's turn as a bias.
#[test]
fn two_equal_wheels_are_one_speed_not_a_straight_line() {
    let bias = 0.2f64.to_radians();
    let (single, a) = run(&turning(bias, |s, d| s.with_distance(d)));
    let (twice, b) = run(&turning(bias, |s, d| s.with_wheels(d, d)));
    let (a, b) = (a.last().unwrap(), b.last().unwrap());
    assert_eq!(single.filter().x[BIAS], twice.filter().x[BIAS]);
    assert!((a.heading.rad() - b.heading.rad()).abs() < 1e-12);
    assert!((a.north_m - b.north_m).hypot(a.east_m - b.east_m) < 1e-9);
}

/// One speed and nothing else draws a track along a heading nothing measures: its
/// uncertainty grows with the distance until it is the whole circle.
#[test]
fn a_speed_alone_knows_the_distance_and_not_the_heading() {
    let samples: Vec<VehicleSample> = (0..=600)
        .map(|k| VehicleSample::at(0.1 * k as f64).with_distance(k as f64))
        .collect();
    let (_, out) = run(&samples);
    let sigma = |k: usize| out[k].heading_sigma_rad;
    assert!(
        sigma(2) < sigma(5) && sigma(5) < sigma(10),
        "{} {} {}",
        sigma(2),
        sigma(5),
        sigma(10)
    );
    // After 600 m nothing is known of the heading: uniform on the circle, π/√3.
    assert!(sigma(600).to_degrees() > 100.0);
    assert!(out[600].status.position_known);
}
