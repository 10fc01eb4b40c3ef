//! Binned-ellipse auto-calibration (EP 0634001).
//!
//! 1. **Initial origin** (claim 6): the mean of the first [`BinnedEllipseConfig::init_samples`]
//!    readings.
//! 2. **Bins by direction** (claim 4): the direction of a reading about the current origin
//!    picks one of `N` bins, which stores the reading (claim 1). With
//!    [`BinnedEllipseConfig::bin_memory`] = 1 (the default, as in the seed) a bin holds one
//!    reading: the first it takes after a full-set update interval without any, then any
//!    that lies nearer its centre direction. (Keeping simply the newest kept, in a dense
//!    noisy turn, the last reading that noise threw back across the bin's edge: the bins
//!    lagged the turn by an extreme of the noise and turned the fitted ellipse, up to 7° of
//!    heading at 5 % noise and 200 readings per degree; see `tests/binned_bound.rs`.) A
//!    larger memory keeps a running mean of the last few.
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
//! 7. **Stored parameters** (claims 13–14): [`BinnedEllipseCalibrator::parameters_to_store`]
//!    gives the parameters once [`BinnedEllipseConfig::min_samples_to_store`] readings were
//!    binned; [`BinnedEllipseCalibrator::from_stored_parameters`] regenerates every bin from
//!    them. (The whole learned state is saved and restored exactly through
//!    [`truenorth_core::Persistent`].)
//! 8. **Restart** (claim 15): every [`BinnedEllipseConfig::update_interval`] readings the full
//!    set is rebuilt; once enough bins hold readings, it is compared with the previous full set
//!    and, if the RMS change of the bins measured in both exceeds
//!    [`BinnedEllipseConfig::restart_threshold`] of `|E_L|`, calibration restarts from scratch.
//!    A transient disturbance touches a few bins and stays below it; a magnet added near the
//!    sensor moves every bin visited and trips it.
//!
//! ## Cost per push, estimate, solve
//! A full-set update (steps 3–5) is about 20,000 bin operations for 64 bins, far more than a
//! push may cost. So push starts it on a copy of the bins (the `binned_update` module) and
//! advances it by one bounded slice on every second push only, over at most
//! `min(update_interval, 96)` pushes (the `binned_refresh` module); the pushes between do
//! no update work at all. The finished refresh is then assessed over a few pushes (the
//! restart check and the locus's turning; the quality report in bounded steps, one per push,
//! its completion by the least-squares fit of the same readings, and the other acceptance
//! tests) and applied at the next, which swaps in its bins, origin and estimate together
//! (so the published estimate is always one update's) and bins the readings that arrived
//! meanwhile about the new origin, exactly as if the update had been done at once when it
//! started; at most 16 of them in that push and as many in each of the next (readings
//! pushed meanwhile queue behind them), which bins them exactly as binning them at once
//! would. The estimate ([`truenorth_core::OnlineCalibrator::estimate`], O(1)) changes
//! only at the application, and that push returns [`Pushed::NewEstimate`].
//!
//! `solve` leaves the calibrator unchanged: it completes any update in progress and runs a
//! full update on a copy, then applies the acceptance tests (origin, filled bins, arc about
//! the origin, the locus's own turning, residual). `progress().ready` runs that same path, so
//! the two always agree; both cost a full update (about half a millisecond for 64 bins):
//! call them now and then, not per sample.
//!
//! Push, solve and progress allocate nothing.

use nalgebra::Vector2;
use truenorth_compass::{CompassCalibration2d, EllipsePhasors};
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag2Sample, OnlineCalibrator, Progress, Pushed, Result,
    Solution, Validate, check_finite, check_finite2,
};

use crate::numerics::reading::read_by_coordinate;
use crate::quality::SectorHint;
use crate::seed::binned::assess::{Assessor, Verdict};
use crate::seed::binned::bins::{
    Bin, BinCentres, BinState, Bins, EMPTY, MAX_BINS, bin_centres, bin_reading, filled,
    hinted_bin_index,
};
pub use crate::seed::binned::config::{BinnedEllipseConfig, MAX_INIT_SAMPLES};
use crate::seed::binned::refresh::RefreshJob;
use crate::seed::seed_quality::with_expected_field;

use core::f64::consts::TAU;

use crate::seed::binned::update::{DRAIN_PER_PUSH, REFRESH_PUSHES, REFRESH_STRIDE, Update};
pub use crate::seed::binned::update::{MAX_UPDATE_PUSHES, UpdatePhase};

