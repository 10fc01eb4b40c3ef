//! Fixes stamped seconds after their epoch (a logger's queue, a receiver on another clock),
//! on simulated drives with a real receiver's habits: told the delay
//! (`GnssConfig::latency_s`), the estimator compares each fix with where the dead-reckoned
//! path was at its epoch, and does as well as with fixes stamped on time; not told, it
//! rejects fixes by the hundred and turns its heading to follow the late ones.
//!
//! Run: `cargo test --release -p truenorth-fusion --test vehicle_gnss_late -- --nocapture`.

use truenorth_core::{HeadingEstimator, VehicleSample, angle_diff};
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

/// How much later than the receiver's own delay the fixes are stamped, s.
const LATE_S: f64 = 2.0;

/// One run: heading RMS against the truth once referred to true north (°), and the fixes
/// rejected.
fn run(d: &LogDrive, rows: &[VehicleSample], latency_s: f64) -> (f64, u32) {
    let mut config = VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(SensorPriors::for_wheels(&d.vehicle.wheels)),
        ..VehicleConfig::default()
    };
    config.gnss.latency_s = latency_s;
    let mut nav = VehicleEstimator::new(config).unwrap();
    let (mut sq, mut n) = (0.0, 0usize);
    for (s, t) in rows.iter().zip(&d.truth) {
        let e = nav.update(s).unwrap();
        if let Some(decl) = nav.gnss_declination_rad() {
            sq += angle_diff(e.heading.rad() + decl, t.heading_rad).powi(2);
            n += 1;
        }
    }
    (
        (sq / n.max(1) as f64).sqrt().to_degrees(),
        nav.gnss_counts().rejected,
    )
}

#[test]
fn fixes_stamped_late_are_taken_at_their_epoch_when_told() {
    let default_latency = VehicleConfig::default().gnss.latency_s;
    let (mut on_time_sq, mut told_sq, mut untold_sq) = (0.0, 0.0, 0.0);
    let mut drives = 0.0;
    for seed in 0..4 {
        let config = LogDriveConfig::new(seed, VehicleKind::RearWheelCar, SensorSet::WHEELS_GYRO)
            .with_gnss();
        let d = LogDrive::new(config).unwrap();
        let samples = d.vehicle_samples();
        let late = d.samples_with_fixes_late(LATE_S);
        let on_time = run(&d, &samples, default_latency);
        let told = run(&d, &late, default_latency + LATE_S);
        let untold = run(&d, &late, default_latency);
        println!(
            "seed {seed}: heading RMS {:.2}° ({} fixes rejected) on time; {LATE_S} s late {:.2}° ({}) told, {:.2}° ({}) not told",
            on_time.0, on_time.1, told.0, told.1, untold.0, untold.1
        );
        // Told, the late fixes are as good as fixes on time, within the trail's chords (a
        // tenth of a second each) and the heading's drift over the delay. (Drawn back along
        // the heading of then instead of the path, seeds 0 and 1 came to 2.35° and 2.27°.)
        assert!(
            told.0 <= 1.15 * on_time.0 + 0.15,
            "seed {seed}: told {:.2}° against {:.2}° on time",
            told.0,
            on_time.0
        );
        on_time_sq += on_time.0.powi(2);
        told_sq += told.0.powi(2);
        untold_sq += untold.0.powi(2);
        drives += 1.0;
    }
    let rms = |sq: f64| (sq / drives).sqrt();
    let (on_time, told, untold) = (rms(on_time_sq), rms(told_sq), rms(untold_sq));
    println!(
        "heading RMS over the drives: on time {on_time:.2}°, {LATE_S} s late told {told:.2}°, not told {untold:.2}°"
    );
    assert!(
        untold > 2.0 * told,
        "not told {untold:.2}°, told {told:.2}°"
    );
}
