//! Binned-ellipse auto-calibration (METHODS.md §D, seed EP 0634001).
//!
//! 1. **Initial origin** (claim 6): the mean of the first [`BinnedEllipseConfig::init_samples`]
//!    readings.
//! 2. **Bins by direction** (claim 4): the direction of a reading about the current origin
//!    picks one of `N` bins, which stores the reading (claim 1). With
//!    [`BinnedEllipseConfig::bin_memory`] = 1 (the default, as in the seed) a new reading
//!    replaces the stored one; a larger memory keeps a running mean of the last few.
//! 3. **Interpolation** (claims 1–2): once more than
//!    [`BinnedEllipseConfig::min_filled_bins`] bins hold readings, every empty bin gets a value
//!    by linear interpolation between its nearest filled neighbours. What is interpolated is
//!    the *magnitude* of the sensed field (the seed's "values of the magnitude"), placed at the
//!    empty bin's own direction, so a long gap is bridged by an arc rather than a chord.
//!    Interpolated values are recomputed at every update, so a new measurement always replaces
//!    one (claim 3). Filled bins are treated the same way — their reading, which may lie
//!    anywhere within the bin, is one end of the interpolation at the bin's centre direction —
//!    so the full set is exactly uniform in direction. Without this refinement the mean of the
//!    set is biased by where readings fall within their bins (about 1° of heading error on
//!    the reference turn; with it, under 0.2°).
//! 4. **Origin iteration** (claims 1, 5, 12): the new origin is the mean of the full set; the
//!    stored readings are re-binned about it (two landing in one bin are merged); this is
//!    repeated [`BinnedEllipseConfig::origin_iterations`] times.
//! 5. **Ellipse parameters** (claims 7–9):
//!    - Ω_e minimises `S(θ) = Σ R_i² |cos(θ_i − θ)|` (a 1° scan of [0, π) refined by golden
//!      section). **It finds the minor axis**: to first order in `r`,
//!      `S(θ) ∝ 1 + (2/3) r cos 2(θ − α)` with α the major axis, so the minimum lies across the
//!      major axis. Consequently the ratio below comes out negative (`E_R/E_L < 0` about the
//!      minor axis), which the phasor formulas take as it is
//!      ([`EllipsePhasors::normalised`] gives the `r ≥ 0` form).
//!    - Ratio: with `X'`, `Y'` the readings rotated by Ω_e (claim 9),
//!      `k = Σ R_i²|X'_i| / Σ R_i²|Y'_i|` and `E_R/E_L = (k − 1)/(k + 1)`; and
//!      `|E_L| = (π/4) Σ R_i²(|X'_i| + |Y'_i|) / Σ R_i²`. The weights `R_i²` are the seed's own
//!      (from S(θ)) and are what makes these means right: the bins are uniform in the
//!      *direction* of the reading, and `R² dθ = |E_L|²(1 − r²) du` turns a sum over directions
//!      into an integral over the earth-field phase `u`, over which `mean|cos u| = 2/π`. The
//!      seed equalises the two means by increments instead; the ratio is the same quantity.
//! 6. **Heading** (claims 10–11): [`EllipsePhasors`] in `truenorth-compass`; the solve returns
//!    its closed form as a [`CompassCalibration2d`].
//! 7. **Persistence** (claims 13–14): [`BinnedEllipseCalibrator::parameters_to_store`] gives
//!    the parameters once [`BinnedEllipseConfig::min_samples_to_store`] readings were binned;
//!    [`BinnedEllipseCalibrator::restore`] regenerates every bin from them.
//! 8. **Restart** (claim 15): every [`BinnedEllipseConfig::update_interval`] readings the full
//!    set is rebuilt; once enough bins hold readings, it is compared with the previous full set
//!    and, if the RMS change of the bins measured in both exceeds
//!    [`BinnedEllipseConfig::restart_threshold`] of `|E_L|`, calibration restarts from scratch.
//!    A transient disturbance touches a few bins and stays below it; a magnet added near the
//!    sensor moves every bin visited and trips it.
//!
//! Push allocates nothing; neither does solve.

use core::f64::consts::{PI, TAU};

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::{CompassCalibration2d, EllipsePhasors};
use truenorth_core::{
    Calibrator, Error, Mag2Sample, Progress, Result, Solution, angle_diff, check_finite2,
    wrap_two_pi,
};

