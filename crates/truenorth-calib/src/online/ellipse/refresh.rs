//! A staged refresh of the [`crate::OnlineEllipseCalibrator`]'s estimate: the direct fit from
//! a copy of the running sums and the retained readings, then its quality and refusals, one
//! short stage per push (see the `ellipse` module for the scheme and the
//! approximations the sums imply).

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use core::f64::consts::TAU;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3};
use truenorth_compass::{CompassCalibration2d, CompassCalibration2dIn};
use truenorth_core::{Error, FitQuality, Real, Result, Solution};

use crate::fits::ellipse::direct::{
    Ellipse, conic_to_ellipse, denormalise, from_params, solve_direct, to_params,
};

use crate::fits::ellipse::fit::sampson_normal_equations;
use crate::fits::lm::LmSteps;
use crate::fits::normalise::Normaliser;
use crate::numerics::linalg::{condition_from_eigenvalues, sym_eigen2, sym_eigen5, sym_sqrt2};
use crate::online::conic_sums::{ConicSums, LAYOUT_2D, MONOMIALS_2D, Retained, inverse_factor};
use crate::quality::{self, COVERAGE_BINS, Coverage, GAP_BINS, turns, turns_in};

use crate::online::conic::{
    ConicRefresh, RefreshBase, bound_deg, noise_factor, refuse_fit, report,
};
use crate::online::ellipse::config::OnlineEllipseConfig;
use crate::quality::{anisotropy_2d, direct_fit_bias_rad};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Headings over which the heading-error bound takes its worst (5° apart, as the batch
/// report).
const BOUND_HEADINGS: usize = 72;

/// Parameters of the heading-error model (centre 2, symmetric soft iron 3).
const PARAMS: usize = 5;

/// Direction slots of the retained readings (5° each): coverage is measured on at most one
/// reading per slot, so it may err short by up to a slot.
pub const ONLINE_SLOTS_2D: usize = 72;

pub(crate) type Sums = ConicSums<f64, 2, MONOMIALS_2D>;
pub(crate) type Slots = Retained<f64, 2, ONLINE_SLOTS_2D>;
type Base = RefreshBase<2, MONOMIALS_2D, ONLINE_SLOTS_2D, CompassCalibration2d>;

/// The direction slot of reading `p` under calibration `m`: its calibrated direction,
/// counter-clockwise from +x, in slots of 5°. `None` at the centre or for non-finite values.
/// In the readings' float type `T`: the slot is a bookkeeping choice, whose rounding in
/// `f32` moves a reading at most into a neighbouring slot.
#[inline]
pub(crate) fn slot_of<T: Real>(m: &CompassCalibration2dIn<T>, p: &Vector2<T>) -> Option<usize> {
    let h = m.correct(p);
    let r2 = h.norm_squared();
    if !(r2 > T::zero() && r2.is_finite()) {
        return None;
    }
    let slot = (turns_in(h.y, h.x) * T::of(ONLINE_SLOTS_2D as f64)).to_f64() as usize;
    Some(slot.min(ONLINE_SLOTS_2D - 1))
}

/// Coverage of the live retained readings about calibration `m`, with the bins of
/// [`quality::coverage`]: share of the [`COVERAGE_BINS`] 10° bins filled and the largest
/// empty run of the 0.5° bins.
pub(crate) fn coverage_of(
    slots: &Slots,
    now: u64,
    lifetime: u64,
    m: &CompassCalibration2d,
) -> Coverage {
    const WORDS: usize = GAP_BINS.div_ceil(64);
    let mut fine = [0u64; WORDS];
    let mut coarse = 0u64;
    let mut any = false;
    for p in slots.live(now, lifetime) {
        let h = m.correct(p);
        let r2 = h.norm_squared();
        if !(r2 > 0.0 && r2.is_finite()) {
            continue;
        }
        let t = turns(h.y, h.x);
        let c = ((t * COVERAGE_BINS as f64) as usize).min(COVERAGE_BINS - 1);
        let f = ((t * GAP_BINS as f64) as usize).min(GAP_BINS - 1);
        coarse |= 1 << c;
        fine[f / 64] |= 1 << (f % 64);
        any = true;
    }
    if !any {
        return Coverage {
            fraction: 0.0,
            largest_gap_rad: TAU,
        };
    }
    // Largest cyclic run of empty fine bins: between consecutive occupied ones, and from
    // the last round to the first.
    let (mut first, mut prev, mut gap) = (None, 0usize, 0usize);
    for (w, &word) in fine.iter().enumerate() {
        let mut bits = word;
        while bits != 0 {
            let i = w * 64 + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            match first {
                None => first = Some(i),
                Some(_) => gap = gap.max(i - prev - 1),
            }
            prev = i;
        }
    }
    let first = first.unwrap_or(0);
    gap = gap.max(first + GAP_BINS - prev - 1);
    Coverage {
        fraction: coarse.count_ones() as f64 / COVERAGE_BINS as f64,
        largest_gap_rad: gap as f64 * TAU / GAP_BINS as f64,
    }
}

/// A refresh of the estimate: a copy of the sums and retained readings taken when it
/// started, what has been computed from them so far, and the outcome once known. Each
/// [`ConicRefresh::step`] runs one stage; a solve runs them all.
#[derive(Debug, Clone)]
pub(crate) struct Refresh {
    /// Its copies of the sums and retained readings, stage, sorting map and outcome.
    base: Base,
    /// Scatter matrix in normalised coordinates, and the map back (`p = centre + scale q`).
    scatter: SMatrix<f64, 6, 6>,
    centre: Vector2<f64>,
    scale: f64,
    /// The ellipse in normalised coordinates and its calibration.
    ellipse: Option<Ellipse>,
    cal: CompassCalibration2d,
    field: f64,
    /// Quality so far.
    coverage: Coverage,
    residual_rms_rel: f64,
    condition: f64,
    sigma: f64,
    l_inv: Option<SMatrix<f64, PARAMS, PARAMS>>,
    /// The inverse factor of the support's information matrix (each live direction slot
    /// once) and its slots, for the dilution.
    support_l_inv: Option<SMatrix<f64, PARAMS, PARAMS>>,
    support_cells: usize,
    /// The direct fit's bias bound, radians (see `crate::quality::direct_fit_bias_rad`).
    bias_rad: f64,
    /// The geometric refinement of the retained readings (normalised coordinates), its
    /// readings, and the arc they cover about it.
    refine: Option<LmSteps<PARAMS>>,
    support: [Vector2<f64>; ONLINE_SLOTS_2D],
    support_len: usize,
    arc: Coverage,
}

/// `max_u ‖L⁻¹g(u)‖²` over [`BOUND_HEADINGS`] headings, `g(u)` the heading error's gradient
/// (see `crate::quality`); the headings by rotation, without trigonometry per step.
fn worst_over_headings(l: &SMatrix<f64, PARAMS, PARAMS>) -> f64 {
    let (sd, cd) = (TAU / BOUND_HEADINGS as f64).sin_cos();
    let (mut c, mut s) = (1.0, 0.0);
    let mut worst: f64 = 0.0;
    for _ in 0..BOUND_HEADINGS {
        let (px, py) = (-s, c);
        let g = SVector::<f64, PARAMS>::new(-px, -py, px * c, px * s + py * c, py * s);
        worst = worst.max((l * g).norm_squared());
        (c, s) = (c * cd - s * sd, s * cd + c * sd);
    }
    worst
}

/// What the refusal of a stray ellipse says.
const STRAY: &str =
    " (the readings stray from the best ellipse by more than max_residual_rel of the field)";

/// Most Levenberg–Marquardt trials of the geometric refinement of the retained readings,
/// from the direct fit: a short arc moves its centre most in the first few, and eight are
/// enough for `tests/families.rs` to refuse every arc of half a turn or less. They stop
/// early once the step left is negligible (`LmSteps::settled`), as it soon is for a
/// well-spread arc.
const REFINE_TRIALS: u8 = 8;

/// The stages: normalise, fit, cover, assess, and the arc (refined where it is in question)
/// with the report.
pub(crate) const STAGES: u8 = 5;

/// The widest gap in the headings seen about the direct fit, beyond the noise allowance,
/// that still counts as a full turn, degrees: two retained slots of 5°, between which a
/// calibration that moves the directions a little can open a gap of up to two slots.
const FULL_TURN_GAP_DEG: f64 = 10.0;

impl Refresh {
    fn fail(&mut self, e: Error) {
        self.base.fail(e, STAGES);
    }

    /// Stage 0: refuse too few readings; normalise; refuse equal and collinear readings.
    fn normalise(&mut self, cfg: &OnlineEllipseConfig) {
        if !self.base.require_samples(cfg.min_samples, STAGES) {
            return;
        }
        let Some((s, centre, scale)) = self.base.sums.normalised(&LAYOUT_2D) else {
            return self.fail(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            });
        };
        (self.scatter, self.centre, self.scale) = (s, centre, scale);
        // Collinear: the spread across the best line is nil compared with the spread along
        // it (the trace of the covariance is 1 after normalisation). Σx², Σxy, Σy² are the
        // quadratic terms' entries in the constant term's column.
        let w = self.base.sums.weight();
        let cov = Matrix2::new(s[(0, 5)], s[(1, 5)], s[(1, 5)], s[(2, 5)]) / w;
        match sym_eigen2(&cov) {
            None => self.fail(Error::Degenerate {
                reason: "the readings could not be analysed",
            }),
            Some((l, _)) if l[0] <= 1e-12 => self.fail(Error::Degenerate {
                reason: "the readings lie on a straight line; the sensor must turn so the field traces a circle",
            }),
            Some(_) => {}
        }
    }

    /// Stage 1: the direct fit, its calibration, and the sorting map for retained readings.
    fn fit(&mut self, cfg: &OnlineEllipseConfig, lifetime: u64) {
        let e = solve_direct(&self.scatter)
            .and_then(|k| conic_to_ellipse(&k, cfg.limits.max_axis_ratio));
        let e = match e {
            Ok(e) => e,
            Err(err) => {
                self.base.map = self.circle_map();
                let err = self.explain_short_arc(cfg, lifetime, err);
                return self.fail(err);
            }
        };
        let raw = Ellipse {
            centre: self.centre + e.centre * self.scale,
            unit_map: e.unit_map / self.scale,
        };
        let (cal, field) = raw.calibration();
        if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
            return self.fail(Error::Degenerate {
                reason: "the fitted ellipse is not finite; check the input scale",
            });
        }
        self.ellipse = Some(e);
        (self.cal, self.field) = (cal, field);
        self.base.map = Some(cal);
    }

    /// Stage 2: coverage of the retained readings about the fitted calibration.
    fn cover(&mut self, lifetime: u64) {
        self.coverage = coverage_of(&self.base.slots, self.base.sums.count, lifetime, &self.cal);
    }

    /// Whether the arc needs the refinement to be judged: the headings seen about the direct
    /// fit leave a gap wider than [`FULL_TURN_GAP_DEG`] and the noise allowance (a full turn
    /// does not, and its arc is not in question).
    fn arc_in_question(&self) -> bool {
        let allowance = 2.0 * quality::ARC_END_NOISE_SIGMAS * self.sigma;
        !(self.coverage.largest_gap_rad <= FULL_TURN_GAP_DEG.to_radians() + allowance)
    }

    /// The arc is judged about the geometric fit of the readings retained per direction,
    /// not about the direct fit: the algebraic fit of a short noisy arc is pulled towards the
    /// arc, and seen from its centre the readings spread over more of the circle than they
    /// turned through (the batch fit refines every reading for the same reason). It takes
    /// the live retained readings and starts from the direct fit.
    fn start_refinement(&mut self, lifetime: u64) {
        let Some(e) = self.ellipse else { return };
        self.support_len = 0;
        for p in self.base.slots.live(self.base.sums.count, lifetime) {
            self.support[self.support_len] = *p;
            self.support_len += 1;
        }
        self.refine = Some(LmSteps::new(to_params(&e)));
    }

    /// One trial of the refinement, on the Sampson distance of the batch fit.
    fn refine_trial(&mut self) {
        let norm = Normaliser {
            centre: self.centre,
            scale: self.scale,
        };
        let pts = &self.support[..self.support_len];
        if let Some(r) = self.refine.as_mut()
            && !r.step(|p| sampson_normal_equations(pts, &norm, p))
        {
            self.refine = None;
        }
    }

    /// The arc of the retained readings about the refined fit (about the direct fit when
    /// the refinement failed, or ended on no ellipse).
    fn measure_arc(&mut self, lifetime: u64, cfg: &OnlineEllipseConfig) {
        self.arc = self.coverage;
        let Some(r) = self.refine else { return };
        let e = from_params(&r.params);
        let Some(unit_map) = sym_sqrt2(&(e.unit_map * e.unit_map)) else {
            return;
        };
        let e = Ellipse {
            centre: e.centre,
            unit_map,
        };
        if e.semi_axes()
            .is_none_or(|(a, b)| !(a / b <= cfg.limits.max_axis_ratio))
        {
            return;
        }
        let norm = Normaliser {
            centre: self.centre,
            scale: self.scale,
        };
        let (cal, _) = denormalise(&norm, &e).calibration();
        if cal
            .hard_iron
            .iter()
            .chain(cal.soft_iron.iter())
            .all(|x| x.is_finite())
        {
            self.arc = coverage_of(&self.base.slots, self.base.sums.count, lifetime, &cal);
        }
    }

    /// Stage 3: residual, information matrix and the condition of the headings seen.
    fn assess(&mut self, lifetime: u64) {
        let Some(e) = self.ellipse else { return };
        self.assess_sums(&e, lifetime);
    }

    /// Residual and information matrix from the sums, and the condition of the support's
    /// information matrix from the live retained readings (one per direction slot, each
    /// counted once: see `crate::quality`'s `support` module), so that the condition says
    /// what the headings seen determine, whatever the time spent at each.
    fn assess_sums(&mut self, e: &Ellipse, lifetime: u64) {
        // Calibrated readings in field units, u = B(q − c), as an affine map of the
        // normalised q; the scatter of their design vector (u_x², u_xu_y, u_y², u_x, u_y, 1).
        let t = LAYOUT_2D.design_map(&e.unit_map, &(-(e.unit_map * e.centre)));
        let su = t * self.scatter * t.transpose();
        // Σ w (|u|² − 1)² and Σ w r² ≈ ¼ of it (see the module documentation).
        let k0 = SVector::<f64, 6>::new(1.0, 0.0, 1.0, 0.0, 0.0, -1.0);
        let ss = 0.25 * (k0.transpose() * su * k0)[0].max(0.0);
        let w = self.base.sums.weight();
        self.residual_rms_rel = (ss / w).sqrt();
        // φ(u) = (−u_x, −u_y, u_x², 2u_xu_y, u_y²) = P ξ(u) (the quality module's model).
        #[rustfmt::skip]
        let p = SMatrix::<f64, PARAMS, 6>::from_row_slice(&[
            0.0, 0.0, 0.0, -1.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 0.0, -1.0, 0.0,
            1.0, 0.0, 0.0, 0.0, 0.0, 0.0,
            0.0, 2.0, 0.0, 0.0, 0.0, 0.0,
            0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
        ]);
        let info = p * su * p.transpose();
        let info = (info + info.transpose()) * 0.5;
        let mut support = SMatrix::<f64, PARAMS, PARAMS>::zeros();
        let mut cells = 0;
        for q in self.base.slots.live(self.base.sums.count, lifetime) {
            let h = self.cal.correct(q);
            let rho = h.norm();
            if !(rho > 0.0 && rho.is_finite()) {
                continue;
            }
            let (x, y) = (h.x / rho, h.y / rho);
            let phi = quality::regressor_2d(x, y);
            support += phi * phi.transpose();
            cells += 1;
        }
        self.condition = sym_eigen5(&support)
            .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
            .unwrap_or(f64::INFINITY);
        self.support_cells = cells;
        self.support_l_inv = (cells >= PARAMS)
            .then(|| inverse_factor(&support))
            .flatten();
        (self.sigma, self.l_inv) = noise_factor(&self.base.sums, ss, &info);
        // The design vector's sums, (Σu_x², Σu_xu_y, Σu_y², Σu_x, Σu_y, Σ1): the harmonics
        // of the directions, and the anisotropy of B².
        let c = su.column(5);
        let h1 = c[3].hypot(c[4]) / c[5];
        let h2 = (c[0] - c[2]).hypot(2.0 * c[1]) / c[5];
        let kappa = anisotropy_2d(&(e.unit_map * e.unit_map)).unwrap_or(1.0);
        self.bias_rad = direct_fit_bias_rad(self.sigma, kappa, h1, h2);
    }

    /// Stage 4: the heading-error bound, the report and the refusals, in the order of the
    /// batch fit.
    fn finish(&mut self, cfg: &OnlineEllipseConfig, lifetime: u64) {
        // 3σ max_u √(gᵀA⁻¹g) over the headings.
        let worst = self.l_inv.map(|l| worst_over_headings(&l));
        // The support's dilution √(K · max_u gᵀS⁻¹g), as the batch report's.
        let dilution = self.support_l_inv.map_or(f64::INFINITY, |l| {
            (self.support_cells as f64 * worst_over_headings(&l)).sqrt()
        });
        let uncertainty = quality::uncertainty_from_factor(
            self.l_inv.as_ref(),
            self.sigma,
            self.field,
            2,
            dilution,
        );
        let fit = FitQuality {
            points: self.base.sums.count as usize,
            coverage: self.coverage.fraction,
            residual_rms_rel: self.residual_rms_rel,
            condition: self.condition,
        };
        let bound = bound_deg(self.sigma, worst);
        let quality = report(
            fit,
            bound,
            self.bias_rad,
            self.sigma,
            self.field,
            cfg.expected_field,
            uncertainty,
        );
        let checked = quality::require_arc(&self.arc, self.sigma, cfg.min_arc_deg).and_then(|()| {
            refuse_fit(
                &quality,
                cfg.limits.max_residual_rel,
                cfg.limits.max_heading_error_bound_deg,
                self.base.residual_dof(PARAMS),
                STRAY,
            )
        });
        self.base.outcome = Some(match checked {
            Ok(()) => Ok(Solution {
                params: self.cal,
                quality,
            }),
            Err(e) => Err(self.explain_short_arc(cfg, lifetime, e)),
        });
    }

    /// Centre of the algebraic best-fitting circle `|q|² + D x + E y + F = 0` (Kåsa 1976),
    /// from the normalised scatter matrix: its normal equations are the linear terms'
    /// block, with the right-hand side from the `x²` and `y²` columns.
    fn circle_centre(&self) -> Option<Vector2<f64>> {
        let s = &self.scatter;
        let a: Matrix3<f64> = s.fixed_view::<3, 3>(3, 3).into_owned();
        let rhs = -(s.fixed_view::<3, 1>(3, 0) + s.fixed_view::<3, 1>(3, 2));
        let sol = a.cholesky()?.solve(&Vector3::from(rhs));
        let c = self.centre + Vector2::new(-0.5 * sol[0], -0.5 * sol[1]) * self.scale;
        c.iter().all(|x| x.is_finite()).then_some(c)
    }

    fn circle_map(&self) -> Option<CompassCalibration2d> {
        self.circle_centre().map(|c| CompassCalibration2d {
            hard_iron: c,
            soft_iron: Matrix2::identity(),
        })
    }

    /// As the batch fit: a failure that a short arc explains better (a hyperbola, an
    /// ill-conditioned or too uncertain fit) is reported as the short arc, measured about
    /// the best-fitting circle.
    fn explain_short_arc(&self, cfg: &OnlineEllipseConfig, lifetime: u64, e: Error) -> Error {
        if !matches!(
            e,
            Error::NotAnEllipse { .. } | Error::NoConvergence { .. } | Error::Degenerate { .. }
        ) {
            return e;
        }
        match self.circle_map() {
            Some(m) => {
                let cov = coverage_of(&self.base.slots, self.base.sums.count, lifetime, &m);
                quality::require_arc(&cov, 0.0, cfg.min_arc_deg)
                    .err()
                    .unwrap_or(e)
            }
            None => e,
        }
    }
}