/// The binned-ellipse calibrator (EP 0634001). See the module documentation.
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth_calib::{BinnedEllipseCalibrator, BinnedEllipseConfig};
/// use truenorth_compass::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
/// use truenorth_core::{Calibrator, Mag2Sample, OnlineCalibrator, SensorModel, angle_diff};
///
/// let model = MagnetometerModel2d::new(
///     Vector2::new(10.0, -5.0), soft_iron_from_axes(1.3, 1.0, 30f64.to_radians()), 0.0)?;
/// let mut cal = BinnedEllipseCalibrator::new(BinnedEllipseConfig::default())?;
/// for i in 0..720 {
///     let truth = HeadingTruth { heading_rad: (i as f64 * 0.5).to_radians(), horizontal_field: 20.0 };
///     cal.push(&Mag2Sample { t_s: i as f64 * 0.1, mag: model.ideal(&truth)? })?;
/// }
/// assert!(cal.progress().ready);
/// let sol = cal.solve()?;
/// let raw = model.ideal(&HeadingTruth { heading_rad: 1.0, horizontal_field: 20.0 })?;
/// assert!(angle_diff(sol.params.heading_rad(&raw), 1.0).abs().to_degrees() < 0.5);
/// // The running estimate of the last completed update, O(1).
/// assert!(cal.estimate().is_some());
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BinnedEllipseCalibrator {
    pub(crate) config: BinnedEllipseConfig,
    pub(crate) bins: Bins,
    pub(crate) origin: Option<Vector2<f64>>,
    pub(crate) init: [Vector2<f64>; MAX_INIT_SAMPLES],
    pub(crate) init_count: usize,
    pub(crate) samples: usize,
    pub(crate) since_update: usize,
    pub(crate) reference: [Option<Vector2<f64>>; MAX_BINS],
    pub(crate) phasors: Option<EllipsePhasors>,
    pub(crate) restored: bool,
    pub(crate) restarts: usize,
    pub(crate) estimate: Option<Solution<CompassCalibration2d>>,
    pub(crate) update: Option<Update>,
    /// Readings that waited for an applied update and are not binned yet (the front
    /// `backlog_len`; never while an update is in progress).
    pub(crate) backlog: [Vector2<f64>; MAX_UPDATE_PUSHES],
    pub(crate) backlog_len: usize,
    /// Square of the distance from the origin within which a reading's direction is its
    /// noise's (see [`noise_floor_sq`]); 0 until the initial origin is set.
    pub(crate) floor_sq: f64,
    /// How many readings of each bin counted towards the next update since the last one
    /// started (see [`COUNTED_PER_BIN`]).
    pub(crate) counted: [u32; MAX_BINS],
    /// `counted` of the interval before, taken when the last update started: a bin that
    /// took readings in neither keeps its reading only while a new one lies nearer its
    /// centre (see `bins::store_reading`).
    pub(crate) counted_before: [u32; MAX_BINS],
    /// The bins' centre directions (from the configuration).
    centres: BinCentres,
    /// Most readings of one bin that count towards the next update (from the
    /// configuration, see [`counted_cap`]).
    counted_cap: usize,
    /// The bin of the last reading binned, which the next one is almost always in.
    hint: SectorHint,
}

/// Most readings of one bin that count towards the next update
/// ([`BinnedEllipseConfig::update_interval`]) between two updates. A full-set update
/// re-bins the set about the moved origin, which merges readings that fall together, so
/// each update costs the set a little; counting every reading made the updates per turn,
/// and so what the set lost to them, grow with the sampling rate (a recording of 2 000
/// readings per degree ran 5 600 updates per turn and kept 15 of 64 bins). Readings past
/// the first 16 of a bin (the 11 a bin takes at the 2 readings per degree the patent's turn
/// gives, with room) may still replace its reading but bring no update closer, so the
/// updates come per angle turned, not per reading, at any rate. The cap is per bin and
/// update, not per run of readings in a row: near a bin's edge noise moves a dense
/// recording's readings back and forth between two bins hundreds of times as the turn
/// crosses it, and a cap per run counted every crossing (one turn of the `io_speed`
/// ellipse at 500 readings per degree ran 318 updates, kept 27 of 64 bins and was refused
/// for 185° of turning; see `tests/denser_data.rs`). Never below what lets half the bins
/// start an update.
const COUNTED_PER_BIN: usize = 16;

