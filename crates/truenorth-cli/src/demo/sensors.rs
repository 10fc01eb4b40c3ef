//! The demo drive with its sensor streams, and what each sensor gets wrong on its own.

use truenorth::compass::CompassCalibration2d;
use truenorth::core::{VehicleSample, WheelSample, angle_diff};
use truenorth::gyro::{GyroCalibration, YawIntegrator, YawIntegratorConfig};
use truenorth::odometer::{DifferentialOdometer, DifferentialOdometerConfig, FixedTrack};
use truenorth_sim::{VehicleSensorParams, VehicleTruth, scenario, simulate, vehicle_streams};

use super::scenarios::{RATE_HZ, opening_circle};
use crate::io::outln;
use crate::io::{CliError, CliResult};

/// The demo drive with its sensor streams.
pub(super) struct DemoDrive {
    /// End of the opening calibration circle, seconds.
    pub circle_end_s: f64,
    /// The sensor errors simulated.
    pub params: VehicleSensorParams,
    /// The true motion, one sample per sensor sample.
    pub truth: Vec<VehicleTruth>,
    /// The sensor readings.
    pub samples: Vec<VehicleSample>,
}

impl DemoDrive {
    pub(super) fn new(seed: u64) -> CliResult<Self> {
        let err = |e: truenorth::core::Error| CliError::msg(format!("demo drive: {e}"));
        let route = scenario::demo_drive().map_err(err)?;
        let truth = simulate(&route, 0.0, RATE_HZ).map_err(err)?;
        let params = VehicleSensorParams::typical();
        let samples = vehicle_streams(&truth, &params, seed).map_err(err)?;
        let circle_end_s = opening_circle().map_err(err)?.duration_s();
        Ok(Self {
            circle_end_s,
            params,
            truth,
            samples,
        })
    }
}

/// Heading error statistics of one estimate against the truth, degrees.
pub(super) struct HeadingError {
    /// Root mean square.
    pub rms_deg: f64,
    /// Largest magnitude.
    pub max_deg: f64,
    /// At the last sample.
    pub final_deg: f64,
}

pub(super) fn heading_error(truth: &[VehicleTruth], estimate: &[f64]) -> HeadingError {
    let errs: Vec<f64> = truth
        .iter()
        .zip(estimate)
        .map(|(t, e)| angle_diff(*e, t.heading_rad).to_degrees())
        .collect();
    let n = errs.len().max(1) as f64;
    HeadingError {
        rms_deg: (errs.iter().map(|e| e * e).sum::<f64>() / n).sqrt(),
        max_deg: errs.iter().fold(0.0, |m, e| m.max(e.abs())),
        final_deg: errs.last().copied().unwrap_or(0.0),
    }
}

/// The simulated sensors' errors, then what each sensor gets wrong on its own, before any
/// method calibrates it.
pub(super) fn sensor_table(d: &DemoDrive) -> CliResult {
    print_sensor_errors(&d.params)?;
    let h0 = d.truth.first().map_or(0.0, |t| t.heading_rad);
    let mut rows = gyro_alone(d, h0);
    rows.extend(odometer_alone(d, h0).map(|e| ("odometer, nominal", e)));
    rows.extend(compass_alone(d));
    print_alone_table(&rows)
}

/// The lines that describe the simulation's gyro, odometer and compass errors.
fn print_sensor_errors(p: &VehicleSensorParams) -> CliResult {
    outln!("Sensor errors in the simulation (VehicleSensorParams::typical)")?;
    outln!(
        "  yaw gyro   bias {:.2} deg/s, scale error +{:.1} % right / +{:.1} % left, noise {:.3} deg/s/rtHz, bias walk {:.4} deg/s/rts",
        p.gyro.bias_rps.to_degrees(),
        p.gyro.scale_error_pos * 100.0,
        p.gyro.scale_error_neg * 100.0,
        p.gyro.noise_density_rps_per_sqrt_hz.to_degrees(),
        p.gyro.bias_walk_rps_per_sqrt_s.to_degrees()
    )?;
    outln!(
        "  odometer   rear track {:.2} m, wheel scale errors {:+.1} % left / {:+.1} % right, {} cm pulses",
        p.odometer.wheels.track_m(),
        p.odometer.scale_error_l * 100.0,
        p.odometer.scale_error_r * 100.0,
        p.odometer.dist_per_pulse_m.map_or(0.0, |d| d * 100.0)
    )?;
    let hard = p.compass_hard_iron.norm() / p.horizontal_field;
    let eig = p.compass_soft_iron.symmetric_eigen();
    let (major, minor) = (eig.eigenvalues.max(), eig.eigenvalues.min());
    outln!(
        "  compass    hard iron {:.2} x field, soft iron axis ratio {:.2}, noise {:.1} % of the {:.0} uT horizontal field",
        hard,
        major / minor,
        p.compass_noise / p.horizontal_field * 100.0,
        p.horizontal_field
    )?;
    outln!()
}

