//! Which way the gyro's axes lie against the accelerometer's and magnetometer's: the 48
//! signed permutations of three axes (24 rotations, 24 mirror images), each tried as the
//! reading of the gyro, the one whose integrated rotation turns gravity's and the magnetic
//! field's directions as they are seen winning. A gyro column mapped to the wrong axis, a
//! flipped sign or a left-handed mapping loses to the mapping that undoes it.

use std::fmt;

use nalgebra::Matrix3;

use crate::spans::{DirectionSpan, Inertial, Reference, direction_spans, median};
use crate::spans::{median_mismatch_deg, turn_ratio};

/// Spans needed before the gyro's axes are judged at all.
pub const MIN_SPANS: usize = 10;

/// Body gyro axis `b` is read as `sign[b]` times the gyro column along body axis
/// `source[b]` (as the file and options give it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignedPermutation {
    /// For each body axis, the axis it is read from.
    pub source: [usize; 3],
    /// For each body axis, +1 or −1.
    pub sign: [i8; 3],
}

impl SignedPermutation {
    /// Reading every axis as it is.
    pub const IDENTITY: Self = Self {
        source: [0, 1, 2],
        sign: [1, 1, 1],
    };

    /// All 48: the six orders of the axes times the eight choices of signs.
    pub fn all() -> Vec<Self> {
        const ORDERS: [[usize; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        ORDERS
            .iter()
            .flat_map(|&source| {
                (0..8u8).map(move |bits| Self {
                    source,
                    sign: core::array::from_fn(|b| if bits >> b & 1 == 1 { -1 } else { 1 }),
                })
            })
            .collect()
    }

    /// The matrix that applies it to a gyro vector.
    pub fn matrix(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|b, j| {
            if self.source[b] == j {
                f64::from(self.sign[b])
            } else {
                0.0
            }
        })
    }

    /// Whether it is a rotation (determinant +1) rather than a mirror image, which turns
    /// every rotation the wrong way round.
    pub fn is_proper(&self) -> bool {
        self.matrix().determinant() > 0.0
    }

    /// The mapping that undoes this one (its matrix's transpose).
    pub fn inverse(&self) -> Self {
        let mut out = *self;
        for b in 0..3 {
            out.source[self.source[b]] = b;
            out.sign[self.source[b]] = self.sign[b];
        }
        out
    }

    /// Every axis read with the other sign.
    pub fn negated(&self) -> Self {
        Self {
            source: self.source,
            sign: self.sign.map(|s| -s),
        }
    }
}

impl fmt::Display for SignedPermutation {
    /// `x=-y,y=x,z=z`: each body gyro axis and what it is read from.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const AXES: [char; 3] = ['x', 'y', 'z'];
        for b in 0..3 {
            let sep = if b > 0 { "," } else { "" };
            let minus = if self.sign[b] < 0 { "-" } else { "" };
            write!(f, "{sep}{}={minus}{}", AXES[b], AXES[self.source[b]])?;
        }
        Ok(())
    }
}

/// What trying every signed permutation found.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisFit {
    /// The mapping whose predicted turns agree best.
    pub best: SignedPermutation,
    /// Its median mismatch, degrees.
    pub best_deg: f64,
    /// The next best mapping.
    pub runner_up: SignedPermutation,
    /// Its median mismatch, degrees.
    pub runner_up_deg: f64,
    /// The median mismatch of the gyro as it is read, degrees.
    pub as_read_deg: f64,
    /// The median over the 48 mappings of their mismatch, degrees: what a mapping picked
    /// at random gives.
    pub typical_deg: f64,
    /// The spans judged: gravity's and the magnetic field's.
    pub spans: (usize, usize),
    /// The median over the spans of the turn seen over the turn the best mapping's rates
    /// predict: the factor that takes the rates to rad/s (1 if they are in it).
    pub rad_per_unit: f64,
}

impl AxisFit {
    /// How much worse the runner-up agrees than the best (≥ 1; larger is surer).
    pub fn margin(&self) -> f64 {
        self.runner_up_deg / self.best_deg.max(1e-9)
    }

    /// Whether the turns tell the mappings apart at all: the typical mapping agrees more
    /// than three times worse than the best. Turns too small or too few (a car on a
    /// straight road, its specific force tilted by braking rather than by turning) leave
    /// every mapping about as good.
    pub fn is_informative(&self) -> bool {
        self.typical_deg > 3.0 * self.best_deg
    }

