//! What the online least-squares ellipse and ellipsoid calibrators share: the bookkeeping
//! around their running sums, retained readings and staged refresh (push, progress, solve,
//! reset, snapshot and restore), generic over the dimension, as [`crate::fits::normalise`]'s
//! `Normaliser<D>` is. The 2-D and 3-D specifics — the direct fit and its stages, the
//! direction slots, the coverage measure — come from the refresh type through
//! [`ConicRefresh`], so the per-sample path is monomorphised: no dynamic dispatch, no
//! allocation.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use core::fmt::Debug;

use nalgebra::SMatrix;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use truenorth_core::{
    CompassQuality, CompassUncertainty, Error, FitQuality, Progress, Pushed, Real, Result,
    Solution, Validate, check_finite,
};

use crate::online::conic_sums::{
    ConicSums, Retained, RetainedSnapshot, SumsSnapshot, forgetting, inverse_factor, sigma_kappa,
};
use crate::quality::{self, BOUND_SIGMAS};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The inverse of the share of the readings the sums weigh that a refresh waits for, at
/// least, after the last one started.
///
/// A refresh costs as much as thousands of pushes. `n` readings in the sums and `n/64` new
/// ones shift the sums by about a 64th of their weight, so the estimate the next refresh
/// would publish differs from the last by about a 64th of the difference between the new
/// readings' own calibration and the current one: nothing for a calibration that holds, and
/// a change of calibration shows within a 64th of the memory, as forgetting caps the
/// memory at a half-life. Without this the refreshes cost the same per push however long
/// the recording (at the default interval, most of what a push costs on average), while
/// what each refresh can change shrinks as `1/n`.
const REFRESH_SHARE: u64 = 64;

/// The parameters of an online calibrator's configuration that its bookkeeping needs.
pub(crate) trait OnlineConfig: Copy + Debug + PartialEq + Validate {
    /// Fewest readings a solution is accepted from (and when the first refresh starts).
    fn min_samples(&self) -> u32;
    /// Readings between the starts of two refreshes.
    fn refresh_interval_samples(&self) -> u32;
    /// Half-life of a reading's weight, in readings (`None`: never forget).
    fn forgetting_half_life_samples(&self) -> Option<f64>;
}

/// A staged refresh of a `D`-axis online conic calibrator with `M` running monomial sums and
/// `N` retained-reading slots: the dimension's specifics the shared bookkeeping calls.
pub(crate) trait ConicRefresh<const D: usize, const M: usize, const N: usize>:
    Clone + Debug
{
    /// The calibrator's configuration.
    type Config: OnlineConfig;
    /// The calibration it fits (in `f64`, as every fit runs).
    type Cal: Copy + Debug + PartialEq;
    /// The calibration in the float type `T` of the readings, to sort them by.
    type CalIn<T: Real>: Copy + Debug;
    /// Number of stages of a refresh.
    const STAGES: u8;
    /// The refusal of a solve whose refresh ended without an outcome.
    const NOT_READY: Error;
    /// Adds reading `p` to `sums` (see [`ConicSums::add`]).
    fn add<T: Real>(sums: &mut ConicSums<T, D, M>, p: &SVector<T, D>, decay: T) -> Result<()>;
    /// `cal` in the float type `T` (see [`ConicRefresh::CalIn`]).
    fn narrow<T: Real>(cal: &Self::Cal) -> Self::CalIn<T>;
    /// The retained-reading slot of `p` under calibration `cal`, computed in `T`.
    fn slot<T: Real>(cal: &Self::CalIn<T>, p: &SVector<T, D>) -> Option<usize>;
    /// Coverage of the live retained readings about calibration `cal`, as a fraction.
    fn coverage(slots: &Retained<f64, D, N>, now: u64, lifetime: u64, cal: &Self::Cal) -> f64;
    /// Whether every coefficient of `cal` is finite.
    fn is_finite(cal: &Self::Cal) -> bool;
    /// A refresh of copies of `sums` and `slots`, no stage run yet.
    fn start(sums: &ConicSums<f64, D, M>, slots: &Retained<f64, D, N>) -> Self;
    /// Runs stage `stage` (see [`ConicRefresh::step`]).
    fn run_stage(&mut self, stage: u8, cfg: &Self::Config, lifetime: u64);
    /// What every refresh keeps: its copies, its stage, its sorting map and its outcome.
    fn base(&self) -> &RefreshBase<D, M, N, Self::Cal>;
    /// As [`ConicRefresh::base`], mutable.
    fn base_mut(&mut self) -> &mut RefreshBase<D, M, N, Self::Cal>;
    /// As [`ConicRefresh::base`], by value, once the refresh is done.
    fn into_base(self) -> RefreshBase<D, M, N, Self::Cal>;

    /// Runs the next stage; `true` once the outcome is known.
    #[inline]
    fn step(&mut self, cfg: &Self::Config, lifetime: u64) -> bool {
        if self.base().outcome.is_some() {
            return true;
        }
        let stage = self.base().stage;
        self.run_stage(stage, cfg, lifetime);
        self.base_mut().stage += 1;
        self.base().outcome.is_some()
    }
}

