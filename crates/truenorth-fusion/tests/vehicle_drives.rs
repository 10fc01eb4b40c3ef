//! The vehicle estimator on simulated mixed drives.

use truenorth_core::{HeadingEstimator, NavEstimate, VehicleSample, angle_diff};
use truenorth_fusion::vehicle::{TwoPassConfig, TwoPassStart};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_odometer::OdometerWheels;
use truenorth_sim::{DriveSpec, DriveWheels, SimulatedDrive};

struct Outcome {
    disturbed_rms_deg: f64,
    flagged_share: f64,
    a_ratio: f64,
    diff_err: f64,
    gain_err: (f64, f64),
    track_err: f64,
    heading_rms_deg: f64,
    heading_max_deg: f64,
    final_error_pct: f64,
    scaled_error_pct: f64,
    aligned_at_s: f64,
    distance_m: f64,
}

fn run(spec: DriveSpec, gyro: bool) -> Outcome {
    let drive = SimulatedDrive::new(spec).unwrap();
    let wheels: OdometerWheels = spec.wheels.odometer_wheels();
    let mut nav = VehicleEstimator::new(VehicleConfig {
        wheels,
        ..VehicleConfig::default()
    })
    .unwrap();
    let samples: Vec<_> = drive
        .samples
        .iter()
        .map(|s| VehicleSample {
            gyr_z_rps: if gyro { s.gyr_z_rps } else { None },
            ..*s
        })
        .collect();
    let seed_method = std::env::var("SEED_METHOD").ok();
    let estimates: Vec<NavEstimate> = if let Some(m) = seed_method {
        use truenorth_fusion::vehicle::*;
        let mut e: Box<dyn HeadingEstimator> = if m == "B" {
            Box::new(
                SeedOdometerCompass::new(SeedOdometerCompassConfig {
                    wheels,
                    ..Default::default()
                })
                .unwrap(),
            )
        } else {
            Box::new(
                SeedGyroCompass::new(SeedGyroCompassConfig {
                    wheels,
                    ..Default::default()
                })
                .unwrap(),
            )
        };
        samples.iter().map(|s| e.update(s).unwrap()).collect()
    } else if std::env::var("TWO_PASS").is_ok() {
        let mut two = TwoPassStart::new(nav.clone(), TwoPassConfig::default());
        let mut out = Vec::new();
        for s in &samples {
            two.push(s, |_, e, _| out.push(*e)).unwrap();
        }
        two.finish(|_, e, _| out.push(*e)).unwrap();
        nav = two.estimator().clone();
        out
    } else {
        samples.iter().map(|s| nav.update(s).unwrap()).collect()
    };
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
    let (mut dsum, mut dn, mut flagged) = (0.0, 0usize, 0usize);
    let mut aligned_at_s = f64::NAN;
    let mut last = None;
    for (e, t) in estimates.iter().zip(&drive.truth) {
        let e = *e;
        if e.status.heading_absolute {
            if aligned_at_s.is_nan() {
                aligned_at_s = t.t_s;
            }
            let d = angle_diff(e.heading.rad(), t.heading_rad).to_degrees();
            sum += d * d;
            n += 1;
            if drive.disturbed_at(t.t_s) {
                dsum += d * d;
                dn += 1;
            }
            if e.status.compass_disturbed {
                flagged += 1;
            }
            max = max.max(d.abs());
        }
        last = Some((e, *t));
    }
    let (e, t) = last.unwrap();
    let err = (e.north_m - t.north_m).hypot(e.east_m - t.east_m);
    let o = drive.params.odometer;
    let k = 1.0 + 0.5 * (o.scale_error_l + o.scale_error_r);
    let err_scaled = (e.north_m / k - t.north_m).hypot(e.east_m / k - t.east_m);
    let x = nav.filter().x;
    let g = drive.params.gyro;
    Outcome {
        disturbed_rms_deg: (dsum / dn.max(1) as f64).sqrt(),
        flagged_share: flagged as f64 / n.max(1) as f64,
        a_ratio: x[7] / o.speed_coeff_s2_per_m2,
        diff_err: x[6] - ((1.0 + o.scale_error_l) / (1.0 + o.scale_error_r) - 1.0),
        gain_err: (x[4] - g.scale_error_pos, x[5] - g.scale_error_neg),
        track_err: x[9] - (0.5 * (o.scale_error_l + o.scale_error_r)),
        heading_rms_deg: (sum / n.max(1) as f64).sqrt(),
        heading_max_deg: max,
        final_error_pct: 100.0 * err / drive.distance_m(),
        scaled_error_pct: 100.0 * err_scaled / drive.distance_m(),
        aligned_at_s,
        distance_m: drive.distance_m(),
    }
}

#[test]
#[ignore]
fn measure() {
    for (gyro, wheels) in [
        (true, DriveWheels::Rear),
        (false, DriveWheels::Rear),
        (false, DriveWheels::Front),
        (true, DriveWheels::Front),
    ] {
        for seed in 0..std::env::var("SEEDS").map_or(8, |s| s.parse().unwrap()) {
            let o = run(
                DriveSpec {
                    wheels,
                    opening_turn: std::env::var("NO_TURN").is_err(),
                    disturbances: std::env::var("CLEAN").is_err(),
                    rate_hz: std::env::var("RATE").map_or(10.0, |r| r.parse().unwrap()),
                    ..DriveSpec::new(seed)
                },
                gyro,
            );
            println!(
                "gyro {gyro:5} {wheels:?} seed {seed}: {:.0} m, aligned {:.0} s, hdg RMS {:.2}° max {:.1}° (disturbed {:.2}°, flagged {:.1} %), final {:.3} % (scale removed {:.3} %), a/a_true {:.2}, δ err {:.1e}, gain err {:.1e} {:.1e} track err {:.1e}",
                o.distance_m,
                o.aligned_at_s,
                o.heading_rms_deg,
                o.heading_max_deg,
                o.disturbed_rms_deg,
                100.0 * o.flagged_share,
                o.final_error_pct,
                o.scaled_error_pct,
                o.a_ratio,
                o.diff_err,
                o.gain_err.0,
                o.gain_err.1,
                o.track_err
            );
        }
    }
}

