//! Each sensor's likely unit and the gyro's axes, judged from the physics the readings must
//! obey rather than from their headers: an accelerometer at rest reads one gravity, a
//! magnetometer the Earth's 25–65 µT, and a gyro turns gravity's and the magnetic field's
//! directions in the body as they are seen to turn (the checks of `truenorth::checks`).

use serde::Serialize;

use truenorth::checks::{
    AccUnit, AxisFit, Fix, GyroUnit, Inertial, Reference, SignedPermutation, axes_are_wrong,
    check_rows, fit_gyro_axes, likely_acc_unit, median, median_magnitude,
};

use super::Recording;
use crate::io::InputOptions;
use crate::io::checking::{fix_columns, say};

/// The accelerometer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AccReport {
    /// Median magnitude in the file's numbers.
    pub median_magnitude: Option<f64>,
    /// The unit in which that is one gravity (`m/s2`, `g`, `mg`).
    pub likely_unit: Option<&'static str>,
    /// The body axis gravity's reaction points along at rest (`+x` … `-z`), when one
    /// dominates: that axis points up (frd reads it on `-z`).
    pub up_axis: Option<String>,
}

/// The gyro's axes against the accelerometer's and magnetometer's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxesReport {
    /// Median mismatch of the gyro as read, degrees.
    pub as_read_deg: f64,
    /// The mapping that agrees best (`x=-y,y=x,z=z`: body axis = column).
    pub best: String,
    /// Whether it is a rotation (else a mirror image: a left-handed mapping).
    pub best_is_rotation: bool,
    /// Its median mismatch, degrees.
    pub best_deg: f64,
    /// The next best mapping.
    pub runner_up: String,
    /// Its median mismatch, degrees.
    pub runner_up_deg: f64,
    /// Runner-up's mismatch over the best's (larger is surer).
    pub margin: f64,
    /// Spans judged on gravity and on the magnetic field.
    pub spans_gravity: usize,
    /// See `spans_gravity`.
    pub spans_magnetic: usize,
    /// The gyro as read's mismatch over the best's (1 when it is the best; `orientation`
    /// refuses above 3).
    pub as_read_margin: f64,
    /// The typical mapping's mismatch over the best's: under 3 the turns do not tell the
    /// mappings apart (`undecided`).
    pub typical_margin: f64,
    /// `ok` (the gyro as read is the best), `wrong` (another mapping is better beyond
    /// doubt: `orientation` refuses), `doubtful` (another is better, not by enough) or
    /// `undecided` (the turns do not tell the mappings apart).
    pub verdict: &'static str,
    /// Whether the verdict is `wrong`.
    pub wrong: bool,
    /// The `--column` value (as the program takes it, unquoted) that reads the gyro as the
    /// best mapping, when that is not as read.
    pub fix: Option<String>,
}

/// The gyro.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GyroReport {
    /// `rad/s` or `deg/s`, when the turns decide it.
    pub likely_unit: Option<&'static str>,
    /// The other unit's best mismatch over the likely unit's (larger is surer).
    pub unit_margin: Option<f64>,
    /// The turn seen over the turn the rates predict: the factor that takes the file's
    /// numbers to rad/s (1 for rad/s, 0.0175 for deg/s).
    pub rad_per_unit: Option<f64>,
    /// The axes, when there were enough turns to judge.
    pub axes: Option<AxesReport>,
}

/// The magnetometer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MagReport {
    /// Median magnitude in the file's numbers.
    pub median_magnitude: Option<f64>,
    /// The unit that makes it the nearest to an Earth field (45 µT).
    pub likely_unit: Option<&'static str>,
    /// That field, µT.
    pub field_ut: Option<f64>,
    /// Other units that give a field between 10 and 300 µT (an uncalibrated sensor's
    /// offset can triple its magnitude).
    pub also_possible: Vec<&'static str>,
}

/// The gyro's unit is named when the other unit's best mapping agrees this many times
/// worse: the 20 BROAD trials and x-io's recording show 3.3–25 (the test
/// `inspect_recordings`), a car on a straight road about 1.
const UNIT_MARGIN: f64 = 2.0;

/// The units a magnetometer is logged in, with the factor to µT.
const MAG_UNITS: [(&str, f64); 4] = [("uT", 1.0), ("nT", 1e-3), ("G", 100.0), ("mG", 0.1)];

/// The accelerometer's report, if the recording has one.
pub fn acc(rec: &Recording, rows: &[Inertial]) -> Option<AccReport> {
    rec.vector("acc")?;
    let median = median_magnitude(rows, Reference::Gravity);
    Some(AccReport {
        median_magnitude: median,
        likely_unit: median.and_then(likely_acc_unit).map(AccUnit::name),
        up_axis: median.and_then(|m| up_axis(rows, m)),
    })
}

