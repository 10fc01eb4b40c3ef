//! Extremum tracking for the turn calibration (EP 0640207).
//!
//! During a turn each magnetometer axis swings between a maximum and a minimum once per
//! revolution. Both halves of the turn calibrator use those extrema: the compass half takes the
//! centre and radii from their values (claims 4–5), the gyro half takes the relative heading
//! `G` recorded at each of them (claims 1, 6–7). So the tracker records, with every extremum,
//! the sample index and an opaque `tag` chosen by the caller — the gyro half tags samples with
//! `G`, the compass half with the timestamp — and the pairing of a maximum with the opposite
//! minimum *of the same half revolution* is done once, here.
//!
//! ## Detection
//! A streaming turning-point detector with hysteresis: an extremum is confirmed once the
//! signal has moved away from it by at least `h` on *both* sides, with
//! `h = max(swing_fraction · (running max − running min), noise_multiple · mean |Δx|)`.
//! The first term ignores small wiggles once the swing is known; the second keeps noise on a
//! stationary start from being taken for extrema (`mean |Δx|`, the mean sample-to-sample step,
//! is about 1.1 σ for noise alone). A candidate with no swing of `h` before it lies at the
//! start of the record and one with no swing after it at the end: neither is confirmed, since
//! the true extremum may lie outside the record (an extremum at the edge of the record is
//! refused, not guessed). Allocation-free: the most recent [`MAX_EXTREMA`]
//! extrema are kept.

extern crate alloc;

use alloc::vec::Vec;

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Validate, check_range};

/// Confirmed extrema kept per axis (the most recent ones): 32 revolutions.
pub const MAX_EXTREMA: usize = 64;

/// Maximum or minimum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ExtremumKind {
    /// A local maximum.
    Max,
    /// A local minimum.
    Min,
}

/// One extremum of one axis: its value, where it occurred and the caller's tag there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Extremum<T> {
    /// Maximum or minimum.
    pub kind: ExtremumKind,
    /// The signal's value at the extremum.
    pub value: f64,
    /// Index of the sample (0-based, in the order pushed).
    pub index: usize,
    /// The caller's tag for that sample (e.g. the relative heading G there).
    pub tag: T,
}

/// A maximum and the minimum next to it in time: half a revolution apart, never across
/// revolutions (EP 0640207).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HalfTurnPair<T> {
    /// The maximum.
    pub max: Extremum<T>,
    /// The minimum.
    pub min: Extremum<T>,
}

impl<T> HalfTurnPair<T> {
    /// `(max + min) / 2`: the centre of the swing (claim 4).
    pub fn centre(&self) -> f64 {
        0.5 * (self.max.value + self.min.value)
    }

    /// `(max − min) / 2`: the radius of the swing (claim 5).
    pub fn radius(&self) -> f64 {
        0.5 * (self.max.value - self.min.value)
    }

    /// Whether the maximum came first.
    pub fn max_first(&self) -> bool {
        self.max.index < self.min.index
    }
}

/// Thresholds of the extremum detector (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExtremaConfig {
    /// Hysteresis as a share of the running range, in (0, 1). Default 0.1: an extremum is
    /// confirmed about 37° of turn after it (`1 − cos 37° ≈ 0.2` of the half-range).
    pub swing_fraction: f64,
    /// Hysteresis as a multiple of the mean sample-to-sample step. Default 8.
    pub noise_multiple: f64,
}

impl Default for ExtremaConfig {
    fn default() -> Self {
        Self {
            swing_fraction: 0.1,
            noise_multiple: 8.0,
        }
    }
}

