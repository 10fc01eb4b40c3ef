//! Properties of the kinematic vehicle and the hand-held motion.

use std::f64::consts::PI;

use nalgebra::UnitQuaternion;
use proptest::prelude::*;
use truenorth_core::angle_diff;
use truenorth_sim::{
    HandheldParams, RouteBuilder, handheld_motion, scenario, simulate, simulate_at,
};

#[test]
fn quarter_right_turn_ends_at_radius_radius() {
    // Heading north, a right turn of radius R: the centre is R to the east, so after 90° the
    // vehicle heads east at (north R, east R).
    let r = 20.0;
    let route = RouteBuilder::at_speed(4.0)
        .unwrap()
        .turn(PI / 2.0, r)
        .unwrap()
        .build();
    let last = *simulate(&route, 0.0, 100.0).unwrap().last().unwrap();
    assert!((last.north_m - r).abs() < 1e-9, "{last:?}");
    assert!((last.east_m - r).abs() < 1e-9, "{last:?}");
    assert!((last.heading_rad - PI / 2.0).abs() < 1e-12);
    assert!(last.yaw_rate_rps >= 0.0);
}

#[test]
fn scenarios_build_and_end_at_rest() {
    for route in [
        scenario::calibration_circle(10.0, 5.0, 1.25).unwrap(),
        scenario::city_blocks(4, 100.0).unwrap(),
        scenario::highway(2000.0).unwrap(),
        scenario::parking().unwrap(),
        scenario::demo_drive().unwrap(),
    ] {
        let truth = simulate(&route, 0.3, 50.0).unwrap();
        let last = truth.last().unwrap();
        assert!(last.speed_mps.abs() < 1e-9, "ends moving: {last:?}");
        assert!(truth.iter().all(|s| s.speed_mps >= 0.0));
    }
}

#[test]
fn calibration_circle_turns_at_least_a_full_circle() {
    let truth = simulate(
        &scenario::calibration_circle(10.0, 5.0, 1.25).unwrap(),
        0.0,
        50.0,
    )
    .unwrap();
    let turned = truth.last().unwrap().heading_unwrapped_rad;
    assert!((turned.to_degrees() - 450.0).abs() < 1e-6);
}

#[test]
fn bad_inputs_are_typed_errors() {
    assert!(
        RouteBuilder::new().straight(10.0).is_err(),
        "straight at rest"
    );
    assert!(
        RouteBuilder::at_speed(5.0).unwrap().stop(1.0).is_err(),
        "stop while moving"
    );
    assert!(RouteBuilder::at_speed(f64::NAN).is_err());
    assert!(RouteBuilder::at_speed(5.0).unwrap().turn(1.0, 0.0).is_err());
    let route = RouteBuilder::at_speed(5.0)
        .unwrap()
        .straight(1.0)
        .unwrap()
        .build();
    assert!(simulate(&route, 0.0, 0.0).is_err());
    assert!(simulate(&route, 0.0, f64::NAN).is_err());
    assert!(
        handheld_motion(&HandheldParams {
            rate_hz: -1.0,
            ..Default::default()
        })
        .is_err()
    );
    // Absurd sizes are refused, not attempted.
    assert!(simulate(&route, 0.0, 1e300).is_err());
    let huge = HandheldParams {
        rate_hz: 1e300,
        ..Default::default()
    };
    assert!(handheld_motion(&huge).is_err());
}

proptest! {
    #[test]
    fn heading_change_is_curvature_times_distance(
        legs in proptest::collection::vec((-3.0f64..3.0, 3.0f64..200.0, 1.0f64..30.0), 1..6),
        rate in 5.0f64..200.0,
    ) {
        let mut b = RouteBuilder::at_speed(10.0).unwrap();
        let mut expected = 0.0;
        let mut turned = 0.0;
        for (angle, radius, straight) in legs {
            prop_assume!(angle.abs() > 1e-3);
            b = b.turn(angle, radius).unwrap().straight(straight).unwrap();
            expected += angle;
            turned += angle.abs();
        }
        let route = b.build();
        prop_assert!((route.turned_rad() - turned).abs() < 1e-9);
        let truth = simulate(&route, 0.0, rate).unwrap();
        let last = truth.last().unwrap();
        prop_assert!((last.heading_unwrapped_rad - expected).abs() < 1e-9);
        prop_assert!(angle_diff(last.heading_rad, expected).abs() < 1e-9);
        // Timestamps strictly increase.
        prop_assert!(truth.windows(2).all(|w| w[1].t_s > w[0].t_s));
    }

    #[test]
    fn full_circle_closes(radius in 2.0f64..500.0, speed in 0.5f64..40.0, rate in 10.0f64..200.0) {
        let route = RouteBuilder::at_speed(speed).unwrap().turn(2.0 * PI, radius).unwrap().build();
        let last = *simulate(&route, 1.0, rate).unwrap().last().unwrap();
        prop_assert!(last.north_m.hypot(last.east_m) < 1e-9 * radius.max(1.0));
        prop_assert!((last.distance_m - 2.0 * PI * radius).abs() < 1e-9 * radius);
    }

    #[test]
    fn handheld_is_deterministic_by_seed(seed in any::<u64>()) {
        let p = HandheldParams { duration_s: 2.0, seed, ..Default::default() };
        let a = handheld_motion(&p).unwrap();
        let b = handheld_motion(&p).unwrap();
        prop_assert_eq!(&a, &b);
        let c = handheld_motion(&HandheldParams { seed: seed.wrapping_add(1), ..p }).unwrap();
        prop_assert!(a != c);
    }

    #[test]
    fn handheld_gyro_matches_attitude(seed in any::<u64>()) {
        // The attitude increment between samples is the body rate integrated over the step.
        let p = HandheldParams { duration_s: 3.0, rate_hz: 200.0, seed, ..Default::default() };
        let m = handheld_motion(&p).unwrap();
        let dt = 1.0 / p.rate_hz;
        for w in m.windows(2) {
            let dq: UnitQuaternion<f64> = w[0].attitude.inverse() * w[1].attitude;
            let mean_rate = 0.5 * (w[0].gyr_rps + w[1].gyr_rps);
            prop_assert!((dq.scaled_axis() / dt - mean_rate).norm() < 1e-3);
        }
    }
}

