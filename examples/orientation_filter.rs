//! An orientation filter on two minutes of simulated hand-held motion (a consumer IMU whose
//! gyro has 0.3°/s of bias on every axis), scored against the truth. The estimator is chosen
//! in one line: both implement `OrientationEstimator`, so the loop does not change.
//!
//! Run: `cargo run --release --example orientation_filter [quaternion|euler]`

use truenorth::Error;
use truenorth::fusion::{
    AttitudeError, EulerDetector, EulerDetectorConfig, GyroTiming, QuaternionFilter,
    QuaternionFilterConfig,
};
use truenorth::prelude::*;
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

fn main() -> Result<(), Error> {
    let method = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "quaternion".into());

    // The one line a user changes to swap methods.
    let mut estimator: Box<dyn OrientationEstimator> = match method.as_str() {
        "euler" => Box::new(EulerDetector::new(EulerDetectorConfig::default())?),
        _ => Box::new(QuaternionFilter::new(QuaternionFilterConfig {
            // The simulator's gyro reads the rate at each instant, not the mean over a step.
            gyro_timing: GyroTiming::Instantaneous,
            ..QuaternionFilterConfig::default()
        })?),
    };

    let truth = handheld_motion(&HandheldParams {
        duration_s: 120.0,
        ..HandheldParams::default()
    })?;
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), 3)?;

    // Score after the first 20 s, once the filter has found the gyro bias and north.
    let (mut heading_sq, mut inclination_sq, mut n) = (0.0, 0.0, 0.0);
    let mut last = None;
    for (sample, t) in samples.iter().zip(&truth) {
        let estimate = estimator.update(sample)?;
        if t.t_s >= 20.0 {
            let e = AttitudeError::between(&estimate.attitude, &t.attitude);
            heading_sq += e.heading_rad.powi(2);
            inclination_sq += e.inclination_rad.powi(2);
            n += 1.0;
        }
        last = Some(estimate);
    }
    println!(
        "{method}: heading {:.2} deg RMS, inclination {:.2} deg RMS over {n} samples",
        (heading_sq / n).sqrt().to_degrees(),
        (inclination_sq / n).sqrt().to_degrees()
    );
    if let Some(e) = last {
        let bias = e.gyro_bias_rps.map(f64::to_degrees);
        println!(
            "learned gyro bias {:.2?} deg/s (true: 0.3 on each axis)",
            bias.as_slice()
        );
        match e.sigma_rad {
            Some(s) => println!(
                "reported 1-sigma about north, east, down: {:.2?} deg",
                s.map(f64::to_degrees).as_slice()
            ),
            None => println!("this method reports no sigma"),
        }
    }
    Ok(())
}