impl Validate for ExtremaConfig {
    /// Checks the ranges documented on the fields: `swing_fraction` strictly between 0 and 1,
    /// `noise_multiple` finite and ≥ 0.
    fn validate(&self) -> Result<()> {
        // The open interval (0, 1) as the closed one between its first and last f64.
        check_range(
            "extrema swing_fraction",
            self.swing_fraction,
            f64::MIN_POSITIVE,
            1.0 - f64::EPSILON / 2.0,
        )?;
        check_range("extrema noise_multiple", self.noise_multiple, 0.0, f64::MAX)?;
        Ok(())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
enum Phase<T> {
    /// No direction known yet: track the running max and min, and the opposite extreme seen
    /// before each, to tell an interior extremum from one at the start of the record.
    Start {
        hi: Extremum<T>,
        lo: Extremum<T>,
        /// Lowest value before `hi` occurred.
        lo_before_hi: f64,
        /// Highest value before `lo` occurred.
        hi_before_lo: f64,
    },
    /// Rising towards the candidate maximum.
    Rising(Extremum<T>),
    /// Falling towards the candidate minimum.
    Falling(Extremum<T>),
}

/// Streaming extremum detector for one axis. See the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtremumTracker<T: Copy> {
    config: ExtremaConfig,
    phase: Option<Phase<T>>,
    ring: [Option<Extremum<T>>; MAX_EXTREMA],
    confirmed: usize,
    leading_edge: Option<Extremum<T>>,
    samples: usize,
    last: f64,
    abs_step_sum: f64,
    min: f64,
    max: f64,
}

impl<T: Copy> ExtremumTracker<T> {
    /// An empty tracker. Validate `config` first ([`Validate::validate`]).
    pub fn new(config: ExtremaConfig) -> Self {
        Self {
            config,
            phase: None,
            ring: [None; MAX_EXTREMA],
            confirmed: 0,
            leading_edge: None,
            samples: 0,
            last: 0.0,
            abs_step_sum: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
        }
    }

    /// Forgets everything.
    pub fn reset(&mut self) {
        *self = Self::new(self.config);
    }

    /// Samples seen.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The detector thresholds in force.
    pub fn config(&self) -> &ExtremaConfig {
        &self.config
    }

    /// Smallest and largest value seen (`(inf, -inf)` before any sample).
    pub fn range(&self) -> (f64, f64) {
        (self.min, self.max)
    }

    /// The hysteresis now in force.
    pub fn hysteresis(&self) -> f64 {
        hysteresis_of(
            &self.config,
            self.samples,
            self.abs_step_sum,
            self.min,
            self.max,
        )
    }

    /// Feeds the value of sample `index` (indices must increase) with the caller's tag.
    /// Non-finite values are ignored (the caller validates and reports them).
    pub fn push(&mut self, index: usize, value: f64, tag: T) {
        self.push_range(index, value, tag);
    }

    /// [`Self::push`], returning the range after it ([`Self::range`]) from the values just
    /// computed: a caller that needs it would otherwise load it back as one pair from the
    /// two halves just stored, which the processor cannot forward from the stores.
    ///
    /// The candidate is updated where it lies (a whole new phase, built and copied back
    /// on every sample, stalled the copy on the store of its parts), and the hysteresis,
    /// a division, is computed only when a comparison needs it: while the signal moves on
    /// past the candidate it does not. Inlined into the calibrators' push, which then read
    /// the range just updated from registers, not back from memory.
    #[inline(always)]
    pub(crate) fn push_range(&mut self, index: usize, value: f64, tag: T) -> (f64, f64) {
        if !value.is_finite() {
            return (self.min, self.max);
        }
        if self.samples > 0 {
            self.abs_step_sum += (value - self.last).abs();
        }
        self.samples += 1;
        self.last = value;
        self.min = self.min.min(value);
        self.max = self.max.max(value);
        let here = move |kind| Extremum {
            kind,
            value,
            index,
            tag,
        };
        let (config, samples, abs_step_sum, min, max) = (
            self.config,
            self.samples,
            self.abs_step_sum,
            self.min,
            self.max,
        );
        let h = || hysteresis_of(&config, samples, abs_step_sum, min, max);
        match &mut self.phase {
            Some(Phase::Rising(cand)) => {
                if value > cand.value {
                    *cand = here(ExtremumKind::Max);
                } else if value <= cand.value - h() {
                    let confirmed = *cand;
                    self.phase = Some(Phase::Falling(here(ExtremumKind::Min)));
                    self.confirm(confirmed);
                }
            }
            Some(Phase::Falling(cand)) => {
                if value < cand.value {
                    *cand = here(ExtremumKind::Min);
                } else if value >= cand.value + h() {
                    let confirmed = *cand;
                    self.phase = Some(Phase::Rising(here(ExtremumKind::Max)));
                    self.confirm(confirmed);
                }
            }
            _ => self.push_at_start(value, h(), here),
        }
        (min, max)
    }

