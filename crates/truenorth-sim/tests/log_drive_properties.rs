//! Properties of [`LogDrive`]: any configuration gives a drive or a typed error, the same
//! seed the same drive, and the truth behind every reading is exact.

use proptest::prelude::*;
use truenorth_sim::{
    Episodes, GnssConfig, LogDrive, LogDriveConfig, OdometryReading, Origin, RouteShape, SensorSet,
    Span, TiltConfig, VehicleKind, simulate_at,
};

/// A short drive of `kind` carrying `sensors`.
fn short(seed: u64, kind: VehicleKind, sensors: SensorSet) -> LogDriveConfig {
    let mut c = LogDriveConfig::new(seed, kind, sensors);
    c.motion.length_m = if kind.is_car() { 200.0 } else { 20.0 };
    c
}

fn kind() -> impl Strategy<Value = VehicleKind> {
    prop::sample::select(VehicleKind::ALL.to_vec())
}

type Setter = fn(&mut LogDriveConfig, f64);

/// Every numeric field a user may set, one at a time.
const SETTERS: [Setter; 32] = [
    |c, x| c.motion.length_m = x.min(400.0),
    |c, x| {
        c.motion.shape = RouteShape::Circling {
            turns: x.min(3.0),
            radius_m: Span::new(5.0, 10.0),
            lateral_mps2: Span::fixed(2.0),
        }
    },
    |c, x| {
        c.motion.shape = RouteShape::Circling {
            turns: 1.0,
            radius_m: Span::new(x, 10.0),
            lateral_mps2: Span::fixed(2.0),
        }
    },
    |c, x| {
        c.motion.shape = RouteShape::Circling {
            turns: 1.0,
            radius_m: Span::fixed(10.0),
            lateral_mps2: Span::new(0.5, x),
        }
    },
    |c, x| c.motion.rests.as_mut().unwrap().duration_s = Span::new(0.5, x),
    |c, x| c.motion.rests.as_mut().unwrap().min_gap_s = x,
    |c, x| c.motion.rests.as_mut().unwrap().mean_extra_gap_s = x,
    |c, x| c.timing.gyro.rate_hz = Span::new(x, 200.0),
    |c, x| c.timing.odometry.latency_s = Span::fixed(x),
    |c, x| c.timing.compass.jitter_s = x,
    |c, x| c.timing.odometry.drop_probability = Span::new(0.0, x),
    |c, x| c.timing.stamp_resolution_s = x,
    |c, x| c.timing.start_s = x,
    |c, x| c.wheels.loop_hz = x,
    |c, x| c.wheels.lag_s = Span::new(0.0, x),
    |c, x| c.wheels.tick_m = Span::fixed(x),
    |c, x| c.wheels.speed_quantum_mps = x,
    |c, x| c.wheels.dist_quantum_m = x,
    |c, x| c.yaw_rate.bias_dps = Span::new(0.0, x),
    |c, x| c.yaw_rate.scale_error = x,
    |c, x| c.yaw_rate.tilt_deg = Span::fixed(x),
    |c, x| c.compass.field_ut = Span::fixed(x),
    |c, x| c.skid_steer.ground_factor = Span::new(1.0, x),
    |c, x| c.robot.track_m = Some(Span::fixed(x)),
    |c, x| {
        c.gnss = Some(GnssConfig {
            sigma_m: Span::new(0.0, x),
            ..GnssConfig::for_car()
        })
    },
    |c, x| {
        c.gnss = Some(GnssConfig {
            tau_s: Span::fixed(x),
            ..GnssConfig::for_car()
        })
    },
    |c, x| {
        c.gnss = Some(GnssConfig {
            origin: Origin {
                lat_deg: x,
                ..Origin::BERLIN
            },
            ..GnssConfig::for_car()
        })
    },
    |c, x| {
        c.gnss = Some(GnssConfig {
            outages: Some(Episodes {
                first_after_s: 0.0,
                mean_gap_s: x,
                duration_s: Span::new(1.0, 5.0),
            }),
            ..GnssConfig::for_car()
        })
    },
    |c, x| {
        c.gnss = Some(GnssConfig {
            lever_forward_m: Span::fixed(x),
            ..GnssConfig::for_robot()
        })
    },
    |c, x| c.compass.declination_deg = Some(x),
    |c, x| {
        c.tilt = Some(TiltConfig {
            dip_deg: Span::fixed(x),
            ..TiltConfig::for_car()
        })
    },
    |c, x| {
        c.tilt = Some(TiltConfig {
            grade_length_m: Span::fixed(x),
            ..TiltConfig::for_robot()
        })
    },
];

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop::num::f64::ANY,
        prop::sample::select(vec![
            0.0,
            -1.0,
            1e-9,
            0.5,
            1.0,
            3.0,
            1e9,
            f64::NAN,
            f64::INFINITY
        ]),
        0.0f64..10.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Any value in any field gives a drive whose rows are well formed, or a typed error.
    #[test]
    fn any_value_in_any_field_gives_a_drive_or_a_typed_error(
        k in kind(), field in 0..SETTERS.len(), x in value(), seed in any::<u64>(),
    ) {
        let mut c = short(seed, k, SensorSet::WHEELS_GYRO.with_compass());
        SETTERS[field](&mut c, x);
        if let Ok(d) = LogDrive::new(c) {
            prop_assert_eq!(d.rows.len(), d.truth.len());
            prop_assert!(d.rows.windows(2).all(|w| w[1].t_s > w[0].t_s));
            let csv = d.to_csv();
            prop_assert!(!csv.contains("NaN") && !csv.contains("inf"));
        }
    }

    /// The same seed gives the same drive; another seed another.
    #[test]
    fn drives_are_deterministic_by_seed(seed in any::<u64>(), k in kind()) {
        let c = short(seed, k, SensorSet::SPEED_YAW.with_compass());
        let (a, b) = (LogDrive::new(c).unwrap(), LogDrive::new(c).unwrap());
        prop_assert_eq!(&a.rows, &b.rows);
        prop_assert_eq!(&a.truth, &b.truth);
        let other = LogDrive::new(LogDriveConfig { seed: seed ^ 1, ..c }).unwrap();
        prop_assert!(a.rows != other.rows);
    }

    /// With its noise and walk removed, the gyro reads exactly its gain times the true yaw
    /// rate at the instant the truth says it measured, plus its bias, to half a quantum.
    #[test]
    fn a_gyro_reading_is_its_errors_applied_to_the_truth_at_its_instant(seed in any::<u64>(), k in kind()) {
        let mut c = short(seed, k, SensorSet::GYRO_COMPASS);
        c.yaw_rate.noise_dps_per_sqrt_hz = Span::fixed(0.0);
        c.yaw_rate.bias_walk_dps_per_sqrt_s = Span::fixed(0.0);
        let d = LogDrive::new(c).unwrap();
        let e = d.errors.yaw_rate;
        let start = c.timing.start_s;
        let at: Vec<(f64, f64)> = d.rows.iter().zip(&d.measured)
            .filter_map(|(r, m)| Some((m.gyro_s? - start, r.gyr_z_rps?))).collect();
        let times: Vec<f64> = at.iter().map(|a| a.0).collect();
        let truth = simulate_at(&d.route, d.heading0_rad, &times).unwrap();
        for ((_, g), t) in at.iter().zip(&truth) {
            let rate = t.yaw_rate_rps;
            let expect = e.gain(rate * e.tilt_rad.cos() >= 0.0) * rate + e.gyro.bias_rps;
            prop_assert!((g - expect).abs() <= 0.5 * e.quantum_rps + 1e-12, "{} vs {}", g, expect);
        }
    }

    /// The odometer pair's counts are its wheels' true paths, scaled and cut to whole pulses,
    /// at the instant the truth says the controller counted them: on a rear axle, their mean
    /// is the distance driven times the mean scale (the slip only moves the difference).
    #[test]
    fn wheel_counts_are_the_distance_driven_at_their_instant(seed in any::<u64>()) {
        let c = short(seed, VehicleKind::RearWheelCar, SensorSet::WHEELS);
        let d = LogDrive::new(c).unwrap();
        let rear = d.errors.rear;
        let tick = rear.dist_per_pulse_m.unwrap();
        let mut times = Vec::new();
        let mut means = Vec::new();
        for (r, m) in d.rows.iter().zip(&d.measured) {
            if let (Some(OdometryReading::WheelDistances([l, rr])), Some(at)) = (r.odometry, m.odometry_s) {
                times.push(at);
                means.push((l / (1.0 + rear.scale_error_l) + rr / (1.0 + rear.scale_error_r)) / 2.0);
            }
        }
        let truth = simulate_at(&d.route, d.heading0_rad, &times).unwrap();
        let start = truth[0].distance_m - means[0];
        for (t, m) in truth.iter().zip(&means) {
            prop_assert!((t.distance_m - start - m).abs() <= 2.0 * tick, "{} vs {}", t.distance_m - start, m);
        }
    }
}

