//! Auto-calibrating compass with a figure of merit (US 5,297,063).
//!
//! The seed stores heading data points taken after the heading has changed (claim 1 step d),
//! computes the centre of the circle through three of them (e), adds it to a running sum of
//! centres and computes their mean-square error (f, g), computes a figure of merit for the new
//! centre's accuracy (h), and moves the centre estimate towards the new centre by that figure
//! of merit (i). Heading is the arctangent of the centred reading (j–l).
//!
//! ## What "the heading has changed" means here
//! A reading becomes a *data point* when, compared with the previous data point, (1) it has
//! moved by more than [`MeritCircleConfig::noise_multiple`] times the mean sample-to-sample
//! step (so noise on a stationary compass never makes data points), and (2) once a centre
//! estimate exists, its direction about that centre has turned by at least
//! [`MeritCircleConfig::min_turn_rad`]; before then, it has moved by at least
//! [`MeritCircleConfig::spread_fraction`] of the spread of the readings so far.
//! The last [`RING`] data points are kept; each new one forms a triple with the two of them
//! that give the best-conditioned centre.
//!
//! ## The figure of merit, exactly
//! For the new circumcentre `c` (from the triple), with `ĉ` the current estimate:
//!
//! 1. **Geometry** — `γ`, the triple's noise amplification (see
//!    [`crate::circumcircle`]): the centre's per-axis error per unit of point
//!    noise. `w_geom = (2/3)/γ²`, which is 1 for the best possible triple (equilateral) and
//!    falls to 0 as the points close up or line up. Triples with `γ >`
//!    [`MeritCircleConfig::max_amplification`] are not used at all.
//! 2. **MSE** — the running mean `c̄` and mean-square error `MSE = (1/n) Σ|cₖ − c̄|²` of all
//!    `n` centres so far (Welford's update), the seed's steps (f)–(g). With `d = |c − ĉ|`,
//!    `w_agree = MSE / (MSE + d²)`: a centre as far from the estimate as the centres
//!    typically scatter gets ½, an outlier gets little. (`w_agree = 1` while `n < 3` or
//!    `MSE = 0`.)
//! 3. **Weight and merit** — `w = w_geom · w_agree`. With `W` the weight accumulated so far
//!    (capped at [`MeritCircleConfig::weight_memory`] so the estimate keeps tracking slow
//!    changes), the figure of merit is `m = w / (W + w)` ∈ [0, 1], and
//!    `ĉ ← ĉ + m (c − ĉ)`, `W ← min(W + w, weight_memory)`. Until the cap is reached this is
//!    exactly the weighted mean of all centres with weights `w`, i.e. an inverse-variance
//!    weighting by geometry, de-weighted where the centre disagrees with the scatter seen so
//!    far. The first centre has `m = 1`.
//!
//! The method fits a circle: it removes hard iron but not soft iron. The quality report's
//! `heading_error_systematic_deg` is the larger of the two-cycle heading error that leaves
//! and the heading difference from a least-squares ellipse fit of the kept readings, plus
//! that fit's second-order bias (the `fit_gap` module; computed with the last step of the
//! report).
//!
//! ## Online estimate, readiness and persistence
//! At every new heading data point the calibrator runs its own `solve` and keeps the result
//! as the current estimate ([`OnlineCalibrator::estimate`], O(1)); the push that changed it
//! returns [`Pushed::NewEstimate`]. The solve is spread over the pushes that follow, one
//! bounded share each: the acceptance tests at the next push, then the quality report in
//! four steps on a copy of the kept readings (the published estimate stays
//! the previous one until the last step, and equals `solve` of the state the refresh
//! started from bit for bit). `progress().ready` runs the acceptance tests of `solve`
//! (centres, field, arc) on the same data, so the two always agree. The whole learned state,
//! configuration included, is saved and restored through [`Persistent`](truenorth_core::Persistent).

extern crate alloc;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag2Sample, OnlineCalibrator, Progress, Pushed, Result,
    Solution, Validate, check_finite, check_finite2,
};

use crate::numerics::circumcentre::{BEST_AMPLIFICATION_SQ, Circumcircle, circumcircle};
use crate::numerics::reading::read_by_coordinate;
use crate::quality::{
    Coverage, Direction, coverage, mean_corrected_norm_2d, require_arc, turned_at_least,
};
use crate::seed::direction_slots::{DirectionSlots, SLOTS};
use crate::seed::fit_gap::complete_bound;
use crate::seed::seed_quality::{SeedJob, seed_assessment, with_expected_field};

use crate::seed::merit_circle::config::MeritCircleConfig;
use crate::seed::merit_circle::config::RING;