impl ConicRefresh<2, MONOMIALS_2D, ONLINE_SLOTS_2D> for Refresh {
    type Config = OnlineEllipseConfig;
    type Cal = CompassCalibration2d;
    type CalIn<T: Real> = CompassCalibration2dIn<T>;
    const STAGES: u8 = STAGES;
    const NOT_READY: Error = Error::NotReady {
        what: "online ellipse solution",
        hint: "push readings of a turn",
    };

    #[inline]
    fn add<T: Real>(
        sums: &mut ConicSums<T, 2, MONOMIALS_2D>,
        p: &Vector2<T>,
        decay: T,
    ) -> Result<()> {
        sums.add(&LAYOUT_2D, p, decay)
    }

    fn narrow<T: Real>(cal: &CompassCalibration2d) -> CompassCalibration2dIn<T> {
        cal.to_precision()
    }

    #[inline]
    fn slot<T: Real>(cal: &CompassCalibration2dIn<T>, p: &Vector2<T>) -> Option<usize> {
        slot_of(cal, p)
    }

    fn coverage(slots: &Slots, now: u64, lifetime: u64, cal: &CompassCalibration2d) -> f64 {
        coverage_of(slots, now, lifetime, cal).fraction
    }

    fn is_finite(m: &CompassCalibration2d) -> bool {
        m.hard_iron
            .iter()
            .chain(m.soft_iron.iter())
            .all(|x| x.is_finite())
    }

