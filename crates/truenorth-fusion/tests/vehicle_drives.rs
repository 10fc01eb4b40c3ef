//! The vehicle estimator on simulated mixed drives.

use truenorth_core::{HeadingEstimator, angle_diff};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_odometer::OdometerWheels;
use truenorth_sim::{DriveSpec, DriveWheels, SimulatedDrive};

struct Outcome {
    heading_rms_deg: f64,
    heading_max_deg: f64,
    final_error_pct: f64,
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
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
    let mut aligned_at_s = f64::NAN;
    let mut last = None;
    for (s, t) in drive.samples.iter().zip(&drive.truth) {
        let mut s = *s;
        if !gyro {
            s.gyr_z_rps = None;
        }
        let e = nav.update(&s).unwrap();
        if e.status.heading_absolute {
            if aligned_at_s.is_nan() {
                aligned_at_s = t.t_s;
            }
            let d = angle_diff(e.heading.rad(), t.heading_rad).to_degrees();
            sum += d * d;
            n += 1;
            max = max.max(d.abs());
        }
        last = Some((e, *t));
    }
    let (e, t) = last.unwrap();
    let err = (e.north_m - t.north_m).hypot(e.east_m - t.east_m);
    Outcome {
        heading_rms_deg: (sum / n.max(1) as f64).sqrt(),
        heading_max_deg: max,
        final_error_pct: 100.0 * err / drive.distance_m(),
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
        for seed in 0..8 {
            let o = run(
                DriveSpec {
                    wheels,
                    ..DriveSpec::new(seed)
                },
                gyro,
            );
            println!(
                "gyro {gyro:5} {wheels:?} seed {seed}: {:.0} m, aligned at {:.0} s, heading RMS {:.2}° max {:.1}°, final {:.3} %",
                o.distance_m,
                o.aligned_at_s,
                o.heading_rms_deg,
                o.heading_max_deg,
                o.final_error_pct
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
    let spec = DriveSpec::new(seed);
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
    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    for (k, (s, t)) in drive.samples.iter().zip(&drive.truth).enumerate() {
        let mut s = *s;
        if !gyro {
            s.gyr_z_rps = None;
        }
        let e = nav.update(&s).unwrap();
        if k % 10 == 0 && t.t_s < 60.0 || k % 100 == 0 {
            let x = nav.filter().x;
            let d = angle_diff(e.heading.rad(), t.heading_rad).to_degrees();
            println!(
                "t {:6.1} err {:7.2} sig {:5.2} b {:6.3} s+ {:6.4}±{:6.4} s- {:6.4} diff {:8.5}±{:7.5} a {:9.2e} v {:4.1} k {:6.4} dist {} used {} cal {}",
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
                t.speed_mps,
                t.curvature_per_m,
                e.status.compass_disturbed as u8,
                e.status.compass_used as u8,
                e.status.compass_calibrated as u8
            );
        }
    }
}
