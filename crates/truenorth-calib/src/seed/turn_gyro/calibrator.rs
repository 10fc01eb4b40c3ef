//! The gyro-and-compass turn calibrator of EP 0640207: the standstill's zero reading, the
//! extrema placed on the relative heading, the conversion constant and the compass from them.

use core::f64::consts::PI;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, Progress, Pushed, Result, Solution, TimeStep, Validate,
    check_finite, check_finite2,
};
use truenorth_gyro::{GyroCalibration, YawIncrement};

use crate::quality::{self, calibrated_coverage_2d, require_arc};
use crate::seed::direction_slots::DirectionSlots;
use crate::seed::extrema::ExtremumKind;
use crate::seed::seed_quality::seed_assessment;
use crate::seed::turn::{TurnConfig, TurnEllipse, TurnExtrema};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Shortest standstill accepted before the turn, s.
pub const MIN_REST_S: f64 = 1.0;

/// Length of one block of the leading record, s.
const BLOCK_S: f64 = 0.25;

/// Blocks kept of the leading record (one minute).
pub(super) const BLOCKS: usize = 240;

/// A block belongs to the standstill while its magnetometer reading is within this share of
/// the turn's swing (half the peak-to-peak range) of the first block's (3 %: 1.7° of turn,
/// several times a block's share of 1 % reading noise)…
const REST_TOLERANCE: f64 = 0.03;

/// …and its mean rate within this many of the standstill's block spreads of the
/// standstill's mean so far: a turn that winds in slowly moves the rate before the field.
const REST_RATE_SIGMAS: f64 = 5.0;

/// Blocks of the standstill left out next to the start of the turn (which may hold its
/// first moments).
const REST_MARGIN_BLOCKS: usize = 2;

/// Readings kept for placing extrema, one per [`SPACING_RAD`] of relative heading: 320
/// cover 160°, enough for ±60° around an extremum with room to spare.
pub(super) const RING: usize = 320;

/// Relative heading between two kept readings, rad (0.5°).
const SPACING_RAD: f64 = 0.5 * PI / 180.0;

/// Half-width of the sinusoid's window around an extremum, rad of relative heading.
const WINDOW_RAD: f64 = 60.0 * PI / 180.0;

/// Extrema confirmed but waiting for the readings on their far side, per axis.
pub(super) const PENDING: usize = 8;

/// Extrema placed per axis (one revolution gives two).
pub(super) const PLACED: usize = 64;

/// One sample of a turn: the raw yaw rate and the raw two-axis compass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Raw yaw rate, rad/s (with the gyro's own zero and gain).
    pub gyr_z_rps: f64,
    /// Raw magnetometer (mag_x, mag_y).
    pub mag: Vector2<f64>,
}

/// The gyro and compass calibration of one turn.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnCalibration {
    /// The gyro's zero reading and conversion constant (as a gain: raw per true rate).
    pub gyro: GyroCalibration,
    /// The compass's centre and radii (claims 4, 5, 10).
    pub compass: CompassCalibration2d,
}

/// How far to trust a [`TurnCalibration`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnQuality {
    /// The compass half's report.
    pub compass: CompassQuality,
    /// Standard deviation of the gyro gain: the spread of the half-turn pairs' constants
    /// over the square root of their number (0 when there is one pair per axis).
    pub gyro_gain_sigma: f64,
    /// Standard deviation of the zero reading, rad/s (the spread of the standstill's
    /// blocks over the square root of their number).
    pub gyro_zero_sigma_rps: f64,
    /// Length of the standstill the zero came from, s.
    pub rest_s: f64,
    /// Half-turn pairs behind the constant, X and Y.
    pub pairs: (usize, usize),
    /// The angle turned, rad, positive right.
    pub turned_rad: f64,
}

/// Where a sample was on the raw relative-heading scale.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RawHeading {
    /// Time since the first sample, s.
    pub t_s: f64,
    /// `∫ raw rate dt` since the first sample, raw rad.
    pub integral: f64,
}

impl RawHeading {
    fn g(&self, zero: f64) -> f64 {
        self.integral - zero * self.t_s
    }
}

/// Sums over the half-turn pairs of one axis.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PairSums {
    k: f64,
    k2: f64,
    centre: f64,
    radius: f64,
    n: usize,
}

/// A summary of a quarter second of the leading record.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Block {
    pub(super) gyro_sum: f64,
    pub(super) gyro_sq: f64,
    pub(super) mag_sum: Vector2<f64>,
    pub(super) n: u32,
}

