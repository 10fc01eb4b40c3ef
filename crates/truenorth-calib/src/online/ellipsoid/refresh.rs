//! A staged refresh of the [`crate::OnlineEllipsoidCalibrator`]'s estimate: the direct fit
//! of Li & Griffiths (2004) from a copy of the running sums and the retained readings, split
//! over several pushes (reduction, constrained minimum, ellipsoid), then coverage, the
//! information matrix, its condition by a Jacobi solver a few sweeps at a time, the
//! heading-error bound in chunks, and the refusals.
//!
//! This module holds the refresh's state, its stages' order ([`ConicRefresh::run_stage`])
//! and the last stage (report and refusals); the stages themselves live in `fit_stages`
//! (1–5) and `support_stages` (6 to the bound), the staged eigen-solver in `jacobi`.

use nalgebra::{SMatrix, SVector, Vector3};
use truenorth_compass::{CompassCalibration3d, CompassCalibration3dIn};
use truenorth_core::{Error, FitQuality, Real, Result, Solution};

use crate::fits::ellipsoid::config::ORIENTATION_HINT;
use crate::fits::ellipsoid::direct::{Ellipsoid, Reduced};
use crate::online::conic::{ConicRefresh, RefreshBase, bound_deg, refuse_fit, report};
use crate::online::conic_sums::{ConicSums, LAYOUT_3D, MONOMIALS_3D, Retained};
use crate::online::ellipsoid::config::OnlineEllipsoidConfig;
use crate::quality::{self, SPHERE_CELLS};

mod fit_stages;
mod jacobi;
mod support_stages;

use jacobi::Jacobi9;

/// Parameters of the direction-error model (centre 3, symmetric soft iron 6).
const PARAMS: usize = 9;
/// Entries of the upper triangle of a `PARAMS × PARAMS` matrix.
const UPPER: usize = PARAMS * (PARAMS + 1) / 2;

/// Test directions of the bound (a Fibonacci lattice, as the batch report), and how many a
/// refresh stage visits.
const BOUND_DIRECTIONS: usize = 256;
/// 16: each direction is visited for the bound and for the support's dilution.
const BOUND_CHUNK: usize = 16;

/// Stages of a refresh: pre-check, normalise, the direct fit in three (reduction, the
/// constrained minimum, the ellipsoid), coverage, information matrix, the support's in two
/// halves of the retained readings, its condition in sweeps of a Jacobi eigen-solver, the
/// bound in chunks, and the report.
const SUPPORT_FIRST_STAGE: u8 = 6;
const SUPPORT_STAGES: u8 = 2;
const JACOBI_FIRST_STAGE: u8 = SUPPORT_FIRST_STAGE + SUPPORT_STAGES;
const _: () = assert!(SPHERE_CELLS.is_multiple_of(SUPPORT_STAGES as usize));
const JACOBI_STAGES: u8 = 4;
/// Jacobi sweeps per stage (a sweep is 36 rotations of two rows and columns).
const SWEEPS_PER_STAGE: usize = 2;
const BOUND_FIRST_STAGE: u8 = JACOBI_FIRST_STAGE + JACOBI_STAGES;
pub(crate) const STAGES: u8 = BOUND_FIRST_STAGE + (BOUND_DIRECTIONS / BOUND_CHUNK) as u8 + 1;

/// What the refusal of a stray ellipsoid says.
const STRAY: &str =
    " (the readings stray from the best ellipsoid by more than max_residual_rel of the field)";

pub(crate) type Sums = ConicSums<f64, 3, MONOMIALS_3D>;
pub(crate) type Slots = Retained<f64, 3, SPHERE_CELLS>;
type Base = RefreshBase<3, MONOMIALS_3D, SPHERE_CELLS, CompassCalibration3d>;