use crate::quality::{MIN_ARC_DEG, locus_turning_rad, require_arc};
use crate::seed_quality::seed_assessment;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Most bins a calibrator can have (fixed arrays keep it allocation-free).
pub const MAX_BINS: usize = 128;

/// Most initial readings averaged for the first origin.
pub const MAX_INIT_SAMPLES: usize = 64;

/// Options of the [`BinnedEllipseCalibrator`] (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BinnedEllipseConfig {
    /// Number of direction bins N, even, 8..=[`MAX_BINS`] (64).
    pub bins: usize,
    /// Readings averaged for the initial origin, 1..=[`MAX_INIT_SAMPLES`] (8).
    pub init_samples: usize,
    /// Filled bins needed before interpolating and iterating the origin (N/4 = 16).
    pub min_filled_bins: usize,
    /// Interpolate/re-bin passes before the ellipse parameters are computed (4).
    pub origin_iterations: usize,
    /// How many readings a bin averages; 1 = the newest replaces the stored one (1).
    pub bin_memory: u32,
    /// Readings between full-set updates (and restart checks) during push (128).
    pub update_interval: usize,
    /// RMS change between successive full sets, relative to `|E_L|`, that restarts (0.1).
    /// On the reference turn noise and re-binning change the set by 0.01–0.03 between
    /// updates, a lorry passing (half the earth's field for 3 s) by no more, and a magnet
    /// shifting the hard iron by 0.6 of the field by about 0.16 within one update.
    pub restart_threshold: f64,
    /// Share of bins holding readings before changes are monitored (0.75; re-binning about a
    /// moved origin merges a few readings, so a full turn typically leaves 50–64 of 64 filled).
    pub monitor_from_fraction: f64,
    /// Readings binned before the parameters may be stored (256).
    pub min_samples_to_store: usize,
    /// Shortest arc of headings accepted by solve, degrees ([`MIN_ARC_DEG`]). It is checked
    /// twice: about the fitted origin, and as the locus's own turning
    /// ([`crate::quality::locus_turning_rad`]), which errs short by up to a chord at each
    /// end. In practice a turn of about 250° is needed (1 % noise, 20 seeds: 13 of 20 turns of
    /// 230° accepted, all of 250°; none of 210° or less).
    pub min_arc_deg: f64,
    /// Largest RMS radial residual of the binned readings, relative to `|E_L|`, that solve
    /// accepts (0.1). The ellipse model leaves only noise; more means the readings are not a
    /// rotation in a constant field (a short arc lost in noise, a disturbance).
    pub max_residual_rel: f64,
}

impl Default for BinnedEllipseConfig {
    fn default() -> Self {
        Self {
            bins: 64,
            init_samples: 8,
            min_filled_bins: 16,
            origin_iterations: 4,
            bin_memory: 1,
            update_interval: 128,
            restart_threshold: 0.1,
            monitor_from_fraction: 0.75,
            min_samples_to_store: 256,
            min_arc_deg: MIN_ARC_DEG,
            max_residual_rel: 0.1,
        }
    }
}

impl BinnedEllipseConfig {
    /// Checks every option's range.
    pub fn validate(&self) -> Result<()> {
        let check = |what, value: f64, min: f64, max: f64| {
            if value.is_finite() && value >= min && value <= max {
                Ok(())
            } else {
                Err(Error::OutOfRange {
                    what,
                    value,
                    min,
                    max,
                })
            }
        };
        check(
            "binned ellipse bins",
            self.bins as f64,
            8.0,
            MAX_BINS as f64,
        )?;
        if !self.bins.is_multiple_of(2) {
            return Err(Error::OutOfRange {
                what: "binned ellipse bins (must be even, so opposite directions pair up)",
                value: self.bins as f64,
                min: 8.0,
                max: MAX_BINS as f64,
            });
        }
        check(
            "binned ellipse init_samples",
            self.init_samples as f64,
            1.0,
            MAX_INIT_SAMPLES as f64,
        )?;
        check(
            "binned ellipse min_filled_bins",
            self.min_filled_bins as f64,
            3.0,
            self.bins as f64,
        )?;
        check(
            "binned ellipse origin_iterations",
            self.origin_iterations as f64,
            0.0,
            1000.0,
        )?;
        check(
            "binned ellipse bin_memory",
            f64::from(self.bin_memory),
            1.0,
            1e9,
        )?;
        check(
            "binned ellipse update_interval",
            self.update_interval as f64,
            1.0,
            1e12,
        )?;
        check(
            "binned ellipse restart_threshold",
            self.restart_threshold,
            0.0,
            f64::MAX,
        )?;
        check(
            "binned ellipse monitor_from_fraction",
            self.monitor_from_fraction,
            0.0,
            1.0,
        )?;
        check("binned ellipse min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check(
            "binned ellipse max_residual_rel",
            self.max_residual_rel,
            0.0,
            f64::MAX,
        )?;
        Ok(())
    }
}