    fn start(sums: &Sums, slots: &Slots) -> Self {
        Self {
            base: Base::new(sums, slots),
            scatter: SMatrix::zeros(),
            centre: Vector2::zeros(),
            scale: 1.0,
            ellipse: None,
            cal: CompassCalibration2d::identity(),
            field: 0.0,
            coverage: Coverage {
                fraction: 0.0,
                largest_gap_rad: TAU,
            },
            residual_rms_rel: 0.0,
            condition: f64::INFINITY,
            sigma: 0.0,
            l_inv: None,
            support_l_inv: None,
            support_cells: 0,
            bias_rad: 0.0,
            refine: None,
            support: [Vector2::zeros(); ONLINE_SLOTS_2D],
            support_len: 0,
            arc: Coverage {
                fraction: 0.0,
                largest_gap_rad: TAU,
            },
        }
    }

    fn run_stage(&mut self, stage: u8, cfg: &OnlineEllipseConfig, lifetime: u64) {
        match stage {
            0 => self.normalise(cfg),
            1 => self.fit(cfg, lifetime),
            2 => self.cover(lifetime),
            3 => self.assess(lifetime),
            _ => {
                // The arc is judged about the geometric fit of the retained readings where it
                // is in question (a partial turn: rare once the calibrator has seen a full
                // one, so the cost falls on a few refreshes of the first turn); a full turn
                // is decided by the direct fit's coverage. The trials run in this one stage
                // (~2 µs each) rather than one per push: a caller that pushes sparsely
                // (a vehicle's compass learner takes a reading per 2° of turn) would wait
                // eight more readings for its first calibration, which delayed a front-wheel
                // drive's compass past its straights (`truenorth-cli/tests/drive.rs`).
                self.arc = self.coverage;
                if self.arc_in_question() {
                    self.start_refinement(lifetime);
                    for _ in 0..REFINE_TRIALS {
                        self.refine_trial();
                        if self.refine.is_none_or(|r| r.settled(self.support_len)) {
                            break;
                        }
                    }
                    self.measure_arc(lifetime, cfg);
                }
                self.finish(cfg, lifetime);
            }
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