/// Where the merit-circle estimate stands.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeritCircleState {
    /// The current centre estimate ĉ, if any.
    pub centre: Option<Vector2<f64>>,
    /// Heading data points taken.
    pub data_points: usize,
    /// Circumcentres used.
    pub centres: usize,
    /// Triples skipped as degenerate (γ too large or collinear).
    pub degenerate_triples: usize,
    /// Mean of all circumcentres (the seed's running sum divided by the count).
    pub centre_mean: Vector2<f64>,
    /// Mean-square error of the circumcentres about their mean.
    pub centre_mse: f64,
    /// Figure of merit of the last centre.
    pub last_merit: f64,
    /// Accumulated weight W.
    pub weight: f64,
}

/// The merit-circle calibrator (US 5,297,063). Push allocates nothing.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use truenorth_calib::{MeritCircleCalibrator, MeritCircleConfig};
/// use truenorth_compass::{HeadingTruth, MagnetometerModel2d};
/// use truenorth_core::{Calibrator, Mag2Sample, OnlineCalibrator, SensorModel};
///
/// let model = MagnetometerModel2d::new(Vector2::new(8.0, -3.0), Matrix2::identity(), 0.0)?;
/// let mut cal = MeritCircleCalibrator::new(MeritCircleConfig::default())?;
/// for i in 0..720 {
///     let truth = HeadingTruth { heading_rad: (i as f64).to_radians(), horizontal_field: 20.0 };
///     cal.push(&Mag2Sample { t_s: i as f64 * 0.1, mag: model.ideal(&truth)? })?;
/// }
/// assert!(cal.progress().ready);
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector2::new(8.0, -3.0)).norm() < 1e-6);
/// // The running estimate, O(1), is the solve of the last heading data point.
/// assert!(cal.estimate().is_some());
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct MeritCircleCalibrator {
    pub(crate) config: MeritCircleConfig,
    pub(crate) samples: usize,
    pub(crate) prev: Option<Vector2<f64>>,
    pub(crate) step_sum: f64,
    pub(crate) lo: Vector2<f64>,
    pub(crate) hi: Vector2<f64>,
    pub(crate) ring: [Vector2<f64>; RING],
    pub(crate) ring_len: usize,
    pub(crate) ring_next: usize,
    pub(crate) last_point: Option<Vector2<f64>>,
    pub(crate) state: MeritCircleState,
    pub(crate) centre_m2: f64,
    pub(crate) slots: DirectionSlots,
    pub(crate) estimate: Option<Solution<CompassCalibration2d>>,
    /// A data point was taken at the previous push; the estimate is refreshed at the start
    /// of this one (from the state that push left), so that the triple search and the
    /// refresh, each a few microseconds, never fall on one push (unless a data point falls
    /// on a refresh step).
    pub(crate) refresh_due: bool,
    /// The quality report of that refresh in progress, one bounded step per push (on a copy
    /// of the kept readings, so the published estimate stays the previous refresh's until
    /// it completes).
    pub(crate) seed: Option<SeedJob>,
    /// The direction of the last data point about the centre, with the centre and point it
    /// was computed for: it changes only when either does, so the new-data-point test
    /// takes it once, not per push.
    last_direction: Option<(Vector2<f64>, Vector2<f64>, Direction)>,
}

impl Default for MeritCircleCalibrator {
    fn default() -> Self {
        Self::build(MeritCircleConfig::default())
    }
}