/// Most readings of one bin that count towards the next update: the bin's share of two
/// update intervals, and never fewer than [`COUNTED_PER_BIN`]. Taken once from the
/// configuration, not per reading (an integer division).
fn counted_cap(config: &BinnedEllipseConfig) -> usize {
    (2 * config.update_interval)
        .div_ceil(config.bins)
        .max(COUNTED_PER_BIN)
}

/// How many per-axis noise σ a reading must lie from the origin for its direction to be
/// the locus's rather than its noise's: for noise alone the distance exceeds `cσ` with
/// probability `exp(−c²/2)`, 4·10⁻⁶ at 5, so that even the thousands of readings a dense
/// recording takes while it passes its starting point leave no bin to noise.
const NOISE_FLOOR_SIGMAS: f64 = 5.0;

/// The square of the distance from the initial origin (the mean of `init`, claim 6) within
/// which a reading shows noise rather than a direction: [`NOISE_FLOOR_SIGMAS`] times the
/// per-axis noise σ of the initial readings, estimated from their successive differences
/// (`E|Δ|² = 4σ²` for two axes of independent noise). The initial origin lies on the locus,
/// not inside it; readings close to it point every way, and a recording dense enough to
/// take many of them before it moves off (10⁷ readings over ten turns) filled every bin with
/// that noise, fitted an ellipse to it, and refused, where a sparser recording of the same
/// turns was accepted. Readings inside the floor carry no direction at any density, so
/// skipping them keeps more readings from ever refusing what fewer accepted. The motion
/// between readings adds to the differences, so the floor stays below a quarter of the
/// field as long as a turn takes at least about as many readings as there are bins, which
/// filling the bins needs anyway.
pub(crate) fn noise_floor_sq(init: &[Vector2<f64>]) -> f64 {
    if init.len() < 2 {
        return 0.0;
    }
    let ss: f64 = init.windows(2).map(|w| (w[1] - w[0]).norm_squared()).sum();
    let sigma_sq = ss / (4.0 * (init.len() - 1) as f64);
    NOISE_FLOOR_SIGMAS * NOISE_FLOOR_SIGMAS * sigma_sq
}

impl Default for BinnedEllipseCalibrator {
    fn default() -> Self {
        Self::build(BinnedEllipseConfig::default())
    }
}