proptest! {
    /// An eased turn turns through exactly the angle asked, its yaw rate never jumps by more
    /// than the easing allows in one sample, and a clothoid's heading is exact at any rate.
    #[test]
    fn eased_turns_turn_exactly_and_smoothly(
        angle in prop_oneof![-7.0f64..-0.05, 0.05f64..7.0],
        radius in 5.0f64..200.0,
        speed in 2.0f64..30.0,
        ease in 0.2f64..3.0,
        rate_hz in 5.0f64..100.0,
    ) {
        let route = RouteBuilder::at_speed(speed)
            .unwrap()
            .eased_turn(angle, radius, ease)
            .unwrap()
            .straight(10.0)
            .unwrap()
            .build();
        prop_assert!((route.turned_rad() - angle.abs()).abs() < 1e-9 * angle.abs().max(1.0));
        let truth = simulate(&route, 0.0, rate_hz).unwrap();
        let last = truth.last().unwrap();
        prop_assert!((last.heading_unwrapped_rad - angle).abs() < 1e-9, "{}", last.heading_unwrapped_rad);
        // The yaw rate ramps: between samples it changes by at most (v/R)·dt/ease.
        let dt = 1.0 / rate_hz;
        let effective_ease = ease.min(angle.abs() * radius / speed);
        let max_jump = speed / radius * dt / effective_ease * (1.0 + 1e-9) + 1e-12;
        for w in truth.windows(2) {
            prop_assert!((w[1].yaw_rate_rps - w[0].yaw_rate_rps).abs() <= max_jump);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The truth at instants of a sensor's own clock is the truth of the fixed-rate
    /// integration: bit for bit at the same instants, and to rounding at any subset of them
    /// (the steps between differ, the arcs do not).
    #[test]
    fn truth_at_any_instants_is_the_fixed_rate_truth(
        rate in 5.0f64..80.0, keep in proptest::collection::vec(any::<bool>(), 64), heading in -3.0f64..3.0,
    ) {
        let route = scenario::city_blocks(2, 60.0).unwrap();
        let grid = simulate(&route, heading, rate).unwrap();
        let times: Vec<f64> = grid.iter().map(|s| s.t_s).collect();
        prop_assert_eq!(&simulate_at(&route, heading, &times).unwrap(), &grid);
        let picked: Vec<&truenorth_sim::VehicleTruth> = grid
            .iter()
            .enumerate()
            .filter(|(k, _)| keep[k % keep.len()])
            .map(|(_, s)| s)
            .collect();
        let at: Vec<f64> = picked.iter().map(|s| s.t_s).collect();
        let sparse = simulate_at(&route, heading, &at).unwrap();
        for (a, b) in sparse.iter().zip(picked) {
            prop_assert!((a.north_m - b.north_m).abs() < 1e-6 && (a.east_m - b.east_m).abs() < 1e-6);
            prop_assert!((a.heading_unwrapped_rad - b.heading_unwrapped_rad).abs() < 1e-9);
            prop_assert!((a.distance_m - b.distance_m).abs() < 1e-9);
            prop_assert_eq!(a.t_s, b.t_s);
        }
    }
}

#[test]
fn instants_out_of_order_or_not_finite_are_typed_errors() {
    let route = scenario::parking().unwrap();
    assert!(simulate_at(&route, 0.0, &[1.0, 1.0]).is_err());
    assert!(simulate_at(&route, 0.0, &[2.0, 1.0]).is_err());
    assert!(simulate_at(&route, 0.0, &[f64::NAN]).is_err());
    assert!(simulate_at(&route, 0.0, &[-1.0]).is_err());
    assert!(simulate_at(&route, f64::INFINITY, &[1.0]).is_err());
    assert_eq!(simulate_at(&route, 0.0, &[]).unwrap(), vec![]);
    // Past the end the vehicle keeps going straight at its last speed (here at rest).
    let end = route.duration_s();
    let after = simulate_at(&route, 0.0, &[end, end + 10.0]).unwrap();
    assert_eq!(after[0].north_m, after[1].north_m);
}
