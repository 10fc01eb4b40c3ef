//! `truenorth demo`: the simulator and every method on it, with a results table.

use std::path::PathBuf;

use truenorth::calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, MeritCircleCalibrator, OnlineEllipseCalibrator,
    OnlineEllipseConfig, TurnCompassCalibrator,
};
use truenorth::compass::CompassCalibration2d;
use truenorth::core::{
    Calibrator, CompassQuality, Mag2Sample, VehicleSample, WheelSample, angle_diff,
};
use truenorth::gyro::{GyroCalibration, YawIntegrator, YawIntegratorConfig};
use truenorth::odometer::{DifferentialOdometer, DifferentialOdometerConfig, FixedTrack};
use truenorth_sim::{
    Route, VehicleSensorParams, VehicleTruth, scenario, simulate, vehicle_streams,
};

use crate::io::{CliError, CliResult};
use crate::svg::{Series, Style, write_plot};

/// Arguments of `truenorth demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for plots and CSV artefacts.
    #[arg(long, default_value = "truenorth-demo")]
    pub out: PathBuf,
    /// Random seed of the simulation.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// The calibration circle that opens the demo drive.
fn opening_circle() -> truenorth::core::Result<Route> {
    scenario::calibration_circle(12.0, 5.0, 1.25)
}

/// Truth sample rate of the demo, Hz.
const RATE_HZ: f64 = 50.0;

/// Runs the demo.
pub fn run(args: &Args) -> CliResult {
    std::fs::create_dir_all(&args.out)
        .map_err(|e| CliError::file(&args.out, format!("cannot create the output folder: {e}")))?;
    println!("truenorth demo (seed {})\n", args.seed);
    scenario_table()?;
    let drive = DemoDrive::new(args.seed)?;
    sensor_table(&drive);
    compass_section(&drive, &args.out)?;
    crate::demo_drive::drive_section(args.seed, &args.out)?;
    crate::demo_orientation::orientation_section(args.seed, &args.out)?;
    Ok(())
}

/// What a scenario asks of a navigation system.
struct Summary {
    duration_s: f64,
    distance_m: f64,
    turned_deg: f64,
    turns_over_45deg: usize,
    stops: usize,
    max_speed_mps: f64,
}

fn summarise(route: &Route, truth: &[VehicleTruth]) -> Summary {
    let mut turns = 0;
    let mut stops = 0;
    let mut in_turn = 0.0f64;
    let mut moving = false;
    for w in truth.windows(2) {
        let d = angle_diff(w[1].heading_rad, w[0].heading_rad);
        if w[1].curvature_per_m != 0.0 {
            in_turn += d;
        } else if in_turn != 0.0 {
            if in_turn.abs() > 45f64.to_radians() {
                turns += 1;
            }
            in_turn = 0.0;
        }
        if moving && w[1].speed_mps == 0.0 {
            stops += 1;
        }
        moving = w[1].speed_mps > 0.0;
    }
    if in_turn.abs() > 45f64.to_radians() {
        turns += 1;
    }
    let last = truth.last().copied().unwrap_or_default();
    Summary {
        duration_s: last.t_s,
        distance_m: last.distance_m,
        turned_deg: route.turned_rad().to_degrees(),
        turns_over_45deg: turns,
        stops,
        max_speed_mps: truth.iter().map(|s| s.speed_mps).fold(0.0, f64::max),
    }
}

fn scenario_table() -> CliResult {
    let scenarios: [(&str, truenorth::core::Result<Route>); 5] = [
        ("calibration circle", opening_circle()),
        ("city blocks", scenario::city_blocks(8, 150.0)),
        ("highway", scenario::highway(3000.0)),
        ("parking", scenario::parking()),
        ("whole demo drive", scenario::demo_drive()),
    ];
    println!("Scenarios (rear-axle kinematic model, truth at {RATE_HZ} Hz)");
    println!(
        "{:<20} {:>9} {:>11} {:>11} {:>9} {:>6} {:>10}",
        "scenario", "time s", "distance m", "turned deg", "turns>45", "stops", "max km/h"
    );
    for (name, route) in scenarios {
        let route = route.map_err(|e| CliError::msg(format!("scenario {name}: {e}")))?;
        let truth = simulate(&route, 0.0, RATE_HZ)
            .map_err(|e| CliError::msg(format!("scenario {name}: {e}")))?;
        let s = summarise(&route, &truth);
        println!(
            "{:<20} {:>9.1} {:>11.1} {:>11.1} {:>9} {:>6} {:>10.1}",
            name,
            s.duration_s,
            s.distance_m,
            s.turned_deg,
            s.turns_over_45deg,
            s.stops,
            s.max_speed_mps * 3.6
        );
    }
    println!();
    Ok(())
}

