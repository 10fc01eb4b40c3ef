//! A staged refresh of the [`crate::OnlineEllipsoidCalibrator`]'s estimate: the direct fit
//! of Li & Griffiths (2004) from a copy of the running sums and the retained readings, split
//! over several pushes (reduction, constrained minimum, ellipsoid), then coverage, the
//! information matrix, its condition by a Jacobi solver a few sweeps at a time, the
//! heading-error bound in chunks, and the refusals.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{Error, FitQuality, Mag3Sample, Result, Solution};

use crate::fits::ellipsoid::direct::{
    Ellipsoid, Reduced, constrained_quadric, quadric_to_ellipsoid, reduce, second_moments,
};

use crate::fits::ellipsoid::config::ORIENTATION_HINT;
use crate::numerics::linalg::{condition_from_eigenvalues, sym_eigen3};
use crate::online::conic_sums::inverse_factor;
use crate::online::conic_sums::{ConicSums, LAYOUT_3D, MONOMIALS_3D, Retained};
use crate::quality::CompassUncertainty;
use crate::quality::{self, SPHERE_CELLS};

use crate::online::conic::{
    ConicRefresh, RefreshBase, bound_deg, direct_fit_bias_rad, noise_factor, refuse_fit, report,
};
use crate::online::ellipsoid_config::OnlineEllipsoidConfig;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

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

pub(crate) type Sums = ConicSums<3, MONOMIALS_3D>;
pub(crate) type Slots = Retained<3, SPHERE_CELLS>;
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

/// Eigenvalues of a symmetric 9×9 matrix by the cyclic Jacobi method (Golub & Van Loan,
/// *Matrix Computations*, 4th ed., §8.5.2–8.5.3), one sweep of the 36 rotations at a time, so
/// that a refresh can spread the work over several pushes. Each rotation zeroes one
/// off-diagonal pair; a sweep that finds nothing above rounding to rotate ends it.
#[derive(Debug, Clone, Copy)]
struct Jacobi9 {
    a: SMatrix<f64, PARAMS, PARAMS>,
    sweeps: u32,
    /// `None` while running; `Some(true)` converged, `Some(false)` failed (non-finite).
    state: Option<bool>,
}

/// Most sweeps before the Jacobi solver gives up (it converges quadratically: a 9×9 matrix
/// needs well under ten).
const JACOBI_MAX_SWEEPS: u32 = 50;

impl Jacobi9 {
    fn new(m: &SMatrix<f64, PARAMS, PARAMS>) -> Self {
        let finite = m.iter().all(|x| x.is_finite());
        Self {
            a: (m + m.transpose()) * 0.5,
            sweeps: 0,
            state: (!finite).then_some(false),
        }
    }