/// What a bin holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BinState {
    /// Nothing yet: the full set interpolates it.
    Empty,
    /// Real readings.
    Measured,
    /// Regenerated from stored parameters (claim 13); the next reading replaces it.
    Regenerated,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Bin {
    value: Vector2<f64>,
    count: u32,
    state: BinState,
}

const EMPTY: Bin = Bin {
    value: Vector2::new(0.0, 0.0),
    count: 0,
    state: BinState::Empty,
};

/// The binned-ellipse calibrator (EP 0634001). See the module documentation.
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth_calib::BinnedEllipseCalibrator;
/// use truenorth_compass::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
/// use truenorth_core::{Calibrator, Mag2Sample, SensorModel, angle_diff};
///
/// let model = MagnetometerModel2d::new(
///     Vector2::new(10.0, -5.0), soft_iron_from_axes(1.3, 1.0, 30f64.to_radians()), 0.0)?;
/// let mut cal = BinnedEllipseCalibrator::new();
/// for i in 0..720 {
///     let truth = HeadingTruth { heading_rad: (i as f64 * 0.5).to_radians(), horizontal_field: 20.0 };
///     cal.push(&Mag2Sample { t_s: i as f64 * 0.1, mag: model.ideal(&truth) })?;
/// }
/// let sol = cal.solve()?;
/// let raw = model.ideal(&HeadingTruth { heading_rad: 1.0, horizontal_field: 20.0 });
/// assert!(angle_diff(sol.params.heading_rad(&raw), 1.0).abs().to_degrees() < 0.5);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BinnedEllipseCalibrator {
    config: BinnedEllipseConfig,
    bins: [Bin; MAX_BINS],
    origin: Option<Vector2<f64>>,
    init: [Vector2<f64>; MAX_INIT_SAMPLES],
    init_count: usize,
    samples: usize,
    since_update: usize,
    reference: [Option<Vector2<f64>>; MAX_BINS],
    phasors: Option<EllipsePhasors>,
    restored: bool,
    restarts: usize,
}

impl Default for BinnedEllipseCalibrator {
    fn default() -> Self {
        Self::new()
    }
}

impl BinnedEllipseCalibrator {
    /// How far the tangent of the locus turns along the bins holding readings (measured or
    /// regenerated from a verified calibration), walked in bin order from just after the
    /// longest run of empty bins so that no chord cuts across the locus.
    fn measured_turning_rad(&self, field: f64) -> f64 {
        let n = self.config.bins;
        let has_reading = |i: usize| self.bins[i % n].state != BinState::Empty;
        let (mut run, mut longest, mut longest_end) = (0usize, 0usize, 0usize);
        for i in 0..2 * n {
            if has_reading(i) {
                run = 0;
            } else {
                run += 1;
                if run > longest {
                    longest = run;
                    longest_end = i;
                }
            }
        }
        let start = if longest == 0 {
            0
        } else {
            (longest_end + 1) % n
        };
        // Chords of at least a quarter of the field (about 14° of a circle): bin values
        // scatter across the locus by a few per cent of the field, which turns chords between
        // neighbouring bins by tens of degrees.
        locus_turning_rad(
            (0..n)
                .map(|k| (start + k) % n)
                .filter(|&i| has_reading(i))
                .map(|i| &self.bins[i].value),
            0.25 * field,
        )
    }

    /// A calibrator with the default options.
    pub fn new() -> Self {
        Self::build(BinnedEllipseConfig::default())
    }