/// What every staged refresh keeps: a copy of the sums and retained readings taken when it
/// started, the stages run, the calibration to sort retained readings by from now on, and
/// the outcome once known.
#[derive(Debug, Clone)]
pub(crate) struct RefreshBase<const D: usize, const M: usize, const N: usize, C> {
    pub sums: ConicSums<f64, D, M>,
    pub slots: Retained<f64, D, N>,
    pub stage: u8,
    pub map: Option<C>,
    pub outcome: Option<Result<Solution<C>>>,
}

impl<const D: usize, const M: usize, const N: usize, C> RefreshBase<D, M, N, C> {
    /// Copies of `sums` and `slots`, no stage run yet.
    pub fn new(sums: &ConicSums<f64, D, M>, slots: &Retained<f64, D, N>) -> Self {
        Self {
            sums: *sums,
            slots: *slots,
            stage: 0,
            map: None,
            outcome: None,
        }
    }

    /// Ends the refresh with refusal `e`, past its last stage (`stages`).
    pub fn fail(&mut self, e: Error, stages: u8) {
        self.outcome = Some(Err(e));
        self.stage = stages;
    }

    /// Refuses fewer readings than `min_samples`; whether there are enough.
    pub fn require_samples(&mut self, min_samples: u32, stages: u8) -> bool {
        let count = self.sums.count;
        if count < u64::from(min_samples) {
            self.fail(
                Error::TooFewPoints {
                    got: count as usize,
                    need: min_samples as usize,
                },
                stages,
            );
            return false;
        }
        true
    }

    /// The degrees of freedom of σ with `params` parameters: the effective count of
    /// readings (the count, without forgetting) less the parameters. The refusal on the
    /// heading-error bound widens it by their Student-t factor, the report keeps the plain
    /// 3σ one, as the batch fits'.
    pub fn residual_dof(&self, params: usize) -> f64 {
        self.sums.effective_count() - params as f64
    }
}

/// The residual standard deviation σ of a fit of `P` parameters from the weighted residual
/// sum of squares `weighted_ss` (see [`sigma_kappa`]), and `L⁻¹` of its information matrix
/// scaled by `√κ`, so that `‖L⁻¹g‖²` is the variance factor of a gradient `g` directly.
/// `(∞, None)` when the readings do not outnumber the parameters.
pub(crate) fn noise_factor<const D: usize, const M: usize, const P: usize>(
    sums: &ConicSums<f64, D, M>,
    weighted_ss: f64,
    info: &SMatrix<f64, P, P>,
) -> (f64, Option<SMatrix<f64, P, P>>) {
    match sigma_kappa(weighted_ss, sums.weight(), sums.effective_count(), P) {
        Some((sigma, kappa)) => (sigma, inverse_factor(info).map(|l| l * kappa.sqrt())),
        None => (f64::INFINITY, None),
    }
}

