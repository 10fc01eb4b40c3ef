//! The compass half of the one-turn calibration (EP 0640207
//! claims 4, 5 and 10).
//!
//! The vehicle turns through at least one full revolution. Each magnetometer axis passes a
//! maximum and a minimum once per revolution; the centre of the locus is
//! `X₀ = (X_max + X_min)/2`, `Y₀ = (Y_max + Y_min)/2` (claim 4), its radii
//! `a = (X_max − X_min)/2`, `b = (Y_max − Y_min)/2` (claim 5), and the heading is the angle of
//! the line from the centre to the reading with the axes scaled by `a` and `b` (claim 10).
//!
//! The extrema come from [`crate::seed::extrema`], which the gyro half (conversion constant `k`
//! from the relative heading at the extrema, §A.2–3) reuses: [`TurnExtrema`] is generic over
//! the tag recorded with each extremum, and pairs each maximum with the minimum next to it in
//! time — within one revolution, never across revolutions (§A.3) — averaging over all such
//! pairs when the turn goes on for more than one revolution.
//!
//! Refusals: a turn of less than 360° ([`Error::IncompleteTurn`]); an axis whose maximum or
//! minimum lies at the start or end of the record, where the true extremum may be outside it
//! ([`Error::Degenerate`]); a turn that reverses direction.
//!
//! The method scales the two axes but cannot remove a *rotated* soft iron (an ellipse whose
//! axes are not the sensor's): the quality report gives what that leaves (the two-cycle part
//! of the residual) as `heading_error_systematic_deg`.
//!
//! `progress().ready` runs the acceptance tests of `solve` (the extrema, then the arc of the
//! calibrated readings), so the two always agree; the calibrator saves and restores its whole
//! state through [`Persistent`].

extern crate alloc;

use alloc::vec::Vec;
use core::f64::consts::TAU;

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag2Sample, Persistent, Progress, Pushed, Result, Solution,
    TimeStep, Validate, angle_diff, check_finite, check_finite2, check_positive, check_range,
};

