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
//! no update work at all. The finished refresh is then assessed over two pushes (the
//! restart check and the locus's turning; the quality report and the other acceptance
//! tests) and applied at a third, which swaps in its bins, origin and estimate together
//! (so the published estimate is always one update's) and bins the readings that arrived
//! meanwhile about the new origin, exactly as if the update had been done at once when it
//! started. The estimate ([`truenorth_core::OnlineCalibrator::estimate`], O(1)) changes
//! only then, and that push returns [`Pushed::NewEstimate`].
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

use crate::binned_assess::{Assessor, Verdict};
pub use crate::binned_config::BinnedEllipseConfig;
use crate::binned_refresh::{
    Bin, BinState, Bins, EMPTY, MAX_BINS, RefreshJob, bin_reading, filled,
};

use core::f64::consts::TAU;

pub use crate::binned_update::{MAX_UPDATE_PUSHES, UpdatePhase};
use crate::binned_update::{REFRESH_PUSHES, REFRESH_STRIDE, Update};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Most initial readings averaged for the first origin.
pub const MAX_INIT_SAMPLES: usize = 64;

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

    /// The push logic proper, for a finite reading (no update in progress).
    fn ingest(&mut self, p: &Vector2<f64>) {
        self.samples += 1;
        if self.origin.is_none() {
            // Claim 6: average the first readings for the initial origin, then bin them.
            self.init[self.init_count] = *p;
            self.init_count += 1;
            if self.init_count >= self.config.init_samples {
                let k = self.init_count;
                let init = self.init;
                let o = init[..k].iter().sum::<Vector2<f64>>() / k as f64;
                self.origin = Some(o);
                for q in &init[..k] {
                    self.bin(q);
                }
            }
            return;
        }
        self.bin(p);
        self.since_update += 1;
        if self.since_update >= self.config.update_interval
            && self.filled_bins() >= self.config.min_filled_bins
        {
            self.since_update = 0;
            self.start_update();
        }
    }

    fn bin(&mut self, p: &Vector2<f64>) {
        if let Some(origin) = self.origin {
            bin_reading(
                &mut self.bins,
                self.config.bins,
                &origin,
                p,
                self.config.bin_memory,
            );
        }
    }

    /// Starts a full-set update on a copy of the bins, with the refresh spread evenly over
    /// the working pushes (every `stride`-th) among the first
    /// `min(update_interval, REFRESH_PUSHES)`.
    fn start_update(&mut self) {
        let Some(origin) = self.origin else { return };
        let n = self.config.bins;
        let span = self.config.update_interval.clamp(1, REFRESH_PUSHES);
        let stride = REFRESH_STRIDE.min(span);
        let working = span / stride;
        let bound = RefreshJob::work_bound(n, self.config.origin_iterations);
        self.update = Some(Update {
            job: RefreshJob::start(
                &self.bins,
                n,
                &origin,
                self.config.origin_iterations,
                self.config.min_filled_bins,
            ),
            start_bins: self.bins,
            start_origin: origin,
            budget: bound.div_ceil(working),
            stride,
            advanced: 0,
            phase: UpdatePhase::Refresh,
            precheck: None,
            verdict: None,
            pending: [Vector2::zeros(); MAX_UPDATE_PUSHES],
            pending_len: 0,
        });
    }

    /// Applies a finished, assessed update: its bins and origin, then the verdict (restart,
    /// or new parameters, reference and estimate), all in this one push so that what is
    /// published is always one update's; then bins the readings that arrived meanwhile.
    /// Returns whether the estimate changed.
    fn complete_update(&mut self, mut u: Update) -> bool {
        u.job.finish();
        let verdict = match u.verdict {
            Some(v) => v,
            None => self.assessor().assess(&u.job),
        };
        let before = self.estimate;
        self.bins = u.job.bins;
        self.origin = Some(u.job.origin);
        match verdict {
            Verdict::Failed => {}
            Verdict::Restart(params) => {
                self.phasors = Some(params);
                self.restart();
            }
            Verdict::Accept(params, estimate) => {
                self.phasors = Some(params);
                self.capture_reference();
                self.estimate = estimate;
            }
        }
        for p in &u.pending[..u.pending_len] {
            self.ingest(p);
        }
        self.estimate != before
    }

    /// Runs any update in progress to its end and applies it.
    fn finish_update(&mut self) {
        if let Some(u) = self.update.take() {
            self.complete_update(u);
        }
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
        self.assessor().accept(&self.bins, &params)
    }

    /// What the assessment of an update reads of this calibrator.
    pub(crate) fn assessor(&self) -> Assessor<'_> {
        Assessor {
            config: &self.config,
            reference: &self.reference,
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
        let p = sample.mag;
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite2("magnetometer reading", &p)?;
        if let Some(u) = self.update.as_mut() {
            u.pending[u.pending_len] = p;
            u.pending_len += 1;
        } else {
            self.ingest(&p);
        }
        let Some(u) = self.update.as_mut() else {
            return Ok(Pushed::Accepted);
        };
        // The phase at the start of this push decides its work: one slice of the refresh
        // (on working pushes), or the assessment, or the application — never two of them.
        let phase = u.phase;
        u.step_refresh();
        let full = u.pending_len >= MAX_UPDATE_PUSHES;
        match phase {
            _ if full => {}
            UpdatePhase::Refresh => return Ok(Pushed::Accepted),
            UpdatePhase::Precheck | UpdatePhase::Assess => {
                let assessor = Assessor {
                    config: &self.config,
                    reference: &self.reference,
                    samples: self.samples,
                };
                if let Some(u) = self.update.as_mut() {
                    u.advance_assessment(&assessor);
                }
                return Ok(Pushed::Accepted);
            }
            UpdatePhase::Apply => {}
        }
        let Some(u) = self.update.take() else {
            return Ok(Pushed::Accepted);
        };
        // The refresh ends within `REFRESH_PUSHES` and three more pushes complete it, well
        // within the pending buffer; completing at once when it is full is a safeguard that
        // does not change the result.
        if self.complete_update(u) {
            Ok(Pushed::NewEstimate)
        } else {
            Ok(Pushed::Accepted)
        }
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
        self.clone().solve_in_place()
    }

    fn reset(&mut self) {
        *self = Self::build(self.config);
    }
}