impl BinnedEllipseCalibrator {
    /// A calibrator with the given configuration (validated).
    pub fn new(config: BinnedEllipseConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::build(config))
    }

    pub(crate) fn build(config: BinnedEllipseConfig) -> Self {
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
            estimate: None,
            update: None,
            backlog: [Vector2::zeros(); MAX_UPDATE_PUSHES],
            backlog_len: 0,
            floor_sq: 0.0,
            counted: [0; MAX_BINS],
            counted_before: [0; MAX_BINS],
            centres: bin_centres(config.bins),
            counted_cap: counted_cap(&config),
            hint: SectorHint::new(),
        }
    }

    /// Switch-on with stored parameters (claim 13): takes the stored origin and regenerates
    /// every bin from the ellipse. New readings replace regenerated values bin by bin; if
    /// they show that the locus has moved (a magnet was added while the compass was off),
    /// the restart rule of claim 15 applies.
    pub fn from_stored_parameters(
        config: BinnedEllipseConfig,
        stored: &EllipsePhasors,
    ) -> Result<Self> {
        config.validate()?;
        stored.validate()?;
        let mut c = Self::build(config);
        c.origin = Some(stored.origin);
        let n = config.bins;
        for (i, bin) in c.bins[..n].iter_mut().enumerate() {
            let dir = (i as f64 + 0.5) * TAU / n as f64;
            *bin = Bin {
                value: stored.point_at_direction(dir),
                count: 0,
                state: BinState::Regenerated,
            };
        }
        c.phasors = Some(*stored);
        c.restored = true;
        c.capture_reference();
        Ok(c)
    }

    /// The configuration in use.
    pub fn config(&self) -> &BinnedEllipseConfig {
        &self.config
    }

    /// The origin of the bins (of the last completed update).
    pub fn origin(&self) -> Option<Vector2<f64>> {
        self.origin
    }

    /// The ellipse parameters of the last completed full-set update, if any.
    pub fn phasors(&self) -> Option<EllipsePhasors> {
        self.phasors
    }

    /// How often a change of the locus restarted calibration (claim 15).
    pub fn restarts(&self) -> usize {
        self.restarts
    }

    /// Bins holding real or regenerated readings (the readings of an update in progress not
    /// yet binned).
    pub fn filled_bins(&self) -> usize {
        filled(&self.bins, self.config.bins)
    }

    /// The state of each of the N bins.
    pub fn bin_states(&self) -> impl Iterator<Item = BinState> + '_ {
        self.bins[..self.config.bins].iter().map(|b| b.state)
    }

    /// Whether a full-set update is in progress.
    pub fn updating(&self) -> bool {
        self.update.is_some()
    }

    /// Readings that waited for the last applied update and are still to be binned (a
    /// bounded number are binned per push; see the module documentation).
    pub fn waiting_readings(&self) -> usize {
        self.backlog_len
    }

    /// How many pushes the assessment of the update in progress has had (0 outside phase
    /// [`UpdatePhase::Assess`] and at its start).
    pub fn assessment_steps(&self) -> usize {
        self.update
            .as_ref()
            .filter(|u| u.phase == UpdatePhase::Assess)
            .map_or(0, |u| u.assess_steps)
    }

    /// The phase of the full-set update in progress, if any, and how many pushes it has
    /// seen.
    pub fn update_phase(&self) -> Option<(UpdatePhase, usize)> {
        self.update.as_ref().map(|u| (u.phase, u.advanced))
    }

    /// The ellipse parameters a solve now would use, before its acceptance tests: completes
    /// any update in progress and runs a full one, on a copy (the calibrator is unchanged;
    /// the cost of a solve).
    pub fn solve_phasors(&self) -> Result<EllipsePhasors> {
        let mut scratch = self.clone();
        scratch.finish_update();
        scratch.refresh()
    }

    /// The parameters to store when the compass is switched off (claims 13–14), those of
    /// [`Self::solve_phasors`]: `Some` only once
    /// [`BinnedEllipseConfig::min_samples_to_store`] readings were binned since the last
    /// (re)start, or when the current parameters were themselves restored.
    pub fn parameters_to_store(&self) -> Option<EllipsePhasors> {
        let mut scratch = self.clone();
        scratch.finish_update();
        let enough = scratch.samples >= self.config.min_samples_to_store || scratch.restored;
        if !enough {
            return None;
        }
        scratch.refresh().ok()
    }

    /// The push logic proper, for a finite reading (no update in progress). Inlined, with
    /// the binning, into push: one function keeps the reading and the bin in registers.
    #[inline(always)]
    fn ingest(&mut self, p: Vector2<f64>) {
        self.samples += 1;
        if self.origin.is_none() {
            self.ingest_initial(&p);
            return;
        }
        if self.bin(p) {
            self.since_update += 1;
        }
        if self.since_update >= self.config.update_interval
            && self.filled_bins() >= self.config.min_filled_bins
        {
            self.since_update = 0;
            self.counted_before = self.counted;
            self.counted = [0; MAX_BINS];
            self.start_update();
        }
    }

    /// Claim 6: averages the first readings for the initial origin, then bins them (the
    /// first readings only, kept out of line).
    #[inline(never)]
    fn ingest_initial(&mut self, p: &Vector2<f64>) {
        self.init[self.init_count] = *p;
        self.init_count += 1;
        if self.init_count >= self.config.init_samples {
            let k = self.init_count;
            let init = self.init;
            let o = init[..k].iter().sum::<Vector2<f64>>() / k as f64;
            self.origin = Some(o);
            self.floor_sq = noise_floor_sq(&init[..k]);
            for &q in &init[..k] {
                self.bin(q);
            }
        }
    }

    /// Bins `p` if it has a direction about the origin; returns whether it counts towards
    /// the next update (see [`COUNTED_PER_BIN`]).
    #[inline(always)]
    fn bin(&mut self, p: Vector2<f64>) -> bool {
        let Some(origin) = self.origin else {
            return false;
        };
        if (p - origin).norm_squared() <= self.floor_sq {
            return false;
        }
        let n = self.config.bins;
        let Some(i) = bin_reading(
            &mut self.bins,
            &self.centres,
            &origin,
            &p,
            self.config.bin_memory,
            #[inline(always)]
            |d| hinted_bin_index(d, n, &mut self.hint),
            |i| self.counted[i] == 0 && self.counted_before[i] == 0,
        ) else {
            return false;
        };
        let counted = &mut self.counted[i];
        if (*counted as usize) < self.counted_cap {
            *counted += 1;
            true
        } else {
            false
        }
    }

    /// The per-bin counts towards the next update, as saved (the first `n` bins).
    pub(crate) fn counted_bins(&self) -> &[u32] {
        &self.counted[..self.config.bins]
    }

    /// The per-bin counts of the interval before, as saved (the first `n` bins).
    pub(crate) fn counted_before_bins(&self) -> &[u32] {
        &self.counted_before[..self.config.bins]
    }

    /// A full update now (claims 1, 5, 12 then 7–9): iterate the origin, then compute the
    /// ellipse parameters; the re-binned bins are kept.
    fn refresh(&mut self) -> Result<EllipsePhasors> {
        let Some(origin) = self.origin else {
            return Err(Error::NotReady {
                what: "the binned-ellipse origin",
                hint: "push more readings",
            });
        };
        let mut job = RefreshJob::start(
            &self.bins,
            self.config.bins,
            &origin,
            self.config.origin_iterations,
            self.config.min_filled_bins,
        );
        job.finish();
        self.bins = job.bins;
        self.origin = Some(job.origin);
        let p = job.result.unwrap_or(Err(Error::NotReady {
            what: "the binned-ellipse update",
            hint: "push more readings",
        }))?;
        self.phasors = Some(p);
        Ok(p)
    }

    /// Solve on this (scratch) calibrator: complete any update, run a full one, accept.
    fn solve_in_place(&mut self) -> Result<Solution<CompassCalibration2d>> {
        self.finish_update();
        // Before the first origin every reading since the (re)start waits in `init`: a
        // count of readings. After it the bins count headings, however many readings
        // each holds.
        if self.origin.is_none() {
            return Err(Error::TooFewPoints {
                got: self.samples,
                need: self.config.init_samples,
            });
        }
        let filled = self.filled_bins();
        if filled < self.config.min_filled_bins {
            return Err(Error::TooFewBins {
                filled,
                need: self.config.min_filled_bins,
                bins: self.config.bins,
            });
        }
        let params = self.refresh()?;
        self.assessor().accept(&self.bins, &params)
    }

    /// What the assessment of an update reads of this calibrator.
    pub(crate) fn assessor(&self) -> Assessor<'_> {
        Assessor {
            config: &self.config,
            reference: &self.reference,
            phasors: self.phasors.as_ref(),
            samples: self.samples,
        }
    }

    /// The filled bins' values become the reference for the next restart check.
    fn capture_reference(&mut self) {
        let n = self.config.bins;
        for i in 0..n {
            self.reference[i] =
                (self.bins[i].state != BinState::Empty).then_some(self.bins[i].value);
        }
    }

    /// Forgets the readings and the origin (claim 15); keeps the configuration and the count
    /// of restarts.
    fn restart(&mut self) {
        let restarts = self.restarts + 1;
        *self = Self::build(self.config);
        self.restarts = restarts;
    }
}