#[test]
#[ignore]
fn trace() {
    let seed: u64 = std::env::var("SEED")
        .map(|s| s.parse().unwrap())
        .unwrap_or(1);
    let gyro = std::env::var("GYRO").is_ok();
    let wheels = if std::env::var("FRONT").is_ok() {
        DriveWheels::Front
    } else {
        DriveWheels::Rear
    };
    let spec = DriveSpec {
        opening_turn: std::env::var("NO_TURN").is_err(),
        wheels,
        ..DriveSpec::new(seed)
    };
    let drive = SimulatedDrive::new(spec).unwrap();
    println!("params {:?}", drive.params);
    for d in &drive.disturbances {
        println!(
            "dist {:.0}..{:.0} {:?}",
            d.start_s,
            d.start_s + d.duration_s,
            d.field_ned
        );
    }
    let mut nav = VehicleEstimator::new(VehicleConfig {
        wheels: wheels.odometer_wheels(),
        ..VehicleConfig::default()
    })
    .unwrap();
    for (k, (s, t)) in drive.samples.iter().zip(&drive.truth).enumerate() {
        let mut s = *s;
        if !gyro {
            s.gyr_z_rps = None;
        }
        let before = nav.compass().fix().map(|f| f.calibration);
        let e = nav.update(&s).unwrap();
        if nav.compass().fix().map(|f| f.calibration) != before {
            let f = nav.compass().fix().unwrap();
            let truth_cal = truenorth_compass::CompassCalibration2d {
                hard_iron: drive.params.compass_hard_iron,
                soft_iron: drive.params.compass_soft_iron.try_inverse().unwrap(),
            };
            let worst = (0..360)
                .map(|d| {
                    let psi = (d as f64).to_radians();
                    let raw = drive.params.compass_soft_iron
                        * nalgebra::Vector2::new(20.0 * psi.cos(), -20.0 * psi.sin())
                        + drive.params.compass_hard_iron;
                    angle_diff(f.calibration.heading_rad(&raw), psi)
                        .to_degrees()
                        .abs()
                })
                .fold(0.0, f64::max);
            let _ = truth_cal;
            println!(
                "t {:.0} new fix clean {} 3σ {:.2} sys {:.2} noise {:.2} points {} cov {:.2} worst true heading error {:.2}°",
                t.t_s,
                nav.compass_learner().clean_in_use(),
                f.quality.heading_error_3sigma_deg,
                f.quality.heading_error_systematic_deg,
                f.quality.heading_noise_rms_deg,
                f.quality.fit.points,
                f.quality.fit.coverage,
                worst
            );
        }
        if k % 300 == 0 && !e.status.heading_absolute {
            use truenorth_core::Calibrator;
            let c = nav.compass_learner().calibrator();
            println!(
                "t {:.0} progress {:?} solve {:?}",
                t.t_s,
                c.progress(),
                c.solve().map(|s| s.quality)
            );
        }
        if k % 10 == 0 && t.t_s < std::env::var("FINE").map_or(60.0, |v| v.parse().unwrap())
            || k % 100 == 0
        {
            let x = nav.filter().x;
            let d = angle_diff(e.heading.rad(), t.heading_rad).to_degrees();
            println!(
                "t {:6.1} err {:7.2} sig {:5.2} b {:6.3} s+ {:6.4}±{:6.4} s- {:6.4} diff {:8.5}±{:7.5} a {:9.2e}±{:8.1e} v {:4.1} k {:6.4} dist {} used {} cal {}",
                t.t_s,
                d,
                e.heading_sigma_rad.to_degrees(),
                x[3].to_degrees(),
                x[4],
                nav.filter().sigma(4),
                x[5],
                x[6],
                nav.filter().sigma(6),
                x[7],
                nav.filter().sigma(7),
                t.speed_mps,
                t.curvature_per_m,
                e.status.compass_disturbed as u8,
                e.status.compass_used as u8,
                e.status.compass_calibrated as u8
            );
        }
    }
}

#[test]
#[ignore]
fn dump_mag() {
    let seed: u64 = std::env::var("SEED")
        .map(|s| s.parse().unwrap())
        .unwrap_or(4);
    let drive = SimulatedDrive::new(DriveSpec {
        opening_turn: false,
        disturbances: false,
        ..DriveSpec::new(seed)
    })
    .unwrap();
    let mut out = String::new();
    for (s, t) in drive.samples.iter().zip(&drive.truth) {
        if t.t_s > 600.0 {
            break;
        }
        let m = s.mag.unwrap();
        out += &format!("{},{},{},{}\n", t.t_s, m.x, m.y, t.heading_rad.to_degrees());
    }
    std::fs::write("/tmp/mag4.csv", out).unwrap();
}
