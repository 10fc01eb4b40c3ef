//! The vehicle estimators on simulated mixed drives of 9-13 km (city blocks, curves, roundabouts,
//! ramps, highway; gyro bias, drift and per-direction scale, wheel scale and quantisation,
//! hard and soft iron, short strong and long slow field-turning disturbances; one parameter
//! set for every seed).
//!
//! The suite holds the goals on eight seeds per configuration; the wider measurement is
//! `cargo test --release -p truenorth-fusion --test vehicle_drives -- --ignored --nocapture`
//! (`SEEDS=40` for more drives, `NO_TURN=1` for drives that open without a full turn).

use truenorth_core::{HeadingEstimator, NavEstimate, VehicleSample};
use truenorth_fusion::vehicle::{
    SeedGyroCompass, SeedGyroCompassConfig, SeedOdometerCompass, SeedOdometerCompassConfig,
    TwoPassConfig, TwoPassStart,
};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_sim::{DriveScore, DriveSpec, DriveWheels, SimulatedDrive};

/// Which estimator runs the drive.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    /// The fused estimator, streaming: heading is relative until the compass is learned.
    Fused,
    /// The fused estimator with the two-pass start (what `truenorth drive` does by default).
    FusedTwoPass,
    /// Gyro + compass, US 4,788,645's companion EP 0640207 configuration.
    SeedGyroCompass,
    /// Compass + odometer, US 4,788,645.
    SeedOdometerCompass,
}

/// The compass's systematic error in this simulator's world: its roads are flat and its
/// compass level, so no grade or camber tilts the field's vertical part into the heading
/// (the default's 3°, `CompassGates::systematic_deg`); what is left is the installation's,
/// 0.3°.
fn level_world_compass() -> truenorth_fusion::CompassGates {
    truenorth_fusion::CompassGates {
        systematic_deg: 0.3,
        ..truenorth_fusion::CompassGates::default()
    }
}

fn run(drive: &SimulatedDrive, gyro: bool, method: Method) -> DriveScore {
    let wheels = drive.spec.wheels.odometer_wheels();
    let samples = drive.samples.iter().map(|s| VehicleSample {
        gyr_z_rps: if gyro { s.gyr_z_rps } else { None },
        ..*s
    });
    let nav = || {
        VehicleEstimator::new(VehicleConfig {
            wheels,
            compass: level_world_compass(),
            ..VehicleConfig::default()
        })
        .unwrap()
    };
    let estimates: Vec<NavEstimate> = match method {
        Method::FusedTwoPass => {
            let mut two = TwoPassStart::new(nav(), TwoPassConfig::default()).unwrap();
            let mut out = Vec::new();
            for s in samples {
                two.push(&s, |_, e, _| out.push(*e)).unwrap();
            }
            two.finish(|_, e, _| out.push(*e)).unwrap();
            out
        }
        _ => {
            let mut e: Box<dyn HeadingEstimator> = match method {
                Method::Fused => Box::new(nav()),
                Method::SeedGyroCompass => Box::new(
                    SeedGyroCompass::new(SeedGyroCompassConfig {
                        wheels,
                        ..Default::default()
                    })
                    .unwrap(),
                ),
                _ => Box::new(
                    SeedOdometerCompass::new(SeedOdometerCompassConfig {
                        wheels,
                        ..Default::default()
                    })
                    .unwrap(),
                ),
            };
            samples.map(|s| e.update(&s).unwrap()).collect()
        }
    };
    drive.score(&estimates).unwrap()
}

fn drive(seed: u64, wheels: DriveWheels, opening_turn: bool) -> SimulatedDrive {
    SimulatedDrive::new(DriveSpec {
        wheels,
        opening_turn,
        ..DriveSpec::new(seed)
    })
    .unwrap()
}

const CONFIGS: [(bool, DriveWheels); 4] = [
    (true, DriveWheels::Rear),
    (true, DriveWheels::Front),
    (false, DriveWheels::Rear),
    (false, DriveWheels::Front),
];

/// The goals of the fused estimator, as `truenorth drive` runs it: with a gyro, heading RMS
/// ≤ 0.5° and final position error ≤ 0.3 % of the distance; compass and wheels alone,
/// ≤ 1 % of the distance (the telematics norm is about 2.5 %). The final error is judged
/// once the odometer's mean scale is divided out: the simulator draws it within ±0.4 %, no
/// sensor on board sees it, and left in it would decide a 0.3 % goal by the draw.
#[test]
fn fused_estimator_meets_its_goals_on_eight_mixed_drives_per_configuration() {
    for (gyro, wheels) in CONFIGS {
        let mut heading = Vec::new();
        let mut fin = Vec::new();
        let mut removed = Vec::new();
        for seed in 0..8 {
            let d = drive(seed, wheels, true);
            let o = run(&d, gyro, Method::FusedTwoPass);
            heading.push(o.heading_rms_deg);
            fin.push(o.final_error_pct);
            removed.push(o.scale_removed_pct);
            let label = format!("gyro {gyro} {wheels:?} seed {seed}");
            assert!(d.distance_m() > 7500.0, "{label}: {} m", d.distance_m());
            assert_eq!(
                o.absolute_from_s, 0.0,
                "{label}: every row referred to north"
            );
            if gyro {
                assert!(
                    o.heading_rms_deg <= 0.5,
                    "{label}: heading RMS {:.2}°",
                    o.heading_rms_deg
                );
                assert!(
                    o.scale_removed_pct <= 0.3,
                    "{label}: final {:.3} % with the mean wheel scale divided out",
                    o.scale_removed_pct
                );
            } else {
                assert!(
                    o.scale_removed_pct <= 1.0,
                    "{label}: final {:.3} % with the mean wheel scale divided out",
                    o.scale_removed_pct
                );
            }
        }
        heading.sort_by(f64::total_cmp);
        fin.sort_by(f64::total_cmp);
        removed.sort_by(f64::total_cmp);
        println!(
            "gyro {gyro} {wheels:?}: heading RMS median {:.2}° (worst {:.2}°), final median {:.3} % (worst {:.3} %), scale removed median {:.3} % (worst {:.3} %)",
            0.5 * (heading[3] + heading[4]),
            heading[7],
            0.5 * (fin[3] + fin[4]),
            fin[7],
            0.5 * (removed[3] + removed[4]),
            removed[7]
        );
    }
}