/// The equal-area direction cell of `h` (as [`quality::sphere_coverage`]: bands uniform in
/// `z/|h|`, sectors of longitude). `None` at the centre or for non-finite values.
#[inline]
pub(crate) fn cell(h: &Vector3<f64>) -> Option<usize> {
    let n = h.norm();
    (n > 0.0 && n.is_finite()).then(|| quality::sphere_cell(h.x, h.y, h.z, n) as usize)
}

/// Share of the cells holding a live retained reading, seen through calibration `m`.
pub(crate) fn coverage_of(slots: &Slots, now: u64, lifetime: u64, m: &CompassCalibration3d) -> f64 {
    let mut filled = [0u64; SPHERE_CELLS.div_ceil(64)];
    for p in slots.live(now, lifetime) {
        if let Some(c) = cell(&m.correct(p)) {
            filled[c / 64] |= 1 << (c % 64);
        }
    }
    filled.iter().map(|w| w.count_ones()).sum::<u32>() as f64 / SPHERE_CELLS as f64
}

/// A refresh of the estimate (see the two-axis calibrator's for the scheme).
#[derive(Debug, Clone)]
pub(crate) struct Refresh {
    /// Its copies of the sums and retained readings, stage, sorting map and outcome.
    base: Base,
    scatter: SMatrix<f64, 10, 10>,
    centre: Vector3<f64>,
    scale: f64,
    ellipsoid: Option<Ellipsoid>,
    cal: CompassCalibration3d,
    field: f64,
    coverage: f64,
    residual_rms_rel: f64,
    info: SMatrix<f64, PARAMS, PARAMS>,
    /// The direct fit between its stages: the reduced scatter with the map back to the
    /// linear terms, then the quadric.
    reduced: Reduced,
    quadric: SVector<f64, 10>,
    jacobi: Jacobi9,
    condition: f64,
    sigma: f64,
    l_inv: Option<SMatrix<f64, PARAMS, PARAMS>>,
    worst: f64,
    /// The direct fit's bias bound, radians (see `crate::quality::direct_fit_bias_rad`).
    bias_rad: f64,
    /// The support's information matrix (upper triangle, row by row) while it is summed,
    /// then its inverse factor, its cells, and the worst of `trace(G A⁻¹ Gᵀ)` over the
    /// directions visited so far for it.
    support_sums: [f64; UPPER],
    support_l_inv: Option<SMatrix<f64, PARAMS, PARAMS>>,
    support_cells: usize,
    support_worst: f64,
}

impl Refresh {
    fn fail(&mut self, e: Error) {
        self.base.fail(e, STAGES);
    }

    /// Stage 0: too few readings.
    fn pre_check(&mut self, cfg: &OnlineEllipsoidConfig) {
        self.base.require_samples(cfg.min_samples, STAGES);
    }

    /// Last stage: the report and the refusals, in the order of the batch fit.
    fn finish(&mut self, cfg: &OnlineEllipsoidConfig) {
        let fit = FitQuality {
            points: self.base.sums.count as usize,
            coverage: self.coverage,
            residual_rms_rel: self.residual_rms_rel,
            condition: self.condition,
        };
        let bound = bound_deg(self.sigma, self.l_inv.map(|_| self.worst));
        let uncertainty = self.uncertainty();
        let quality = report(
            fit,
            bound,
            self.bias_rad,
            self.sigma,
            self.field,
            cfg.expected_field,
            uncertainty,
        );
        let checked = quality::require_determined(
            &uncertainty,
            3,
            cfg.limits.max_heading_error_bound_deg,
            ORIENTATION_HINT,
        )
        .and_then(|()| quality::require_linear(&uncertainty, self.sigma, cfg.max_noise_dilution))
        .and_then(|()| {
            refuse_fit(
                &quality,
                cfg.limits.max_residual_rel,
                cfg.limits.max_heading_error_bound_deg,
                self.base.residual_dof(PARAMS),
                STRAY,
            )
        });
        self.base.outcome = Some(checked.map(|()| Solution {
            params: self.cal,
            quality,
        }));
    }
}