impl OnlineCalibrator for BinnedEllipseCalibrator {
    /// The solution of the last completed full-set update that passed the acceptance tests.
    fn estimate(&self) -> Option<Solution<CompassCalibration2d>> {
        self.estimate
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
                mag: m.sample(&truth, 0.05, &mut rng).unwrap(),
            })
            .unwrap();
        }
    }

    #[test]
    fn s_theta_finds_the_minor_axis_and_the_ratio_is_negative_about_it() {
        let mut m = reference();
        let mut c = BinnedEllipseCalibrator::default();
        drive(&mut c, &mut m, 0.0, 450.0);
        c.solve().unwrap();
        let p = c.solve_phasors().unwrap();
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
        let mut c = BinnedEllipseCalibrator::default();
        drive(&mut c, &mut m, 0.0, 60.0);
        // Not enough readings yet to store (claim 14).
        assert!(c.parameters_to_store().is_none());
        drive(&mut c, &mut m, 60.0, 400.0);
        let before = c.solve().unwrap().params;
        let stored = c.parameters_to_store().unwrap();
        let mut on = BinnedEllipseCalibrator::from_stored_parameters(
            BinnedEllipseConfig::default(),
            &stored,
        )
        .unwrap();
        assert_eq!(on.filled_bins(), 64);
        assert!(on.bin_states().all(|s| s == BinState::Regenerated));
        let after = on.solve().unwrap().params;
        assert!((after.hard_iron - before.hard_iron).norm() < 1e-3 * H);
        assert!((after.soft_iron - before.soft_iron).norm() < 5e-3);
        // New readings replace regenerated values bin by bin.
        drive(&mut on, &mut m, 0.0, 30.0);
        assert!(on.bin_states().any(|s| s == BinState::Measured));
        assert!(
            BinnedEllipseCalibrator::from_stored_parameters(
                BinnedEllipseConfig::default(),
                &EllipsePhasors {
                    ratio: 2.0,
                    ..stored
                }
            )
            .is_err()
        );
    }

    #[test]
    fn a_new_magnet_restarts_a_passing_lorry_does_not() {
        let mut m = reference();
        let mut c = BinnedEllipseCalibrator::default();
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

    /// A snapshot taken at any push of a whole update cycle (every phase: refresh on idle
    /// and working pushes, precheck, assessment, application) restores to a calibrator that
    /// continues bit-identically.
    #[test]
    fn snapshot_at_every_phase_of_an_update_continues_identically() {
        use truenorth_core::Persistent;
        let mut m = reference();
        let mut rng = SplitMix64::new(3);
        let stream: Vec<_> = (0..900)
            .map(|i| {
                let truth = HeadingTruth {
                    heading_rad: (i as f64 * 0.5).to_radians(),
                    horizontal_field: H,
                };
                Mag2Sample {
                    t_s: i as f64,
                    mag: m.sample(&truth, 0.05, &mut rng).unwrap(),
                }
            })
            .collect();
        let mut straight = BinnedEllipseCalibrator::default();
        let mut phases = std::collections::BTreeSet::new();
        for (k, s) in stream.iter().enumerate() {
            if k >= 600 {
                phases.insert(format!("{:?}", straight.update_phase().map(|p| p.0)));
                let mut resumed = BinnedEllipseCalibrator::restore(straight.snapshot()).unwrap();
                assert_eq!(resumed, straight, "push {k}");
                let mut copy = straight.clone();
                for t in &stream[k..(k + 5).min(stream.len())] {
                    assert_eq!(copy.push(t).unwrap(), resumed.push(t).unwrap(), "push {k}");
                    assert_eq!(copy.estimate(), resumed.estimate());
                }
                assert_eq!(copy, resumed);
            }
            straight.push(s).unwrap();
        }
        // Every phase was visited.
        assert_eq!(phases.len(), 5, "{phases:?}");
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
            assert!(BinnedEllipseCalibrator::new(cfg).is_err(), "{cfg:?}");
        }
    }
}
