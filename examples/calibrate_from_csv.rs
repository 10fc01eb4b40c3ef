//! Calibrate a compass from a CSV file and store the calibration for later runs, as a
//! program that logs its own magnetometer would: read `t_s,mag_x,mag_y` rows, push them to
//! a calibrator, refuse a calibration whose verdict is poor, write the parameters as JSON,
//! and read them back (validated) to turn a reading into a heading.
//!
//! Run: `cargo run --release --example calibrate_from_csv [FILE.csv]` (without a file it
//! writes a simulated calibration circle to a temporary CSV first, so that it runs anywhere).

use std::error::Error;
use std::fs;
use std::path::PathBuf;

use truenorth::calib::EllipseCalibrator;
use truenorth::core::Grade;
use truenorth::nalgebra::Vector2;
use truenorth::prelude::*;
use truenorth_sim::{VehicleSensorParams, scenario, simulate, vehicle_streams};

/// A simulated calibration circle as `t_s,mag_x,mag_y` rows.
fn simulated_csv() -> Result<PathBuf, Box<dyn Error>> {
    let route = scenario::calibration_circle(12.0, 5.0, 1.25)?;
    let truth = simulate(&route, 0.0, 50.0)?;
    let samples = vehicle_streams(&truth, &VehicleSensorParams::typical(), 7)?;
    let mut text = String::from("t_s,mag_x,mag_y\n");
    for s in &samples {
        if let Some(m) = s.mag {
            text += &format!("{},{},{}\n", s.t_s, m.x, m.y);
        }
    }
    let path = std::env::temp_dir().join(format!("truenorth-circle-{}.csv", std::process::id()));
    fs::write(&path, text)?;
    Ok(path)
}

/// The readings of a `t_s,mag_x,mag_y` file (columns found by name).
fn read_csv(path: &PathBuf) -> Result<Vec<Mag2Sample>, Box<dyn Error>> {
    let text = fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or(format!("no `{name}` column"))
    };
    let (t, x, y) = (col("t_s")?, col("mag_x")?, col("mag_y")?);
    let mut samples = Vec::new();
    for (row, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let value = |k: usize| -> Result<f64, Box<dyn Error>> {
            let cell = cells
                .get(k)
                .ok_or(format!("row {}: too few cells", row + 2))?;
            Ok(cell.trim().parse()?)
        };
        samples.push(Mag2Sample::new(value(t)?, value(x)?, value(y)?));
    }
    Ok(samples)
}

fn main() -> Result<(), Box<dyn Error>> {
    let (path, simulated) = match std::env::args().nth(1) {
        Some(p) => (PathBuf::from(p), false),
        None => (simulated_csv()?, true),
    };
    let samples = read_csv(&path)?;

    // Any 2-D calibrator fits here (a one-line swap): the least-squares ellipse.
    let mut calibrator = EllipseCalibrator::default();
    for s in &samples {
        calibrator.push(s)?;
    }
    let solution = calibrator.solve()?;
    let verdict = solution.quality.verdict();
    println!(
        "{} readings: verdict {} ({verdict})",
        samples.len(),
        verdict.grade
    );
    if verdict.grade == Grade::Poor {
        return Err(format!("refusing a poor calibration: {verdict}").into());
    }

    // Store it, then load it as the next run would: the load validates the parameters.
    let stored = path.with_extension("calibration.json");
    fs::write(&stored, serde_json::to_string_pretty(&solution.params)?)?;
    let loaded: CompassCalibration2d = serde_json::from_str(&fs::read_to_string(&stored)?)?;
    let reading = Vector2::new(samples[0].mag.x, samples[0].mag.y);
    println!(
        "stored {}; the first reading's magnetic heading: {:.2} deg",
        stored.display(),
        rad_to_deg(wrap_two_pi(loaded.heading_rad(&reading)))
    );
    if simulated {
        fs::remove_file(&path)?;
        fs::remove_file(&stored)?;
    }
    Ok(())
}