    /// A calibrator with the given options (validated).
    pub fn with_config(config: BinnedEllipseConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::build(config))
    }

    fn build(config: BinnedEllipseConfig) -> Self {
        Self {
            config,
            bins: [EMPTY; MAX_BINS],
            origin: None,
            init: [Vector2::zeros(); MAX_INIT_SAMPLES],
            init_count: 0,
            samples: 0,
            since_update: 0,
            reference: [None; MAX_BINS],
            phasors: None,
            restored: false,
            restarts: 0,
        }
    }

    /// The options in force.
    pub fn config(&self) -> &BinnedEllipseConfig {
        &self.config
    }

    /// The current origin estimate.
    pub fn origin(&self) -> Option<Vector2<f64>> {
        self.origin
    }

    /// The ellipse parameters of the last full-set update, if any.
    pub fn phasors(&self) -> Option<EllipsePhasors> {
        self.phasors
    }

    /// How often a change of the locus restarted calibration (claim 15).
    pub fn restarts(&self) -> usize {
        self.restarts
    }

    /// Bins holding real or regenerated readings.
    pub fn filled_bins(&self) -> usize {
        self.bins[..self.config.bins]
            .iter()
            .filter(|b| b.state != BinState::Empty)
            .count()
    }

    /// The state of each of the N bins.
    pub fn bin_states(&self) -> impl Iterator<Item = BinState> + '_ {
        self.bins[..self.config.bins].iter().map(|b| b.state)
    }

    /// The parameters to store when the compass is switched off (claims 13–14): `Some` only
    /// once [`BinnedEllipseConfig::min_samples_to_store`] readings were binned since the last
    /// (re)start, or when the current parameters were themselves restored.
    pub fn parameters_to_store(&self) -> Option<EllipsePhasors> {
        let enough = self.samples >= self.config.min_samples_to_store || self.restored;
        self.phasors.filter(|_| enough)
    }

    /// Switch-on with stored parameters (claim 13): forgets everything, takes the stored
    /// origin, and regenerates every bin from the ellipse. New readings replace regenerated
    /// values bin by bin; if they show that the locus has moved (a magnet was added while the
    /// compass was off), the restart rule of claim 15 applies.
    pub fn restore(&mut self, stored: &EllipsePhasors) -> Result<()> {
        stored.validate()?;
        let restarts = self.restarts;
        *self = Self::build(self.config);
        self.restarts = restarts;
        self.origin = Some(stored.origin);
        let n = self.config.bins;
        for (i, bin) in self.bins[..n].iter_mut().enumerate() {
            let dir = (i as f64 + 0.5) * TAU / n as f64;
            *bin = Bin {
                value: stored.point_at_direction(dir),
                count: 0,
                state: BinState::Regenerated,
            };
        }
        self.phasors = Some(*stored);
        self.restored = true;
        self.capture_reference();
        Ok(())
    }

    fn bin_index(&self, d: &Vector2<f64>) -> Option<usize> {
        if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
            return None;
        }
        let n = self.config.bins;
        Some(((wrap_two_pi(d.y.atan2(d.x)) / TAU * n as f64) as usize).min(n - 1))
    }

    /// Puts a reading in its bin about the current origin (claims 1, 3, 4).
    fn bin(&mut self, p: &Vector2<f64>) {
        let Some(origin) = self.origin else { return };
        let Some(i) = self.bin_index(&(p - origin)) else {
            return;
        };
        let memory = self.config.bin_memory;
        let b = &mut self.bins[i];
        if b.state != BinState::Measured {
            *b = Bin {
                value: *p,
                count: 1,
                state: BinState::Measured,
            };
        } else {
            b.count = b.count.saturating_add(1);
            let w = 1.0 / f64::from(b.count.min(memory));
            b.value += (p - b.value) * w;
        }
    }

    /// The full set (claim 1): the locus sampled at the centre direction of every bin. The
    /// magnitude there is interpolated linearly, in direction, between the two nearest stored
    /// readings on either side (claim 2) — for an empty bin these are its filled neighbours;
    /// for a filled bin its own reading is one of them. Placing every value at its bin's
    /// direction keeps the set uniform in direction whatever the readings' positions within
    /// their bins, which the mean (claim 5) and the R²-weighted sums of the parameters rely
    /// on. `None` when fewer than two bins are filled.
    fn full_set(&self, origin: &Vector2<f64>) -> Option<[Vector2<f64>; MAX_BINS]> {
        let n = self.config.bins;
        // (angle, magnitude) of each filled bin's reading about the origin.
        let mut polar = [(0.0f64, 0.0f64); MAX_BINS];
        let mut k = 0;
        for b in self.bins[..n].iter().filter(|b| b.state != BinState::Empty) {
            let d = b.value - origin;
            if d.norm() > 0.0 {
                polar[k] = (d.y.atan2(d.x), d.norm());
                k += 1;
            }
        }
        if k < 2 {
            return None;
        }
        let mut out = [Vector2::zeros(); MAX_BINS];
        for (i, slot) in out[..n].iter_mut().enumerate() {
            let dir = (i as f64 + 0.5) * TAU / n as f64;
            // Nearest reading at or before `dir` and nearest after it, going round the circle.
            let (mut before, mut after) = ((-TAU, 0.0), (TAU, 0.0));
            for &(a, r) in &polar[..k] {
                let delta = angle_diff(a, dir);
                if delta <= 0.0 && delta > before.0 {
                    before = (delta, r);
                }
                if delta > 0.0 && delta < after.0 {
                    after = (delta, r);
                }
            }
            // With k ≥ 2 readings at distinct angles both exist; if all share one angle, use it.
            if before.0 <= -TAU {
                before = (after.0 - TAU, after.1);
            }
            if after.0 >= TAU {
                after = (before.0 + TAU, before.1);
            }
            let span = after.0 - before.0;
            let r = if span > 0.0 {
                before.1 + (after.1 - before.1) * (-before.0) / span
            } else {
                before.1
            };
            *slot = origin + Vector2::new(dir.cos(), dir.sin()) * r;
        }
        Some(out)
    }

    /// Moves every stored reading to its bin about `new_origin`, merging readings that land in
    /// one bin (weighted by their counts) — the "adjusting" of claim 1.
    fn rebin(&mut self, new_origin: Vector2<f64>) {
        let n = self.config.bins;
        let old = self.bins;
        self.bins = [EMPTY; MAX_BINS];
        self.origin = Some(new_origin);
        for b in old[..n].iter().filter(|b| b.state != BinState::Empty) {
            let Some(i) = self.bin_index(&(b.value - new_origin)) else {
                continue;
            };
            let t = &mut self.bins[i];
            if t.state == BinState::Empty {
                *t = *b;
            } else {
                let (wa, wb) = (f64::from(t.count.max(1)), f64::from(b.count.max(1)));
                t.value = (t.value * wa + b.value * wb) / (wa + wb);
                t.count = t.count.saturating_add(b.count);
                if b.state == BinState::Measured {
                    t.state = BinState::Measured;
                }
            }
        }
    }

    /// Claims 1, 5, 12 then 7–9: iterate the origin, then compute the ellipse parameters.
    fn refresh(&mut self) -> Result<EllipsePhasors> {
        let n = self.config.bins;
        let Some(mut origin) = self.origin else {
            return Err(Error::NotReady {
                what: "the binned-ellipse origin",
                hint: "push more readings",
            });
        };
        for _ in 0..self.config.origin_iterations {
            let Some(full) = self.full_set(&origin) else {
                break;
            };
            let mean = full[..n].iter().sum::<Vector2<f64>>() / n as f64;
            if !(mean.x.is_finite() && mean.y.is_finite()) {
                break;
            }
            self.rebin(mean);
            origin = mean;
        }
        let full = self.full_set(&origin).ok_or(Error::TooFewPoints {
            got: self.filled_bins(),
            need: self.config.min_filled_bins,
        })?;
        let p = ellipse_parameters(&full[..n], &origin)?;
        self.phasors = Some(p);
        Ok(p)
    }

    /// The filled bins' values become the reference for the next restart check.
    fn capture_reference(&mut self) {
        let n = self.config.bins;
        for i in 0..n {
            self.reference[i] =
                (self.bins[i].state != BinState::Empty).then_some(self.bins[i].value);
        }
    }

    fn filled_fraction(&self) -> f64 {
        self.filled_bins() as f64 / self.config.bins as f64
    }

    /// RMS change of the bins filled now and in the reference, relative to `|E_L|`, when
    /// both cover at least `monitor_from_fraction` of the bins.
    fn change_since_reference(&self, e_l: f64) -> Option<f64> {
        let n = self.config.bins;
        let need = self.config.monitor_from_fraction * n as f64;
        let ref_filled = self.reference[..n].iter().filter(|r| r.is_some()).count();
        if (ref_filled as f64) < need || (self.filled_bins() as f64) < need {
            return None;
        }
        let (mut ss, mut k) = (0.0, 0usize);
        for i in 0..n {
            if let (Some(r), true) = (self.reference[i], self.bins[i].state != BinState::Empty) {
                ss += (self.bins[i].value - r).norm_squared();
                k += 1;
            }
        }
        (k > 0 && e_l > 0.0).then(|| (ss / k as f64).sqrt() / e_l)
    }

    /// Forgets the readings and the origin (claim 15); keeps the options and the count of
    /// restarts.
    fn restart(&mut self) {
        let restarts = self.restarts + 1;
        *self = Self::build(self.config);
        self.restarts = restarts;
    }
}