/// The axis most of gravity's reaction lies along over the rows near one gravity (over
/// 80 % of it on average), with its sign.
fn up_axis(rows: &[Inertial], median: f64) -> Option<String> {
    let still: Vec<_> = rows
        .iter()
        .filter(|r| (r.acc.norm() / median - 1.0).abs() < 0.05)
        .map(|r| r.acc.normalize())
        .collect();
    if still.is_empty() {
        return None;
    }
    let mean = still.iter().sum::<nalgebra::Vector3<f64>>() / still.len() as f64;
    let i = mean.iamax();
    let c = mean[i];
    (c.abs() > 0.8).then(|| format!("{}{}", if c > 0.0 { "+" } else { "-" }, ['x', 'y', 'z'][i]))
}

/// The gyro's report, if the recording has one: the unit whose fit of the axes agrees
/// better, and the axes under it.
pub fn gyro(rec: &Recording, rows: &[Inertial], opts: &InputOptions) -> Option<GyroReport> {
    rec.vector("gyr")?;
    let fits = [GyroUnit::RadPerS, GyroUnit::DegPerS]
        .map(|u| fit_gyro_axes(rows, u.to_rad_per_s()).map(|f| (u, f)));
    let [Some(rad), Some(deg)] = fits else {
        return Some(GyroReport {
            likely_unit: None,
            unit_margin: None,
            rad_per_unit: None,
            axes: None,
        });
    };
    let (chosen, other) = if rad.1.best_deg <= deg.1.best_deg {
        (rad, deg)
    } else {
        (deg, rad)
    };
    let unit_margin = other.1.best_deg / chosen.1.best_deg.max(1e-9);
    Some(GyroReport {
        likely_unit: (unit_margin >= UNIT_MARGIN).then(|| chosen.0.name()),
        unit_margin: Some(unit_margin),
        rad_per_unit: Some(chosen.1.rad_per_unit),
        axes: Some(axes(&chosen.1, opts)),
    })
}

/// The axes part of the gyro's report.
fn axes(fit: &AxisFit, opts: &InputOptions) -> AxesReport {
    let wrong = axes_are_wrong(fit);
    let as_read = fit.best == SignedPermutation::IDENTITY;
    let informative = fit.is_informative();
    AxesReport {
        as_read_deg: fit.as_read_deg,
        best: fit.best.to_string(),
        best_is_rotation: fit.best.is_proper(),
        best_deg: fit.best_deg,
        runner_up: fit.runner_up.to_string(),
        runner_up_deg: fit.runner_up_deg,
        margin: fit.margin(),
        spans_gravity: fit.spans.0,
        spans_magnetic: fit.spans.1,
        as_read_margin: fit.as_read_margin(),
        typical_margin: fit.typical_deg / fit.best_deg.max(1e-9),
        verdict: match (informative, as_read, wrong) {
            (false, _, _) => "undecided",
            (true, true, _) => "ok",
            (true, false, true) => "wrong",
            (true, false, false) => "doubtful",
        },
        wrong,
        fix: (informative && !as_read).then(|| fix_columns(&fit.best, opts)),
    }
}

/// The magnetometer's report, if the recording has one.
pub fn mag(rec: &Recording) -> Option<MagReport> {
    let [x, y, z] = rec.vector("mag")?;
    let mut norms: Vec<f64> = (0..x.len())
        .map(|k| (x[k] * x[k] + y[k] * y[k] + z[k] * z[k]).sqrt())
        .filter(|n| n.is_finite() && *n > 0.0)
        .collect();
    let median = median(&mut norms);
    let distance = |(_, k): &(&str, f64), m: f64| (m * k / 45.0).ln().abs();
    let likely = median.and_then(|m| {
        MAG_UNITS
            .iter()
            .min_by(|a, b| distance(a, m).total_cmp(&distance(b, m)))
            .copied()
    });
    Some(MagReport {
        median_magnitude: median,
        likely_unit: likely.map(|u| u.0),
        field_ut: median.zip(likely).map(|(m, u)| m * u.1),
        also_possible: MAG_UNITS
            .iter()
            .filter(|u| Some(u.0) != likely.map(|l| l.0))
            .filter(|u| median.is_some_and(|m| (10.0..300.0).contains(&(m * u.1))))
            .map(|u| u.0)
            .collect(),
    })
}

/// What `orientation`'s checks find that the unit and gyro-axis lines do not say: no unit
/// fits (the gyro's turns off by a factor no unit gives, an accelerometer reading no
/// gravity), or the magnetometer, not the gyro, read through a wrong mapping; each said as
/// `orientation` says it (read as rad/s and m/s², the file's numbers, under `opts`).
pub fn other_findings(rows: &[Inertial], opts: &InputOptions) -> Vec<String> {
    check_rows(rows, GyroUnit::RadPerS, AccUnit::MetrePerS2)
        .into_iter()
        .filter(|f| matches!(f.fix, Fix::Advice(_) | Fix::MagAxes { .. }))
        .map(|f| say(&f, opts))
        .collect()
}