    /// One sweep; returns whether the solver has ended (converged or failed).
    fn sweep(&mut self) -> bool {
        if self.state.is_some() {
            return true;
        }
        if self.sweeps >= JACOBI_MAX_SWEEPS {
            self.state = Some(false);
            return true;
        }
        self.sweeps += 1;
        let a = &mut self.a;
        let mut rotated = false;
        for p in 0..PARAMS - 1 {
            for q in p + 1..PARAMS {
                let apq = a[(p, q)];
                // Negligible against both diagonal entries: rounding level, leave it.
                if apq == 0.0
                    || apq.abs() <= f64::EPSILON * 0.5 * (a[(p, p)].abs() * a[(q, q)].abs()).sqrt()
                {
                    a[(p, q)] = 0.0;
                    a[(q, p)] = 0.0;
                    continue;
                }
                rotated = true;
                let tau = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = t * c;
                for k in 0..PARAMS {
                    let (akp, akq) = (a[(k, p)], a[(k, q)]);
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..PARAMS {
                    let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                a[(p, q)] = 0.0;
                a[(q, p)] = 0.0;
            }
        }
        if !a.iter().all(|x| x.is_finite()) {
            self.state = Some(false);
        } else if !rotated {
            self.state = Some(true);
        }
        self.state.is_some()
    }

    /// Sweeps to the end; returns whether it converged.
    fn finish(&mut self) -> bool {
        while !self.sweep() {}
        self.state == Some(true)
    }

    /// The eigenvalues in ascending order, once converged.
    fn ascending(&self) -> Option<SVector<f64, PARAMS>> {
        if self.state != Some(true) {
            return None;
        }
        let mut l = self.a.diagonal();
        l.as_mut_slice().sort_unstable_by(f64::total_cmp);
        Some(l)
    }
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
    /// The direct fit's bias bound, radians (see `crate::online::conic::direct_fit_bias_rad`).
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

    /// After a stage of the fit: a fit that failed on readings that, seen from the centre
    /// of their bounding box, fill less than [`OnlineEllipsoidConfig::min_coverage`] of the
    /// direction cells is better explained by that (a turn about one axis, a small patch of
    /// orientations) than by the symptom (a hyperboloid, a flat quadric). Explains; never
    /// refuses a fit that succeeded, so more readings cannot turn into a refusal here.
    fn explain_failure(&mut self, cfg: &OnlineEllipsoidConfig, lifetime: u64) {
        if !matches!(
            self.base.outcome,
            Some(Err(Error::NotAnEllipse { .. } | Error::Degenerate { .. }))
        ) {
            return;
        }
        let now = self.base.sums.count;
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in self.base.slots.live(now, lifetime) {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let centre = (lo + hi) * 0.5;
        let pre = quality::sphere_coverage(self.base.slots.live(now, lifetime), &centre);
        if let Err(e) = quality::require_sphere_coverage(pre, cfg.min_coverage) {
            self.base.map = Some(CompassCalibration3d {
                hard_iron: centre,
                soft_iron: Matrix3::identity(),
            })
            .filter(|m| m.hard_iron.iter().all(|x| x.is_finite()));
            self.base.outcome = Some(Err(e));
        }
    }

    /// Normalise; refuse equal and coplanar readings (the start of stage 1).
    fn normalise(&mut self) {
        let Some((s, centre, scale)) = self.base.sums.normalised(&LAYOUT_3D) else {
            return self.fail(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            });
        };
        (self.scatter, self.centre, self.scale) = (s, centre, scale);
        let cov = second_moments(&s, self.base.sums.weight());
        match sym_eigen3(&cov) {
            None => self.fail(Error::Degenerate {
                reason: "the readings could not be analysed",
            }),
            Some((l, _)) if l[0] <= 1e-12 => self.fail(Error::Degenerate {
                reason: "the readings lie in a plane (or on a line); tumble the sensor about more than one axis",
            }),
            Some(_) => {}
        }
    }

    /// Stage 1: normalise, then the first step of the direct fit ([`reduce`]): eliminate the
    /// linear terms and refuse a hyperboloid.
    fn reduce_stage(&mut self) {
        self.normalise();
        if self.base.outcome.is_some() {
            return;
        }
        match reduce(&self.scatter) {
            Ok(r) => self.reduced = r,
            Err(e) => self.fail(e),
        }
    }

    /// Stage 2: the constrained minimum of the direct fit ([`constrained_quadric`]).
    fn constrained_stage(&mut self) {
        match constrained_quadric(&self.reduced) {
            Ok(k) => self.quadric = k,
            Err(e) => self.fail(e),
        }
    }

    /// Stage 3: the ellipsoid of the quadric and its calibration.
    fn fit(&mut self, cfg: &OnlineEllipsoidConfig) {
        let e = match quadric_to_ellipsoid(&self.quadric, cfg.limits.max_axis_ratio) {
            Ok(e) => e,
            Err(err) => return self.fail(err),
        };
        let raw = Ellipsoid {
            centre: self.centre + e.centre * self.scale,
            unit_map: e.unit_map / self.scale,
        };
        let (cal, field) = raw.calibration();
        if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
            return self.fail(Error::Degenerate {
                reason: "the fitted ellipsoid is not finite; check the input scale",
            });
        }
        self.ellipsoid = Some(e);
        (self.cal, self.field) = (cal, field);
        self.base.map = Some(cal);
    }

    /// Stage 4: coverage of the calibrated directions.
    fn cover(&mut self, lifetime: u64) {
        self.coverage = coverage_of(&self.base.slots, self.base.sums.count, lifetime, &self.cal);
    }

    /// Stage 5: residual and information matrix from the scatter of the calibrated
    /// readings' design vector (see the two-axis module), and its inverse factor.
    fn inform(&mut self) {
        let Some(e) = self.ellipsoid else { return };
        let t = LAYOUT_3D.design_map(&e.unit_map, &(-(e.unit_map * e.centre)));
        let su = t * self.scatter * t.transpose();
        let mut k0 = SVector::<f64, 10>::zeros();
        (k0[0], k0[1], k0[2], k0[9]) = (1.0, 1.0, 1.0, -1.0);
        let ss = 0.25 * (k0.transpose() * su * k0)[0].max(0.0);
        let w = self.base.sums.weight();
        self.residual_rms_rel = (ss / w).sqrt();
        // φ(u) = (−u, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²) = P ξ(u), with
        // ξ(u) = (u_x², u_y², u_z², 2u_yu_z, 2u_xu_z, 2u_xu_y, 2u_x, 2u_y, 2u_z, 1).
        let mut p = SMatrix::<f64, PARAMS, 10>::zeros();
        for (row, (col, f)) in [
            (6, -0.5),
            (7, -0.5),
            (8, -0.5),
            (0, 1.0),
            (5, 1.0),
            (4, 1.0),
            (1, 1.0),
            (3, 1.0),
            (2, 1.0),
        ]
        .into_iter()
        .enumerate()
        {
            p[(row, col)] = f;
        }
        let info = p * su * p.transpose();
        self.info = (info + info.transpose()) * 0.5;
        (self.sigma, self.l_inv) = noise_factor(&self.base.sums, ss, &self.info);
        // The design vector's sums, (Σx², Σy², Σz², 2Σyz, 2Σxz, 2Σxy, 2Σx, 2Σy, 2Σz, Σ1) of
        // the calibrated directions: their harmonics (h₂ the distance of their second
        // moment from I/3, over √(2/3), its value for readings all in one direction), and
        // the anisotropy of B².
        let c = su.column(9);
        let n = c[9];
        let h1 = Vector3::new(c[6], c[7], c[8]).norm() / (2.0 * n);
        let m = Matrix3::new(
            c[0],
            0.5 * c[5],
            0.5 * c[4],
            0.5 * c[5],
            c[1],
            0.5 * c[3],
            0.5 * c[4],
            0.5 * c[3],
            c[2],
        ) / n
            - Matrix3::identity() / 3.0;
        let h2 = m.norm() / (2.0f64 / 3.0).sqrt();
        let kappa = sym_eigen3(&(e.unit_map * e.unit_map)).map_or(1.0, |(l, _)| {
            let (hi, lo) = (l.max(), l.min());
            ((hi - lo) / (hi + lo)).abs()
        });
        self.bias_rad = direct_fit_bias_rad(self.sigma, kappa, h1, h2);
    }

    /// Stages 6–7: the information matrix of the support (see `crate::quality`'s `support`
    /// module): the live retained readings, one per direction cell, each counted once, so
    /// that its condition and dilution say what the orientations determine, whatever the
    /// time spent in each; half of the cells per stage, the upper triangle only. The last
    /// starts the Jacobi solver on it and keeps its inverse factor.
    fn support(&mut self, half: usize, lifetime: u64) {
        let now = self.base.sums.count;
        let cells = SPHERE_CELLS / SUPPORT_STAGES as usize;
        for j in half * cells..(half + 1) * cells {
            if !self.base.slots.is_live(j, now, lifetime) {
                continue;
            }
            let h = self.cal.correct(&self.base.slots.reading[j]);
            let rho = h.norm();
            if !(rho > 0.0 && rho.is_finite()) {
                continue;
            }
            let phi = quality::regressor_3d(&(h / rho));
            let mut k = 0;
            for r in 0..PARAMS {
                for c in r..PARAMS {
                    self.support_sums[k] += phi[r] * phi[c];
                    k += 1;
                }
            }
            self.support_cells += 1;
        }
        if half + 1 == SUPPORT_STAGES as usize {
            let mut a = SMatrix::<f64, PARAMS, PARAMS>::zeros();
            let mut k = 0;
            for r in 0..PARAMS {
                for c in r..PARAMS {
                    (a[(r, c)], a[(c, r)]) = (self.support_sums[k], self.support_sums[k]);
                    k += 1;
                }
            }
            self.jacobi = Jacobi9::new(&a);
            self.support_l_inv = (self.support_cells >= PARAMS)
                .then(|| inverse_factor(&a))
                .flatten();
        }
    }

    /// Stages 8–11: condition number of the support's information matrix, a few Jacobi
    /// sweeps per stage (the last stage finishes the solver should it not have converged).
    fn condition(&mut self, last: bool) {
        let converged = if last {
            self.jacobi.finish()
        } else {
            (0..SWEEPS_PER_STAGE).any(|_| self.jacobi.sweep())
        };
        if converged || last {
            self.condition = self
                .jacobi
                .ascending()
                .map(|l| condition_from_eigenvalues(l.as_slice()))
                .unwrap_or(f64::INFINITY);
        }
    }

    /// Stages 12–27: the worst of `trace(G A⁻¹ Gᵀ)` over 16 of the lattice directions,
    /// `G(u)` the Jacobian of the direction error `(I − uuᵀ)(E u − d)` (see
    /// `crate::quality`), for the bound (`A` of every reading) and for the support's
    /// dilution.
    fn bound_chunk(&mut self, chunk: usize) {
        let Some(l) = self.l_inv else { return };
        let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
        for k in chunk * BOUND_CHUNK..(chunk + 1) * BOUND_CHUNK {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / BOUND_DIRECTIONS as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            let u = Vector3::new(r * c, r * s, z);
            let proj = Matrix3::identity() - u * u.transpose();
            let mut g = SMatrix::<f64, 3, PARAMS>::zeros();
            for kk in 0..3 {
                g.set_column(kk, &(-proj.column(kk)));
            }
            for (j, &(a, b)) in [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
                .iter()
                .enumerate()
            {
                let mut eu = Vector3::zeros();
                eu[a] += u[b];
                if a != b {
                    eu[b] += u[a];
                }
                g.set_column(3 + j, &(proj * eu));
            }
            self.worst = self.worst.max((l * g.transpose()).norm_squared());
            if let Some(ls) = self.support_l_inv {
                self.support_worst = self.support_worst.max((ls * g.transpose()).norm_squared());
            }
        }
    }

    /// What the readings determine: the support's dilution (see `crate::quality`) and the
    /// parameters' σ from the information factor.
    fn uncertainty(&self) -> CompassUncertainty {
        let dilution = match self.support_l_inv {
            Some(_) => (self.support_cells as f64 * self.support_worst).sqrt(),
            None => f64::INFINITY,
        };
        match self.l_inv {
            Some(l) => quality::uncertainty_from_factor(&l, self.sigma, self.field, 3, dilution),
            None => CompassUncertainty {
                dilution: if dilution.is_finite() {
                    dilution
                } else {
                    f64::INFINITY
                },
                ..CompassUncertainty::UNDETERMINED
            },
        }
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
    type Sample = Mag3Sample;
    const STAGES: u8 = STAGES;
    const NOT_READY: Error = Error::NotReady {
        what: "online ellipsoid solution",
        hint: "push readings of a tumble",
    };

    #[inline]
    fn reading(sample: &Mag3Sample) -> (f64, &Vector3<f64>) {
        (sample.t_s, &sample.mag)
    }

    #[inline]
    fn add(sums: &mut Sums, p: &Vector3<f64>, decay: f64) -> Result<()> {
        sums.add(&LAYOUT_3D, p, decay)
    }

    #[inline]
    fn slot(cal: &CompassCalibration3d, p: &Vector3<f64>) -> Option<usize> {
        cell(&cal.correct(p))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::linalg::sym_eigen9;
    use proptest::prelude::*;

    proptest! {
        /// The staged Jacobi solver gives the eigenvalues of the QR-based decomposition the
        /// batch fit uses, to rounding relative to the matrix's norm, on symmetric matrices
        /// of any conditioning.
        #[test]
        fn jacobi_eigenvalues_match_the_batch_decomposition(
            entries in proptest::collection::vec(-1.0f64..1.0, 81),
            log_spread in 0.0f64..8.0,
        ) {
            let g = SMatrix::<f64, PARAMS, PARAMS>::from_iterator(entries);
            // A Gram matrix with eigenvalues spread over `log_spread` decades.
            let d = SMatrix::<f64, PARAMS, PARAMS>::from_fn(|i, j| {
                if i == j { 10f64.powf(-log_spread * i as f64 / 8.0) } else { 0.0 }
            });
            let m = g * d * g.transpose();
            let (expect, _) = sym_eigen9(&m).unwrap();
            let mut j = Jacobi9::new(&m);
            let mut sweeps = 0;
            while !j.sweep() {
                sweeps += 1;
            }
            // It converges (rather than giving up at the sweep limit); on the information
            // matrix of a refresh that takes four or five sweeps, here up to about ten.
            prop_assert!(j.state == Some(true) && sweeps < JACOBI_MAX_SWEEPS as usize, "{} sweeps", sweeps);
            let got = j.ascending().unwrap();
            let scale = m.norm();
            for i in 0..PARAMS {
                prop_assert!((got[i] - expect[i]).abs() <= 1e-13 * scale, "{}: {} vs {}", i, got[i], expect[i]);
            }
        }
    }

    #[test]
    fn jacobi_refuses_non_finite_input() {
        let mut m = SMatrix::<f64, PARAMS, PARAMS>::identity();
        m[(2, 3)] = f64::NAN;
        let mut j = Jacobi9::new(&m);
        assert!(j.sweep());
        assert!(j.ascending().is_none());
    }
}
