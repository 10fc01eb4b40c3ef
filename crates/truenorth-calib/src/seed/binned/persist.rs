//! Saving and restoring a [`BinnedEllipseCalibrator`] exactly ([`Persistent`]): the
//! configuration, the bins, the origin and restart reference, the estimate, and any
//! full-set update in progress (as the bins it started from, how many pushes advanced it
//! and the readings that arrived since, so restoring replays it to the same point), and the
//! readings still waiting to be binned after an update was applied.

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::{CompassCalibration2d, EllipsePhasors};
use truenorth_core::{Error, Persistent, Result, Solution, Validate};

use crate::seed::binned::bins::{Bin, BinState, Bins, EMPTY, MAX_BINS};
use crate::seed::binned::calibrator::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, MAX_INIT_SAMPLES,
};
use crate::seed::binned::refresh::RefreshJob;
use crate::seed::binned::update::{
    ASSESS_PUSHES, MAX_UPDATE_PUSHES, REFRESH_STRIDE, Update, UpdatePhase,
};

/// A full-set update in progress, as saved (opaque).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BinnedUpdateState {
    start_bins: Vec<Bin>,
    start_origin: Vector2<f64>,
    budget: usize,
    stride: usize,
    advanced: usize,
    phase: UpdatePhase,
    assess_steps: usize,
    pending: Vec<Vector2<f64>>,
}

/// The saved state of a [`BinnedEllipseCalibrator`] ([`Persistent::State`]). Plain data
/// without infinities; the bins and any update in progress are opaque.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BinnedEllipseCalibratorState {
    /// The configuration.
    pub config: BinnedEllipseConfig,
    bins: Vec<Bin>,
    /// The origin of the bins.
    pub origin: Option<Vector2<f64>>,
    init: Vec<Vector2<f64>>,
    /// Readings pushed since the last (re)start.
    pub samples: usize,
    since_update: usize,
    reference: Vec<Option<Vector2<f64>>>,
    /// The parameters of the last completed update.
    pub phasors: Option<EllipsePhasors>,
    restored: bool,
    /// Restarts so far.
    pub restarts: usize,
    /// The current estimate.
    pub estimate: Option<Solution<CompassCalibration2d>>,
    update: Option<BinnedUpdateState>,
    backlog: Vec<Vector2<f64>>,
    /// Per bin, the readings counted towards the next update since the last one started
    /// (empty in a state saved before they were kept: all zero).
    #[serde(default)]
    counted: Vec<u32>,
    /// The same counts of the interval before the last update started (empty in a state
    /// saved before they were kept: all zero, so that the next reading of each bin replaces
    /// its stored one, as every reading did then).
    #[serde(default)]
    counted_before: Vec<u32>,
}

fn finite2(v: &Vector2<f64>) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

/// Bins from their saved form: exactly `n` of them, finite, with counts that fit their
/// state.
fn bins_from(saved: &[Bin], n: usize) -> Result<Bins> {
    if saved.len() != n {
        return Err(Error::InvalidSnapshot {
            reason: "the binned ellipse must save exactly its configured number of bins",
        });
    }
    let mut bins = [EMPTY; MAX_BINS];
    for (b, s) in bins.iter_mut().zip(saved) {
        let consistent = match s.state {
            BinState::Empty => s.count == 0,
            BinState::Measured => s.count > 0,
            BinState::Regenerated => true,
        };
        if !(finite2(&s.value) && consistent) {
            return Err(Error::InvalidSnapshot {
                reason: "a saved bin is not finite or its count does not fit its state",
            });
        }
        *b = *s;
    }
    Ok(bins)
}

impl Persistent for BinnedEllipseCalibrator {
    type State = BinnedEllipseCalibratorState;
    const SNAPSHOT_VERSION: u32 = 3;

    fn state(&self) -> BinnedEllipseCalibratorState {
        let n = self.config.bins;
        BinnedEllipseCalibratorState {
            config: self.config,
            bins: self.bins[..n].to_vec(),
            origin: self.origin,
            init: self.init[..self.init_count].to_vec(),
            samples: self.samples,
            since_update: self.since_update,
            reference: self.reference[..n].to_vec(),
            phasors: self.phasors,
            restored: self.restored,
            restarts: self.restarts,
            estimate: self.estimate,
            update: self.update.as_ref().map(|u| BinnedUpdateState {
                start_bins: u.start_bins[..n].to_vec(),
                start_origin: u.start_origin,
                budget: u.budget,
                stride: u.stride,
                advanced: u.advanced,
                phase: u.phase,
                assess_steps: u.assess_steps,
                pending: u.pending[..u.pending_len].to_vec(),
            }),
            backlog: self.backlog[..self.backlog_len].to_vec(),
            counted: self.counted_bins().to_vec(),
            counted_before: self.counted_before_bins().to_vec(),
        }
    }

