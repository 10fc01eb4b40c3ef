//! The physics every inertial check leans on: a fixed direction in the world (gravity at
//! rest, the Earth's magnetic field away from magnets) seen from a turning body turns
//! against the body's rotation, which the gyro integrates. Between two moments half a
//! second apart at which the direction is trusted, the turn the gyro predicts and the turn
//! seen must agree; a gyro read in the wrong unit or along the wrong axes predicts another.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use truenorth_core::ImuSample;

/// Length of the spans over which the gyro's rotation is compared with the turn of a
/// direction, s: long enough for a hand-held turn of several degrees, short enough that a
/// consumer gyro's bias (under 1°/s) adds under 0.5°.
pub const SPAN_S: f64 = 0.5;

/// A reading is trusted when its magnitude is within this fraction of the recording's
/// median (the median is unit-free: the test of direction does not depend on the unit).
pub const NEAR_MEDIAN: f64 = 0.05;

/// Spans whose direction turned by less than this are left out: noise, not motion.
pub const MIN_TURN_RAD: f64 = 0.087;

/// A span with a step longer than this is left out: the gyro cannot be integrated over it.
const LONGEST_STEP_S: f64 = 0.1;

/// One row of inertial readings as read (in the file's units, in body axes after the axis
/// convention and the column mapping); a magnetometer slower than the gyro is absent on
/// some rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertial {
    /// Time, s.
    pub t_s: f64,
    /// Gyro rates, in the declared unit times its factor (rad/s if the unit is right).
    pub gyr: Vector3<f64>,
    /// Specific force, any unit.
    pub acc: Vector3<f64>,
    /// Magnetic field, any unit, when the row has one.
    pub mag: Option<Vector3<f64>>,
}

impl Inertial {
    /// The rows of `samples` whose time, gyro and accelerometer are all finite.
    pub fn from_samples(samples: &[ImuSample]) -> Vec<Self> {
        samples
            .iter()
            .filter_map(|s| {
                Some(Self {
                    t_s: s.t_s,
                    gyr: s.gyr_rps.as_xyz()?,
                    acc: s.acc_mps2.as_xyz()?,
                    mag: s.mag.as_xyz().filter(|m| m.iter().all(|v| v.is_finite())),
                })
            })
            .filter(Self::is_finite)
            .collect()
    }

    /// Whether time, gyro and accelerometer are finite (the magnetometer may be absent).
    pub fn is_finite(&self) -> bool {
        self.t_s.is_finite()
            && self
                .gyr
                .iter()
                .chain(self.acc.iter())
                .all(|v| v.is_finite())
    }
}

/// Which world-fixed direction a span follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// Gravity, from the accelerometer near rest.
    Gravity,
    /// The magnetic field, from the magnetometer away from disturbances.
    Magnetic,
}

impl Reference {
    /// The reading of this reference on `row`, if it has one.
    pub fn reading(self, row: &Inertial) -> Option<Vector3<f64>> {
        match self {
            Self::Gravity => Some(row.acc),
            Self::Magnetic => row.mag,
        }
    }
}

/// Rows `from..=to` over which the reference direction turned from `u0` to `u1` (unit
/// vectors in body axes) with both ends trusted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionSpan {
    /// First row.
    pub from: usize,
    /// Last row.
    pub to: usize,
    /// The direction at `from`.
    pub u0: Vector3<f64>,
    /// The direction at `to`.
    pub u1: Vector3<f64>,
}

/// The median magnitude of `reference` over `rows`, if any row has it.
pub fn median_magnitude(rows: &[Inertial], reference: Reference) -> Option<f64> {
    let mut norms: Vec<f64> = rows
        .iter()
        .filter_map(|r| reference.reading(r))
        .map(|v| v.norm())
        .filter(|n| n.is_finite())
        .collect();
    if norms.is_empty() {
        return None;
    }
    norms.sort_by(f64::total_cmp);
    Some(norms[norms.len() / 2])
}

/// Consecutive spans of about [`SPAN_S`] whose two ends have the reference within
/// [`NEAR_MEDIAN`] of its median magnitude (near rest, or undisturbed) and over which its
/// direction turned by more than noise.
pub fn direction_spans(rows: &[Inertial], reference: Reference) -> Vec<DirectionSpan> {
    let Some(median) = median_magnitude(rows, reference).filter(|m| *m > 0.0) else {
        return Vec::new();
    };
    let trusted = |k: usize| {
        reference
            .reading(&rows[k])
            .filter(|v| (v.norm() / median - 1.0).abs() < NEAR_MEDIAN)
    };
    let mut spans = Vec::new();
    let mut k = 0;
    while k + 1 < rows.len() {
        let t0 = rows[k].t_s;
        let mut end = k + 1;
        while end < rows.len() && rows[end].t_s - t0 < SPAN_S {
            end += 1;
        }
        // A slower sensor: the first row after the span's length that carries it.
        while end < rows.len() && reference.reading(&rows[end]).is_none() {
            end += 1;
        }
        if end >= rows.len() {
            break;
        }
        if let Some(span) = span_between(rows, k, end, &trusted) {
            spans.push(span);
        }
        k = end;
    }
    spans
}