/// The heading-error bound, degrees: [`BOUND_SIGMAS`]·σ times the square root of the worst
/// variance factor over the test directions (`None` without an information factor: ∞).
pub(crate) fn bound_deg(sigma: f64, worst: Option<f64>) -> f64 {
    match worst {
        Some(w) => {
            let b = (BOUND_SIGMAS * sigma * w.sqrt()).to_degrees();
            if b.is_finite() { b } else { f64::INFINITY }
        }
        None => f64::INFINITY,
    }
}

/// The quality report of a refresh, the direct fit's bias bound (radians) as its
/// systematic part.
pub(crate) fn report(
    fit: FitQuality,
    bound_deg: f64,
    bias_rad: f64,
    sigma: f64,
    field: f64,
    expected_field: Option<f64>,
    uncertainty: CompassUncertainty,
) -> CompassQuality {
    quality::with_expected_field(
        CompassQuality {
            fit,
            heading_error_3sigma_deg: bound_deg,
            heading_error_systematic_deg: bias_rad.to_degrees(),
            heading_noise_rms_deg: sigma.to_degrees(),
            field_magnitude: field,
            field_ratio_to_expected: None,
            uncertainty,
        },
        expected_field,
    )
}

/// The refusals that follow the coverage checks, in the order of the batch fits: the
/// residual (beyond `max_residual_rel`, an [`Error::NotAnEllipse`] with detail `stray`),
/// then the heading-error bound widened by the Student-t factor of σ's `dof` degrees of
/// freedom ([`quality::require_certain`]).
pub(crate) fn refuse_fit(
    q: &CompassQuality,
    max_residual_rel: f64,
    max_bound_deg: f64,
    dof: f64,
    stray: &'static str,
) -> Result<()> {
    if !(q.fit.residual_rms_rel <= max_residual_rel) {
        Err(Error::NotAnEllipse { detail: stray })
    } else {
        quality::require_certain(q, dof, max_bound_deg)
    }
}

/// The state and per-sample logic of an online conic calibrator (see the
/// `ellipse` module for the scheme), its sums and retained readings in `T`.
///
/// The per-sample path (the sums, the sorting of a reading into its slot) runs in `T`; a
/// refresh converts its copies of the sums and readings to `f64` (exact) and fits in
/// `f64` whatever `T` is, and its calibration is narrowed back to `T` to sort readings by.
#[derive(Debug, Clone)]
pub(crate) struct OnlineCore<T: Real, const D: usize, const M: usize, const N: usize, R>
where
    R: ConicRefresh<D, M, N>,
{
    pub config: R::Config,
    /// Per-reading weight factor and retained-reading lifetime, from the config.
    decay: T,
    lifetime: u64,
    sums: ConicSums<T, D, M>,
    slots: Retained<T, D, N>,
    /// The calibration retained readings are sorted by (`None` before the first refresh),
    /// and the same in `T`.
    map: Option<R::Cal>,
    map_in: Option<R::CalIn<T>>,
    estimate: Option<Solution<R::Cal>>,
    /// Sample count at which the next refresh starts.
    next_refresh: u64,
    pending: Option<R>,
}

