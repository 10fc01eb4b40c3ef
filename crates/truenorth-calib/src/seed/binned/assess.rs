//! The assessment of a finished full-set update of the binned ellipse: the restart check
//! (EP 0634001 claim 15) and the acceptance tests a solve applies (arc about the origin,
//! the locus's own turning, residual), on any set of bins. It reads only what stays fixed
//! while an update is in progress (the configuration, the restart reference and the
//! sample count), so an update can be assessed over a few pushes (the quality report in
//! the bounded steps of [`SeedJob`], then its completion by the least-squares fit of the
//! same readings, `fit_gap`) and applied in the next.

use nalgebra::Vector2;
use truenorth_compass::{CompassCalibration2d, EllipsePhasors};
use truenorth_core::{Error, Result, Solution};

use crate::quality::{Assessment2d, locus_turning_rad, require_arc, require_certain};
use crate::seed::binned::bins::{BinState, Bins, MAX_BINS, filled};
use crate::seed::binned::config::BinnedEllipseConfig;
use crate::seed::binned::refresh::RefreshJob;
use crate::seed::fit_gap::complete_bound;
use crate::seed::seed_quality::{SeedJob, seed_assessment};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// How many times the change that noise alone makes a restart needs (see
/// `Assessor::precheck`): 2. The squared RMS change over `n` bins is a χ² with `2n` degrees
/// of freedom over `2n`; with the 16 bins or more an update needs, twice its expectation
/// in RMS (four times in square) has a chance below 10⁻¹⁰ (found necessary by
/// `tests/more_data.rs`: at 7 % noise the default threshold of 10 % of the field restarted
/// a good calibration on every update).
const RESTART_NOISE_MULTIPLE: f64 = 2.0;

/// What an assessed update will do when applied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verdict {
    /// The refresh failed (e.g. a degenerate set mid-turn): bins and origin are taken, the
    /// parameters and estimate kept; the next update retries.
    Failed,
    /// The locus moved (claim 15): calibration restarts.
    Restart(EllipsePhasors),
    /// New parameters, and the estimate they give (`None` if the acceptance tests refuse).
    Accept(EllipsePhasors, Option<Solution<CompassCalibration2d>>),
}

/// The first half of an assessment: the restart check and the locus's own turning (the
/// second half, the quality report and the remaining acceptance tests, costs as much again).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Precheck {
    /// The refresh failed.
    Failed,
    /// The locus moved (claim 15).
    Restart(EllipsePhasors),
    /// New parameters, and how far the locus turns along the bins, degrees.
    Turned(EllipsePhasors, f64),
}

/// What the assessment reads of a calibrator.
pub(crate) struct Assessor<'a> {
    pub config: &'a BinnedEllipseConfig,
    pub reference: &'a [Option<Vector2<f64>>; MAX_BINS],
    /// The parameters in use, taken with the reference.
    pub phasors: Option<&'a EllipsePhasors>,
    pub samples: usize,
}

