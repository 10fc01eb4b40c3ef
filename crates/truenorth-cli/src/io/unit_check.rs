//! The units a recording's inertial columns were declared in, checked against the physics
//! they must obey: at rest an accelerometer reads one gravity, and between two moments of
//! near rest the direction of gravity in the body turns exactly as the gyro says. A unit off
//! by a constant factor (deg/s read as rad/s, g read as m/s²) breaks one of these by that
//! factor, which no sensor error comes near.

use super::direction_spans::{Inertial, Reference, direction_spans, median, mismatch_rad};
use super::errln;
use super::gyro_axes::{axes_are_wrong, fit_gyro_axes, fix_columns, shell_word};
use super::{AccUnit, CliError, CliResult, GyroUnit, InputOptions};
use nalgebra::Matrix3;
use truenorth::core::{Fixed, ImuSample};

/// Standard gravity, m/s².
const G_MPS2: f64 = 9.806_65;

/// Spans needed before the gyro's unit is judged at all.
const MIN_SPANS: usize = 10;

/// Which option a finding is about, and so which `--accept-*` lets a run go on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FindingKind {
    /// A unit (`--gyro-unit`, `--acc-unit`; `--accept-units`).
    Units,
    /// The gyro's axes against the other sensors' (`--column`; `--accept-axes`).
    Axes,
}

/// What a check found wrong, in the words of a refusal that names the fix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// What it is about.
    pub kind: FindingKind,
    /// The likely problem and the option that fixes it.
    pub message: String,
    /// The 1-based row of the input where the evidence became clear, if known.
    pub row: Option<usize>,
}

/// Checks the accelerometer's magnitude and the gyro's rate scale of `samples` (already
/// converted from the declared units `gyro` and `acc`, so meant to be rad/s and m/s²) and
/// says what contradicts them.
pub fn check_inertial_units(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let rows = Inertial::from_samples(samples);
    let mut findings = Vec::new();
    let Some(median) = super::direction_spans::median_magnitude(&rows, Reference::Gravity) else {
        return findings;
    };
    let units = |message| Finding {
        kind: FindingKind::Units,
        message,
        row: None,
    };
    findings.extend(acc_finding(median * acc.to_mps2().recip(), acc).map(units));
    findings.extend(gyro_finding(&rows, gyro).map(units));
    findings
}

/// `check_inertial_units`, then, when the units hold, the gyro's axes against the
/// directions of gravity and the magnetic field (`opts`: the options the file was read
/// with, which the fix composes with).
pub fn check_inertial(
    samples: &[ImuSample],
    gyro: GyroUnit,
    acc: AccUnit,
    opts: &InputOptions,
) -> Vec<Finding> {
    let mut findings = check_inertial_units(samples, gyro, acc);
    if findings.iter().any(|f| f.kind == FindingKind::Units) {
        return findings;
    }
    let rows = Inertial::from_samples(samples);
    if let Some(fit) = fit_gyro_axes(&rows, 1.0).filter(axes_are_wrong) {
        findings.push(Finding {
            kind: FindingKind::Axes,
            message: format!(
                "the gyro's axes do not turn gravity's and the magnetic field's directions as the accelerometer and magnetometer see them (median mismatch {:.1}° over {} spans); with its axes taken as {} (each as it is now read; {}) they do ({:.1}°): pass --column {} after the options given",
                fit.as_read_deg,
                fit.spans.0 + fit.spans.1,
                fit.best,
                if fit.best.is_proper() { "a rotation" } else { "a mirror image" },
                fit.best_deg,
                shell_word(&fix_columns(&fit.best, opts))
            ),
            row: None,
        });
    }
    findings
}

/// Acts on `findings` about `input`: refuses on the first one not accepted (its message
/// and the `--accept-*` flag that would go on), says each accepted one on stderr.
pub fn refuse_or_warn(
    findings: &[Finding],
    input: &std::path::Path,
    accept_units: bool,
    accept_axes: bool,
) -> CliResult {
    for finding in findings {
        let (accepted, flag) = match finding.kind {
            FindingKind::Units => (accept_units, "--accept-units"),
            FindingKind::Axes => (accept_axes, "--accept-axes"),
        };
        if accepted {
            errln!("warning: {}: {}", input.display(), finding.message);
        } else {
            let message = format!("{} (or {flag} to go on)", finding.message);
            return Err(match finding.row {
                Some(row) => CliError::row(input, row, message),
                None => CliError::file(input, message),
            });
        }
    }
    Ok(())
}

/// The unit in which a median specific force of `raw_median` (in the file's own numbers) is
/// one gravity within what motion adds: about 9.81 in m/s², 1 in g, 1000 in mg.
pub fn likely_acc_unit(raw_median: f64) -> Option<AccUnit> {
    [AccUnit::MetrePerS2, AccUnit::G, AccUnit::MilliG]
        .into_iter()
        .find(|unit| (0.7..1.4).contains(&(raw_median * unit.to_mps2() / G_MPS2)))
}

/// The name of `unit` as the option takes it.
pub fn acc_unit_name(unit: AccUnit) -> &'static str {
    match unit {
        AccUnit::MetrePerS2 => "m/s2",
        AccUnit::G => "g",
        AccUnit::MilliG => "mg",
    }
}

/// The name of `unit` as the option takes it.
pub fn gyro_unit_name(unit: GyroUnit) -> &'static str {
    match unit {
        GyroUnit::RadPerS => "rad/s",
        GyroUnit::DegPerS => "deg/s",
    }
}

/// Over a whole recording the median specific force is gravity's within what the motion
/// adds; `raw_median` is that median in the file's own numbers, which say which unit they are
/// in.
fn acc_finding(raw_median: f64, declared: AccUnit) -> Option<String> {
    let likely = likely_acc_unit(raw_median)?;
    let name = acc_unit_name(likely);
    (likely != declared).then(|| {
        format!(
            "the accelerometer's median magnitude is {} in the file, one gravity in {name}, not in the declared unit: pass --acc-unit {name}",
            Fixed(raw_median, 3)
        )
    })
}

/// Between two near-rest readings about half a second apart, gravity's direction in the
/// body turns by the rotation the gyro integrates. Compares that prediction with the rates
/// as declared and as the other unit would give them, and reports the other unit when it
/// explains the turns and the declared one does not.
fn gyro_finding(rows: &[Inertial], declared: GyroUnit) -> Option<String> {
    let other = match declared {
        GyroUnit::RadPerS => GyroUnit::DegPerS,
        GyroUnit::DegPerS => GyroUnit::RadPerS,
    };
    let name = gyro_unit_name(other);
    // The rates were multiplied by the declared factor; this turns them into the other's.
    let rescale = other.to_rad_per_s() / declared.to_rad_per_s();
    let spans = direction_spans(rows, Reference::Gravity);
    if spans.len() < MIN_SPANS {
        return None;
    }
    let median_deg = |gyro: Matrix3<f64>| {
        let mut v: Vec<f64> = spans.iter().map(|s| mismatch_rad(rows, s, &gyro)).collect();
        median(&mut v).map_or(f64::NAN, f64::to_degrees)
    };
    let declared_deg = median_deg(Matrix3::identity());
    let other_deg = median_deg(Matrix3::identity() * rescale);
    (other_deg * 3.0 < declared_deg && declared_deg > 10.0).then(|| {
        format!(
            "the gyro columns in the declared unit do not turn gravity's direction as the accelerometer sees it (median mismatch {declared_deg:.1}° over {} spans of {} s near rest); in {name} they do ({other_deg:.1}°): pass --gyro-unit {name}",
            spans.len(),
            super::direction_spans::SPAN_S
        )
    })
}