    /// [`Self::push`] before a direction is known (no phase, or [`Phase::Start`]): the
    /// first samples only, kept out of the loop.
    #[inline(never)]
    fn push_at_start(&mut self, value: f64, h: f64, here: impl Fn(ExtremumKind) -> Extremum<T>) {
        let next = match self.phase {
            Some(Phase::Start {
                mut hi,
                mut lo,
                mut lo_before_hi,
                mut hi_before_lo,
            }) => {
                if value > hi.value {
                    lo_before_hi = lo.value;
                    hi = here(ExtremumKind::Max);
                }
                if value < lo.value {
                    hi_before_lo = hi.value;
                    lo = here(ExtremumKind::Min);
                }
                let fell = value <= hi.value - h && h > 0.0;
                let rose = value >= lo.value + h && h > 0.0;
                // If both apply, the earlier extremum is the one the signal has left first.
                if fell && (!rose || hi.index <= lo.index) {
                    self.settle_first(hi, hi.value - lo_before_hi >= h);
                    Phase::Falling(here(ExtremumKind::Min))
                } else if rose {
                    self.settle_first(lo, hi_before_lo - lo.value >= h);
                    Phase::Rising(here(ExtremumKind::Max))
                } else {
                    Phase::Start {
                        hi,
                        lo,
                        lo_before_hi,
                        hi_before_lo,
                    }
                }
            }
            _ => Phase::Start {
                hi: here(ExtremumKind::Max),
                lo: here(ExtremumKind::Min),
                lo_before_hi: value,
                hi_before_lo: value,
            },
        };
        self.phase = Some(next);
    }

    fn settle_first(&mut self, e: Extremum<T>, interior: bool) {
        if interior {
            self.confirm(e);
        } else {
            self.leading_edge = Some(e);
        }
    }

    fn confirm(&mut self, e: Extremum<T>) {
        self.ring[self.confirmed % MAX_EXTREMA] = Some(e);
        self.confirmed += 1;
    }

    /// How many extrema were confirmed in all (may exceed [`MAX_EXTREMA`]).
    pub fn confirmed_count(&self) -> usize {
        self.confirmed
    }

    /// The kept confirmed extrema, oldest first. They alternate between maxima and minima.
    pub fn extrema(&self) -> impl Iterator<Item = &Extremum<T>> {
        let kept = self.confirmed.min(MAX_EXTREMA);
        let start = self.confirmed - kept;
        (start..self.confirmed).filter_map(move |i| self.ring[i % MAX_EXTREMA].as_ref())
    }

    /// Whether a confirmed extremum of `kind` is kept.
    pub fn has(&self, kind: ExtremumKind) -> bool {
        self.extrema().any(|e| e.kind == kind)
    }

    /// An extremum found at the start of the record and not confirmed (no swing before it).
    pub fn leading_edge(&self) -> Option<&Extremum<T>> {
        self.leading_edge.as_ref()
    }

    /// The candidate still open at the end of the record (no swing after it yet).
    pub fn trailing_candidate(&self) -> Option<&Extremum<T>> {
        match &self.phase {
            Some(Phase::Rising(c)) | Some(Phase::Falling(c)) => Some(c),
            _ => None,
        }
    }

