//! What a new user writes from the README and `cargo doc -p truenorth` alone, with the facade
//! as the only dependency: calibrate a compass and read its verdict, then run an orientation
//! estimator chosen in one line. Prints `downstream: ok` when every step did what it says.

use truenorth::calib::EllipseCalibrator;
use truenorth::fusion::{EulerDetector, EulerDetectorConfig, QuaternionFilter};
use truenorth::nalgebra::{Vector2, Vector3};
use truenorth::prelude::*;

/// Errors of the library compose with `?` into the program's own.
type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// A turn of a compass with a hard iron of (20, −10) and an elliptic soft iron.
fn readings() -> Vec<Mag2Sample> {
    (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            Mag2Sample::new(
                0.1 * k as f64,
                20.0 + 30.0 * a.cos(),
                -10.0 + 24.0 * a.sin(),
            )
        })
        .collect()
}

fn calibrate() -> Result<CompassCalibration2d> {
    let mut calibrator = EllipseCalibrator::default();
    for s in readings() {
        calibrator.push(&s)?;
    }
    let solution = calibrator.solve()?;
    let verdict = solution.quality.verdict();
    println!(
        "hard iron {:.3?}, verdict {} ({verdict})",
        solution.params.hard_iron.as_slice(),
        verdict.grade
    );
    let hard_iron_error = (solution.params.hard_iron - Vector2::new(20.0, -10.0)).norm();
    if hard_iron_error > 1e-6 {
        return Err(format!("the calibration missed the hard iron by {hard_iron_error}").into());
    }
    Ok(solution.params)
}

/// Ten seconds at rest, level, facing magnetic north.
fn orientation(estimator: &mut dyn OrientationEstimator) -> Result<f64> {
    let mut heading = f64::NAN;
    for k in 1..=1000 {
        let sample = ImuSample::new_9d(
            0.01 * k as f64,
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, -9.81),
            Vector3::new(20.0, 0.0, 45.0),
        );
        let estimate = estimator.update(&sample)?;
        heading = estimate.attitude.euler_angles().2;
    }
    Ok(heading)
}

fn main() -> Result<()> {
    let cal = calibrate()?;
    let h = cal.heading_rad(&Vector2::new(50.0, -10.0));
    println!("heading of a reading along +x: {:.3} deg", h.to_degrees());
    // The one line a user changes to swap methods.
    let mut estimators: [Box<dyn OrientationEstimator>; 2] = [
        Box::new(QuaternionFilter::default()),
        Box::new(EulerDetector::new(EulerDetectorConfig::default())?),
    ];
    for estimator in &mut estimators {
        let heading = orientation(estimator.as_mut())?;
        println!(
            "heading at rest facing north: {:.3} deg",
            heading.to_degrees()
        );
        if heading.abs().to_degrees() > 1.0 {
            return Err("an estimator at rest facing north did not read north".into());
        }
    }
    println!("downstream: ok");
    Ok(())
}