/// `∫₀ˣ |cos t| dt = 2k + (−1)ᵏ sin x` with `k = round(x/π)`: continuous and exact.
fn int_abs_cos(x: f64) -> f64 {
    let k = (x / PI).round();
    let sign = if (k as i64) % 2 == 0 { 1.0 } else { -1.0 };
    2.0 * k + sign * x.sin()
}

/// Mean of `|cos(φ − θ)|` over the bin `[φ_c − Δ/2, φ_c + Δ/2]`.
fn bin_mean_abs_cos(centre: f64, half_width: f64, theta: f64) -> f64 {
    (int_abs_cos(centre + half_width - theta) - int_abs_cos(centre - half_width - theta))
        / (2.0 * half_width)
}

/// The seed's ellipse parameters of a full set about `origin` (claims 7–9; see the module
/// documentation for the weights and which axis Ω_e is). `full[i]` must be the locus at the
/// centre direction `(i + ½)·2π/N` of bin `i`, as the calibrator's full set is.
///
/// Each bin stands for the arc of directions it covers: `|cos(θ_i − θ)|` is replaced by its
/// mean over the bin. With a plain sum the kinks of `|cos|` make `S(θ)` ripple with the bin
/// spacing (relative ripple ≈ (π/N)²/8, against a signal of only ≈ r(θ − Ω_e)² near the
/// minimum), which moved Ω_e by about 1° for N = 64 and r = 0.13; the bin means are smooth.
pub fn ellipse_parameters(full: &[Vector2<f64>], origin: &Vector2<f64>) -> Result<EllipsePhasors> {
    let n = full.len();
    let mut sum_w = 0.0;
    for p in full {
        check_finite2("binned-ellipse full set", p)?;
        sum_w += (p - origin).norm_squared();
    }
    if !(sum_w > 0.0 && sum_w.is_finite()) || n < 4 {
        return Err(Error::Degenerate {
            reason: "all binned readings coincide with the origin; the compass did not turn",
        });
    }
    let half = PI / n as f64;
    let centre = |i: usize| (i as f64 + 0.5) * 2.0 * half;
    // Σ R_i^power · mean_bin |cos(φ − θ)|.
    let weighted = |theta: f64, power: i32| -> f64 {
        full.iter()
            .enumerate()
            .map(|(i, p)| {
                (p - origin).norm().powi(power) * bin_mean_abs_cos(centre(i), half, theta)
            })
            .sum()
    };
    let s = |theta: f64| weighted(theta, 2);
    // Coarse scan of [0, π) at 1°, then golden section on the bracket around the best.
    let step = PI / 180.0;
    let (mut best, mut best_s) = (0.0, f64::INFINITY);
    for k in 0..180 {
        let t = k as f64 * step;
        let v = s(t);
        if v < best_s {
            best = t;
            best_s = v;
        }
    }
    let (mut a, mut b) = (best - step, best + step);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut sc, mut sd) = (s(c), s(d));
    for _ in 0..60 {
        if sc < sd {
            b = d;
            d = c;
            sd = sc;
            c = b - g * (b - a);
            sc = s(c);
        } else {
            a = c;
            c = d;
            sc = sd;
            d = a + g * (b - a);
            sd = s(d);
        }
    }
    let omega = 0.5 * (a + b);
    // Σ R²|X'| = Σ R³|cos(φ − Ω)|, Σ R²|Y'| = Σ R³|sin(φ − Ω)| = Σ R³|cos(φ − Ω − π/2)|.
    let sx = weighted(omega, 3);
    let sy = weighted(omega + 0.5 * PI, 3);
    if !(sy > 0.0 && sx > 0.0) {
        return Err(Error::NotAnEllipse {
            detail: " (the binned readings lie on a line through the origin)",
        });
    }
    let k = sx / sy;
    let ratio = (k - 1.0) / (k + 1.0);
    let e_l = 0.25 * PI * (sx + sy) / sum_w;
    if ratio.abs() >= 0.95 {
        return Err(Error::NotAnEllipse {
            detail: " (axis ratio above 39: the readings are nearly a line)",
        });
    }
    EllipsePhasors::new(*origin, omega, ratio, e_l)
}