/// The demo drive with its sensor streams.
struct DemoDrive {
    /// End of the opening calibration circle, seconds.
    circle_end_s: f64,
    params: VehicleSensorParams,
    truth: Vec<VehicleTruth>,
    samples: Vec<VehicleSample>,
}

impl DemoDrive {
    fn new(seed: u64) -> CliResult<Self> {
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
struct HeadingError {
    rms_deg: f64,
    max_deg: f64,
    final_deg: f64,
}

fn heading_error(truth: &[VehicleTruth], estimate: &[f64]) -> HeadingError {
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

fn sensor_table(d: &DemoDrive) {
    let p = &d.params;
    println!("Sensor errors in the simulation (VehicleSensorParams::typical)");
    println!(
        "  yaw gyro   bias {:.2} deg/s, scale error +{:.1} % right / +{:.1} % left, noise {:.3} deg/s/rtHz, bias walk {:.4} deg/s/rts",
        p.gyro.bias_rps.to_degrees(),
        p.gyro.scale_error_pos * 100.0,
        p.gyro.scale_error_neg * 100.0,
        p.gyro.noise_density_rps_per_sqrt_hz.to_degrees(),
        p.gyro.bias_walk_rps_per_sqrt_s.to_degrees()
    );
    let track_m = p.odometer.wheels.track_m();
    println!(
        "  odometer   rear track {:.2} m, wheel scale errors {:+.1} % left / {:+.1} % right, {} cm pulses",
        track_m,
        p.odometer.scale_error_l * 100.0,
        p.odometer.scale_error_r * 100.0,
        p.odometer.dist_per_pulse_m.map_or(0.0, |d| d * 100.0)
    );
    let hard = p.compass_hard_iron.norm() / p.horizontal_field;
    let eig = p.compass_soft_iron.symmetric_eigen();
    let (major, minor) = (eig.eigenvalues.max(), eig.eigenvalues.min());
    println!(
        "  compass    hard iron {:.2} x field, soft iron axis ratio {:.2}, noise {:.1} % of the {:.0} uT horizontal field",
        hard,
        major / minor,
        p.compass_noise / p.horizontal_field * 100.0,
        p.horizontal_field
    );
    println!();

    // What each sensor gets wrong on its own, before any method calibrates it.
    let h0 = d.truth.first().map_or(0.0, |t| t.heading_rad);
    let mut rows: Vec<(&str, HeadingError)> = Vec::new();
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
    if let Ok(mut odo) = FixedTrack::new(track_m)
        .and_then(|t| DifferentialOdometer::new(t, DifferentialOdometerConfig::default()))
    {
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
        rows.push(("odometer, nominal", heading_error(&d.truth, &est)));
    }
    let raw_compass = CompassCalibration2d::identity();
    let true_compass = CompassCalibration2d {
        hard_iron: p.compass_hard_iron,
        soft_iron: p.compass_soft_iron.try_inverse().unwrap_or_default(),
    };
    for (name, cal) in [
        ("compass, raw", raw_compass),
        ("compass, true calibration", true_compass),
    ] {
        let est: Vec<f64> = d
            .samples
            .iter()
            .map(|s| s.mag.map_or(f64::NAN, |m| cal.heading_rad(&m)))
            .collect();
        rows.push((name, heading_error(&d.truth, &est)));
    }
    println!("Each sensor alone on the whole demo drive (heading error vs truth)");
    println!(
        "{:<28} {:>9} {:>9} {:>10}",
        "source", "RMS deg", "max deg", "final deg"
    );
    for (name, e) in rows {
        println!(
            "{:<28} {:>9.2} {:>9.2} {:>10.2}",
            name, e.rms_deg, e.max_deg, e.final_deg
        );
    }
    println!();
}

type Compass2dCalibrator =
    dyn Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>;

fn compass_section(d: &DemoDrive, out: &std::path::Path) -> CliResult {
    let cal_samples: Vec<Mag2Sample> = d
        .samples
        .iter()
        .filter(|s| s.t_s <= d.circle_end_s)
        .filter_map(|s| s.mag.map(|mag| Mag2Sample { t_s: s.t_s, mag }))
        .collect();
    let p = &d.params;
    println!(
        "Compass calibration: each method fitted on the opening circle ({} samples, hard iron {:.2} x field, soft iron 1.3 rotated 30 deg, noise {:.0} % of field), then applied to the whole drive",
        cal_samples.len(),
        p.compass_hard_iron.norm() / p.horizontal_field,
        p.compass_noise / p.horizontal_field * 100.0
    );
    println!(
        "{:<26} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "method", "RMS deg", "max deg", "3sd deg", "sys deg", "noise deg", "coverage", "residual %"
    );
    let heading_rms = |cal: &CompassCalibration2d| {
        let est: Vec<f64> = d
            .samples
            .iter()
            .map(|s| s.mag.map_or(f64::NAN, |m| cal.heading_rad(&m)))
            .collect();
        heading_error(&d.truth, &est)
    };
    let truth_cal = CompassCalibration2d {
        hard_iron: p.compass_hard_iron,
        soft_iron: p.compass_soft_iron.try_inverse().unwrap_or_default(),
    };
    let floor = heading_rms(&truth_cal);
    println!(
        "{:<26} {:>9.2} {:>9.2} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "(noise floor: true cal.)", floor.rms_deg, floor.max_deg, "-", "-", "-", "-", "-"
    );
    let mut methods: Vec<(&str, Box<Compass2dCalibrator>)> = vec![
        (
            "least-squares ellipse",
            Box::new(EllipseCalibrator::default()),
        ),
        (
            "online least squares",
            Box::new(
                OnlineEllipseCalibrator::new(OnlineEllipseConfig::default())
                    .map_err(|e| CliError::msg(e.to_string()))?,
            ),
        ),
        (
            "binned ellipse (EP0634001)",
            Box::new(BinnedEllipseCalibrator::default()),
        ),
        (
            "merit circle (US5297063)",
            Box::new(MeritCircleCalibrator::default()),
        ),
        (
            "turn extrema (EP0640207)",
            Box::new(TurnCompassCalibrator::default()),
        ),
    ];
    let mut ls_fit: Option<(CompassCalibration2d, f64)> = None;
    for (name, cal) in methods.iter_mut() {
        for s in &cal_samples {
            // A rejected sample is skipped; the solve reports what the rest supports.
            let _ = cal.push(s);
        }
        match cal.solve() {
            Ok(sol) => {
                let e = heading_rms(&sol.params);
                println!(
                    "{:<26} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>8.0}% {:>11.2}",
                    name,
                    e.rms_deg,
                    e.max_deg,
                    sol.quality.heading_error_3sigma_deg,
                    sol.quality.heading_error_systematic_deg,
                    sol.quality.heading_noise_rms_deg,
                    sol.quality.fit.coverage * 100.0,
                    sol.quality.fit.residual_rms_rel * 100.0
                );
                if ls_fit.is_none() {
                    ls_fit = Some((sol.params, sol.quality.field_magnitude));
                }
            }
            Err(e) => println!("{name:<26} refused: {e}"),
        }
    }
    // A half circle is not enough for any method: each must refuse, not guess.
    let half: Vec<&Mag2Sample> = cal_samples
        .iter()
        .zip(&d.truth)
        .filter(|(_, t)| t.heading_unwrapped_rad < std::f64::consts::PI)
        .map(|(s, _)| s)
        .collect();
    let mut refused = 0;
    for (_, cal) in methods.iter_mut() {
        cal.reset();
        for s in &half {
            let _ = cal.push(s);
        }
        refused += usize::from(cal.solve().is_err());
    }
    println!(
        "RMS/max: heading error on the whole drive, noise included. 3sd: three standard deviations of the\n\
         heading error from the fitted parameters' uncertainty; sys: the error the method's model leaves\n\
         whatever the data; noise: RMS noise of one calibrated reading. residual: RMS distance from the\n\
         fitted circle divided by the field."
    );
    println!(
        "half circle (< 180 deg of turn): {refused} of {} methods refuse, as they must",
        methods.len()
    );

    if let Some((cal, field)) = ls_fit {
        let raw: Vec<(f64, f64)> = cal_samples.iter().map(|s| (s.mag.x, s.mag.y)).collect();
        let inverse = cal.soft_iron.try_inverse().unwrap_or_default();
        let ellipse: Vec<(f64, f64)> = (0..360)
            .map(|k| {
                let a = (k as f64).to_radians();
                let r = inverse * nalgebra::Vector2::new(field * a.cos(), field * a.sin())
                    + cal.hard_iron;
                (r.x, r.y)
            })
            .collect();
        let corrected: Vec<(f64, f64)> = cal_samples
            .iter()
            .map(|s| {
                let c = cal.correct(&s.mag);
                (c.x, c.y)
            })
            .collect();
        let path = out.join("compass_calibration.svg");
        write_plot(
            &path,
            "Compass: raw locus, least-squares ellipse, corrected circle",
            "mag_x (uT)",
            "mag_y (uT)",
            &[
                Series {
                    label: "raw readings",
                    colour: "#d62728",
                    points: raw,
                    style: Style::Dots,
                },
                Series {
                    label: "fitted ellipse",
                    colour: "#1f77b4",
                    points: ellipse,
                    style: Style::Closed,
                },
                Series {
                    label: "corrected",
                    colour: "#2ca02c",
                    points: corrected,
                    style: Style::Dots,
                },
            ],
        )?;
        println!("plot: {}", path.display());
    }
    println!();
    Ok(())
}