/// One kept reading for placing extrema.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Kept {
    at: RawHeading,
    mag: Vector2<f64>,
}

/// The gyro-and-compass turn calibrator. Push allocates nothing.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use truenorth_calib::{TurnCalibrator, TurnConfig, TurnSample};
/// use truenorth_core::Calibrator;
///
/// // 3 s at rest, then 1.25 turns at 20°/s, sampled at 20 Hz, with a gyro that reads
/// // 2 % high with a zero of 0.01 rad/s and a compass with hard and soft iron.
/// let mut cal = TurnCalibrator::new(TurnConfig::default())?;
/// let rate = 20f64.to_radians();
/// for k in 0..(60 + 450) {
///     let t = k as f64 * 0.05;
///     let turning = t >= 3.0;
///     let psi = if turning { rate * (t - 3.0) } else { 0.0 };
///     let gyr = 0.01 + if turning { 1.02 * rate } else { 0.0 };
///     let mag = Vector2::new(4.0 + 24.0 * psi.cos(), -2.0 - 18.0 * psi.sin());
///     cal.push(&TurnSample { t_s: t, gyr_z_rps: gyr, mag })?;
/// }
/// let s = cal.solve()?;
/// assert!((s.params.gyro.zero_rps - 0.01).abs() < 1e-6);
/// assert!((s.params.gyro.gain_pos - 1.02).abs() < 1e-3);
/// assert!((s.params.compass.hard_iron - Vector2::new(4.0, -2.0)).norm() < 0.05);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurnCalibrator {
    pub(super) config: TurnConfig,
    pub(super) extrema: TurnExtrema<RawHeading>,
    pub(super) slots: DirectionSlots,
    pub(super) clock: TimeStep,
    pub(super) t0: Option<f64>,
    pub(super) last_rate: f64,
    pub(super) at: RawHeading,
    pub(super) blocks: [Block; BLOCKS],
    pub(super) ring: [Kept; RING],
    pub(super) ring_len: usize,
    pub(super) ring_next: usize,
    pub(super) last_kept_integral: f64,
    /// Extrema placed so far, per axis: (sample index, placed relative heading G*, value).
    pub(super) placed: [[(usize, f64, f64); PLACED]; 2],
    pub(super) placed_len: [usize; 2],
    /// Confirmed extrema waiting to be placed, per axis: (sample index, G at the sample,
    /// maximum or not).
    pub(super) pending: [[(usize, f64, bool); PENDING]; 2],
    pub(super) pending_len: [usize; 2],
    pub(super) confirmed: [usize; 2],
    pub(super) zero: Option<(f64, f64, f64)>,
}

