//! The units a recording's inertial columns were declared in, checked against the physics
//! they must obey: at rest an accelerometer reads one gravity, and between two moments of
//! near rest the direction of gravity in the body turns exactly as the gyro says. A unit off
//! by a constant factor (deg/s read as rad/s, g read as m/s²) breaks one of these by that
//! factor, which no sensor error comes near.

use nalgebra::Matrix3;
use truenorth_core::{Fixed, ImuSample};

use crate::axes::{axes_are_wrong, fit_over};
use crate::finding::{Finding, Fix};
use crate::mag_axes::{magnetometer_reads_the_accelerometer, wrong_magnetometer_axes};
use crate::spans::{DirectionSpan, MIN_TURN_RAD, mismatch_rad, predicted_turn_rad, turn_ratio};
use crate::spans::{Inertial, Reference, SPAN_S, direction_spans, median, median_magnitude};
use crate::units::{AccUnit, GyroUnit, STANDARD_GRAVITY_MPS2};

/// Spans needed before the gyro's unit is judged at all.
const MIN_SPANS: usize = 10;

/// The turn seen over the turn the gyro predicts, outside which no gain error of a gyro
/// explains it: MEMS gains are right to a few percent, and even an uncalibrated one to
/// ±10 %; a unit or a clock that is wrong gives a factor of two or more (mrad/s read as
/// rad/s: 0.001; a time column at half speed: 2).
const GAIN_RANGE: (f64, f64) = (0.67, 1.5);

/// A median mismatch below this (degrees) leaves the gyro's scale unjudged: the spans
/// turned too little for a factor to show beyond the sensors' noise.
const MIN_MISMATCH_DEG: f64 = 5.0;

/// Checks the accelerometer's magnitude and the gyro's rate scale of `samples` (already
/// converted from the declared units `gyro` and `acc`, so meant to be rad/s and m/s²) and
/// says what contradicts them.
pub fn check_inertial_units(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    check_rows_units(&Inertial::from_samples(samples), gyro, acc)
}

/// [`check_inertial_units`] on rows already taken apart.
pub fn check_rows_units(rows: &[Inertial], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    units(rows, &Spans::of(rows), gyro, acc)
}

/// The spans over which gravity's and the field's directions turned: found once, judged
/// by every check.
struct Spans {
    gravity: Vec<DirectionSpan>,
    field: Vec<DirectionSpan>,
}

impl Spans {
    fn of(rows: &[Inertial]) -> Self {
        Self {
            gravity: direction_spans(rows, Reference::Gravity),
            field: direction_spans(rows, Reference::Magnetic),
        }
    }
}

/// The units' findings over `spans`.
fn units(rows: &[Inertial], spans: &Spans, gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let mut findings = Vec::new();
    let Some(median) = median_magnitude(rows, Reference::Gravity) else {
        return findings;
    };
    let raw = median * acc.to_mps2().recip();
    if let Some(none) = acc_fits_no_unit(raw) {
        // Without gravity there is no direction to judge the gyro by.
        findings.push(none);
        return findings;
    }
    findings.extend(acc_finding(raw, acc));
    findings.extend(gyro_finding(rows, spans, gyro));
    findings
}

/// `check_inertial_units`, then, when the units hold, the gyro's axes against the
/// directions of gravity and the magnetic field.
pub fn check_inertial(samples: &[ImuSample], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    check_rows(&Inertial::from_samples(samples), gyro, acc)
}