/// The gyro integrated raw and with its true zero and scale, from the true start heading
/// `h0` (rad).
fn gyro_alone(d: &DemoDrive, h0: f64) -> Vec<(&'static str, HeadingError)> {
    let p = &d.params;
    let mut rows = Vec::new();
    for (name, cal) in [
        ("gyro, raw", GyroCalibration::default()),
        (
            "gyro, true zero+scale",
            GyroCalibration::asymmetric(
                p.gyro.bias_rps,
                1.0 + p.gyro.scale_error_pos,
                1.0 + p.gyro.scale_error_neg,
            )
            .unwrap_or_default(),
        ),
    ] {
        let Ok(mut g) = YawIntegrator::new(YawIntegratorConfig { calibration: cal }) else {
            continue;
        };
        let est: Vec<f64> = d
            .samples
            .iter()
            .map(|s| {
                g.push_yaw_rate(s.t_s, s.gyr_z_rps.unwrap_or(0.0))
                    .map_or(f64::NAN, |_| g.heading_rad() + h0)
            })
            .collect();
        rows.push((name, heading_error(&d.truth, &est)));
    }
    rows
}

/// The wheels' differential heading with the nominal track, from `h0` (rad).
fn odometer_alone(d: &DemoDrive, h0: f64) -> Option<HeadingError> {
    let track_m = d.params.odometer.wheels.track_m();
    let mut odo = FixedTrack::new(track_m)
        .and_then(|t| DifferentialOdometer::new(t, DifferentialOdometerConfig::default()))
        .ok()?;
    let est: Vec<f64> = d
        .samples
        .iter()
        .map(|s| {
            let Some(w) = s.wheels else {
                return f64::NAN;
            };
            let w = WheelSample {
                t_s: s.t_s,
                dist_l_m: w.dist_l_m,
                dist_r_m: w.dist_r_m,
            };
            odo.push(&w).map_or(f64::NAN, |_| odo.heading_rad() + h0)
        })
        .collect();
    Some(heading_error(&d.truth, &est))
}

/// The compass raw and with its true calibration.
fn compass_alone(d: &DemoDrive) -> Vec<(&'static str, HeadingError)> {
    let p = &d.params;
    let raw_compass = CompassCalibration2d::identity();
    let true_compass = CompassCalibration2d {
        hard_iron: p.compass_hard_iron,
        soft_iron: p.compass_soft_iron.try_inverse().unwrap_or_default(),
    };
    [
        ("compass, raw", raw_compass),
        ("compass, true calibration", true_compass),
    ]
    .into_iter()
    .map(|(name, cal)| {
        let est: Vec<f64> = d
            .samples
            .iter()
            .map(|s| s.mag.map_or(f64::NAN, |m| cal.heading_rad(&m)))
            .collect();
        (name, heading_error(&d.truth, &est))
    })
    .collect()
}

/// The table of each sensor alone.
fn print_alone_table(rows: &[(&str, HeadingError)]) -> CliResult {
    outln!("Each sensor alone on the whole demo drive (heading error vs truth)")?;
    outln!(
        "{:<28} {:>9} {:>9} {:>10}",
        "source",
        "RMS deg",
        "max deg",
        "final deg"
    )?;
    for (name, e) in rows {
        outln!(
            "{:<28} {:>9.2} {:>9.2} {:>10.2}",
            name,
            e.rms_deg,
            e.max_deg,
            e.final_deg
        )?;
    }
    outln!()
}
