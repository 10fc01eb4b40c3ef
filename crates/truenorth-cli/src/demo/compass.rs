//! The demo's compass section: every two-axis calibration method fitted on the opening
//! circle and applied to the whole drive, the refusal of half a circle, and a plot of the
//! least-squares fit.

use truenorth::compass::CompassCalibration2d;
use truenorth::core::Mag2Sample;

use super::sensors::{DemoDrive, HeadingError, heading_error};
use crate::io::outln;
use crate::io::{CliError, CliResult};
use crate::plot::{Series, Style, write_plot};
use crate::registry::{CalibrationMethod, Planar};

/// Method names as the table prints them, with the registry's method.
const METHODS: [(&str, CalibrationMethod); 5] = [
    ("least-squares ellipse", CalibrationMethod::Ellipse),
    ("online least squares", CalibrationMethod::OnlineEllipse),
    (
        "binned ellipse (EP0634001)",
        CalibrationMethod::BinnedEllipse,
    ),
    ("merit circle (US5297063)", CalibrationMethod::MeritCircle),
    ("turn extrema (EP0640207)", CalibrationMethod::Turn),
];

/// Prints the compass table and writes `compass_calibration.svg` into `out`: fit every
/// method on the opening circle, score it on the whole drive, check that half a circle is
/// refused, and plot the least-squares fit.
pub(super) fn compass_section(d: &DemoDrive, out: &std::path::Path) -> CliResult {
    let cal_samples: Vec<Mag2Sample> = d
        .samples
        .iter()
        .filter(|s| s.t_s <= d.circle_end_s)
        .filter_map(|s| s.mag.map(|mag| Mag2Sample { t_s: s.t_s, mag }))
        .collect();
    print_header(d, cal_samples.len())?;
    let mut methods = calibrators()?;
    let ls_fit = fit_table(d, &cal_samples, &mut methods)?;
    half_circle(d, &cal_samples, &mut methods)?;
    if let Some((cal, field)) = ls_fit {
        plot_fit(&cal_samples, &cal, field, out)?;
    }
    outln!()?;
    Ok(())
}

/// The heading error of `cal` over the whole drive.
fn whole_drive_error(d: &DemoDrive, cal: &CompassCalibration2d) -> HeadingError {
    let est: Vec<f64> = d
        .samples
        .iter()
        .map(|s| s.mag.map_or(f64::NAN, |m| cal.heading_rad(&m)))
        .collect();
    heading_error(&d.truth, &est)
}

/// The section's title, the table's header and its first row: the true calibration's
/// error, which is the noise floor.
fn print_header(d: &DemoDrive, samples: usize) -> CliResult {
    let p = &d.params;
    outln!(
        "Compass calibration: each method fitted on the opening circle ({} samples, hard iron {:.2} x field, soft iron 1.3 rotated 30 deg, noise {:.0} % of field), then applied to the whole drive",
        samples,
        p.compass_hard_iron.norm() / p.horizontal_field,
        p.compass_noise / p.horizontal_field * 100.0
    )?;
    outln!(
        "{:<26} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "method",
        "RMS deg",
        "max deg",
        "3sd deg",
        "sys deg",
        "noise deg",
        "coverage",
        "residual %"
    )?;
    let truth_cal = CompassCalibration2d {
        hard_iron: p.compass_hard_iron,
        soft_iron: p.compass_soft_iron.try_inverse().unwrap_or_default(),
    };
    let floor = whole_drive_error(d, &truth_cal);
    outln!(
        "{:<26} {:>9.2} {:>9.2} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "(noise floor: true cal.)",
        floor.rms_deg,
        floor.max_deg,
        "-",
        "-",
        "-",
        "-",
        "-"
    )
}

/// Each method's calibrator, from the registry.
fn calibrators() -> CliResult<Vec<(&'static str, Box<Planar>)>> {
    let mut methods: Vec<(&str, Box<Planar>)> = Vec::new();
    for (name, method) in METHODS {
        let calibrator = method
            .calibrator(None)
            .map_err(|e| CliError::msg(e.to_string()))?
            .into_planar()
            .ok_or_else(|| CliError::msg(format!("{name}: not a two-axis method")))?;
        methods.push((name, calibrator));
    }
    Ok(methods)
}

/// Fits each method on `cal_samples` and prints its row; the first fit (least squares)
/// with its field, for the plot.
fn fit_table(
    d: &DemoDrive,
    cal_samples: &[Mag2Sample],
    methods: &mut [(&str, Box<Planar>)],
) -> CliResult<Option<(CompassCalibration2d, f64)>> {
    let mut ls_fit: Option<(CompassCalibration2d, f64)> = None;
    for (name, cal) in methods.iter_mut() {
        for s in cal_samples {
            // A rejected sample is skipped; the solve reports what the rest supports.
            let _ = cal.push(s);
        }
        match cal.solve() {
            Ok(sol) => {
                let e = whole_drive_error(d, &sol.params);
                outln!(
                    "{:<26} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>8.0}% {:>11.2}",
                    name,
                    e.rms_deg,
                    e.max_deg,
                    sol.quality.heading_error_3sigma_deg,
                    sol.quality.heading_error_systematic_deg,
                    sol.quality.heading_noise_rms_deg,
                    sol.quality.fit.coverage * 100.0,
                    sol.quality.fit.residual_rms_rel * 100.0
                )?;
                if ls_fit.is_none() {
                    ls_fit = Some((sol.params, sol.quality.field_magnitude));
                }
            }
            Err(e) => outln!("{name:<26} refused: {e}")?,
        }
    }
    Ok(ls_fit)
}

/// Feeds each method the first half circle, which must be refused, and prints the
/// legend and how many refused.
fn half_circle(
    d: &DemoDrive,
    cal_samples: &[Mag2Sample],
    methods: &mut [(&str, Box<Planar>)],
) -> CliResult {
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
    outln!(
        "RMS/max: heading error on the whole drive, noise included. 3sd: three standard deviations of the\n\
         heading error from the fitted parameters' uncertainty; sys: the error the method's model leaves\n\
         whatever the data; noise: RMS noise of one calibrated reading. residual: RMS distance from the\n\
         fitted circle divided by the field."
    )?;
    outln!(
        "half circle (< 180 deg of turn): {refused} of {} methods refuse, as they must",
        methods.len()
    )
}

/// The raw readings, the fitted ellipse and the corrected circle.
fn plot_fit(
    cal_samples: &[Mag2Sample],
    cal: &CompassCalibration2d,
    field: f64,
    out: &std::path::Path,
) -> CliResult {
    let raw: Vec<(f64, f64)> = cal_samples.iter().map(|s| (s.mag.x, s.mag.y)).collect();
    let inverse = cal.soft_iron.try_inverse().unwrap_or_default();
    let ellipse: Vec<(f64, f64)> = (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            let r =
                inverse * nalgebra::Vector2::new(field * a.cos(), field * a.sin()) + cal.hard_iron;
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
    outln!("plot: {}", path.display())?;
    Ok(())
}
