//! The two axes' extremum trackers of one turn and what they give: the centre and radii of
//! the locus (EP 0640207 claims 4, 5) and the signed angle turned, with the refusals of a
//! record that does not support them.

use core::f64::consts::TAU;

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Result, Validate, angle_diff, check_finite2};

use crate::seed::extrema::{
    ExtremaConfig, ExtremumKind, ExtremumTracker, ExtremumTrackerState, HalfTurnPair, MAX_EXTREMA,
};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Fewest samples a turn calibration accepts.
pub const MIN_TURN_SAMPLES: usize = 16;

/// A step of the unwrapped turn that goes backwards by more than this (radians, 20°) means the
/// turn reversed: the extrema would then not be half a revolution apart.
const REVERSAL_RAD: f64 = 0.35;

/// Centre, radii and the number of pairs behind them for X and Y.
type PairAverages = (Vector2<f64>, Vector2<f64>, (usize, usize));

/// A sample's raw reading and the caller's tag, recorded with each extremum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnTag<T> {
    /// The raw (X, Y) reading at that sample.
    pub point: Vector2<f64>,
    /// The caller's tag (the compass half uses the timestamp; the gyro half the relative
    /// heading G).
    pub tag: T,
}

/// Centre, radii and turn angle found from the extrema of a turn.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnEllipse {
    /// `(X₀, Y₀)`, raw unit (claim 4).
    pub centre: Vector2<f64>,
    /// `(a, b)`, raw unit (claim 5).
    pub radii: Vector2<f64>,
    /// The angle turned over the record, radians, signed: positive for a right turn
    /// (heading increasing).
    pub turned_rad: f64,
    /// Half-turn pairs averaged for X and for Y.
    pub pairs: (usize, usize),
}

impl TurnEllipse {
    /// The compass calibration of claim 10: `hard_iron = (X₀, Y₀)`,
    /// `soft_iron = diag(R/a, R/b)` with `R = (a + b)/2`, so the corrected locus is a circle of
    /// radius `R` (the field in the input unit) and its heading is
    /// `atan2(−(Y − Y₀)/b, (X − X₀)/a)`.
    pub fn calibration(&self) -> CompassCalibration2d {
        let r = self.field();
        CompassCalibration2d {
            hard_iron: self.centre,
            soft_iron: Matrix2::new(r / self.radii.x, 0.0, 0.0, r / self.radii.y),
        }
    }

    /// `(a + b)/2`: the field in the input unit.
    pub fn field(&self) -> f64 {
        0.5 * (self.radii.x + self.radii.y)
    }
}

/// The two axes' extremum trackers of one turn, plus the first and last reading: everything
/// both halves of the turn calibration need, in constant memory.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnExtrema<T: Copy> {
    x: ExtremumTracker<TurnTag<T>>,
    y: ExtremumTracker<TurnTag<T>>,
    first: Option<Vector2<f64>>,
    last: Option<Vector2<f64>>,
    samples: usize,
}

