//! The units a recording's inertial columns were declared in, checked against the physics
//! they must obey: at rest an accelerometer reads one gravity, and between two moments of
//! near rest the direction of gravity in the body turns exactly as the gyro says. A unit off
//! by a constant factor (deg/s read as rad/s, g read as m/s²) breaks one of these by that
//! factor, which no sensor error comes near.

use nalgebra::{UnitQuaternion, Vector3};
use truenorth::core::ImuSample;

use super::{AccUnit, GyroUnit};

/// Standard gravity, m/s².
const G_MPS2: f64 = 9.806_65;

/// Length of the spans over which the gyro's rotation is compared with the turn of gravity's
/// direction, s: long enough for a hand-held turn of several degrees, short enough that a
/// consumer gyro's bias (under 1°/s) adds under 0.5°.
const SPAN_S: f64 = 0.5;

/// A reading is near rest when its magnitude is within this fraction of the recording's
/// median (the median is unit-free: the test of direction does not depend on the unit).
const NEAR_REST: f64 = 0.05;

/// Spans whose gravity direction turned by less than this are left out: noise, not motion.
const MIN_TURN_RAD: f64 = 0.087;

/// Spans needed before the gyro's unit is judged at all.
const MIN_SPANS: usize = 10;

/// What the check found wrong, as the words of a refusal.
pub type Finding = String;

/// Checks the accelerometer's magnitude and the gyro's rate scale of `samples` (already
/// converted from the declared units `gyro` and `acc`, so meant to be rad/s and m/s²) and
/// says what contradicts them.
pub fn check_inertial_units(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let rows: Vec<(f64, Vector3<f64>, Vector3<f64>)> = samples
        .iter()
        .filter_map(|s| Some((s.t_s, s.acc_mps2.as_xyz()?, s.gyr_rps.as_xyz()?)))
        .filter(|(t, a, g)| t.is_finite() && a.iter().chain(g.iter()).all(|v| v.is_finite()))
        .collect();
    let mut findings = Vec::new();
    let mut norms: Vec<f64> = rows.iter().map(|(_, a, _)| a.norm()).collect();
    if norms.is_empty() {
        return findings;
    }
    norms.sort_by(f64::total_cmp);
    let median = norms[norms.len() / 2];
    if let Some(finding) = acc_finding(median * acc.to_mps2().recip(), acc) {
        findings.push(finding);
    }
    if let Some(finding) = gyro_finding(&rows, median, gyro) {
        findings.push(finding);
    }
    findings
}

/// Over a whole recording the median specific force is gravity's within what the motion
/// adds; `raw_median` is that median in the file's own numbers, which say which unit they are
/// in: about 9.81 in m/s², 1 in g, 1000 in mg.
fn acc_finding(raw_median: f64, declared: AccUnit) -> Option<Finding> {
    let (likely, name) = [
        (AccUnit::MetrePerS2, "m/s2"),
        (AccUnit::G, "g"),
        (AccUnit::MilliG, "mg"),
    ]
    .into_iter()
    .find(|(unit, _)| (0.7..1.4).contains(&(raw_median * unit.to_mps2() / G_MPS2)))?;
    (likely != declared).then(|| {
        format!(
            "the accelerometer's median magnitude is {raw_median:.3} in the file, one gravity in {name}, not in the declared unit: pass --acc-unit {name}"
        )
    })
}

/// Between two near-rest readings `SPAN_S` apart, gravity's direction in the body turns by
/// the rotation the gyro integrates. Compares that prediction with the rates as declared and
/// as the other unit would give them, and reports the other unit when it explains the turns
/// and the declared one does not.
fn gyro_finding(
    rows: &[(f64, Vector3<f64>, Vector3<f64>)],
    median: f64,
    declared: GyroUnit,
) -> Option<Finding> {
    let (other, name) = match declared {
        GyroUnit::RadPerS => (GyroUnit::DegPerS, "deg/s"),
        GyroUnit::DegPerS => (GyroUnit::RadPerS, "rad/s"),
    };
    // The rates were multiplied by the declared factor; this turns them into the other's.
    let rescale = other.to_rad_per_s() / declared.to_rad_per_s();
    let still = |a: &Vector3<f64>| (a.norm() / median - 1.0).abs() < NEAR_REST;
    let mut as_declared = Vec::new();
    let mut as_other = Vec::new();
    let mut k = 0;
    while k + 1 < rows.len() {
        let (t0, a0, _) = rows[k];
        let mut end = k + 1;
        while end < rows.len() && rows[end].0 - t0 < SPAN_S {
            end += 1;
        }
        if end >= rows.len() {
            break;
        }
        let (t1, a1, _) = rows[end];
        let longest_step_s = rows[k..=end]
            .windows(2)
            .map(|w| w[1].0 - w[0].0)
            .fold(0.0, f64::max);
        if still(&a0) && still(&a1) && t1 - t0 < 2.0 * SPAN_S && longest_step_s < 0.1 {
            let (u0, u1) = (a0.normalize(), a1.normalize());
            if u0.angle(&u1) > MIN_TURN_RAD {
                as_declared.push(mismatch_rad(&rows[k..=end], 1.0, &u0, &u1));
                as_other.push(mismatch_rad(&rows[k..=end], rescale, &u0, &u1));
            }
        }
        k = end;
    }
    if as_declared.len() < MIN_SPANS {
        return None;
    }
    let median_deg = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2].to_degrees()
    };
    let (declared_deg, other_deg) = (median_deg(&mut as_declared), median_deg(&mut as_other));
    (other_deg * 3.0 < declared_deg && declared_deg > 10.0).then(|| {
        format!(
            "the gyro columns in the declared unit do not turn gravity's direction as the accelerometer sees it (median mismatch {declared_deg:.1}° over {} spans of {SPAN_S} s near rest); in {name} they do ({other_deg:.1}°): pass --gyro-unit {name}",
            as_declared.len()
        )
    })
}

/// The angle between where gravity's direction `u1` is seen at the end of `span` and where
/// the gyro's rates (times `scale`) carry its start `u0`, radians.
fn mismatch_rad(
    span: &[(f64, Vector3<f64>, Vector3<f64>)],
    scale: f64,
    u0: &Vector3<f64>,
    u1: &Vector3<f64>,
) -> f64 {
    let mut body = UnitQuaternion::identity();
    for w in span.windows(2) {
        body *= UnitQuaternion::from_scaled_axis(w[0].2 * scale * (w[1].0 - w[0].0));
    }
    // A fixed vector seen from the body turns against the body's rotation.
    (body.inverse() * u0).angle(u1)
}