impl MeritCircleCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: MeritCircleConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::build(config))
    }

    pub(crate) fn build(config: MeritCircleConfig) -> Self {
        Self {
            config,
            samples: 0,
            prev: None,
            step_sum: 0.0,
            lo: Vector2::repeat(f64::INFINITY),
            hi: Vector2::repeat(f64::NEG_INFINITY),
            ring: [Vector2::zeros(); RING],
            ring_len: 0,
            ring_next: 0,
            last_point: None,
            state: MeritCircleState {
                centre: None,
                data_points: 0,
                centres: 0,
                degenerate_triples: 0,
                centre_mean: Vector2::zeros(),
                centre_mse: 0.0,
                last_merit: 0.0,
                weight: 0.0,
            },
            centre_m2: 0.0,
            slots: DirectionSlots::new(),
            estimate: None,
            refresh_due: false,
            seed: None,
            last_direction: None,
        }
    }

    /// The share of an estimate refresh the next push does: `Some(0)` the acceptance tests
    /// (which start the quality report), `Some(k)` step `k` of the report (`1..=4`), `None`
    /// none.
    pub fn refresh_stage(&self) -> Option<usize> {
        match &self.seed {
            Some(job) => Some(1 + job.steps()),
            None => self.refresh_due.then_some(0),
        }
    }

    /// The options in force.
    pub fn config(&self) -> &MeritCircleConfig {
        &self.config
    }

    /// The estimate and its statistics.
    pub fn state(&self) -> &MeritCircleState {
        &self.state
    }

    /// Whether `p` counts as a new heading data point (see the module documentation).
    fn heading_changed(&mut self, p: &Vector2<f64>) -> bool {
        let Some(last) = self.last_point else {
            return true;
        };
        let chord = (p - last).norm();
        let mean_step = self.step_sum / (self.samples.max(2) - 1) as f64;
        if chord <= self.config.noise_multiple * mean_step {
            return false;
        }
        match self.state.centre {
            Some(c) => {
                let b = match self.last_direction {
                    // Bit for bit: a zero's sign can change an `atan2`.
                    Some((centre, point, b))
                        if same_bits(&centre, &c) && same_bits(&point, &last) =>
                    {
                        b
                    }
                    _ => {
                        let b = Direction::of(&(last - c));
                        self.last_direction = Some((c, last, b));
                        b
                    }
                };
                // `|angle_diff(atan2(p − c), atan2(last − c))| ≥ min_turn_rad`, mostly
                // without the `atan2`.
                turned_at_least(&(p - c), &b, self.config.min_turn_rad)
            }
            None => {
                let spread = (self.hi - self.lo).max();
                chord >= self.config.spread_fraction * spread
            }
        }
    }

    /// The best-conditioned triple of `p` with two kept data points.
    fn best_triple(&self, p: &Vector2<f64>) -> Option<Circumcircle> {
        let mut best: Option<Circumcircle> = None;
        for i in 0..self.ring_len {
            for j in i + 1..self.ring_len {
                if let Some(c) = circumcircle(p, &self.ring[i], &self.ring[j])
                    && best.is_none_or(|b| c.amplification < b.amplification)
                {
                    best = Some(c);
                }
            }
        }
        best
    }

    /// Steps (f)–(i) of the seed for a new circumcentre.
    fn update(&mut self, cc: &Circumcircle) {
        let s = &mut self.state;
        let c = cc.centre;
        s.centres += 1;
        let n = s.centres as f64;
        let delta = c - s.centre_mean;
        s.centre_mean += delta / n;
        self.centre_m2 += delta.dot(&(c - s.centre_mean));
        s.centre_mse = self.centre_m2 / n;
        let w_geom = BEST_AMPLIFICATION_SQ / (cc.amplification * cc.amplification);
        let (w, estimate) = match s.centre {
            None => (w_geom, c),
            Some(e) => {
                let d2 = (c - e).norm_squared();
                let w_agree = if s.centres >= 3 && s.centre_mse > 0.0 {
                    s.centre_mse / (s.centre_mse + d2)
                } else {
                    1.0
                };
                let w = w_geom * w_agree;
                let merit = if s.weight + w > 0.0 {
                    w / (s.weight + w)
                } else {
                    0.0
                };
                s.last_merit = merit;
                (w, e + (c - e) * merit)
            }
        };
        if s.centre.is_none() {
            s.last_merit = 1.0;
        }
        s.centre = Some(estimate);
        s.weight = (s.weight + w).min(self.config.weight_memory);
    }
}

/// What the acceptance tests of the merit circle pass on: the calibration, the field, the
/// kept readings (the front `n` of the buffer) and their coverage.
type Accepted = (
    CompassCalibration2d,
    f64,
    [Vector2<f64>; SLOTS],
    usize,
    Coverage,
);

impl MeritCircleCalibrator {
    /// The acceptance tests of `solve`, shared with `progress` so the two always agree:
    /// enough centres, a field, and the arc about the centre. Returns the calibration, the
    /// field, the kept readings (front `n` of the buffer) and their coverage.
    fn accepted(&self) -> Result<Accepted> {
        let s = &self.state;
        let centre = match s.centre {
            Some(c) if s.centres >= self.config.min_centres => c,
            _ if s.data_points >= 3 && s.degenerate_triples > 0 && s.centres == 0 => {
                return Err(Error::Degenerate {
                    reason: "every triple of heading data points was (nearly) collinear or bunched; turn the compass through a wider arc",
                });
            }
            _ => {
                return Err(Error::TooFewPoints {
                    got: s.data_points,
                    need: self.config.min_centres + 2,
                });
            }
        };
        let cal = CompassCalibration2d {
            hard_iron: centre,
            ..CompassCalibration2d::identity()
        };
        let mut buf = [Vector2::zeros(); SLOTS];
        let n = self.slots.collect(&mut buf);
        let field = mean_corrected_norm_2d(&buf[..n], &cal);
        if !(field > 0.0 && field.is_finite()) {
            return Err(Error::Degenerate {
                reason: "the readings coincide with the fitted centre; the compass did not turn",
            });
        }
        let cov = coverage(&buf[..n], &centre);
        require_arc(&cov, 0.0, self.config.min_arc_deg)?;
        Ok((cal, field, buf, n, cov))
    }
}