impl Assessor<'_> {
    /// What a finished refresh will do (the restart check of claim 15, the acceptance
    /// tests on its bins). Pure: reads only what stays fixed while an update is in
    /// progress (the reference, the sample count, the configuration).
    pub(crate) fn assess(&self, job: &RefreshJob) -> Verdict {
        self.conclude(job, self.precheck(job))
    }

    /// The first half of [`Self::assess`].
    pub(crate) fn precheck(&self, job: &RefreshJob) -> Precheck {
        match job.result {
            Some(Ok(params)) => {
                // Noise alone moves single readings: two of them in one bin differ by a
                // vector of RMS 2σ (relative to the field, σ per axis), so the RMS change
                // over the bins is about 2σ with no change of the locus. A restart needs
                // RESTART_NOISE_MULTIPLE times that as well as the configured threshold,
                // σ taken from the reference (the new set may hold the change itself).
                let threshold = self
                    .config
                    .restart_threshold
                    .max(RESTART_NOISE_MULTIPLE * 2.0 * self.reference_noise());
                if self
                    .change_since_reference(&job.bins, params.earth_magnitude)
                    .is_some_and(|change| change > threshold)
                {
                    Precheck::Restart(params)
                } else {
                    let turned_deg = self
                        .measured_turning_rad(&job.bins, params.earth_magnitude.abs())
                        .to_degrees();
                    Precheck::Turned(params, turned_deg)
                }
            }
            _ => Precheck::Failed,
        }
    }

    /// The second half of [`Self::assess`], given its first.
    pub(crate) fn conclude(&self, job: &RefreshJob, pre: Precheck) -> Verdict {
        match pre {
            Precheck::Failed => Verdict::Failed,
            Precheck::Restart(params) => Verdict::Restart(params),
            Precheck::Turned(params, turned_deg) => Verdict::Accept(
                params,
                self.accept_turned(&job.bins, &params, turned_deg).ok(),
            ),
        }
    }

    /// The acceptance tests and the report of a solution with `params` on the current bins.
    pub(crate) fn accept(
        &self,
        bins: &Bins,
        params: &EllipsePhasors,
    ) -> Result<Solution<CompassCalibration2d>> {
        let turned_deg = self
            .measured_turning_rad(bins, params.earth_magnitude.abs())
            .to_degrees();
        self.accept_turned(bins, params, turned_deg)
    }

    /// [`Self::accept`] with the locus's turning already measured.
    fn accept_turned(
        &self,
        bins: &Bins,
        params: &EllipsePhasors,
        turned_deg: f64,
    ) -> Result<Solution<CompassCalibration2d>> {
        let job = self.seed_job(bins, params);
        let a = complete_bound(
            seed_assessment(
                job.points(),
                job.calibration(),
                job.field(),
                job.samples_used(),
            ),
            job.points(),
            job.calibration(),
        );
        self.judge(&a, job.calibration(), turned_deg, job.points().len())
    }

    /// The quality report of a solution with `params` on `bins`, not yet run (see
    /// [`SeedJob`]): it reads the bins holding readings.
    pub(crate) fn seed_job(&self, bins: &Bins, params: &EllipsePhasors) -> SeedJob {
        let cal = params.to_calibration();
        let n = self.config.bins;
        let mut pts = [Vector2::zeros(); MAX_BINS];
        let mut k = 0;
        for b in bins[..n].iter().filter(|b| b.state != BinState::Empty) {
            pts[k] = b.value;
            k += 1;
        }
        SeedJob::start(&pts[..k], &cal, params.earth_magnitude, self.samples)
    }

    /// The acceptance tests on the report `a` of `cal` from `bins_used` bins, given the
    /// locus's turning.
    pub(crate) fn judge(
        &self,
        a: &Assessment2d,
        cal: &CompassCalibration2d,
        turned_deg: f64,
        bins_used: usize,
    ) -> Result<Solution<CompassCalibration2d>> {
        require_arc(
            &a.coverage,
            a.quality.heading_noise_rms_deg.to_radians(),
            self.config.min_arc_deg,
        )?;
        // The arc above is seen from the method's own origin, which a short arc pulls towards
        // itself (so the arc looks longer than it is); the locus's own turning cannot be
        // fooled that way.
        if turned_deg < self.config.min_arc_deg {
            return Err(Error::InsufficientCoverage {
                covered_deg: turned_deg.floor(),
                noise_deg: 0.0,
                need_deg: self.config.min_arc_deg,
            });
        }
        // NaN residuals are refused too.
        if a.quality.fit.residual_rms_rel.is_nan()
            || a.quality.fit.residual_rms_rel > self.config.max_residual_rel
        {
            return Err(Error::NotAnEllipse {
                detail: " (the binned readings scatter by more than max_residual_rel about the fitted ellipse)",
            });
        }
        // The bound comes from the binned readings: their count less the five parameters
        // is the residual's degrees of freedom.
        require_certain(
            &a.quality,
            bins_used as f64 - 5.0,
            self.config.max_heading_error_bound_deg,
        )?;
        Ok(Solution {
            params: *cal,
            quality: a.quality,
        })
    }

    /// The per-axis noise of a single reading, relative to the field: the RMS radial
    /// residual of the reference's readings about the parameters taken with it (0 when
    /// there are none, or too few readings to say).
    fn reference_noise(&self) -> f64 {
        let Some(params) = self.phasors else {
            return 0.0;
        };
        let cal = params.to_calibration();
        let field = params.earth_magnitude.abs();
        let (mut ss, mut k) = (0.0, 0usize);
        for r in self.reference[..self.config.bins].iter().flatten() {
            let res = cal.correct(r).norm() / field - 1.0;
            if res.is_finite() {
                ss += res * res;
                k += 1;
            }
        }
        // Five parameters were fitted to these readings.
        if k > 5 {
            (ss / (k - 5) as f64).sqrt()
        } else {
            0.0
        }
    }

    /// RMS change of the bins filled now and in the reference, relative to `|E_L|`, when
    /// both cover at least `monitor_from_fraction` of the bins.
    fn change_since_reference(&self, bins: &Bins, e_l: f64) -> Option<f64> {
        let n = self.config.bins;
        let need = self.config.monitor_from_fraction * n as f64;
        let ref_filled = self.reference[..n].iter().filter(|r| r.is_some()).count();
        if (ref_filled as f64) < need || (filled(bins, n) as f64) < need {
            return None;
        }
        let (mut ss, mut k) = (0.0, 0usize);
        for (r, b) in self.reference[..n].iter().zip(&bins[..n]) {
            if let (Some(r), true) = (r, b.state != BinState::Empty) {
                ss += (b.value - r).norm_squared();
                k += 1;
            }
        }
        (k > 0 && e_l > 0.0).then(|| (ss / k as f64).sqrt() / e_l)
    }

    /// How far the tangent of the locus turns along the bins holding readings (measured or
    /// regenerated from a verified calibration), walked in bin order from just after the
    /// longest run of empty bins so that no chord cuts across the locus.
    fn measured_turning_rad(&self, bins: &Bins, field: f64) -> f64 {
        let n = self.config.bins;
        let has_reading = |i: usize| bins[i % n].state != BinState::Empty;
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
                .map(|i| &bins[i].value),
            0.25 * field,
        )
    }
}