use crate::numerics::direction_slots::{DirectionSlots, SLOTS};
use crate::quality::{MIN_ARC_DEG, calibrated_coverage_2d, require_arc};
use crate::seed::extrema::{
    ExtremaConfig, ExtremumKind, ExtremumTracker, ExtremumTrackerSaved, HalfTurnPair, MAX_EXTREMA,
};
use crate::seed::seed_quality::seed_assessment;

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

    fn with_valid_config(config: ExtremaConfig) -> Self {
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
    pub fn saved(&self) -> TurnExtremaSaved<T> {
        TurnExtremaSaved {
            x: self.x.saved(),
            y: self.y.saved(),
            first: self.first,
            last: self.last,
            samples: self.samples,
        }
    }

    /// Rebuilds the trackers from [`Self::saved`], refusing invalid or inconsistent values.
    pub fn from_saved(s: TurnExtremaSaved<T>) -> Result<Self> {
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
        check_finite2("magnetometer reading", point)?;
        let i = self.samples;
        let t = TurnTag { point: *point, tag };
        self.x.push(i, point.x, t);
        self.y.push(i, point.y, t);
        if self.first.is_none() {
            self.first = Some(*point);
        }
        self.last = Some(*point);
        self.samples += 1;
        Ok(i)
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
    fn turned_rad(&self, centre: &Vector2<f64>, radii: &Vector2<f64>) -> Result<f64> {
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
pub struct TurnExtremaSaved<T> {
    x: ExtremumTrackerSaved<TurnTag<T>>,
    y: ExtremumTrackerSaved<TurnTag<T>>,
    first: Option<Vector2<f64>>,
    last: Option<Vector2<f64>>,
    samples: usize,
}

/// Configuration of the [`TurnCompassCalibrator`] (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TurnConfig {
    /// Extremum detector thresholds ([`ExtremaConfig::default`]).
    pub extrema: ExtremaConfig,
    /// Shortest arc of calibrated headings accepted, degrees, 0..=360 ([`MIN_ARC_DEG`]; a
    /// full turn always passes).
    pub min_arc_deg: f64,
    /// Longest step between two samples, seconds, > 0, that the gyro half
    /// ([`crate::TurnCalibrator`]) integrates its rate across ([`DEFAULT_MAX_GAP_S`]); a
    /// longer one is refused with [`Error::TimeGap`]. The compass half reads no time.
    pub max_gap_s: f64,
}

/// The default [`TurnConfig::max_gap_s`]: 1 s. The trapezoid rule is exact across a step
/// while the rate changes linearly, but a turn that starts or stops inside a step of `g`
/// seconds can hide up to `Δr·g/2` of heading (Δr the change of rate): 10° for a 1-s step
/// at the start of a 20°/s turn, a few per cent of the conversion constant from one
/// revolution. A judgement: every logger sampling at 1 Hz or faster passes, a dropout of
/// more than a second is refused rather than bridged.
pub const DEFAULT_MAX_GAP_S: f64 = 1.0;

impl Validate for TurnConfig {
    fn validate(&self) -> Result<()> {
        self.extrema.validate()?;
        check_range("turn min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check_positive("turn max_gap_s", self.max_gap_s)?;
        Ok(())
    }
}

impl Default for TurnConfig {
    fn default() -> Self {
        Self {
            extrema: ExtremaConfig::default(),
            min_arc_deg: MIN_ARC_DEG,
            max_gap_s: DEFAULT_MAX_GAP_S,
        }
    }
}

/// The compass half of the turn calibrator: centre and radii from the extrema of one or more
/// full turns (EP 0640207 claims 4, 5, 10). Push allocates nothing.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use truenorth_calib::{TurnCompassCalibrator, TurnConfig};
/// use truenorth_compass::{HeadingTruth, MagnetometerModel2d};
/// use truenorth_core::{Calibrator, Mag2Sample, SensorModel};
///
/// let model = MagnetometerModel2d::new(Vector2::new(8.0, -3.0), Matrix2::new(1.2, 0.0, 0.0, 0.9), 0.0)?;
/// let mut cal = TurnCompassCalibrator::new(TurnConfig::default())?;
/// for i in 0..450 { // 450° of turn, 1° per sample, starting at heading 10°
///     let truth = HeadingTruth { heading_rad: (10.0 + i as f64).to_radians(), horizontal_field: 20.0 };
///     cal.push(&Mag2Sample { t_s: i as f64 * 0.1, mag: model.ideal(&truth)? })?;
/// }
/// assert!(cal.progress().ready);
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector2::new(8.0, -3.0)).norm() < 0.1);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurnCompassCalibrator {
    config: TurnConfig,
    extrema: TurnExtrema<f64>,
    slots: DirectionSlots,
    clock: TimeStep,
}

impl Default for TurnCompassCalibrator {
    fn default() -> Self {
        Self::build(TurnConfig::default())
    }
}

impl TurnCompassCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: TurnConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::build(config))
    }

    fn build(config: TurnConfig) -> Self {
        Self {
            config,
            extrema: TurnExtrema::with_valid_config(config.extrema),
            slots: DirectionSlots::new(),
            clock: TimeStep::new(),
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &TurnConfig {
        &self.config
    }

    /// The extrema found so far (tagged with timestamps).
    pub fn extrema(&self) -> &TurnExtrema<f64> {
        &self.extrema
    }

    /// The acceptance tests of `solve`, shared with `progress`: the extrema of a full turn,
    /// then the arc of the calibrated readings.
    fn accepted(&self) -> Result<(TurnEllipse, [Vector2<f64>; SLOTS], usize)> {
        let fit = self.extrema.solve()?;
        let mut buf = [Vector2::zeros(); SLOTS];
        let n = self.slots.collect(&mut buf);
        require_arc(
            &calibrated_coverage_2d(&buf[..n], &fit.calibration()),
            0.0,
            self.config.min_arc_deg,
        )?;
        Ok((fit, buf, n))
    }
}

impl Calibrator for TurnCompassCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    /// Refuses non-finite readings and timestamps that are not finite or do not increase
    /// (the extrema must be found in time order); a refused sample changes nothing.
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        check_finite2("magnetometer reading", &sample.mag)?;
        self.clock.dt_s(sample.t_s)?;
        self.extrema.push(&sample.mag, sample.t_s)?;
        let c = self.extrema.provisional_centre();
        self.slots.push(&sample.mag, &c);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the acceptance tests of [`Calibrator::solve`] (bounded: the kept
    /// extrema and at most 72 readings).
    fn progress(&self) -> Progress {
        let samples = self.extrema.samples();
        let (x0, x1) = self.extrema.x.range();
        let (y0, y1) = self.extrema.y.range();
        let radii = Vector2::new(0.5 * (x1 - x0), 0.5 * (y1 - y0));
        let turned = if samples > 1 && radii.x > 0.0 && radii.y > 0.0 {
            self.extrema
                .turned_rad(&self.extrema.provisional_centre(), &radii)
                .unwrap_or(0.0)
        } else {
            0.0
        };
        Progress {
            samples,
            coverage: (turned.abs() / TAU).min(1.0),
            ready: self.accepted().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        let (fit, buf, n) = self.accepted()?;
        let a = seed_assessment(
            &buf[..n],
            &fit.calibration(),
            fit.field(),
            self.extrema.samples(),
        );
        Ok(Solution {
            params: fit.calibration(),
            quality: a.quality,
        })
    }

    fn reset(&mut self) {
        self.extrema.reset();
        self.slots.clear();
        self.clock.reset();
    }
}

/// The saved state of a [`TurnCompassCalibrator`] ([`Persistent::State`]): configuration,
/// extremum trackers, the kept readings and the last timestamp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnSaved {
    /// The configuration.
    pub config: TurnConfig,
    /// The extremum trackers (opaque).
    pub extrema: TurnExtremaSaved<f64>,
    /// The kept readings by direction slot (72 entries, `None` where empty).
    pub slots: Vec<Option<Vector2<f64>>>,
    /// The last accepted timestamp, seconds.
    pub last_t_s: Option<f64>,
}

impl Persistent for TurnCompassCalibrator {
    type State = TurnSaved;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> TurnSaved {
        TurnSaved {
            config: self.config,
            extrema: self.extrema.saved(),
            slots: self.slots.to_vec(),
            last_t_s: self.clock.last_s(),
        }
    }

    fn from_state(state: TurnSaved) -> Result<Self> {
        let s = state;
        s.config.validate()?;
        let extrema = TurnExtrema::from_saved(s.extrema)?;
        if extrema.x.config() != &s.config.extrema || extrema.y.config() != &s.config.extrema {
            return Err(Error::InvalidSnapshot {
                reason: "the turn's extremum trackers were saved with another configuration",
            });
        }
        let slots = DirectionSlots::from_slice(&s.slots).ok_or(Error::InvalidSnapshot {
            reason: "the turn's direction slots must be 72 finite readings or empty",
        })?;
        let mut clock = TimeStep::new();
        if let Some(t) = s.last_t_s {
            check_finite("saved timestamp", t)?;
            clock.dt_s(t)?;
        }
        if (extrema.samples() > 0) != s.last_t_s.is_some() {
            return Err(Error::InvalidSnapshot {
                reason: "the turn's timestamp does not fit its sample count",
            });
        }
        Ok(Self {
            config: s.config,
            extrema,
            slots,
            clock,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth_compass::{HeadingTruth, MagnetometerModel2d};
    use truenorth_core::SensorModel;

    /// Noise-free readings along a heading profile (degrees), 1 sample per 0.5°.
    fn run(headings: impl Iterator<Item = f64>) -> TurnCompassCalibrator {
        let m = MagnetometerModel2d::new(
            Vector2::new(5.0, -2.0),
            Matrix2::new(1.2, 0.0, 0.0, 0.9),
            0.0,
        )
        .unwrap();
        let mut c = TurnCompassCalibrator::default();
        for (i, h) in headings.enumerate() {
            let truth = HeadingTruth {
                heading_rad: h.to_radians(),
                horizontal_field: 20.0,
            };
            c.push(&Mag2Sample {
                t_s: i as f64,
                mag: m.ideal(&truth).unwrap(),
            })
            .unwrap();
        }
        c
    }

    fn sweep(from: f64, span: f64) -> impl Iterator<Item = f64> {
        let n = (span.abs() * 2.0) as usize;
        (0..=n).map(move |i| from + span * i as f64 / n as f64)
    }

    #[test]
    fn a_turn_and_a_half_gives_centre_radii_and_the_signed_angle() {
        let c = run(sweep(20.0, 540.0));
        let fit = c.extrema().solve().unwrap();
        assert!(
            (fit.turned_rad.to_degrees() - 540.0).abs() < 1.0,
            "{}",
            fit.turned_rad.to_degrees()
        );
        assert!((fit.centre - Vector2::new(5.0, -2.0)).norm() < 1e-3);
        assert!((fit.radii - Vector2::new(24.0, 18.0)).norm() < 1e-2);
        assert!(c.solve().is_ok());
        // The pairs the gyro half will use: half a turn apart, within one revolution; the
        // tags (here timestamps, 2 samples per degree) are 360 samples apart.
        for p in c.extrema().x_pairs().chain(c.extrema().y_pairs()) {
            assert!(((p.max.tag.tag - p.min.tag.tag).abs() - 360.0).abs() <= 2.0);
        }
        // A left turn is negative.
        let left = run(sweep(20.0, -540.0));
        assert!(left.extrema().solve().unwrap().turned_rad < -TAU);
    }

    #[test]
    fn less_than_a_full_turn_is_refused() {
        // 340° from just before the X maximum: both axes pass a maximum and a minimum, and
        // the refusal gives the angle turned about the centre they place.
        let c = run(sweep(-10.0, 340.0));
        match c.solve() {
            Err(Error::IncompleteTurn { turned_deg, .. }) => {
                assert!((turned_deg - 340.0).abs() < 1.0, "{turned_deg}")
            }
            other => panic!("{other:?}"),
        }
        // 300° from 40° passes no X maximum, a third of a turn no extremum pair at all:
        // there is no centre to measure the angle about, and the refusal says so without a
        // figure.
        let c = run(sweep(40.0, 300.0));
        assert!(matches!(c.solve(), Err(Error::Degenerate { .. })));
        let c = run(sweep(40.0, 120.0));
        match c.solve() {
            Err(Error::Degenerate { reason }) => assert!(reason.contains("360°"), "{reason}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_extremum_at_the_edge_is_refused() {
        // Exactly one turn from north: the X maximum is at both ends of the record.
        let c = run(sweep(0.0, 360.0));
        assert!(
            matches!(c.solve(), Err(Error::Degenerate { .. })),
            "{:?}",
            c.solve()
        );
        // A quarter turn more fixes it.
        assert!(run(sweep(0.0, 450.0)).solve().is_ok());
    }

    #[test]
    fn a_reversed_turn_is_refused() {
        let there = sweep(30.0, 300.0);
        let back = sweep(330.0, -300.0);
        let c = run(there.chain(back).chain(sweep(30.0, 300.0)));
        assert!(c.solve().is_err());
    }

    #[test]
    fn too_few_samples_and_bad_input() {
        let mut c = run(sweep(0.0, 5.0));
        assert!(matches!(c.solve(), Err(Error::TooFewPoints { .. })));
        assert!(
            c.push(&Mag2Sample {
                t_s: 1e9,
                mag: Vector2::new(f64::NAN, 0.0)
            })
            .is_err()
        );
        assert!(
            TurnCompassCalibrator::new(TurnConfig {
                extrema: ExtremaConfig {
                    swing_fraction: 1.5,
                    noise_multiple: 8.0
                },
                ..Default::default()
            })
            .is_err()
        );
    }
}
