//! A binned-ellipse full-set update in progress and its schedule: the refresh on a copy of
//! the bins, advanced by one bounded slice on every few pushes, then its assessment over a few
//! pushes (one bounded step each) and its application in one, with the readings that arrive meanwhile kept for
//! binning when it is applied (so the published estimate is always one update's).

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::quality::Assessment2d;
use crate::seed::binned::assess::{Assessor, Precheck, Verdict};
use crate::seed::binned::bins::Bins;
use crate::seed::binned::config::BinnedEllipseConfig;
use crate::seed::binned::refresh::RefreshJob;
use crate::seed::fit_gap::complete_bound;
use crate::seed::seed_quality::SeedJob;

/// Most readings kept while a full-set update is in progress (they are binned when it
/// completes).
pub const MAX_UPDATE_PUSHES: usize = 128;

/// Most pushes the refresh of a full-set update is spread over; its assessment and its
/// application take `ASSESS_PUSHES` pushes after it, so at most
/// `REFRESH_PUSHES + ASSESS_PUSHES` readings wait.
pub(crate) const REFRESH_PUSHES: usize = 96;

/// Pushes from the end of a refresh to the application of its update: the precheck, the
/// [`SeedJob::STEPS`] of the report, its completion by the least-squares fit of the same
/// readings (`fit_gap`), and the application.
pub(crate) const ASSESS_PUSHES: usize = 3 + SeedJob::STEPS;

/// Most waiting readings binned per push once an update is applied (the rest wait for the
/// next pushes; at most `MAX_UPDATE_PUSHES` wait, so they are all binned within
/// `MAX_UPDATE_PUSHES / (DRAIN_PER_PUSH - 1)` pushes).
pub(crate) const DRAIN_PER_PUSH: usize = 16;

/// A refresh advances on every `REFRESH_STRIDE`-th push only, so that most pushes do no
/// refresh work at all (and cost what binning one reading costs).
pub(crate) const REFRESH_STRIDE: usize = 2;

/// Where a full-set update stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum UpdatePhase {
    /// The refresh job advances by one slice every `stride` pushes.
    Refresh,
    /// The refresh is over; the next push checks for a restart and measures the locus's
    /// turning.
    Precheck,
    /// The next pushes complete the assessment: the quality report, one bounded step per
    /// push, its completion by the least-squares fit of the same readings, then the
    /// acceptance tests.
    Assess,
    /// The result is assessed; the next push applies it and bins the readings that waited.
    Apply,
}

/// A full-set update in progress: the job on its copy of the bins, the bins and origin it
/// started from (so that a saved state can replay it exactly), its work per working push
/// and their spacing, how many pushes it has seen, its phase (and, once assessed, its
/// verdict), and the readings that arrived since it started.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Update {
    pub job: RefreshJob,
    pub start_bins: Bins,
    pub start_origin: Vector2<f64>,
    pub budget: usize,
    pub stride: usize,
    pub advanced: usize,
    pub phase: UpdatePhase,
    pub precheck: Option<Precheck>,
    pub verdict: Option<Verdict>,
    /// The quality report in progress (phase `Assess`), and the pushes of that phase so far.
    pub seed: Option<SeedJob>,
    /// The finished report of `seed`, before its completion by `fit_gap` (the next push).
    pub report: Option<Assessment2d>,
    pub assess_steps: usize,
    pub pending: [Vector2<f64>; MAX_UPDATE_PUSHES],
    pub pending_len: usize,
}

impl Update {
    /// An update that has seen no push yet: its refresh job started on `bins` (the first
    /// `n` used) about `origin`, doing `budget` work per working push every `stride` pushes.
    pub(crate) fn start(
        bins: Bins,
        n: usize,
        origin: Vector2<f64>,
        config: &BinnedEllipseConfig,
        budget: usize,
        stride: usize,
    ) -> Self {
        Self {
            job: RefreshJob::start(
                &bins,
                n,
                &origin,
                config.origin_iterations,
                config.min_filled_bins,
            ),
            start_bins: bins,
            start_origin: origin,
            budget,
            stride,
            advanced: 0,
            phase: UpdatePhase::Refresh,
            precheck: None,
            verdict: None,
            seed: None,
            report: None,
            assess_steps: 0,
            pending: [Vector2::zeros(); MAX_UPDATE_PUSHES],
            pending_len: 0,
        }
    }

    /// The assessment's share of a push: its first half in phase `Precheck`, its second in
    /// phase `Assess`.
    pub(crate) fn advance_assessment(&mut self, assessor: &Assessor<'_>) {
        match self.phase {
            UpdatePhase::Precheck => {
                self.precheck = Some(assessor.precheck(&self.job));
                self.phase = UpdatePhase::Assess;
            }
            UpdatePhase::Assess => {
                let pre = match self.precheck {
                    Some(p) => p,
                    None => assessor.precheck(&self.job),
                };
                self.assess_steps += 1;
                match pre {
                    Precheck::Turned(params, turned_deg) => {
                        let bins = &self.job.bins;
                        let seed = self
                            .seed
                            .get_or_insert_with(|| assessor.seed_job(bins, &params));
                        // The report's steps, then its completion (one more push), then
                        // the verdict.
                        match self.report.take() {
                            None => self.report = seed.step(),
                            Some(a) => {
                                let a = complete_bound(a, seed.points(), seed.calibration());
                                let estimate = assessor
                                    .judge(&a, seed.calibration(), turned_deg, seed.points().len())
                                    .ok();
                                self.verdict = Some(Verdict::Accept(params, estimate));
                                self.seed = None;
                                self.phase = UpdatePhase::Apply;
                            }
                        }
                    }
                    other => {
                        self.verdict = Some(assessor.conclude(&self.job, other));
                        self.phase = UpdatePhase::Apply;
                    }
                }
            }
            UpdatePhase::Refresh | UpdatePhase::Apply => {}
        }
    }

    /// One push's share of the work: advances the refresh on every `stride`-th push. The
    /// assessment and application are the calibrator's, which owns the state they read.
    /// (Replaying `advanced` pushes through this rebuilds a saved update exactly.)
    pub(crate) fn step_refresh(&mut self) {
        self.advanced += 1;
        if self.phase == UpdatePhase::Refresh
            && self.advanced.is_multiple_of(self.stride)
            && self.job.advance(self.budget)
        {
            self.phase = UpdatePhase::Precheck;
        }
    }
}