impl<T: Real, const D: usize, const M: usize, const N: usize, R> OnlineCore<T, D, M, N, R>
where
    R: ConicRefresh<D, M, N>,
{
    /// A calibrator with the given configuration, or the first invalid parameter, named.
    pub fn new(config: R::Config) -> Result<Self> {
        config.validate()?;
        let (decay, lifetime) = forgetting(config.forgetting_half_life_samples());
        Ok(Self {
            config,
            decay: T::of(decay),
            lifetime,
            sums: ConicSums::new(),
            slots: Retained::new(),
            map: None,
            map_in: None,
            estimate: None,
            next_refresh: u64::from(config.min_samples()),
            pending: None,
        })
    }

    /// The stage a refresh in progress will run at the next push.
    pub fn refresh_stage(&self) -> Option<u8> {
        self.pending.as_ref().map(|r| r.base().stage)
    }

    /// A refresh of the current sums and retained readings, in `f64`.
    fn start(&self) -> R {
        R::start(&self.sums.widened(), &self.slots.widened())
    }

    /// Completes a finished refresh: adopts its sorting map (re-sorting the retained
    /// readings) and, if it succeeded, its estimate. Returns whether the estimate changed.
    fn publish(&mut self, r: R) -> bool {
        let RefreshBase { map, outcome, .. } = r.into_base();
        if let Some(m) = map {
            let m_in = R::narrow::<T>(&m);
            self.map = Some(m);
            self.map_in = Some(m_in);
            self.slots
                .rekey(|p| R::slot(&m_in, p), self.sums.count, self.lifetime);
        }
        match outcome {
            Some(Ok(sol)) if self.estimate != Some(sol) => {
                self.estimate = Some(sol);
                true
            }
            _ => false,
        }
    }

    /// See [`truenorth_core::Calibrator::push`] on the calibrators: the reading `mag` at
    /// time `t_s`.
    ///
    /// Inlined into the calibrators' pushes, which only convert the sample: one call per
    /// reading instead of two.
    #[inline(always)]
    pub fn push(&mut self, t_s: f64, mag: &SVector<T, D>) -> Result<Pushed> {
        // One test for the usual finite sample: `x · 0` is ±0 for a finite `x` and NaN for
        // an infinite or NaN one, so the sum is NaN exactly when something is not finite;
        // only then are the values checked one by one, for the refusal that names it.
        let probe = mag.iter().fold(t_s * 0.0, |acc, &x| acc + x.to_f64() * 0.0);
        if probe.is_nan() {
            check_finite("timestamp t_s", t_s)?;
            for &x in mag.iter() {
                check_finite("magnetometer reading", x.to_f64())?;
            }
        }
        R::add(&mut self.sums, mag, self.decay)?;
        let now = self.sums.count;
        if !self.slots.refuses_all(self.lifetime) {
            // Before the first refresh there is no calibration to sort by: the first
            // readings take the slots in order, and the first refresh sorts them.
            let slot = match &self.map_in {
                Some(m) => R::slot(m, mag),
                None => Some((now - 1) as usize),
            };
            if let Some(k) = slot {
                self.slots.offer(k, mag, now, self.lifetime);
            }
        }
        if self.pending.is_none() && now < self.next_refresh {
            return Ok(Pushed::Accepted);
        }
        Ok(self.advance_refresh(now))
    }

    /// Starts a refresh if none is running, runs its next stage, and publishes it once
    /// done; at `now` readings.
    ///
    /// Out of line: a refresh holds kilobytes, and inlined into [`OnlineCore::push`] it
    /// gave every push a frame of that size (stack probes, every register saved) for work
    /// that most pushes skip.
    #[inline(never)]
    fn advance_refresh(&mut self, now: u64) -> Pushed {
        if self.pending.is_none() {
            self.pending = Some(self.start());
            self.next_refresh = now + self.refresh_spacing(now);
        }
        let done = match &mut self.pending {
            Some(r) => r.step(&self.config, self.lifetime),
            None => false,
        };
        if done
            && let Some(r) = self.pending.take()
            && self.publish(r)
        {
            return Pushed::NewEstimate;
        }
        Pushed::Accepted
    }

    /// Readings from the start of one refresh, at `now` readings, to the start of the next:
    /// the configured interval, or 1/[`REFRESH_SHARE`] of the readings the sums weigh when
    /// that is longer (all of them; forgetting, those of the last half-life).
    fn refresh_spacing(&self, now: u64) -> u64 {
        let weighed = now.min(self.lifetime / 4);
        u64::from(self.config.refresh_interval_samples()).max(weighed / REFRESH_SHARE)
    }

    /// See [`truenorth_core::Calibrator::progress`] on the calibrators.
    pub fn progress(&self) -> Progress {
        let coverage = self
            .map
            .map(|m| R::coverage(&self.slots.widened(), self.sums.count, self.lifetime, &m))
            .unwrap_or(0.0);
        Progress {
            samples: self.sums.count as usize,
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    /// See [`truenorth_core::Calibrator::solve`] on the calibrators.
    pub fn solve(&self) -> Result<Solution<R::Cal>> {
        let mut r = self.start();
        while !r.step(&self.config, self.lifetime) {}
        r.into_base().outcome.unwrap_or(Err(R::NOT_READY))
    }

    /// Forgets every reading, keeping the configuration.
    pub fn reset(&mut self) {
        self.sums = ConicSums::new();
        self.slots = Retained::new();
        self.map = None;
        self.map_in = None;
        self.estimate = None;
        self.next_refresh = u64::from(self.config.min_samples());
        self.pending = None;
    }

    /// The latest refresh's successful solution.
    pub fn estimate(&self) -> Option<Solution<R::Cal>> {
        self.estimate
    }

    /// The saved state.
    pub fn state(&self) -> OnlineConicState<R::Config, R::Cal> {
        OnlineConicState {
            config: self.config,
            sums: self.sums.snapshot(),
            retained: self.slots.snapshot(),
            sorting: self.map,
            estimate: self.estimate,
            next_refresh: self.next_refresh,
            pending: self.pending.as_ref().map(|r| PendingRefresh {
                sums: r.base().sums.snapshot(),
                retained: r.base().slots.snapshot(),
                stage: r.base().stage,
            }),
        }
    }

    /// Back from a saved state, refusing one that this calibrator could not have written.
    /// A refresh in progress was saved in `f64` and is restored so, whatever `T` is.
    pub fn restore(s: OnlineConicState<R::Config, R::Cal>) -> Result<Self> {
        let mut cal = Self::new(s.config)?;
        cal.sums = ConicSums::restore(&s.sums)?;
        cal.slots = Retained::restore(&s.retained, cal.sums.count)?;
        if !s.sorting.as_ref().is_none_or(R::is_finite)
            || !s.estimate.as_ref().is_none_or(|e| R::is_finite(&e.params))
        {
            return Err(Error::InvalidSnapshot {
                reason: "a saved calibration is not finite",
            });
        }
        cal.map = s.sorting;
        cal.map_in = s.sorting.as_ref().map(R::narrow::<T>);
        cal.estimate = s.estimate;
        cal.next_refresh = s.next_refresh;
        if let Some(p) = s.pending {
            let sums = ConicSums::<f64, D, M>::restore(&p.sums)?;
            if sums.count > cal.sums.count || p.stage >= R::STAGES {
                return Err(Error::InvalidSnapshot {
                    reason: "the saved refresh does not fit the saved sums",
                });
            }
            let slots = Retained::<f64, D, N>::restore(&p.retained, sums.count)?;
            let mut r = R::start(&sums, &slots);
            while r.base().stage < p.stage && !r.step(&cal.config, cal.lifetime) {}
            if r.base().outcome.is_some() || r.base().stage != p.stage {
                return Err(Error::InvalidSnapshot {
                    reason: "the saved refresh had already finished",
                });
            }
            cal.pending = Some(r);
        }
        Ok(cal)
    }
}

/// The saved state of an online least-squares calibrator with configuration `C` fitting
/// calibration `P`: everything it learned and the refresh in progress, so a restored
/// calibrator continues bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OnlineConicState<C, P> {
    /// The configuration.
    pub config: C,
    /// The running sums.
    pub sums: SumsSnapshot,
    /// The retained readings for coverage.
    pub retained: RetainedSnapshot,
    /// The calibration retained readings are sorted by.
    pub sorting: Option<P>,
    /// The current estimate.
    pub estimate: Option<Solution<P>>,
    /// Sample count at which the next refresh starts.
    pub next_refresh: u64,
    /// A refresh in progress: its copy of the sums and retained readings, and how many of
    /// its stages have run (they are run again on restore, with the same result).
    pub pending: Option<PendingRefresh>,
}

/// A refresh in progress, as saved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PendingRefresh {
    /// The sums it works on.
    pub sums: SumsSnapshot,
    /// The retained readings it works on.
    pub retained: RetainedSnapshot,
    /// Stages run.
    pub stage: u8,
}