/// Streaming (no second pass): north is learned during the opening turn, and heading is
/// absolute from then on; the disturbances (the simulator's slow ones turn the field by
/// 10-25° at almost constant magnitude) leave the heading within 1° RMS, which a compass
/// followed through them would not.
#[test]
fn streaming_learns_north_in_the_opening_turn_and_rides_through_disturbances() {
    for seed in 0..4 {
        let d = drive(seed, DriveWheels::Rear, true);
        assert!(!d.disturbances.is_empty());
        let o = run(&d, true, Method::Fused);
        // The opening turn takes well under two minutes: a full turn at walking pace.
        assert!(
            o.absolute_from_s < 120.0,
            "seed {seed}: north after {:.0} s",
            o.absolute_from_s
        );
        assert!(
            o.heading_rms_deg <= 0.5,
            "seed {seed}: {:.2}°",
            o.heading_rms_deg
        );
        assert!(
            o.disturbed_rms_deg <= 1.0,
            "seed {seed}: {:.2}° inside disturbances",
            o.disturbed_rms_deg
        );
    }
}

/// The seed configurations run on the same drives and refer heading to north, and the
/// fused estimator does better than either on every drive (same sensors for the
/// comparison: EP 0640207's configuration uses gyro + compass, US 4,788,645's compass +
/// wheels). The odometer-compass configuration keeps its last compass calibration while
/// its calibrator starts its bins over: dropping it, seed 2 lost its compass for good
/// after 90 s.
#[test]
fn the_fused_estimator_beats_each_seed_configuration_on_the_same_drives() {
    for seed in 0..3 {
        let d = drive(seed, DriveWheels::Rear, true);
        for (gyro, seed_method) in [
            (true, Method::SeedGyroCompass),
            (false, Method::SeedOdometerCompass),
        ] {
            let s = run(&d, gyro, seed_method);
            let f = run(&d, gyro, Method::FusedTwoPass);
            assert!(s.heading_rms_deg.is_finite(), "{seed_method:?} seed {seed}");
            assert!(
                f.heading_rms_deg < s.heading_rms_deg && f.final_error_pct < s.final_error_pct,
                "{seed_method:?} seed {seed}: fused {:.2}° {:.2} %, seed {:.2}° {:.2} %",
                f.heading_rms_deg,
                f.final_error_pct,
                s.heading_rms_deg,
                s.final_error_pct
            );
        }
    }
}

#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn measure() {
    let seeds = std::env::var("SEEDS").map_or(8, |s| s.parse().unwrap());
    let opening_turn = std::env::var("NO_TURN").is_err();
    let methods = [
        Method::FusedTwoPass,
        Method::Fused,
        Method::SeedGyroCompass,
        Method::SeedOdometerCompass,
    ];
    let lengths: Vec<f64> = (0..seeds)
        .map(|seed| drive(seed, DriveWheels::Rear, opening_turn).distance_m())
        .collect();
    println!(
        "{seeds} drives of {:.1}-{:.1} km",
        lengths.iter().copied().fold(f64::INFINITY, f64::min) / 1e3,
        lengths.iter().copied().fold(0.0, f64::max) / 1e3
    );
    println!(
        "method | gyro | wheels | heading RMS ° (median, worst) | final % (median, worst) | scale removed % (median) | fails"
    );
    for method in methods {
        for (gyro, wheels) in CONFIGS {
            if (method == Method::SeedGyroCompass && !gyro)
                || (method == Method::SeedOdometerCompass && gyro)
            {
                continue;
            }
            let mut rows: Vec<DriveScore> = (0..seeds)
                .map(|seed| run(&drive(seed, wheels, opening_turn), gyro, method))
                .collect();
            let fails = rows
                .iter()
                .filter(|o| {
                    if gyro {
                        o.heading_rms_deg > 0.5 || o.final_error_pct > 0.3
                    } else {
                        o.final_error_pct > 1.0
                    }
                })
                .count();
            let median = |rows: &mut Vec<DriveScore>, f: fn(&DriveScore) -> f64| {
                rows.sort_by(|a, b| f(a).total_cmp(&f(b)));
                (f(&rows[rows.len() / 2]), f(rows.last().unwrap()))
            };
            let h = median(&mut rows, |o| o.heading_rms_deg);
            let p = median(&mut rows, |o| o.final_error_pct);
            let s = median(&mut rows, |o| o.scale_removed_pct);
            println!(
                "{method:?} | {gyro} | {wheels:?} | {:.2}, {:.2} | {:.3}, {:.3} | {:.3} | {fails}/{seeds}",
                h.0, h.1, p.0, p.1, s.0
            );
        }
    }
}