    /// Each confirmed extremum paired with the next one (always of the opposite kind): half a
    /// revolution apart, so every pair lies within one revolution. Consecutive pairs share an
    /// extremum, which averages drift over the turn symmetrically.
    pub fn half_turn_pairs(&self) -> impl Iterator<Item = HalfTurnPair<T>> + '_ {
        let kept = self.confirmed.min(MAX_EXTREMA);
        let start = self.confirmed - kept;
        (start + 1..self.confirmed).filter_map(move |i| {
            let a = self.ring[(i - 1) % MAX_EXTREMA]?;
            let b = self.ring[i % MAX_EXTREMA]?;
            match (a.kind, b.kind) {
                (ExtremumKind::Max, ExtremumKind::Min) => Some(HalfTurnPair { max: a, min: b }),
                (ExtremumKind::Min, ExtremumKind::Max) => Some(HalfTurnPair { max: b, min: a }),
                _ => None,
            }
        })
    }
}

/// The hysteresis of a tracker with these running values (see the module documentation):
/// `max(swing_fraction · range, noise_multiple · mean |Δx|)`.
fn hysteresis_of(
    config: &ExtremaConfig,
    samples: usize,
    abs_step_sum: f64,
    min: f64,
    max: f64,
) -> f64 {
    let mean_step = if samples > 1 {
        abs_step_sum / (samples - 1) as f64
    } else {
        0.0
    };
    let range = if samples > 0 { max - min } else { 0.0 };
    (config.swing_fraction * range).max(config.noise_multiple * mean_step)
}

/// The saved state of an [`ExtremumTracker`]: everything it has learned, with its
/// configuration. Opaque; restore it with [`ExtremumTracker::from_saved`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtremumTrackerState<T> {
    config: ExtremaConfig,
    phase: Option<Phase<T>>,
    ring: Vec<Option<Extremum<T>>>,
    confirmed: usize,
    leading_edge: Option<Extremum<T>>,
    samples: usize,
    last: f64,
    abs_step_sum: f64,
    /// Smallest and largest value (`None` before any sample: never an infinity).
    range: Option<(f64, f64)>,
}

impl<T: Copy> ExtremumTracker<T> {
    /// The saved state.
    pub fn saved(&self) -> ExtremumTrackerState<T> {
        ExtremumTrackerState {
            config: self.config,
            phase: self.phase,
            ring: self.ring.to_vec(),
            confirmed: self.confirmed,
            leading_edge: self.leading_edge,
            samples: self.samples,
            last: self.last,
            abs_step_sum: self.abs_step_sum,
            range: (self.samples > 0).then_some((self.min, self.max)),
        }
    }