    fn from_state(state: BinnedEllipseCalibratorState) -> Result<Self> {
        let s = state;
        s.config.validate()?;
        let n = s.config.bins;
        let mut c = Self::build(s.config);
        c.bins = bins_from(&s.bins, n)?;
        check_readings(&s, n)?;
        check_stage(&s, &c.bins[..n])?;
        c.origin = s.origin;
        c.init[..s.init.len()].copy_from_slice(&s.init);
        c.init_count = s.init.len();
        if c.origin.is_some() {
            c.floor_sq = super::calibrator::noise_floor_sq(&s.init);
        }
        for (saved, into) in [
            (&s.counted, &mut c.counted),
            (&s.counted_before, &mut c.counted_before),
        ] {
            match saved.len() {
                0 => {}
                len if len == n => into[..n].copy_from_slice(saved),
                _ => {
                    return Err(Error::InvalidSnapshot {
                        reason: "the binned ellipse must save a count for each of its bins",
                    });
                }
            }
        }
        c.samples = s.samples;
        c.since_update = s.since_update;
        c.reference[..n].copy_from_slice(&s.reference);
        c.phasors = s.phasors;
        c.restored = s.restored;
        c.restarts = s.restarts;
        c.estimate = s.estimate;
        check_backlog(&s)?;
        c.backlog[..s.backlog.len()].copy_from_slice(&s.backlog);
        c.backlog_len = s.backlog.len();
        if let Some(u) = s.update {
            let update = replay_update(u, &s.config, &c)?;
            c.update = Some(update);
        }
        Ok(c)
    }
}

/// A refusal of a damaged binned-ellipse state.
fn invalid<T>(reason: &'static str) -> Result<T> {
    Err(Error::InvalidSnapshot { reason })
}

/// Every saved reading finite and every array of its configured length.
fn check_readings(s: &BinnedEllipseCalibratorState, n: usize) -> Result<()> {
    if !(s.origin.iter().all(finite2)
        && s.init.iter().all(finite2)
        && s.reference.iter().flatten().all(finite2))
    {
        return invalid("a saved binned-ellipse reading is not finite");
    }
    if s.reference.len() != n || s.init.len() > MAX_INIT_SAMPLES {
        return invalid("the saved binned-ellipse arrays have the wrong length");
    }
    Ok(())
}

/// The origin, initial readings, bins, phasors and estimate of one stage of the method.
fn check_stage(s: &BinnedEllipseCalibratorState, bins: &[Bin]) -> Result<()> {
    // Before the origin exists the initial readings are being collected; after, they
    // were averaged and binned.
    let init_ok = match s.origin {
        None => s.init.len() < s.config.init_samples && s.init.len() == s.samples,
        // (Regenerated from stored parameters, it never collected any.)
        Some(_) => true,
    };
    if !init_ok
        || (s.origin.is_none()
            && (s.update.is_some() || bins.iter().any(|b| b.state != BinState::Empty)))
    {
        return invalid(
            "the saved binned-ellipse origin, initial readings and bins do not fit together",
        );
    }
    if let Some(p) = &s.phasors {
        p.validate()?;
    }
    if let Some(e) = &s.estimate
        && !(e.params.hard_iron.iter().chain(e.params.soft_iron.iter())).all(|x| x.is_finite())
    {
        return invalid("the saved binned-ellipse estimate is not finite");
    }
    Ok(())
}

/// Readings wait only after an update was applied, never during one.
fn check_backlog(s: &BinnedEllipseCalibratorState) -> Result<()> {
    if s.backlog.len() >= MAX_UPDATE_PUSHES
        || (!s.backlog.is_empty() && s.update.is_some())
        || !s.backlog.iter().all(finite2)
    {
        return invalid("the saved binned-ellipse waiting readings are inconsistent");
    }
    Ok(())
}

/// The update in progress rebuilt by replaying its pushes from the bins it started from
/// (the refresh job is not saved: replaying rebuilds it exactly), refused where the saved
/// counts cannot come from a real run.
fn replay_update(
    u: BinnedUpdateState,
    config: &BinnedEllipseConfig,
    c: &BinnedEllipseCalibrator,
) -> Result<Update> {
    let n = config.bins;
    let start_bins = bins_from(&u.start_bins, n)?;
    if !(finite2(&u.start_origin) && u.pending.iter().all(finite2)) {
        return invalid("a saved reading of the update in progress is not finite");
    }
    let bound = RefreshJob::work_bound(n, config.origin_iterations);
    if u.pending.len() >= MAX_UPDATE_PUSHES
        || u.advanced == 0
        || u.advanced > MAX_UPDATE_PUSHES
        || u.budget == 0
        || u.budget > bound
        || u.stride == 0
        || u.stride > REFRESH_STRIDE
    {
        return invalid("the saved update in progress is inconsistent");
    }
    let mut update = Update::start(start_bins, n, u.start_origin, config, u.budget, u.stride);
    update.pending[..u.pending.len()].copy_from_slice(&u.pending);
    update.pending_len = u.pending.len();
    // Replaying the pushes rebuilds the job exactly; an assessed update is assessed
    // again (the assessment is pure and what it reads has not changed since).
    for _ in 0..u.advanced {
        update.step_refresh();
    }
    let replayed = match u.phase {
        UpdatePhase::Refresh => UpdatePhase::Refresh,
        _ => UpdatePhase::Precheck,
    };
    if update.phase != replayed {
        return invalid("the saved update in progress does not match its phase");
    }
    // Precheck, the steps of the assessment, then the application: a saved update is
    // at most that many assessment pushes past its refresh.
    let mut left = ASSESS_PUSHES;
    while update.phase != u.phase
        || (u.phase == UpdatePhase::Assess && update.assess_steps < u.assess_steps)
    {
        if left == 0 {
            return invalid("the saved update in progress does not match its phase");
        }
        left -= 1;
        update.advance_assessment(&c.assessor());
    }
    if update.assess_steps != u.assess_steps {
        return invalid("the saved update in progress does not match its phase");
    }
    Ok(update)
}