impl ConicRefresh<3, MONOMIALS_3D, SPHERE_CELLS> for Refresh {
    type Config = OnlineEllipsoidConfig;
    type Cal = CompassCalibration3d;
    type CalIn<T: Real> = CompassCalibration3dIn<T>;
    const STAGES: u8 = STAGES;
    const NOT_READY: Error = Error::NotReady {
        what: "online ellipsoid solution",
        hint: "push readings of a tumble",
    };

    #[inline]
    fn add<T: Real>(
        sums: &mut ConicSums<T, 3, MONOMIALS_3D>,
        p: &Vector3<T>,
        decay: T,
    ) -> Result<()> {
        sums.add(&LAYOUT_3D, p, decay)
    }

    fn narrow<T: Real>(cal: &CompassCalibration3d) -> CompassCalibration3dIn<T> {
        cal.to_precision()
    }

    /// The calibrated reading in `T`, its cell found in `f64` (the cell's band and sector
    /// are comparisons on the direction, exact in either type up to the reading's own
    /// rounding); the cell of [`cell`], by comparisons (see [`quality::sphere_cell_of`]).
    #[inline]
    fn slot<T: Real>(cal: &CompassCalibration3dIn<T>, p: &Vector3<T>) -> Option<usize> {
        quality::sphere_cell_of(&cal.correct(p).map(T::to_f64)).map(|c| c as usize)
    }

    fn coverage(slots: &Slots, now: u64, lifetime: u64, cal: &CompassCalibration3d) -> f64 {
        coverage_of(slots, now, lifetime, cal)
    }

    fn is_finite(m: &CompassCalibration3d) -> bool {
        m.hard_iron
            .iter()
            .chain(m.soft_iron.iter())
            .all(|x| x.is_finite())
    }

    fn start(sums: &Sums, slots: &Slots) -> Self {
        Self {
            base: Base::new(sums, slots),
            scatter: SMatrix::zeros(),
            centre: Vector3::zeros(),
            scale: 1.0,
            ellipsoid: None,
            cal: CompassCalibration3d::identity(),
            field: 0.0,
            coverage: 0.0,
            residual_rms_rel: 0.0,
            info: SMatrix::zeros(),
            reduced: Reduced {
                m: SMatrix::zeros(),
                t: SMatrix::zeros(),
            },
            quadric: SVector::zeros(),
            jacobi: Jacobi9::new(&SMatrix::zeros()),
            condition: f64::INFINITY,
            sigma: f64::INFINITY,
            l_inv: None,
            bias_rad: 0.0,
            support_sums: [0.0; UPPER],
            support_l_inv: None,
            support_cells: 0,
            support_worst: 0.0,
            worst: 0.0,
        }
    }

    fn run_stage(&mut self, stage: u8, cfg: &OnlineEllipsoidConfig, lifetime: u64) {
        match stage {
            0 => self.pre_check(cfg),
            1 => {
                self.reduce_stage();
                self.explain_failure(cfg, lifetime);
            }
            2 => {
                self.constrained_stage();
                self.explain_failure(cfg, lifetime);
            }
            3 => {
                self.fit(cfg);
                self.explain_failure(cfg, lifetime);
            }
            4 => self.cover(lifetime),
            5 => self.inform(),
            s if s < JACOBI_FIRST_STAGE => {
                self.support(usize::from(s - SUPPORT_FIRST_STAGE), lifetime);
            }
            s if s < BOUND_FIRST_STAGE => self.condition(s == BOUND_FIRST_STAGE - 1),
            s if s < STAGES - 1 => self.bound_chunk(usize::from(s - BOUND_FIRST_STAGE)),
            _ => self.finish(cfg),
        }
    }

    fn base(&self) -> &Base {
        &self.base
    }

    fn base_mut(&mut self) -> &mut Base {
        &mut self.base
    }

    fn into_base(self) -> Base {
        self.base
    }
}