impl Calibrator for BinnedEllipseCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;

    fn push(&mut self, sample: &Mag2Sample) -> Result<()> {
        let p = sample.mag;
        check_finite2("magnetometer reading", &p)?;
        self.samples += 1;
        if self.origin.is_none() {
            // Claim 6: average the first readings for the initial origin, then bin them.
            self.init[self.init_count] = p;
            self.init_count += 1;
            if self.init_count >= self.config.init_samples {
                let k = self.init_count;
                let init = self.init;
                self.origin = Some(init[..k].iter().sum::<Vector2<f64>>() / k as f64);
                for q in &init[..k] {
                    self.bin(q);
                }
            }
            return Ok(());
        }
        self.bin(&p);
        self.since_update += 1;
        if self.since_update >= self.config.update_interval
            && self.filled_bins() >= self.config.min_filled_bins
        {
            self.since_update = 0;
            // A failed update (e.g. a degenerate set mid-turn) is retried at the next one.
            if let Ok(params) = self.refresh() {
                if self
                    .change_since_reference(params.earth_magnitude)
                    .is_some_and(|change| change > self.config.restart_threshold)
                {
                    self.restart();
                    return Ok(());
                }
                self.capture_reference();
            }
        }
        Ok(())
    }

    fn progress(&self) -> Progress {
        Progress {
            samples: self.samples,
            coverage: self.filled_fraction(),
            ready: self.filled_bins() >= self.config.min_filled_bins
                && self.filled_fraction() * 360.0 >= self.config.min_arc_deg,
        }
    }

    fn solve(&mut self) -> Result<Solution<CompassCalibration2d>> {
        if self.origin.is_none() {
            return Err(Error::TooFewPoints {
                got: self.samples,
                need: self.config.init_samples,
            });
        }
        let filled = self.filled_bins();
        if filled < self.config.min_filled_bins {
            return Err(Error::TooFewPoints {
                got: filled,
                need: self.config.min_filled_bins,
            });
        }
        let params = self.refresh()?;
        let cal = params.to_calibration();
        let n = self.config.bins;
        let mut pts = [Vector2::zeros(); MAX_BINS];
        let mut k = 0;
        for b in self.bins[..n].iter().filter(|b| b.state != BinState::Empty) {
            pts[k] = b.value;
            k += 1;
        }
        let a = seed_assessment(&pts[..k], &cal, params.earth_magnitude, self.samples);
        require_arc(&a.coverage, self.config.min_arc_deg)?;
        // The arc above is seen from the method's own origin, which a short arc pulls towards
        // itself (so the arc looks longer than it is); the locus's own turning cannot be
        // fooled that way.
        let turned_deg = self
            .measured_turning_rad(params.earth_magnitude.abs())
            .to_degrees();
        if turned_deg < self.config.min_arc_deg {
            return Err(Error::InsufficientCoverage {
                covered_deg: turned_deg.floor(),
                need_deg: self.config.min_arc_deg,
            });
        }
        // NaN residuals are refused too.
        if a.quality.residual_rms_rel.is_nan()
            || a.quality.residual_rms_rel > self.config.max_residual_rel
        {
            return Err(Error::NotAnEllipse {
                detail: " (the binned readings scatter by more than max_residual_rel about the fitted ellipse)",
            });
        }
        Ok(Solution {
            params: cal,
            quality: a.quality,
        })
    }

    fn reset(&mut self) {
        *self = Self::build(self.config);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth_compass::{
        Disturbance, DisturbanceShape, HeadingTruth, MagnetometerModel2d, soft_iron_from_axes,
    };
    use truenorth_core::{SensorModel, SplitMix64, angle_diff};

    const H: f64 = 20.0;

    fn reference() -> MagnetometerModel2d {
        MagnetometerModel2d::new(
            Vector2::new(10.0, -4.0),
            soft_iron_from_axes(1.3, 1.0, 30f64.to_radians()),
            0.01 * H,
        )
        .unwrap()
    }

    /// Turns of `deg` degrees at 2 samples per degree.
    fn drive(c: &mut BinnedEllipseCalibrator, m: &mut MagnetometerModel2d, from: f64, deg: f64) {
        let mut rng = SplitMix64::new(from.to_bits());
        let n = (2.0 * deg) as usize;
        for i in 0..n {
            let truth = HeadingTruth {
                heading_rad: (from + i as f64 * 0.5).to_radians(),
                horizontal_field: H,
            };
            c.push(&Mag2Sample {
                t_s: i as f64,
                mag: m.sample(&truth, 0.05, &mut rng),
            })
            .unwrap();
        }
    }

    #[test]
    fn s_theta_finds_the_minor_axis_and_the_ratio_is_negative_about_it() {
        let mut m = reference();
        let mut c = BinnedEllipseCalibrator::new();
        drive(&mut c, &mut m, 0.0, 450.0);
        c.solve().unwrap();
        let p = c.phasors().unwrap();
        // Major axis at 30°: Ω_e is 120° (mod 180°), r ≈ −0.3/2.3.
        assert!(angle_diff(2.0 * p.omega_e_rad, 2.0 * 120f64.to_radians()).abs() < 0.02);
        assert!((p.ratio + 0.3 / 2.3).abs() < 0.01, "{}", p.ratio);
        assert!((p.earth_magnitude - 1.15 * H).abs() < 0.02 * H);
        let n = p.normalised();
        assert!(angle_diff(2.0 * n.omega_e_rad, 60f64.to_radians()).abs() < 0.02);
    }

    #[test]
    fn stored_parameters_regenerate_the_bins() {
        let mut m = reference();
        let mut c = BinnedEllipseCalibrator::new();
        drive(&mut c, &mut m, 0.0, 60.0);
        // Not enough readings yet to store (claim 14).
        assert!(c.parameters_to_store().is_none());
        drive(&mut c, &mut m, 60.0, 400.0);
        let before = c.solve().unwrap().params;
        let stored = c.parameters_to_store().unwrap();
        let mut on = BinnedEllipseCalibrator::new();
        on.restore(&stored).unwrap();
        assert_eq!(on.filled_bins(), 64);
        assert!(on.bin_states().all(|s| s == BinState::Regenerated));
        let after = on.solve().unwrap().params;
        assert!((after.hard_iron - before.hard_iron).norm() < 1e-3 * H);
        assert!((after.soft_iron - before.soft_iron).norm() < 5e-3);
        // New readings replace regenerated values bin by bin.
        drive(&mut on, &mut m, 0.0, 30.0);
        assert!(on.bin_states().any(|s| s == BinState::Measured));
        assert!(
            on.restore(&EllipsePhasors {
                ratio: 2.0,
                ..stored
            })
            .is_err()
        );
    }

    #[test]
    fn a_new_magnet_restarts_a_passing_lorry_does_not() {
        let mut m = reference();
        let mut c = BinnedEllipseCalibrator::new();
        drive(&mut c, &mut m, 0.0, 720.0);
        assert_eq!(c.restarts(), 0);
        // A lorry passes for a few seconds: a field of half the earth's, briefly.
        let mut lorry = m
            .with_disturbance(Disturbance {
                start_s: m.time_s() + 1.0,
                duration_s: 3.0,
                field_ned: nalgebra::Vector3::new(0.0, 0.5 * H, 0.0),
                shape: DisturbanceShape::RaisedCosine,
            })
            .unwrap();
        drive(&mut c, &mut lorry, 0.0, 720.0);
        assert_eq!(c.restarts(), 0, "a transient restarted calibration");
        // A magnet is fixed near the sensor: the hard iron moves by 0.6 H.
        let mut magnet = MagnetometerModel2d::new(
            m.hard_iron() + Vector2::new(0.6 * H, 0.0),
            m.soft_iron(),
            m.noise_sigma(),
        )
        .unwrap();
        drive(&mut c, &mut magnet, 0.0, 360.0);
        assert!(c.restarts() >= 1, "the magnet went unnoticed");
        drive(&mut c, &mut magnet, 0.0, 450.0);
        let sol = c.solve().unwrap();
        assert!((sol.params.hard_iron - magnet.hard_iron()).norm() < 0.02 * H);
    }

    #[test]
    fn config_is_validated() {
        let bad = [
            BinnedEllipseConfig {
                bins: 63,
                ..Default::default()
            },
            BinnedEllipseConfig {
                bins: 256,
                ..Default::default()
            },
            BinnedEllipseConfig {
                init_samples: 0,
                ..Default::default()
            },
            BinnedEllipseConfig {
                restart_threshold: f64::NAN,
                ..Default::default()
            },
        ];
        for cfg in bad {
            assert!(
                BinnedEllipseCalibrator::with_config(cfg).is_err(),
                "{cfg:?}"
            );
        }
    }
}