impl Calibrator for BinnedEllipseCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    /// Refuses a non-finite reading or timestamp (and changes nothing). Bounded work: at
    /// most one slice, the assessment or the application of a full-set update (see the
    /// module documentation).
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        let p = read_by_coordinate(&sample.mag);
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite2("magnetometer reading", &p)?;
        if let Some(u) = self.update.as_mut() {
            u.pending[u.pending_len] = p;
            u.pending_len += 1;
        } else if self.backlog_len > 0 {
            // Behind the readings still waiting from the last update (never full: it only
            // shrinks by more than one a push).
            self.backlog[self.backlog_len] = p;
            self.backlog_len += 1;
            self.drain(true);
        } else {
            self.ingest(p);
        }
        if self.update.is_none() {
            return Ok(Pushed::Accepted);
        }
        Ok(self.advance_update())
    }

    /// Runs the same path as [`Calibrator::solve`] on a copy (so `ready` agrees with it
    /// exactly, at the cost of a full-set update); `coverage` is the share of bins filled.
    fn progress(&self) -> Progress {
        let mut scratch = self.clone();
        let ready = scratch.solve_in_place().is_ok();
        Progress {
            samples: scratch.samples,
            coverage: scratch.filled_bins() as f64 / self.config.bins as f64,
            ready,
        }
    }

    /// Completes any update in progress and runs a full one, on a copy: the calibrator is
    /// unchanged.
    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        let expected = self.config.expected_field;
        self.clone()
            .solve_in_place()
            .map(|s| with_expected_field(s, expected))
    }

    fn reset(&mut self) {
        *self = Self::build(self.config);
    }
}

impl OnlineCalibrator for BinnedEllipseCalibrator {
    /// The solution of the last completed full-set update that passed the acceptance tests.
    fn estimate(&self) -> Option<Solution<CompassCalibration2d>> {
        self.estimate
            .map(|s| with_expected_field(s, self.config.expected_field))
    }
}

mod update_cycle;

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
