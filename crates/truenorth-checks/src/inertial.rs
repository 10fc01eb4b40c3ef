//! The units a recording's inertial columns were declared in, checked against the physics
//! they must obey: at rest an accelerometer reads one gravity, and between two moments of
//! near rest the direction of gravity in the body turns exactly as the gyro says. A unit off
//! by a constant factor (deg/s read as rad/s, g read as m/s²) breaks one of these by that
//! factor, which no sensor error comes near.

use nalgebra::Matrix3;
use truenorth_core::{Fixed, ImuSample};

use crate::axes::{axes_are_wrong, fit_gyro_axes};
use crate::finding::{Finding, Fix};
use crate::spans::mismatch_rad;
use crate::spans::{Inertial, Reference, SPAN_S, direction_spans, median, median_magnitude};
use crate::units::{AccUnit, GyroUnit, STANDARD_GRAVITY_MPS2};

/// Spans needed before the gyro's unit is judged at all.
const MIN_SPANS: usize = 10;

/// Checks the accelerometer's magnitude and the gyro's rate scale of `samples` (already
/// converted from the declared units `gyro` and `acc`, so meant to be rad/s and m/s²) and
/// says what contradicts them.
pub fn check_inertial_units(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let rows = Inertial::from_samples(samples);
    let mut findings = Vec::new();
    let Some(median) = median_magnitude(&rows, Reference::Gravity) else {
        return findings;
    };
    findings.extend(acc_finding(median * acc.to_mps2().recip(), acc));
    findings.extend(gyro_finding(&rows, gyro));
    findings
}

/// `check_inertial_units`, then, when the units hold, the gyro's axes against the
/// directions of gravity and the magnetic field.
pub fn check_inertial(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let mut findings = check_inertial_units(samples, gyro, acc);
    if !findings.is_empty() {
        return findings;
    }
    let rows = Inertial::from_samples(samples);
    if let Some(fit) = fit_gyro_axes(&rows, 1.0).filter(axes_are_wrong) {
        findings.push(Finding::axes(
            format!(
                "the gyro's axes do not turn gravity's and the magnetic field's directions as the accelerometer and magnetometer see them (median mismatch {:.1}° over {} spans); with its axes taken as {} (each as it is now read; {}) they do ({:.1}°)",
                fit.as_read_deg,
                fit.spans.0 + fit.spans.1,
                fit.best,
                if fit.best.is_proper() { "a rotation" } else { "a mirror image" },
                fit.best_deg,
            ),
            Fix::GyroAxes(fit.best),
        ));
    }
    findings
}

/// The unit in which a median specific force of `raw_median` (in the file's own numbers) is
/// one gravity within what motion adds: about 9.81 in m/s², 1 in g, 1000 in mg.
pub fn likely_acc_unit(raw_median: f64) -> Option<AccUnit> {
    [AccUnit::MetrePerS2, AccUnit::G, AccUnit::MilliG]
        .into_iter()
        .find(|unit| (0.7..1.4).contains(&(raw_median * unit.to_mps2() / STANDARD_GRAVITY_MPS2)))
}

/// Over a whole recording the median specific force is gravity's within what the motion
/// adds; `raw_median` is that median in the file's own numbers, which say which unit they are
/// in.
fn acc_finding(raw_median: f64, declared: AccUnit) -> Option<Finding> {
    let likely = likely_acc_unit(raw_median)?;
    (likely != declared).then(|| {
        Finding::units(
            format!(
                "the accelerometer's median magnitude is {} in the file, one gravity in {}, not in the declared unit",
                Fixed(raw_median, 3),
                likely.name()
            ),
            Fix::AccUnit(likely),
        )
    })
}

/// Between two near-rest readings about half a second apart, gravity's direction in the
/// body turns by the rotation the gyro integrates. Compares that prediction with the rates
/// as declared and as the other unit would give them, and reports the other unit when it
/// explains the turns and the declared one does not.
fn gyro_finding(rows: &[Inertial], declared: GyroUnit) -> Option<Finding> {
    let other = declared.other();
    let name = other.name();
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
        Finding::units(
            format!(
                "the gyro columns in the declared unit do not turn gravity's direction as the accelerometer sees it (median mismatch {declared_deg:.1}° over {} spans of {SPAN_S} s near rest); in {name} they do ({other_deg:.1}°)",
                spans.len(),
            ),
            Fix::GyroUnit(other),
        )
    })
}