/// The span from row `k` to row `end` if both ends are trusted, it is not much longer than
/// [`SPAN_S`], has no long step, and the direction turned.
fn span_between(
    rows: &[Inertial],
    k: usize,
    end: usize,
    trusted: &impl Fn(usize) -> Option<Vector3<f64>>,
) -> Option<DirectionSpan> {
    let (a0, a1) = (trusted(k)?, trusted(end)?);
    let longest_step_s = rows[k..=end]
        .windows(2)
        .map(|w| w[1].t_s - w[0].t_s)
        .fold(0.0, f64::max);
    let short = rows[end].t_s - rows[k].t_s < 2.0 * SPAN_S && longest_step_s < LONGEST_STEP_S;
    let (u0, u1) = (a0.normalize(), a1.normalize());
    (short && u0.angle(&u1) > MIN_TURN_RAD).then_some(DirectionSpan {
        from: k,
        to: end,
        u0,
        u1,
    })
}

/// The body's rotation over `span` as the gyro integrates it with its rates taken through
/// `gyro` (a unit factor, an axis permutation).
fn integrated(rows: &[Inertial], span: &DirectionSpan, gyro: &Matrix3<f64>) -> UnitQuaternion<f64> {
    let mut body = UnitQuaternion::identity();
    for w in rows[span.from..=span.to].windows(2) {
        body *= UnitQuaternion::from_scaled_axis(gyro * w[0].gyr * (w[1].t_s - w[0].t_s));
    }
    body
}

/// The angle between where the direction is seen at the end of `span` and where the gyro's
/// rates (taken through `gyro`) carry its start, radians.
pub fn mismatch_rad(rows: &[Inertial], span: &DirectionSpan, gyro: &Matrix3<f64>) -> f64 {
    // A fixed vector seen from the body turns against the body's rotation.
    (integrated(rows, span, gyro).inverse() * span.u0).angle(&span.u1)
}

/// The median of [`mismatch_rad`] over `spans`, degrees; `None` without spans.
pub fn median_mismatch_deg(
    rows: &[Inertial],
    spans: &[DirectionSpan],
    gyro: &Matrix3<f64>,
) -> Option<f64> {
    let mut v: Vec<f64> = spans.iter().map(|s| mismatch_rad(rows, s, gyro)).collect();
    median(&mut v).map(f64::to_degrees)
}

/// The turn of the direction over `span` over the turn the gyro's rates (through `gyro`)
/// predict to first order: the factor that turns the rates into rad/s (about 1 for rad/s,
/// π/180 for deg/s read as rad/s). `None` when the rates predict no turn.
pub fn turn_ratio(rows: &[Inertial], span: &DirectionSpan, gyro: &Matrix3<f64>) -> Option<f64> {
    let predicted = predicted_turn_rad(rows, span, gyro);
    (predicted > 0.0).then(|| span.u0.angle(&span.u1) / predicted)
}

/// The turn of the direction over `span` that the gyro's rates (through `gyro`) predict to
/// first order, rad.
pub fn predicted_turn_rad(rows: &[Inertial], span: &DirectionSpan, gyro: &Matrix3<f64>) -> f64 {
    let turned: Vector3<f64> = rows[span.from..=span.to]
        .windows(2)
        .map(|w| gyro * w[0].gyr * (w[1].t_s - w[0].t_s))
        .sum();
    turned.cross(&span.u0).norm()
}

/// The median of `v` (sorted in place), `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body turning about its x axis at 1 rad/s, gravity along −z at the start.
    fn rolling(n: usize, dt: f64) -> Vec<Inertial> {
        (0..n)
            .map(|k| {
                let t = k as f64 * dt;
                let turn = UnitQuaternion::from_scaled_axis(Vector3::x() * t);
                Inertial {
                    t_s: t,
                    gyr: Vector3::x(),
                    acc: turn.inverse() * Vector3::new(0.0, 0.0, -9.8),
                    mag: None,
                }
            })
            .collect()
    }

    #[test]
    fn the_gyro_that_turned_the_body_predicts_the_direction_and_others_do_not() {
        let rows = rolling(300, 0.01);
        let spans = direction_spans(&rows, Reference::Gravity);
        assert!(spans.len() >= 4, "{}", spans.len());
        let right = median_mismatch_deg(&rows, &spans, &Matrix3::identity()).unwrap();
        assert!(right < 1.0, "{right}");
        let flipped = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
        let wrong = median_mismatch_deg(&rows, &spans, &flipped).unwrap();
        assert!(wrong > 40.0, "{wrong}");
        let ratio = turn_ratio(&rows, &spans[0], &Matrix3::identity()).unwrap();
        assert!((ratio - 1.0).abs() < 0.1, "{ratio}");
        assert!(direction_spans(&rows, Reference::Magnetic).is_empty());
    }
}