impl TurnCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: TurnConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::fresh(config, TurnExtrema::new(config.extrema)?))
    }

    /// A calibrator that has seen nothing, from a validated `config` and its empty extremum
    /// trackers (so that `reset` cannot fail).
    pub(super) fn fresh(config: TurnConfig, extrema: TurnExtrema<RawHeading>) -> Self {
        Self {
            config,
            extrema,
            slots: DirectionSlots::new(),
            clock: TimeStep::new(),
            t0: None,
            last_rate: 0.0,
            at: RawHeading::default(),
            blocks: [Block::default(); BLOCKS],
            ring: [Kept::default(); RING],
            ring_len: 0,
            ring_next: 0,
            last_kept_integral: f64::NEG_INFINITY,
            placed: [[(0, 0.0, 0.0); PLACED]; 2],
            placed_len: [0; 2],
            pending: [[(0, 0.0, false); PENDING]; 2],
            pending_len: [0; 2],
            confirmed: [0; 2],
            zero: None,
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &TurnConfig {
        &self.config
    }

    /// The gyro's zero reading (rad/s), its standard deviation and the standstill's length
    /// (s), once the turn's swing has shown where the standstill ended.
    pub fn zero(&self) -> Option<(f64, f64, f64)> {
        self.zero
    }

    /// Finds the standstill in the leading blocks: those whose magnetometer reading stays
    /// within [`REST_TOLERANCE`] of the swing of the first block's and whose rate stays
    /// with the standstill's, less [`REST_MARGIN_BLOCKS`] next to the turn.
    fn find_zero(&self) -> Option<(f64, f64, f64)> {
        let (x0, x1) = self.extrema.x().range();
        let (y0, y1) = self.extrema.y().range();
        let swing = 0.5 * (x1 - x0).max(y1 - y0);
        let first = self.blocks.first().filter(|b| b.n > 0)?;
        let m0 = first.mag_sum / f64::from(first.n);
        // Block means: their mean and spread so far (Welford).
        let (mut count, mut mean, mut m2) = (0usize, 0.0f64, 0.0f64);
        let mut rest = 0usize;
        for b in self.blocks.iter().take_while(|b| b.n > 0) {
            let rate = b.gyro_sum / f64::from(b.n);
            let still = (b.mag_sum / f64::from(b.n) - m0).norm() <= REST_TOLERANCE * swing;
            // The spread is trusted from eight blocks on (two seconds of standstill).
            let spread = if count >= 8 {
                (m2 / (count - 1) as f64).sqrt()
            } else {
                f64::INFINITY
            };
            if !still || (rate - mean).abs() > REST_RATE_SIGMAS * spread {
                break;
            }
            count += 1;
            let d = rate - mean;
            mean += d / count as f64;
            m2 += d * (rate - mean);
            rest += 1;
        }
        let blocks = rest.saturating_sub(REST_MARGIN_BLOCKS);
        let rest_s = blocks as f64 * BLOCK_S;
        if rest_s < MIN_REST_S {
            return None;
        }
        let (mut sum, mut n, mut means) = (0.0, 0u32, (0.0f64, 0.0f64));
        for b in &self.blocks[..blocks] {
            sum += b.gyro_sum;
            n += b.n;
            let m = b.gyro_sum / f64::from(b.n);
            means.0 += m;
            means.1 += m * m;
        }
        let k = blocks as f64;
        let spread = ((means.1 - means.0 * means.0 / k) / (k - 1.0)).max(0.0);
        // Blocks, not samples, are the independent unit (noise may be coloured).
        Some((sum / f64::from(n), (spread / k).sqrt(), rest_s))
    }

    /// Queues newly confirmed extrema of `axis` and places those whose far side has been
    /// read.
    fn place_extrema(&mut self, axis: usize) {
        let Some((zero, _, _)) = self.zero else {
            return;
        };
        let tracker = if axis == 0 {
            self.extrema.x()
        } else {
            self.extrema.y()
        };
        let count = tracker.confirmed_count();
        if count != self.confirmed[axis] {
            let new = count - self.confirmed[axis];
            self.confirmed[axis] = count;
            // The tracker keeps its extrema in time order; the new ones are its last.
            let kept = tracker.extrema().count();
            let mut recent = [None; 2];
            for (i, e) in tracker.extrema().enumerate() {
                let back = kept - 1 - i;
                if back < new.min(2) {
                    recent[back] = Some((e.index, e.tag.tag.g(zero), e.kind == ExtremumKind::Max));
                }
            }
            for e in recent.into_iter().flatten().rev() {
                let n = self.pending_len[axis];
                if n < PENDING {
                    self.pending[axis][n] = e;
                    self.pending_len[axis] = n + 1;
                }
            }
        }
        let now = self.at.g(zero);
        let mut k = 0;
        while k < self.pending_len[axis] {
            let (index, g, max) = self.pending[axis][k];
            if (now - g).abs() < 1.2 * WINDOW_RAD {
                k += 1;
                continue;
            }
            if let Some((placed, value)) = self.fit_extremum(axis, g, max, zero) {
                let n = self.placed_len[axis];
                self.placed[axis][n % PLACED] = (index, placed, value);
                self.placed_len[axis] = n + 1;
            }
            let last = self.pending_len[axis] - 1;
            self.pending[axis].swap(k, last);
            self.pending_len[axis] = last;
        }
    }

    /// `G` at the peak (`max`) or trough of axis `axis` near `g`, and the reading there:
    /// `a + b cos u + c sin u` fitted to the kept readings with `u = G − centre` within the
    /// window, twice, the second time centred on the first fit's extremum. `None` without
    /// at least a third of the window read on either side.
    fn fit_extremum(&self, axis: usize, g: f64, max: bool, zero: f64) -> Option<(f64, f64)> {
        let mut centre = g;
        let mut value = 0.0;
        for _ in 0..2 {
            let mut n = nalgebra::Matrix3::<f64>::zeros();
            let mut r = nalgebra::Vector3::<f64>::zeros();
            let (mut lo, mut hi) = (0.0f64, 0.0f64);
            for k in &self.ring[..self.ring_len] {
                let u = k.at.g(zero) - centre;
                if u.abs() > WINDOW_RAD {
                    continue;
                }
                lo = lo.min(u);
                hi = hi.max(u);
                let (su, cu) = u.sin_cos();
                let row = nalgebra::Vector3::new(1.0, cu, su);
                n += row * row.transpose();
                r += row * if axis == 0 { k.mag.x } else { k.mag.y };
            }
            if -lo < WINDOW_RAD / 3.0 || hi < WINDOW_RAD / 3.0 {
                return None;
            }
            let c = n.lu().solve(&r)?;
            let peak = if max {
                c[2].atan2(c[1])
            } else {
                (-c[2]).atan2(-c[1])
            };
            if !peak.is_finite() || peak.abs() > 0.5 * WINDOW_RAD {
                return None;
            }
            let amplitude = c[1].hypot(c[2]);
            value = if max {
                c[0] + amplitude
            } else {
                c[0] - amplitude
            };
            centre += peak;
        }
        Some((centre, value))
    }

    /// `G` and the reading at an extremum: placed already, or placed now from what has
    /// been read.
    fn extremum_g(&self, axis: usize, index: usize) -> Option<(f64, f64)> {
        self.placed_g(axis, index).or_else(|| {
            let (zero, _, _) = self.zero?;
            let n = self.pending_len[axis];
            let &(_, g, max) = self.pending[axis][..n].iter().find(|p| p.0 == index)?;
            self.fit_extremum(axis, g, max, zero)
        })
    }

    fn placed_g(&self, axis: usize, index: usize) -> Option<(f64, f64)> {
        let n = self.placed_len[axis].min(PLACED);
        self.placed[axis][..n]
            .iter()
            .find(|(i, _, _)| *i == index)
            .map(|&(_, g, v)| (g, v))
    }

    /// What the placed pairs of one axis give: the conversion constants' sum and sum of
    /// squares, the centres' and radii's sums, and the number of pairs.
    fn axis_pairs(&self, axis: usize) -> PairSums {
        let mut sums = PairSums::default();
        let pairs = self
            .extrema
            .x_pairs()
            .filter(|_| axis == 0)
            .chain(self.extrema.y_pairs().filter(|_| axis == 1));
        for p in pairs {
            if let (Some((ga, va)), Some((gb, vb))) = (
                self.extremum_g(axis, p.max.index),
                self.extremum_g(axis, p.min.index),
            ) {
                let k = (ga - gb).abs() / PI;
                sums.k += k;
                sums.k2 += k * k;
                sums.centre += 0.5 * (va + vb);
                sums.radius += 0.5 * (va - vb);
                sums.n += 1;
            }
        }
        sums
    }

    fn accepted(&self) -> Result<(TurnEllipse, TurnCalibration, TurnQuality)> {
        let fit = self.extrema.solve()?;
        let mut buf = [Vector2::zeros(); crate::seed::direction_slots::SLOTS];
        let n = self.slots.collect(&mut buf);
        require_arc(
            &calibrated_coverage_2d(&buf[..n], &fit.calibration()),
            0.0,
            self.config.min_arc_deg,
        )?;
        let (zero, zero_sigma, rest_s) = self.zero.or_else(|| self.find_zero()).ok_or(
            Error::Degenerate {
                reason: "the record must start with the vehicle at rest for at least 1 s: the gyro's zero reading is taken there (EP 0640207 claims 8-9)",
            },
        )?;
        let (px, py) = (self.axis_pairs(0), self.axis_pairs(1));
        let (nx, ny) = (px.n, py.n);
        if nx == 0 || ny == 0 {
            return Err(Error::Degenerate {
                reason: "no compass extremum on one axis could be placed between readings on both sides; turn more slowly or sample faster",
            });
        }
        // The gyro must turn the same way as the compass: a gain is positive, so a gyro
        // mounted upside down (or with another axis convention) would otherwise pass.
        let g_turned = self.at.g(zero);
        if g_turned * fit.turned_rad <= 0.0 {
            return Err(Error::Degenerate {
                reason: "the gyro turned the other way from the compass: check the sign of gyr_z (positive for a right turn)",
            });
        }
        let (mx, my) = (px.k / nx as f64, py.k / ny as f64);
        let gain = 0.5 * (mx + my);
        // Variance of an axis's mean constant from the spread of its pairs.
        let spread = |q: f64, n: usize, m: f64| {
            if n > 1 {
                ((q - n as f64 * m * m) / (n as f64 - 1.0)).max(0.0) / n as f64
            } else {
                0.0
            }
        };
        let gain_sigma = 0.5 * (spread(px.k2, nx, mx) + spread(py.k2, ny, my)).sqrt();
        let gyro = GyroCalibration::new(zero, gain)?;
        let (nx, ny) = (nx as f64, ny as f64);
        let fit = TurnEllipse {
            centre: Vector2::new(px.centre / nx, py.centre / ny),
            radii: Vector2::new(px.radius / nx, py.radius / ny),
            ..fit
        };
        if !(fit.radii.x > 0.0 && fit.radii.y > 0.0) {
            return Err(Error::Degenerate {
                reason: "the fitted compass swing is not positive on one axis; the compass did not turn, or an axis is dead",
            });
        }
        let compass = fit.calibration();
        let assessment = seed_assessment(&buf[..n], &compass, fit.field(), self.extrema.samples());
        Ok((
            fit,
            TurnCalibration { gyro, compass },
            TurnQuality {
                compass: assessment.quality,
                gyro_gain_sigma: gain_sigma,
                gyro_zero_sigma_rps: zero_sigma,
                rest_s,
                pairs: (px.n, py.n),
                turned_rad: fit.turned_rad,
            },
        ))
    }
}

impl Calibrator for TurnCalibrator {
    type Sample = TurnSample;
    type Params = TurnCalibration;
    type Quality = TurnQuality;

    /// Refuses a non-finite value, a timestamp that does not increase, or one further than
    /// [`TurnConfig::max_gap_s`] after the last ([`Error::TimeGap`]: the rate cannot be
    /// integrated across it); a refused sample changes nothing.
    fn push(&mut self, sample: &TurnSample) -> Result<Pushed> {
        check_finite("gyr_z", sample.gyr_z_rps)?;
        check_finite2("magnetometer reading", &sample.mag)?;
        let mut clock = self.clock;
        let dt = clock.dt_s(sample.t_s)?;
        if let Some(gap_s) = dt.filter(|&dt| dt > self.config.max_gap_s) {
            return Err(Error::TimeGap {
                what: "the gyro's integrated heading",
                t_s: sample.t_s,
                gap_s,
                max_gap_s: self.config.max_gap_s,
            });
        }
        self.clock = clock;
        let t0 = *self.t0.get_or_insert(sample.t_s);
        if let Some(dt) = dt {
            self.at.integral += YawIncrement::new(self.last_rate, sample.gyr_z_rps, dt).angle_rad();
        }
        self.at.t_s = sample.t_s - t0;
        self.last_rate = sample.gyr_z_rps;
        let block = (self.at.t_s / BLOCK_S) as usize;
        if let Some(b) = self.blocks.get_mut(block) {
            b.gyro_sum += sample.gyr_z_rps;
            b.gyro_sq += sample.gyr_z_rps * sample.gyr_z_rps;
            b.mag_sum += sample.mag;
            b.n += 1;
        }
        if (self.at.integral - self.last_kept_integral).abs() >= SPACING_RAD {
            self.ring[self.ring_next] = Kept {
                at: self.at,
                mag: sample.mag,
            };
            self.ring_next = (self.ring_next + 1) % RING;
            self.ring_len = (self.ring_len + 1).min(RING);
            self.last_kept_integral = self.at.integral;
        }
        let c = self.extrema.push_centred(&sample.mag, self.at)?;
        self.slots.push(&sample.mag, &c);
        if self.zero.is_none()
            && self.extrema.x().confirmed_count() + self.extrema.y().confirmed_count() > 0
        {
            self.zero = self.find_zero();
        }
        self.place_extrema(0);
        self.place_extrema(1);
        Ok(Pushed::Accepted)
    }

    /// `ready` runs the acceptance tests of `solve`.
    fn progress(&self) -> Progress {
        let samples = self.extrema.samples();
        let placed = self.placed_len[0].min(2) + self.placed_len[1].min(2);
        Progress {
            samples,
            coverage: placed as f64 / 4.0,
            ready: self.accepted().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<TurnCalibration, TurnQuality>> {
        let (_, params, mut quality) = self.accepted()?;
        quality.compass = quality::with_expected_field(quality.compass, self.config.expected_field);
        Ok(Solution { params, quality })
    }

    fn reset(&mut self) {
        let mut extrema = self.extrema.clone();
        extrema.reset();
        *self = Self::fresh(self.config, extrema);
    }
}
