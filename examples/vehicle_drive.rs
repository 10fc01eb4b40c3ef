//! Vehicle heading and dead reckoning on a simulated 10 km drive: a yaw gyro with its bias
//! and gain errors, two odometer wheels of slightly different size and a compass with hard and
//! soft iron, none of them calibrated at the start. The fused estimator learns every error as
//! it drives; a patent configuration runs through the same trait for comparison. What the
//! fused estimator learned is saved as JSON and the next drive starts from it.
//!
//! Run: `cargo run --release --example vehicle_drive`

use truenorth::Error;
use truenorth::fusion::vehicle::{SeedOdometerCompass, SeedOdometerCompassConfig};
use truenorth::fusion::{VehicleConfig, VehicleEstimator};
use truenorth::prelude::*;
use truenorth_sim::{DriveSpec, SimulatedDrive};

/// Runs `estimator` over the drive and prints its heading RMS (over the rows where it is
/// referred to north), its final position error and the σ it claimed for that position.
fn score(
    name: &str,
    estimator: &mut dyn HeadingEstimator,
    drive: &SimulatedDrive,
) -> Result<(), Error> {
    let (mut heading_sq, mut referred) = (0.0, 0usize);
    let mut last = None;
    for (sample, truth) in drive.samples.iter().zip(&drive.truth) {
        let e = estimator.update(sample)?;
        if e.status.heading_absolute {
            heading_sq += angle_diff(e.heading.rad(), truth.heading_rad).powi(2);
            referred += 1;
        }
        last = Some((e, truth));
    }
    if let Some((e, truth)) = last {
        let miss_m = (e.north_m - truth.north_m).hypot(e.east_m - truth.east_m);
        // The patent configurations carry no covariance (zero): say so rather than print 0 m.
        let sigma = e.position_cov_m2.trace().sqrt();
        let sigma = if sigma > 0.0 {
            format!("{sigma:.1} m")
        } else {
            "none".to_string()
        };
        println!(
            "{name:<32} heading {:.2} deg RMS after north was found (row {}), final error {miss_m:.1} m = {:.3} % of {:.1} km (claimed 1-sigma: {sigma})",
            (heading_sq / referred.max(1) as f64).sqrt().to_degrees(),
            drive.samples.len() - referred,
            100.0 * miss_m / truth.distance_m,
            truth.distance_m / 1000.0,
        );
    }
    Ok(())
}

fn main() -> Result<(), Error> {
    let drive = SimulatedDrive::new(DriveSpec::new(2))?;
    let wheels = drive.spec.wheels.odometer_wheels();

    let mut fused = VehicleEstimator::new(VehicleConfig {
        wheels,
        ..VehicleConfig::default()
    })?;
    score("fused: gyro + wheels + compass", &mut fused, &drive)?;

    let mut seed = SeedOdometerCompass::new(SeedOdometerCompassConfig {
        wheels,
        ..SeedOdometerCompassConfig::default()
    })?;
    score("US 4,788,645: wheels + compass", &mut seed, &drive)?;

    // What the fused estimator learned (ready to carry to the next drive), against the truth.
    let learned = fused.calibration();
    let gyro = &drive.params.gyro;
    println!(
        "gyro bias at the end {:.3} ± {:.3} deg/s (true at the start {:.3}; it walks), gain error right {:+.2} ± {:.2} % (true {:+.2}), left {:+.2} ± {:.2} % (true {:+.2})",
        learned.gyro_bias_rps.value.to_degrees(),
        learned.gyro_bias_rps.sigma.to_degrees(),
        gyro.bias_rps.to_degrees(),
        100.0 * learned.gyro_gain_error_right.value,
        100.0 * learned.gyro_gain_error_right.sigma,
        100.0 * gyro.scale_error_pos,
        100.0 * learned.gyro_gain_error_left.value,
        100.0 * learned.gyro_gain_error_left.sigma,
        100.0 * gyro.scale_error_neg,
    );

    // Saved for the next drive (as `truenorth drive --calibration-out` writes it), then read
    // back, validated, and driven again from it: north is known from the first rows.
    let saved = serde_json::to_string(&learned).map_err(|_| Error::InvalidSnapshot {
        reason: "the learned calibration did not serialise",
    })?;
    let loaded = serde_json::from_str(&saved).map_err(|_| Error::InvalidSnapshot {
        reason: "the saved calibration did not read back",
    })?;
    let mut next = VehicleEstimator::with_calibration(
        VehicleConfig {
            wheels,
            ..VehicleConfig::default()
        },
        &loaded,
    )?;
    score("fused, from the saved calibration", &mut next, &drive)?;
    Ok(())
}