impl<T: Copy> TurnExtrema<T> {
    /// Empty trackers with the given detector thresholds.
    pub fn new(config: ExtremaConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::with_valid_config(config))
    }

    pub(super) fn with_valid_config(config: ExtremaConfig) -> Self {
        Self {
            x: ExtremumTracker::new(config),
            y: ExtremumTracker::new(config),
            first: None,
            last: None,
            samples: 0,
        }
    }

    /// Forgets everything.
    pub fn reset(&mut self) {
        self.x.reset();
        self.y.reset();
        self.first = None;
        self.last = None;
        self.samples = 0;
    }

    /// The saved state.
    pub fn saved(&self) -> TurnExtremaState<T> {
        TurnExtremaState {
            x: self.x.saved(),
            y: self.y.saved(),
            first: self.first,
            last: self.last,
            samples: self.samples,
        }
    }

    /// Rebuilds the trackers from [`Self::saved`], refusing invalid or inconsistent values.
    pub fn from_saved(s: TurnExtremaState<T>) -> Result<Self> {
        let finite = |v: &Vector2<f64>| v.x.is_finite() && v.y.is_finite();
        let t = Self {
            x: ExtremumTracker::from_saved(s.x)?,
            y: ExtremumTracker::from_saved(s.y)?,
            first: s.first,
            last: s.last,
            samples: s.samples,
        };
        if !(t.first.iter().chain(&t.last).all(finite)
            && t.x.samples() == t.samples
            && t.y.samples() == t.samples
            && (t.samples > 0) == t.first.is_some()
            && (t.samples > 0) == t.last.is_some())
        {
            return Err(Error::InvalidSnapshot {
                reason: "the turn's extremum trackers do not fit together",
            });
        }
        Ok(t)
    }

    /// Feeds one finite reading with its tag; returns its sample index.
    /// Non-finite readings are refused with a typed error and not counted.
    pub fn push(&mut self, point: &Vector2<f64>, tag: T) -> Result<usize> {
        let i = self.samples;
        self.push_centred(point, tag)?;
        Ok(i)
    }

    /// [`Self::push`], returning the provisional centre after it
    /// ([`Self::provisional_centre`]) from the ranges just updated, which stay in registers
    /// (loaded back as pairs from the halves just stored, they stall the processor). The
    /// reading is taken coordinate by coordinate for the same reason: a caller that stored
    /// them one by one cannot forward them to a load of the pair.
    #[inline(always)]
    pub(crate) fn push_centred(&mut self, point: &Vector2<f64>, tag: T) -> Result<Vector2<f64>> {
        let (x, y) = (point.x, point.y);
        check_finite2("magnetometer reading", &Vector2::new(x, y))?;
        let point = Vector2::new(x, y);
        let i = self.samples;
        let t = TurnTag { point, tag };
        let (x0, x1) = self.x.push_range(i, x, t);
        let (y0, y1) = self.y.push_range(i, y, t);
        if self.first.is_none() {
            self.first = Some(point);
        }
        self.last = Some(point);
        self.samples += 1;
        // As `provisional_centre` with at least one sample.
        Ok(Vector2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1)))
    }

    /// Samples accepted.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The X axis tracker (its extrema carry [`TurnTag`]s).
    pub fn x(&self) -> &ExtremumTracker<TurnTag<T>> {
        &self.x
    }

    /// The Y axis tracker.
    pub fn y(&self) -> &ExtremumTracker<TurnTag<T>> {
        &self.y
    }

    /// X maxima paired with the X minima next to them (same revolution).
    pub fn x_pairs(&self) -> impl Iterator<Item = HalfTurnPair<TurnTag<T>>> + '_ {
        self.x.half_turn_pairs()
    }

    /// Y maxima paired with the Y minima next to them (same revolution).
    pub fn y_pairs(&self) -> impl Iterator<Item = HalfTurnPair<TurnTag<T>>> + '_ {
        self.y.half_turn_pairs()
    }

    /// Midpoint of the running ranges: the centre estimate before the extrema are known.
    pub fn provisional_centre(&self) -> Vector2<f64> {
        let (x0, x1) = self.x.range();
        let (y0, y1) = self.y.range();
        if self.samples == 0 {
            Vector2::zeros()
        } else {
            Vector2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1))
        }
    }

    /// Centre, radii and pair counts averaged over the half-turn pairs of each axis, if both
    /// axes have one.
    fn averaged_pairs(&self) -> Option<PairAverages> {
        let avg = |it: &mut dyn Iterator<Item = HalfTurnPair<TurnTag<T>>>| {
            let (mut c, mut r, mut n) = (0.0, 0.0, 0usize);
            for p in it {
                c += p.centre();
                r += p.radius();
                n += 1;
            }
            (n > 0).then(|| (c / n as f64, r / n as f64, n))
        };
        let (cx, rx, nx) = avg(&mut self.x.half_turn_pairs())?;
        let (cy, ry, ny) = avg(&mut self.y.half_turn_pairs())?;
        Some((Vector2::new(cx, cy), Vector2::new(rx, ry), (nx, ny)))
    }

    /// The signed angle turned (positive = right turn), measured about `centre` with the axes
    /// scaled by `radii`, by unwrapping the sequence first reading → extrema of both axes in
    /// time order → last reading. Constant memory.
    ///
    /// Consecutive extrema are about a quarter turn apart, so the steps between them unwrap
    /// without ambiguity, and one that goes backwards by more than [`REVERSAL_RAD`] means the
    /// turn reversed. The two steps at the ends are not so bounded: an extremum is confirmed
    /// only once the signal has retreated from it by the tracker's hysteresis, which on a
    /// coarsely sampled turn (tens of degrees per reading) can lag it by more than half a
    /// turn, so the last reading may lie more than 180° past the last confirmed extremum. An
    /// end step is therefore read in the direction the extrema turned, unless it goes back
    /// by more than [`REVERSAL_RAD`] and less than a quarter turn (a retreat that far could
    /// not have passed the next extremum unconfirmed); a retreat of more than a quarter turn
    /// past an extremum confirms a new extremum on the way back, which the steps between
    /// extrema see.
    pub(super) fn turned_rad(&self, centre: &Vector2<f64>, radii: &Vector2<f64>) -> Result<f64> {
        let (Some(first), Some(last)) = (self.first, self.last) else {
            return Ok(0.0);
        };
        if self.x.confirmed_count() > MAX_EXTREMA || self.y.confirmed_count() > MAX_EXTREMA {
            // Older extrema were dropped; at least this many half turns happened.
            let half_turns = self.x.confirmed_count().min(self.y.confirmed_count());
            return Ok(half_turns as f64 * core::f64::consts::PI);
        }
        // Phase in the raw plane (counter-clockwise); heading is its negative.
        let phase =
            |p: &Vector2<f64>| ((p.y - centre.y) / radii.y).atan2((p.x - centre.x) / radii.x);
        let mut xs = self.x.extrema().peekable();
        let mut ys = self.y.extrema().peekable();
        // At most MAX_EXTREMA per axis (checked above).
        let mut buf = [0.0; 2 * MAX_EXTREMA];
        let mut len = 0;
        loop {
            let next = match (xs.peek(), ys.peek()) {
                (Some(a), Some(b)) if a.index <= b.index => xs.next(),
                (Some(_), Some(_)) => ys.next(),
                (Some(_), None) => xs.next(),
                (None, Some(_)) => ys.next(),
                (None, None) => break,
            };
            if let Some(e) = next {
                buf[len] = phase(&e.tag.point);
                len += 1;
            }
        }
        let points = &buf[..len];
        let inner: f64 = points.windows(2).map(|w| angle_diff(w[1], w[0])).sum();
        let reversed = |s: f64, dir: f64| s * dir < -REVERSAL_RAD;
        let (start, end) = match (points.first(), points.last()) {
            (Some(&a), Some(&b)) => (angle_diff(a, phase(&first)), angle_diff(phase(&last), b)),
            _ => (angle_diff(phase(&last), phase(&first)), 0.0),
        };
        let dir = if points.len() >= 2 {
            inner.signum()
        } else {
            (start + end).signum()
        };
        if points
            .windows(2)
            .any(|w| reversed(angle_diff(w[1], w[0]), dir))
        {
            return Err(Error::Degenerate {
                reason: "the turn changed direction; calibrate on one steady turn (at least 360° one way): cut the record where the turn ends",
            });
        }
        let mut total = inner;
        for s in [start, end] {
            total += if !reversed(s, dir) {
                s
            } else if s * dir < -core::f64::consts::FRAC_PI_2 {
                s + dir * TAU
            } else {
                return Err(Error::Degenerate {
                    reason: "the turn changed direction; calibrate on one steady turn (at least 360° one way): cut the record where the turn ends",
                });
            };
        }
        Ok(-total)
    }

    /// Centre, radii and turn angle, or why the record does not support them: too few samples,
    /// a turn under 360°, an extremum at the edge of the record, a reversed turn, or readings
    /// that do not change.
    pub fn solve(&self) -> Result<TurnEllipse> {
        if self.samples < MIN_TURN_SAMPLES {
            return Err(Error::TooFewPoints {
                got: self.samples,
                need: MIN_TURN_SAMPLES,
            });
        }
        let (x0, x1) = self.x.range();
        let (y0, y1) = self.y.range();
        let swing = Vector2::new(0.5 * (x1 - x0), 0.5 * (y1 - y0));
        if !(swing.x > 0.0 && swing.y > 0.0 && swing.x.is_finite() && swing.y.is_finite()) {
            return Err(Error::Degenerate {
                reason: "the magnetometer readings do not change on one axis; the compass did not turn, or an axis is dead",
            });
        }
        // Without a maximum and a minimum on both axes there is no centre to measure the
        // turn about (the middle of the ranges of a short arc lies on its chord, from which
        // a 1° arc reads as half a turn), and the turn is short of a revolution: a full one
        // passes both extrema of both axes.
        let Some((centre, radii, pairs)) = self.averaged_pairs() else {
            return Err(Error::Degenerate {
                reason: "the compass has not passed a maximum and a minimum on both axes, so the turn is short of a full revolution (need at least 360° one way); turn on",
            });
        };
        if !(radii.x > 0.0 && radii.y > 0.0 && radii.x.is_finite() && radii.y.is_finite()) {
            return Err(Error::Degenerate {
                reason: "the magnetometer readings do not change on one axis; the compass did not turn, or an axis is dead",
            });
        }
        let turned_rad = self.turned_rad(&centre, &radii)?;
        let need = TAU * (1.0 - 1e-9);
        if turned_rad.abs() < need {
            return Err(Error::IncompleteTurn {
                turned_deg: turned_rad.abs().to_degrees(),
                need_deg: 360.0,
            });
        }
        let complete =
            |t: &ExtremumTracker<TurnTag<T>>| t.has(ExtremumKind::Max) && t.has(ExtremumKind::Min);
        if !complete(&self.x) || !complete(&self.y) {
            return Err(Error::Degenerate {
                reason: "a magnetometer maximum or minimum lies at the start or end of the record, where the true extremum may be outside it; turn on for another quarter turn",
            });
        }
        Ok(TurnEllipse {
            centre,
            radii,
            turned_rad,
            pairs,
        })
    }
}

/// The saved state of a [`TurnExtrema`] (opaque; see [`TurnExtrema::from_saved`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnExtremaState<T> {
    x: ExtremumTrackerState<TurnTag<T>>,
    y: ExtremumTrackerState<TurnTag<T>>,
    first: Option<Vector2<f64>>,
    last: Option<Vector2<f64>>,
    samples: usize,
}