    /// Rebuilds a tracker from [`Self::saved`], refusing an invalid configuration or
    /// values that are not finite or do not fit together.
    pub fn from_saved(s: ExtremumTrackerState<T>) -> Result<Self> {
        s.config.validate()?;
        let invalid = |reason| Err(Error::InvalidSnapshot { reason });
        if s.ring.len() != MAX_EXTREMA {
            return invalid("an extremum tracker must keep exactly 64 extremum slots");
        }
        let extremum_ok = |e: &Extremum<T>| e.value.is_finite();
        let phase_ok = match &s.phase {
            None => s.samples == 0,
            Some(Phase::Start {
                hi,
                lo,
                lo_before_hi,
                hi_before_lo,
            }) => {
                extremum_ok(hi)
                    && extremum_ok(lo)
                    && lo_before_hi.is_finite()
                    && hi_before_lo.is_finite()
            }
            Some(Phase::Rising(c)) | Some(Phase::Falling(c)) => extremum_ok(c),
        };
        let range_ok = match s.range {
            None => s.samples == 0,
            Some((lo, hi)) => lo.is_finite() && hi.is_finite() && lo <= hi,
        };
        if !(phase_ok
            && range_ok
            && s.ring.iter().flatten().all(extremum_ok)
            && s.leading_edge.iter().all(extremum_ok)
            && s.last.is_finite()
            && s.abs_step_sum.is_finite()
            && s.abs_step_sum >= 0.0
            && s.ring.iter().filter(|e| e.is_some()).count() == s.confirmed.min(MAX_EXTREMA))
        {
            return invalid("an extremum tracker's values are not finite or do not fit together");
        }
        let mut t = Self::new(s.config);
        t.phase = s.phase;
        t.ring.copy_from_slice(&s.ring);
        t.confirmed = s.confirmed;
        t.leading_edge = s.leading_edge;
        t.samples = s.samples;
        t.last = s.last;
        t.abs_step_sum = s.abs_step_sum;
        if let Some((lo, hi)) = s.range {
            t.min = lo;
            t.max = hi;
        }
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{NoiseSource, SplitMix64};

    fn track(values: &[f64]) -> ExtremumTracker<usize> {
        let mut t = ExtremumTracker::new(ExtremaConfig::default());
        for (i, &v) in values.iter().enumerate() {
            t.push(i, v, i * 10);
        }
        t
    }

    #[test]
    fn cosine_over_two_turns_from_an_interior_start() {
        // Start at phase 45°: the first max (at 360°) and min (at 180°) are interior.
        let v: Vec<f64> = (0..=720)
            .map(|d| (f64::from(d) + 45.0).to_radians().cos())
            .collect();
        let t = track(&v);
        let e: Vec<_> = t.extrema().copied().collect();
        assert_eq!(e.len(), 4, "{e:?}"); // min 135, max 315, min 495, max 675
        assert_eq!(e[0].kind, ExtremumKind::Min);
        assert_eq!(e[0].index, 135);
        assert_eq!(e[0].tag, 1350);
        assert_eq!(e[1].index, 315);
        // The record starts falling: its first sample is a maximum at the edge, not confirmed.
        assert_eq!(
            t.leading_edge().map(|e| (e.kind, e.index)),
            Some((ExtremumKind::Max, 0))
        );
        let pairs: Vec<_> = t.half_turn_pairs().collect();
        assert_eq!(pairs.len(), 3);
        for p in pairs {
            assert!(p.centre().abs() < 1e-9);
            assert!((p.radius() - 1.0).abs() < 1e-9);
            assert_eq!(p.max.index.abs_diff(p.min.index), 180);
        }
    }

    #[test]
    fn an_extremum_at_the_start_or_end_is_not_confirmed() {
        // cos from phase 0 to 360: both maxima are at the edges.
        let v: Vec<f64> = (0..=360).map(|d| f64::from(d).to_radians().cos()).collect();
        let t = track(&v);
        assert!(!t.has(ExtremumKind::Max));
        assert!(t.has(ExtremumKind::Min));
        assert_eq!(t.leading_edge().map(|e| e.index), Some(0));
        assert_eq!(t.trailing_candidate().map(|e| e.index), Some(360));
    }

    #[test]
    fn noise_on_a_stationary_start_makes_no_extrema() {
        let mut rng = SplitMix64::new(5);
        let mut v: Vec<f64> = (0..500).map(|_| 1.0 + rng.normal(0.01)).collect();
        v.extend((0..=750).map(|d| (f64::from(d) + 30.0).to_radians().cos() + rng.normal(0.01)));
        let t = track(&v);
        let e: Vec<_> = t.extrema().collect();
        assert_eq!(e.len(), 4, "{e:?}");
        assert!(e.iter().all(|e| e.index >= 500));
    }

    proptest! {
        #[test]
        fn never_panics_and_alternates(v in proptest::collection::vec(proptest::num::f64::ANY, 0..300)) {
            let t = track(&v);
            let e: Vec<_> = t.extrema().collect();
            for w in e.windows(2) {
                prop_assert!(w[0].kind != w[1].kind);
                prop_assert!(w[0].index < w[1].index);
            }
        }
    }
}