/// [`check_inertial`] on rows already taken apart, then, when neither a unit nor a mapping
/// of the axes explains the turns, by what factor they miss ("no unit fits").
pub fn check_rows(rows: &[Inertial], gyro: GyroUnit, acc: AccUnit) -> Vec<Finding> {
    let spans = Spans::of(rows);
    let mut findings = units(rows, &spans, gyro, acc);
    if !findings.is_empty() {
        return findings;
    }
    if magnetometer_reads_the_accelerometer(rows) {
        findings.push(Finding::axes(
            "the magnetometer's readings are parallel to the accelerometer's on every row, which no field and specific force are: its columns hold the accelerometer's".into(),
            Fix::Advice("map mag_x, mag_y, mag_z to the magnetometer's own columns".into()),
        ));
        return findings;
    }
    if let Some(m) = wrong_magnetometer_axes(rows, &spans.gravity, &spans.field) {
        findings.push(Finding::axes(
            format!(
                "the gyro turns gravity's direction as the accelerometer sees it ({} spans) but the magnetic field's only read through another mapping (median mismatch {:.1}° as read, {:.1}° so; {} spans): the magnetometer is mirrored or mounted turned",
                m.spans.0, m.as_read_deg, m.best_deg, m.spans.1
            ),
            Fix::MagAxes {
                mirror: m.mirror_fix,
                rotation: m.rotation_fix,
            },
        ));
        return findings;
    }
    let pooled: Vec<DirectionSpan> = spans.gravity.iter().chain(&spans.field).copied().collect();
    let counts = (spans.gravity.len(), spans.field.len());
    let Some(fit) = fit_over(rows, &pooled, counts, 1.0) else {
        return findings;
    };
    if axes_are_wrong(&fit) {
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
    } else {
        findings.extend(scale_finding(rows, &spans, &fit.best.matrix(), gyro));
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

/// An accelerometer whose median magnitude `raw_median` (the file's numbers) is one gravity
/// in no unit: gravity removed (a phone's "linear acceleration"), or a unit none of
/// m/s², g and mg. Said as what it is, not taken as a unit.
fn acc_fits_no_unit(raw_median: f64) -> Option<Finding> {
    likely_acc_unit(raw_median).is_none().then(|| {
        Finding::units(
            format!(
                "the accelerometer's median magnitude is {} in the file: one gravity in none of m/s2, g and mg, so no unit fits; at rest an accelerometer reads gravity's reaction, and one reading nearly zero has had gravity removed (linear acceleration)",
                Fixed(raw_median, 4)
            ),
            Fix::Advice(
                "give the accelerometer's specific force with gravity in it (a phone's raw accelerometer, not its linear acceleration), in m/s2, g or mg".into(),
            ),
        )
    })
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
///
/// The magnetic field's directions, which no acceleration bends, must not contradict the
/// verdict: swung at arm's length, a device's specific force is tilted by the swing, and
/// gravity's spans alone would blame a right unit.
fn gyro_finding(rows: &[Inertial], spans: &Spans, declared: GyroUnit) -> Option<Finding> {
    let other = declared.other();
    let name = other.name();
    // The rates were multiplied by the declared factor; this turns them into the other's.
    let (as_read, rescaled) = (
        Matrix3::identity(),
        Matrix3::identity() * (other.to_rad_per_s() / declared.to_rad_per_s()),
    );
    let (gravity, magnetic) = (&spans.gravity, &spans.field);
    if gravity.len() < MIN_SPANS {
        return None;
    }
    let declared_deg = median_deg(rows, gravity, &as_read);
    let other_deg = median_deg(rows, gravity, &rescaled);
    if other_deg * 3.0 >= declared_deg || declared_deg <= 10.0 {
        return None;
    }
    let field_disagrees = magnetic.len() >= MIN_SPANS
        && median_deg(rows, magnetic, &rescaled) >= median_deg(rows, magnetic, &as_read);
    (!field_disagrees).then(|| {
        Finding::units(
            format!(
                "the gyro columns in the declared unit do not turn gravity's direction as the accelerometer sees it (median mismatch {declared_deg:.1}° over {} spans of {SPAN_S} s near rest); in {name} they do ({other_deg:.1}°)",
                gravity.len(),
            ),
            Fix::GyroUnit(other),
        )
    })
}

/// When neither unit nor a mapping of the axes explains the turns, the turn seen over the
/// turn the rates (through `gyro`, the best mapping) predict says by what factor the rates
/// or the clock are off: that is the finding, with no unit to pass. The field's turns, which
/// no acceleration bends, veto it where they fit.
fn scale_finding(
    rows: &[Inertial],
    spans: &Spans,
    gyro: &Matrix3<f64>,
    declared: GyroUnit,
) -> Option<Finding> {
    let fits = |r: f64| (GAIN_RANGE.0..=GAIN_RANGE.1).contains(&r);
    let gravity = &spans.gravity;
    let ratio = turn_ratio_median(rows, gravity, gyro)?;
    let declared_deg = median_deg(rows, gravity, gyro);
    // Below a few degrees of mismatch the spans' turns are too small to weigh a factor.
    if declared_deg <= MIN_MISMATCH_DEG || fits(ratio) {
        return None;
    }
    if turn_ratio_median(rows, &spans.field, gyro).is_some_and(fits) {
        return None;
    }
    let other = declared.other();
    let rescale = other.to_rad_per_s() / declared.to_rad_per_s();
    let other_deg = median_deg(rows, gravity, &(gyro * rescale));
    Some(Finding::units(
        format!(
            "the gyro's turns fit no unit: gravity's direction turns {ratio:.3} times what the gyro's rates integrate to (median over {} spans of {SPAN_S} s near rest; mismatch {declared_deg:.1}° in the declared unit, {other_deg:.1}° in {})",
            gravity.len(),
            other.name()
        ),
        Fix::Advice(format!(
            "the rates times {ratio:.3} would turn as the directions do: check the gyro's unit (mrad/s is 0.001 rad/s) and that t_s is in seconds"
        )),
    ))
}

/// The median over `spans` of the turn seen over the turn the rates predict, over
/// the spans in which the rates predict a turn too (at least [`MIN_TURN_RAD`]); `None` with
/// fewer than [`MIN_SPANS`] of them. A car's specific force tilts as it brakes while its
/// gyro hardly turns: a ratio there says nothing of the gyro's scale.
fn turn_ratio_median(
    rows: &[Inertial],
    spans: &[DirectionSpan],
    gyro: &Matrix3<f64>,
) -> Option<f64> {
    let mut ratios: Vec<f64> = spans
        .iter()
        .filter(|s| predicted_turn_rad(rows, s, gyro) >= MIN_TURN_RAD)
        .filter_map(|s| turn_ratio(rows, s, gyro))
        .collect();
    if ratios.len() < MIN_SPANS {
        return None;
    }
    median(&mut ratios)
}

/// The median over `spans` of the mismatch between the direction seen and the one the
/// gyro's rates through `gyro` predict, degrees.
fn median_deg(rows: &[Inertial], spans: &[DirectionSpan], gyro: &Matrix3<f64>) -> f64 {
    let mut v: Vec<f64> = spans.iter().map(|s| mismatch_rad(rows, s, gyro)).collect();
    median(&mut v).map_or(f64::NAN, f64::to_degrees)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    /// A device swung at arm's length like a pendulum (±50° about its y axis, 0.8 Hz): its
    /// specific force stays near the arm, nearly fixed in the body (here it turns by 15 % of
    /// the body's turn), so gravity's "direction" hardly turns while the gyro says it does;
    /// the magnetic field turns as the gyro says.
    fn swinging(with_mag: bool) -> Vec<Inertial> {
        let (amplitude, omega) = (50f64.to_radians(), std::f64::consts::TAU * 0.8);
        let field_n = Vector3::new(20.0, 0.0, 45.0);
        (0..6000)
            .map(|k| {
                let t = k as f64 * 0.01;
                let angle = amplitude * (omega * t).sin();
                let body = Rotation3::from_axis_angle(&Vector3::y_axis(), angle);
                Inertial {
                    t_s: t,
                    gyr: Vector3::new(0.0, amplitude * omega * (omega * t).cos(), 0.0),
                    acc: Rotation3::from_axis_angle(&Vector3::y_axis(), -0.15 * angle)
                        * Vector3::new(0.0, 0.0, -9.81),
                    mag: with_mag.then(|| body.inverse() * field_n),
                }
            })
            .collect()
    }

    /// The swing's gravity spans alone favour deg/s; the field, which no acceleration
    /// bends, says rad/s fits, so nothing is refused.
    #[test]
    fn a_swing_that_tilts_the_specific_force_is_not_blamed_on_the_unit() {
        let alone = check_rows_units(&swinging(false), GyroUnit::RadPerS, AccUnit::MetrePerS2);
        assert!(
            alone
                .iter()
                .any(|f| f.fix == Fix::GyroUnit(GyroUnit::DegPerS)),
            "{alone:?}"
        );
        let with_field = check_rows_units(&swinging(true), GyroUnit::RadPerS, AccUnit::MetrePerS2);
        assert!(with_field.is_empty(), "{with_field:?}");
    }
}