impl Calibrator for MeritCircleCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    /// Refuses a non-finite reading or timestamp (and changes nothing). Returns
    /// [`Pushed::NewEstimate`] on the push after a heading data point, when the estimate
    /// refreshed from the state that data point left has changed.
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        let p = read_by_coordinate(&sample.mag);
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite2("magnetometer reading", &p)?;
        let mut pushed = Pushed::Accepted;
        // One bounded share of the refresh per push: the acceptance tests (which start the
        // quality report), or one step of the report. The result is exactly `solve` of the
        // state the refresh started from.
        let refreshed = if let Some(job) = self.seed.as_mut() {
            let done = job.step().map(|a| {
                // Bounded, as the job: one direct fit of at most 72 kept readings.
                let a = complete_bound(a, job.points(), job.calibration());
                Some(Solution {
                    params: *job.calibration(),
                    quality: a.quality,
                })
            });
            if done.is_some() {
                self.seed = None;
            }
            done
        } else if self.refresh_due {
            // Bounded: at most 72 kept readings.
            self.refresh_due = false;
            match self.accepted() {
                Ok((cal, field, buf, n, _)) => {
                    self.seed = Some(SeedJob::start(&buf[..n], &cal, field, self.samples));
                    None
                }
                Err(_) => Some(None),
            }
        } else {
            None
        };
        if let Some(estimate) = refreshed
            && estimate != self.estimate
        {
            self.estimate = estimate;
            pushed = Pushed::NewEstimate;
        }
        if let Some(prev) = self.prev {
            self.step_sum += (p - prev).norm();
        }
        self.prev = Some(p);
        self.samples += 1;
        self.lo = self.lo.inf(&p);
        self.hi = self.hi.sup(&p);
        let slot_centre = self.state.centre.unwrap_or((self.lo + self.hi) * 0.5);
        self.slots.push(&p, &slot_centre);
        if self.samples <= self.config.warmup_samples || !self.heading_changed(&p) {
            return Ok(pushed);
        }
        // A new heading data point (step d).
        self.state.data_points += 1;
        self.last_point = Some(p);
        if self.ring_len >= 2 {
            match self.best_triple(&p) {
                Some(cc) if cc.amplification <= self.config.max_amplification => self.update(&cc),
                _ => self.state.degenerate_triples += 1,
            }
        }
        self.ring[self.ring_next] = p;
        self.ring_next = (self.ring_next + 1) % RING;
        self.ring_len = (self.ring_len + 1).min(RING);
        // The estimate is refreshed once per data point (every `min_turn_rad` of turn), at
        // the next push: a bounded pass over the kept readings, never per sample.
        self.refresh_due = true;
        Ok(pushed)
    }

    /// Runs the acceptance tests of [`Calibrator::solve`] (bounded: at most 72 kept
    /// readings), so `ready` is exactly whether `solve` succeeds.
    fn progress(&self) -> Progress {
        let (coverage, ready) = match self.accepted() {
            Ok((_, _, _, _, cov)) => (cov.fraction, true),
            Err(_) => {
                let cov = self.state.centre.map(|c| {
                    let mut buf = [Vector2::zeros(); SLOTS];
                    let n = self.slots.collect(&mut buf);
                    coverage(&buf[..n], &c).fraction
                });
                (cov.unwrap_or(0.0), false)
            }
        };
        Progress {
            samples: self.samples,
            coverage,
            ready,
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        let (cal, field, buf, n, _) = self.accepted()?;
        let a = complete_bound(
            seed_assessment(&buf[..n], &cal, field, self.samples),
            &buf[..n],
            &cal,
        );
        let solution = Solution {
            params: cal,
            quality: a.quality,
        };
        Ok(with_expected_field(solution, self.config.expected_field))
    }

    fn reset(&mut self) {
        *self = Self::build(self.config);
    }
}

impl OnlineCalibrator for MeritCircleCalibrator {
    /// The solve of the latest heading data point (`None` before one succeeded).
    fn estimate(&self) -> Option<Solution<CompassCalibration2d>> {
        self.estimate
            .map(|s| with_expected_field(s, self.config.expected_field))
    }
}

/// Whether `a` and `b` are the same bits (so any arithmetic on them gives the same result).
fn same_bits(a: &Vector2<f64>, b: &Vector2<f64>) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}