#[test]
fn a_configuration_reads_from_json_with_its_defaults_and_names_an_unknown_value() {
    let c = LogDriveConfig::real_skid_steer(3);
    let json = serde_json::to_string(&c).unwrap();
    let back: LogDriveConfig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, c);
    let partial: LogDriveConfig =
        serde_json::from_str(r#"{"seed": 5, "motion": {"length_m": 100.0}}"#).unwrap();
    assert_eq!(partial.seed, 5);
    assert_eq!(partial.motion.length_m, 100.0);
    assert_eq!(partial.motion.rests, LogDriveConfig::default().motion.rests);
    let bad: Result<LogDriveConfig, _> = serde_json::from_str(r#"{"kind": "Tank"}"#);
    assert!(bad.unwrap_err().to_string().contains("Tank"));
}

#[test]
fn impossible_sets_and_sizes_are_refused_with_a_reason() {
    let e = LogDrive::new(short(
        1,
        VehicleKind::Differential,
        SensorSet::FOUR_WHEEL_SPEEDS,
    ))
    .unwrap_err();
    assert!(e.to_string().contains("two wheels"), "{e}");
    let mut c = short(1, VehicleKind::SkidSteer, SensorSet::WHEELS);
    c.motion.length_m = 1e6;
    c.wheels.loop_hz = 1e4;
    let e = LogDrive::new(c).unwrap_err();
    assert!(e.to_string().contains("readings of the drive"), "{e}");
}