    /// How much worse the gyro as read agrees than the best (1 when it is the best).
    pub fn as_read_margin(&self) -> f64 {
        self.as_read_deg / self.best_deg.max(1e-9)
    }
}

/// The spans over which gravity's (near rest) and the magnetic field's (undisturbed)
/// directions turned, both kinds pooled; the counts of each.
pub fn reference_spans(rows: &[Inertial]) -> (Vec<DirectionSpan>, (usize, usize)) {
    let mut spans = direction_spans(rows, Reference::Gravity);
    let gravity = spans.len();
    spans.extend(direction_spans(rows, Reference::Magnetic));
    let magnetic = spans.len() - gravity;
    (spans, (gravity, magnetic))
}

/// Tries the 48 mappings on `rows` with the gyro's rates times `scale` (a unit factor);
/// `None` with fewer than `MIN_SPANS` spans to judge on.
pub fn fit_gyro_axes(rows: &[Inertial], scale: f64) -> Option<AxisFit> {
    let (spans, counts) = reference_spans(rows);
    fit_over(rows, &spans, counts, scale)
}

/// Tries the 48 mappings over `spans` (`counts` of them on gravity and on the field).
pub fn fit_over(
    rows: &[Inertial],
    spans: &[DirectionSpan],
    counts: (usize, usize),
    scale: f64,
) -> Option<AxisFit> {
    if spans.len() < MIN_SPANS {
        return None;
    }
    let mut scored: Vec<(SignedPermutation, f64)> = SignedPermutation::all()
        .into_iter()
        .filter_map(|p| Some((p, median_mismatch_deg(rows, spans, &(p.matrix() * scale))?)))
        .collect();
    scored.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (best, best_deg) = *scored.first()?;
    let (runner_up, runner_up_deg) = *scored.get(1)?;
    let as_read_deg = scored
        .iter()
        .find(|(p, _)| *p == SignedPermutation::IDENTITY)
        .map_or(f64::NAN, |s| s.1);
    let mut all: Vec<f64> = scored.iter().map(|s| s.1).collect();
    let typical_deg = median(&mut all).unwrap_or(f64::NAN);
    let mut ratios: Vec<f64> = spans
        .iter()
        .filter_map(|s| turn_ratio(rows, s, &best.matrix()))
        .collect();
    let rad_per_unit = median(&mut ratios).unwrap_or(f64::NAN);
    Some(AxisFit {
        best,
        best_deg,
        runner_up,
        runner_up_deg,
        as_read_deg,
        typical_deg,
        spans: counts,
        rad_per_unit,
    })
}

/// Whether the gyro as read is wrong beyond doubt: another mapping agrees more than three
/// times better (the unit check's factor) and the gyro as read is off by more than 5°. On
/// the 20 BROAD trials and x-io's recording as published the gyro as read is always the
/// best (1.9–5.7°, the runner-up 1.9–15 times worse); a flipped y, swapped x and y, or
/// x and y turned by 90° make it 3.5–21 times worse than the best on every BROAD trial; a
/// flipped z, nearly vertical on a hand-held device and so seen only by the magnetometer,
/// 2.1 times on some. Found by the test `inspect_recordings`.
pub fn axes_are_wrong(fit: &AxisFit) -> bool {
    fit.best != SignedPermutation::IDENTITY
        && fit.is_informative()
        && fit.as_read_deg > 5.0
        && fit.as_read_deg > 3.0 * fit.best_deg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn there_are_48_distinct_mappings_half_of_them_rotations() {
        let all = SignedPermutation::all();
        assert_eq!(all.len(), 48);
        let proper = all.iter().filter(|p| p.is_proper()).count();
        assert_eq!(proper, 24);
        for (i, a) in all.iter().enumerate() {
            assert!(all[i + 1..].iter().all(|b| b != a));
            let m = a.matrix();
            assert!((m * m.transpose() - Matrix3::identity()).norm() < 1e-12);
        }
        assert_eq!(SignedPermutation::IDENTITY.to_string(), "x=x,y=y,z=z");
        for p in &all {
            assert_eq!(p.inverse().matrix(), p.matrix().transpose());
            assert_eq!(p.negated().matrix(), -p.matrix());
        }
    }
}
