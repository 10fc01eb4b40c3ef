//! The full-set update cycle of the binned ellipse calibrator (claims 1, 5, 12 then 7–9):
//! started on a copy of the bins, refreshed a slice per push, assessed, applied in one
//! push, and the readings that arrived meanwhile binned after it. Out of the push's file:
//! the push itself is the hot path, the cycle runs once an update interval.

use super::*;

impl BinnedEllipseCalibrator {
    /// Starts a full-set update on a copy of the bins, with the refresh spread evenly over
    /// the working pushes (every `stride`-th) among the first
    /// `min(update_interval, REFRESH_PUSHES)`. Out of line: it copies the bins, and the
    /// push that inlined it reserved the stack for them on every reading.
    #[inline(never)]
    pub(super) fn start_update(&mut self) {
        let Some(origin) = self.origin else { return };
        let n = self.config.bins;
        let span = self.config.update_interval.clamp(1, REFRESH_PUSHES);
        let stride = REFRESH_STRIDE.min(span);
        let working = span / stride;
        let bound = RefreshJob::work_bound(n, self.config.origin_iterations);
        self.update = Some(Update::start(
            self.bins,
            n,
            origin,
            &self.config,
            bound.div_ceil(working),
            stride,
        ));
    }

    /// Applies a finished, assessed update: its bins and origin, then the verdict (restart,
    /// or new parameters, reference and estimate), all in this one push so that what is
    /// published is always one update's; then bins the readings that arrived meanwhile
    /// (with `spread`, a bounded number of them now and the rest on the next pushes, see
    /// [`Self::drain`]). Returns whether the estimate changed.
    pub(super) fn complete_update(&mut self, mut u: Update, spread: bool) -> bool {
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
        // No backlog while an update is in progress, and a restart above cleared it anyway.
        self.backlog[..u.pending_len].copy_from_slice(&u.pending[..u.pending_len]);
        self.backlog_len = u.pending_len;
        self.drain(spread);
        self.estimate != before
    }

    /// Bins waiting readings in the order they arrived: with `spread`, at most
    /// `DRAIN_PER_PUSH` of them, else all. Binning them over several pushes gives exactly
    /// the bins of binning them at once as long as none of them starts the next update
    /// (the readings pushed meanwhile queue behind them, so the order is the same): each
    /// reading raises the count towards `update_interval` by at most one, so while the
    /// count plus the backlog is below it none can, and once it reaches it only the latest
    /// reading can, and all are binned in that push — exactly when the update would start
    /// if nothing had waited.
    #[inline(never)]
    pub(super) fn drain(&mut self, spread: bool) {
        let len = self.backlog_len;
        if len == 0 {
            return;
        }
        let all = !spread || self.since_update + len >= self.config.update_interval;
        let k = if all { len } else { len.min(DRAIN_PER_PUSH) };
        for i in 0..k {
            let p = self.backlog[i];
            self.ingest(p);
        }
        self.backlog.copy_within(k..len, 0);
        // Unused entries stay zero, so equal states compare equal.
        self.backlog[len - k..len].fill(Vector2::zeros());
        self.backlog_len = len - k;
    }

    /// Runs any update in progress to its end and applies it.
    pub(super) fn finish_update(&mut self) {
        self.drain(false);
        if let Some(u) = self.update.take() {
            self.complete_update(u, false);
        }
    }

    /// The update work of a push while a full-set update is in progress: one slice of the
    /// refresh (on working pushes), or the assessment, or the application — never two of
    /// them. Kept out of line: the update and its copy of the bins are large, and a push
    /// that inlined them reserved (and probed) their stack space on every reading.
    #[inline(never)]
    pub(super) fn advance_update(&mut self) -> Pushed {
        let Some(u) = self.update.as_mut() else {
            return Pushed::Accepted;
        };
        // The phase at the start of this push decides its work: one slice of the refresh
        // (on working pushes), or the assessment, or the application — never two of them.
        let phase = u.phase;
        u.step_refresh();
        let full = u.pending_len >= MAX_UPDATE_PUSHES;
        match phase {
            _ if full => {}
            UpdatePhase::Refresh => return Pushed::Accepted,
            UpdatePhase::Precheck | UpdatePhase::Assess => {
                let assessor = Assessor {
                    config: &self.config,
                    reference: &self.reference,
                    phasors: self.phasors.as_ref(),
                    samples: self.samples,
                };
                if let Some(u) = self.update.as_mut() {
                    u.advance_assessment(&assessor);
                }
                return Pushed::Accepted;
            }
            UpdatePhase::Apply => {}
        }
        let Some(u) = self.update.take() else {
            return Pushed::Accepted;
        };
        // The refresh ends within `REFRESH_PUSHES` and a few more pushes complete it, well
        // within the pending buffer; completing at once when it is full is a safeguard that
        // does not change the result.
        if self.complete_update(u, !full) {
            Pushed::NewEstimate
        } else {
            Pushed::Accepted
        }
    }
}
