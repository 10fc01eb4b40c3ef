//! A hand-held pointing instrument with a three-axis magnetometer and accelerometer, both
//! uncalibrated and mounted a little askew: the user takes a few dozen shots (eight in
//! assorted directions, then two runs of eight rolled about one target), the joint
//! calibrator learns both sensors and the rotation between them from the constant angle
//! between gravity and the field, and every later shot gives a tilt-compensated heading and
//! a tilt from one reading of each sensor.
//!
//! Run: `cargo run --release --example calibrate_mag_accel`

use truenorth::calib::{MagAccelCalibrator, MagAccelConfig, MagAccelSample};
use truenorth::prelude::*;
use truenorth_sim::{FewShotInstrument, protocol_shots};

fn main() -> Result<(), truenorth::Error> {
    // The instrument's errors (a random draw for seed 5) and the shots a user takes.
    let instrument = FewShotInstrument::typical(5);
    let shots = protocol_shots(&instrument, 8, 2, 8, 5);

    let mut calibrator = MagAccelCalibrator::new(MagAccelConfig::default())?;
    for (k, shot) in shots.iter().enumerate() {
        calibrator.push(&MagAccelSample {
            t_s: k as f64,
            mag: shot.mag,
            acc: shot.acc,
        })?;
    }
    let Solution { params, quality } = calibrator.solve()?;
    let verdict = quality.mag.verdict();
    println!(
        "{} shots, {} runs found; dip {:.2} deg (true {:.2}); heading bound {:.2} deg (3 sigma); verdict {}",
        shots.len(),
        quality.runs,
        quality.dip_deg,
        instrument.dip_rad.to_degrees(),
        quality.mag.heading_error_bound_deg(),
        verdict.grade
    );

    // New shots, not used in the calibration: heading of the pointing axis and tilt.
    let check = protocol_shots(&instrument, 12, 0, 0, 99);
    let mut worst_deg: f64 = 0.0;
    for shot in &check {
        let (heading, tilt) = params.attitude(&shot.mag, &shot.acc)?;
        let error = angle_diff(heading.rad(), shot.attitude.yaw_rad).to_degrees();
        worst_deg = worst_deg.max(error.abs());
        println!(
            "heading {:7.2} deg (true {:7.2}), pitch {:6.2} deg, roll {:7.2} deg",
            rad_to_deg(wrap_two_pi(heading.rad())),
            rad_to_deg(wrap_two_pi(shot.attitude.yaw_rad)),
            rad_to_deg(tilt.pitch_rad),
            rad_to_deg(tilt.roll_rad)
        );
    }
    println!(
        "largest heading error over {} new shots: {worst_deg:.2} deg",
        check.len()
    );
    Ok(())
}
