//! End to end: a simulated car drives a calibration circle with a badly placed compass
//! (hard iron half the field, a 1.3 : 1 soft iron), the least-squares calibrator learns the
//! correction and says how far to trust it, and the calibrated compass gives true heading in
//! London via the World Magnetic Model.
//!
//! Run: `cargo run --release --example calibrate_compass`

use truenorth::Error;
use truenorth::calib::EllipseCalibrator;
use truenorth::geomag::declination;
use truenorth::prelude::*;
use truenorth_sim::{VehicleSensorParams, scenario, simulate, vehicle_streams};

fn main() -> Result<(), Error> {
    // Ground truth and what the sensors report (deterministic for seed 7).
    let route = scenario::calibration_circle(12.0, 5.0, 1.25)?;
    let truth = simulate(&route, 0.0, 50.0)?;
    let samples = vehicle_streams(&truth, &VehicleSensorParams::typical(), 7)?;

    // Calibrate: push the compass readings, then solve (or be told why not).
    let mut calibrator = EllipseCalibrator::default();
    for s in &samples {
        if let Some(mag) = s.mag {
            calibrator.push(&Mag2Sample { t_s: s.t_s, mag })?;
        }
    }
    let Solution {
        params: cal,
        quality,
    } = calibrator.solve()?;
    println!(
        "hard iron {:.2?} uT, soft iron {:.3?}",
        cal.hard_iron.as_slice(),
        cal.soft_iron.as_slice()
    );
    println!(
        "coverage {:.0} %, residual {:.2} % of the field, predicted heading-error bound {:.2} deg",
        quality.fit.coverage * 100.0,
        quality.fit.residual_rms_rel * 100.0,
        quality.heading_error_bound_deg()
    );

    // Heading error against the truth, before and after.
    let rms = |f: &dyn Fn(&nalgebra::Vector2<f64>) -> f64| {
        let sum: f64 = truth
            .iter()
            .zip(&samples)
            .filter_map(|(t, s)| s.mag.map(|m| angle_diff(f(&m), t.heading_rad).powi(2)))
            .sum();
        (sum / truth.len() as f64).sqrt().to_degrees()
    };
    println!(
        "heading RMS raw {:.1} deg, calibrated {:.2} deg",
        rms(&|m| (-m.y).atan2(m.x)),
        rms(&|m| cal.heading_rad(m))
    );

    // True north: add London's declination, once, through the typed heading.
    let decl = declination(deg_to_rad(51.5), deg_to_rad(-0.13), 0.0, 2026.5)?;
    if let Some(last) = samples.last().and_then(|s| s.mag) {
        let magnetic = cal.magnetic_heading(&last);
        println!(
            "final heading: {:.1} deg magnetic, {:.1} deg true (declination {:+.2} deg)",
            rad_to_deg(magnetic.rad()),
            rad_to_deg(magnetic.to_true(decl).rad()),
            rad_to_deg(decl.0)
        );
    }
    Ok(())
}
