//! Online least-squares ellipse calibration of a two-axis compass, in bounded memory: the
//! direct ellipse fit of [`crate::EllipseCalibrator`] (Fitzgibbon, Pilu & Fisher 1999 in
//! the form of Halíř & Flusser 1998) solved from running monomial sums instead of stored
//! readings (see the `conic_sums` module), optionally forgetting old readings.
//!
//! Per reading, [`OnlineEllipseCalibrator::push`] adds the 15 monomials of degree ≤ 4 to
//! the sums (one product each) and may keep the reading as its direction slot's
//! representative for coverage: O(1), no allocation. Every
//! [`OnlineEllipseConfig::refresh_interval_samples`] readings a refresh of the estimate
//! starts on a copy of the sums and runs one short stage per push (normalise; direct fit;
//! coverage; residual and information matrix; heading-error bound and refusals), so that no push pays for a whole solve.
//!
//! What the sums cannot give exactly is approximated to first order in the residuals, which
//! are small whenever a calibration is accepted:
//! * the residual of a reading is taken from the algebraic distance `|u|² − 1 ≈ 2(|u| − 1)`
//!   of its calibrated reading `u` (in field units), so `Σr² ≈ ¼ Σ(|u|² − 1)²`, a quadratic
//!   form in the scatter matrix of the design vector of `u`;
//! * the information matrix of the quality report (see [`crate::quality`]) is built on
//!   `u` itself rather than on `u/|u|`.
//!
//! There is no geometric refinement: on a full turn the direct fit has the same first-order
//! covariance as the maximum-likelihood fit and differs from it by an `O(σ²)` bias only
//! (Kanatani 2008, "Statistical optimization for geometric fitting: theoretical accuracy
//! bound and high order error analysis", IJCV 80), a small fraction of the per-reading
//! noise at any noise a compass calibration is accepted at.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use core::f64::consts::TAU;

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, FitQuality, Mag2Sample, OnlineCalibrator, Persistent,
    Progress, Pushed, Result, Snapshot, Solution, Validate, check_finite, check_finite2,
    check_positive, check_range, check_snapshot_version,
};

use crate::conic_sums::{
    ConicSums, LAYOUT_2D, MONOMIALS_2D, Retained, RetainedSnapshot, SumsSnapshot, forgetting,
    inverse_factor, sigma_kappa, t_factor,
};
use crate::ellipse_fit::{Ellipse, MIN_POINTS_2D, conic_to_ellipse, solve_direct};
use crate::linalg::{condition_from_eigenvalues, sym_eigen2, sym_eigen5};
use crate::quality::{self, BOUND_SIGMAS, COVERAGE_BINS, Coverage, GAP_BINS, MIN_ARC_DEG, turns};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Direction slots of the retained readings (5° each): coverage is measured on at most one
/// reading per slot, so it may err short by up to a slot.
pub const ONLINE_SLOTS_2D: usize = 72;

/// Headings over which the heading-error bound takes its worst (5° apart, as the batch
/// report).
const BOUND_HEADINGS: usize = 72;

/// Parameters of the heading-error model (centre 2, symmetric soft iron 3).
const PARAMS: usize = 5;

/// Configuration of [`OnlineEllipseCalibrator`]. The refusal limits are those of
/// [`crate::EllipseConfig`], with the same defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OnlineEllipseConfig {
    /// Shortest arc of heading accepted, degrees, 0..=360 ([`MIN_ARC_DEG`], 200).
    pub min_arc_deg: f64,
    /// Fewest readings a solution is accepted from, MIN_POINTS_2D..=10⁶ (30). More than the
    /// fit's minimum ([`MIN_POINTS_2D`]): a refresh runs unattended, and with few residuals
    /// beyond the parameters the noise, and so the heading-error bound, is estimated from
    /// so few residuals that a chance fit of a short arc can pass every other check.
    pub min_samples: u32,
    /// Readings between the starts of two refreshes of the estimate, 1..=10⁶ (32). A
    /// refresh runs over the next five pushes, one stage each.
    pub refresh_interval_samples: u32,
    /// Half-life of a reading's weight, in readings, 20..=10⁹ (`None`: never forget). With
    /// forgetting the calibration follows a slowly changing hard or soft iron; readings
    /// older than four half-lives no longer count towards coverage.
    pub forgetting_half_life_samples: Option<f64>,
    /// Largest ratio of the semi-axes accepted, ≥ 1 (10).
    pub max_axis_ratio: f64,
    /// Largest condition number of the information matrix accepted, ≥ 1 (1e4).
    pub max_condition: f64,
    /// Largest residual RMS, relative to the fitted field, accepted, > 0 (0.2).
    pub max_residual_rel: f64,
    /// Largest heading-error bound of the calibration accepted, degrees, > 0 (10).
    pub max_heading_error_bound_deg: f64,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`] (`None`).
    pub expected_field: Option<f64>,
}

impl Default for OnlineEllipseConfig {
    fn default() -> Self {
        Self {
            min_arc_deg: MIN_ARC_DEG,
            min_samples: 30,
            refresh_interval_samples: 32,
            forgetting_half_life_samples: None,
            max_axis_ratio: 10.0,
            max_condition: 1e4,
            max_residual_rel: 0.2,
            max_heading_error_bound_deg: 10.0,
            expected_field: None,
        }
    }
}

impl Validate for OnlineEllipseConfig {
    fn validate(&self) -> Result<()> {
        check_range("online ellipse min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check_range(
            "online ellipse min_samples",
            self.min_samples as f64,
            MIN_POINTS_2D as f64,
            1e6,
        )?;
        check_range(
            "online ellipse refresh_interval_samples",
            self.refresh_interval_samples as f64,
            1.0,
            1e6,
        )?;
        if let Some(h) = self.forgetting_half_life_samples {
            check_range("online ellipse forgetting_half_life_samples", h, 20.0, 1e9)?;
        }
        check_range(
            "online ellipse max_axis_ratio",
            self.max_axis_ratio,
            1.0,
            f64::MAX,
        )?;
        check_range(
            "online ellipse max_condition",
            self.max_condition,
            1.0,
            f64::MAX,
        )?;
        check_positive("online ellipse max_residual_rel", self.max_residual_rel)?;
        check_positive(
            "online ellipse max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        if let Some(f) = self.expected_field {
            check_positive("online ellipse expected_field", f)?;
        }
        Ok(())
    }
}

type Sums = ConicSums<2, MONOMIALS_2D>;
type Slots = Retained<2, ONLINE_SLOTS_2D>;

/// The direction slot of reading `p` under calibration `m`: its calibrated direction,
/// counter-clockwise from +x, in slots of 5°. `None` at the centre or for non-finite values.
#[inline]
fn slot_of(m: &CompassCalibration2d, p: &Vector2<f64>) -> Option<usize> {
    let h = m.correct(p);
    let r2 = h.norm_squared();
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    Some(((turns(h.y, h.x) * ONLINE_SLOTS_2D as f64) as usize).min(ONLINE_SLOTS_2D - 1))
}

/// Coverage of the live retained readings about calibration `m`, with the bins of
/// [`quality::coverage`]: share of the [`COVERAGE_BINS`] 10° bins filled and the largest
/// empty run of the 0.5° bins.
fn coverage_of(slots: &Slots, now: u64, lifetime: u64, m: &CompassCalibration2d) -> Coverage {
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
/// [`Refresh::step`] runs one stage; [`OnlineEllipseCalibrator::solve`] runs them all.
#[derive(Debug, Clone)]
struct Refresh {
    sums: Sums,
    slots: Slots,
    stage: u8,
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
    /// The calibration to sort retained readings by from now on.
    map: Option<CompassCalibration2d>,
    outcome: Option<Result<Solution<CompassCalibration2d>>>,
}

/// Number of stages of a refresh.
const STAGES: u8 = 5;

impl Refresh {
    fn start(sums: &Sums, slots: &Slots) -> Self {
        Self {
            sums: *sums,
            slots: *slots,
            stage: 0,
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
            map: None,
            outcome: None,
        }
    }

    /// The Student-t widening of the 3σ bound for the degrees of freedom of σ (see
    /// [`t_factor`]): the refusal on the heading-error bound uses the widened bound, the
    /// report the plain 3σ one, as the batch fit's.
    fn t_factor(&self) -> f64 {
        t_factor(self.sums.effective_count() - PARAMS as f64)
    }

    fn fail(&mut self, e: Error) {
        self.outcome = Some(Err(e));
        self.stage = STAGES;
    }

    /// Runs the next stage; `true` once the outcome is known.
    fn step(&mut self, cfg: &OnlineEllipseConfig, lifetime: u64) -> bool {
        if self.outcome.is_some() {
            return true;
        }
        match self.stage {
            0 => self.normalise(cfg),
            1 => self.fit(cfg, lifetime),
            2 => self.cover(lifetime),
            3 => self.assess(),
            _ => self.finish(cfg, lifetime),
        }
        self.stage += 1;
        self.outcome.is_some()
    }

    /// Stage 0: refuse too few readings; normalise; refuse equal and collinear readings.
    fn normalise(&mut self, cfg: &OnlineEllipseConfig) {
        let count = self.sums.count;
        if count < u64::from(cfg.min_samples) {
            return self.fail(Error::TooFewPoints {
                got: count as usize,
                need: cfg.min_samples as usize,
            });
        }
        let Some((s, centre, scale)) = self.sums.normalised(&LAYOUT_2D) else {
            return self.fail(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            });
        };
        (self.scatter, self.centre, self.scale) = (s, centre, scale);
        // Collinear: the spread across the best line is nil compared with the spread along
        // it (the trace of the covariance is 1 after normalisation). Σx², Σxy, Σy² are the
        // quadratic terms' entries in the constant term's column.
        let w = self.sums.weight();
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
        let e = solve_direct(&self.scatter).and_then(|k| conic_to_ellipse(&k, cfg.max_axis_ratio));
        let e = match e {
            Ok(e) => e,
            Err(err) => {
                self.map = self.circle_map();
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
        self.map = Some(cal);
    }

    /// Stage 2: coverage of the retained readings about the fitted calibration.
    fn cover(&mut self, lifetime: u64) {
        self.coverage = coverage_of(&self.slots, self.sums.count, lifetime, &self.cal);
    }

    /// Stage 3: residual, information matrix and its condition, from the sums.
    fn assess(&mut self) {
        let Some(e) = self.ellipse else { return };
        // Calibrated readings in field units, u = B(q − c), as an affine map of the
        // normalised q; the scatter of their design vector (u_x², u_xu_y, u_y², u_x, u_y, 1).
        let t = LAYOUT_2D.design_map(&e.unit_map, &(-(e.unit_map * e.centre)));
        let su = t * self.scatter * t.transpose();
        // Σ w (|u|² − 1)² and Σ w r² ≈ ¼ of it (see the module documentation).
        let k0 = SVector::<f64, 6>::new(1.0, 0.0, 1.0, 0.0, 0.0, -1.0);
        let ss = 0.25 * (k0.transpose() * su * k0)[0].max(0.0);
        let w = self.sums.weight();
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
        self.condition = sym_eigen5(&info)
            .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
            .unwrap_or(f64::INFINITY);
        match sigma_kappa(ss, w, self.sums.effective_count(), PARAMS) {
            Some((sigma, kappa)) => {
                self.sigma = sigma;
                // Scale L⁻¹ by √κ so that ‖L⁻¹g‖² is the variance factor directly.
                self.l_inv = inverse_factor(&info).map(|l| l * kappa.sqrt());
            }
            None => {
                self.sigma = f64::INFINITY;
                self.l_inv = None;
            }
        }
    }

    /// Stage 4: the heading-error bound, the report and the refusals, in the order of the
    /// batch fit.
    fn finish(&mut self, cfg: &OnlineEllipseConfig, lifetime: u64) {
        let bound = match self.l_inv {
            Some(l) => {
                // 3σ max_u √(gᵀA⁻¹g) over 72 headings, g(u) the heading error's gradient
                // (see `crate::quality`); the headings by rotation, without trigonometry
                // per step.
                let (sd, cd) = (TAU / BOUND_HEADINGS as f64).sin_cos();
                let (mut c, mut s) = (1.0, 0.0);
                let mut worst: f64 = 0.0;
                for _ in 0..BOUND_HEADINGS {
                    let (px, py) = (-s, c);
                    let g = SVector::<f64, PARAMS>::new(-px, -py, px * c, px * s + py * c, py * s);
                    worst = worst.max((l * g).norm_squared());
                    (c, s) = (c * cd - s * sd, s * cd + c * sd);
                }
                let b = (BOUND_SIGMAS * self.sigma * worst.sqrt()).to_degrees();
                if b.is_finite() { b } else { f64::INFINITY }
            }
            None => f64::INFINITY,
        };
        let quality = quality::with_expected_field(
            CompassQuality {
                fit: FitQuality {
                    points: self.sums.count as usize,
                    coverage: self.coverage.fraction,
                    residual_rms_rel: self.residual_rms_rel,
                    condition: self.condition,
                },
                heading_error_3sigma_deg: bound,
                heading_error_systematic_deg: 0.0,
                heading_noise_rms_deg: self.sigma.to_degrees(),
                field_magnitude: self.field,
                field_ratio_to_expected: None,
            },
            cfg.expected_field,
        );
        let checked = quality::require_arc(&self.coverage, cfg.min_arc_deg).and_then(|()| {
            if !(quality.fit.condition <= cfg.max_condition) {
                Err(Error::Degenerate {
                    reason: "the headings seen do not determine the ellipse (information matrix ill-conditioned); turn through a fuller circle",
                })
            } else if !(quality.fit.residual_rms_rel <= cfg.max_residual_rel) {
                Err(Error::NotAnEllipse {
                    detail: " (the readings stray from the best ellipse by more than max_residual_rel of the field)",
                })
            } else if !(quality.heading_error_bound_deg() * self.t_factor() <= cfg.max_heading_error_bound_deg) {
                Err(Error::Degenerate {
                    reason: "the predicted heading error exceeds max_heading_error_bound_deg: too few readings or too much noise for the part of the circle covered; record a full turn away from magnetic disturbances",
                })
            } else {
                Ok(())
            }
        });
        self.outcome = Some(match checked {
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
                let cov = coverage_of(&self.slots, self.sums.count, lifetime, &m);
                quality::require_arc(&cov, cfg.min_arc_deg)
                    .err()
                    .unwrap_or(e)
            }
            None => e,
        }
    }
}

/// Online least-squares ellipse calibrator: the direct fit of [`crate::EllipseCalibrator`]
/// from running sums, O(1) memory and O(1) per push (see the module documentation).
///
/// ```
/// use nalgebra::Vector2;
/// use truenorth_calib::{OnlineEllipseCalibrator, OnlineEllipseConfig};
/// use truenorth_core::{Calibrator, Mag2Sample, OnlineCalibrator};
///
/// let mut cal = OnlineEllipseCalibrator::new(OnlineEllipseConfig::default())?;
/// for k in 0..360 {
///     let psi = (k as f64).to_radians();
///     // A level compass in a 30-unit field with a (10, −4) hard iron.
///     let mag = Vector2::new(10.0 + 30.0 * psi.cos(), -4.0 - 30.0 * psi.sin());
///     cal.push(&Mag2Sample { t_s: k as f64, mag })?;
/// }
/// // The running estimate, O(1), and a fresh solve from the current sums agree.
/// let est = cal.estimate().expect("refreshed during the turn");
/// assert!((est.params.hard_iron - Vector2::new(10.0, -4.0)).norm() < 1e-6);
/// let sol = cal.solve()?;
/// assert!((sol.quality.field_magnitude - 30.0).abs() < 1e-6);
/// assert!(cal.progress().ready);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OnlineEllipseCalibrator {
    config: OnlineEllipseConfig,
    /// Per-reading weight factor and retained-reading lifetime, from the config.
    decay: f64,
    lifetime: u64,
    sums: Sums,
    slots: Slots,
    /// The calibration retained readings are sorted by (`None` before the first refresh).
    map: Option<CompassCalibration2d>,
    estimate: Option<Solution<CompassCalibration2d>>,
    /// Sample count at which the next refresh starts.
    next_refresh: u64,
    pending: Option<Refresh>,
}

impl OnlineEllipseCalibrator {
    /// A calibrator with the given configuration, or the first invalid parameter, named.
    pub fn new(config: OnlineEllipseConfig) -> Result<Self> {
        config.validate()?;
        let (decay, lifetime) = forgetting(config.forgetting_half_life_samples);
        Ok(Self {
            config,
            decay,
            lifetime,
            sums: Sums::new(),
            slots: Slots::new(),
            map: None,
            estimate: None,
            next_refresh: u64::from(config.min_samples),
            pending: None,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &OnlineEllipseConfig {
        &self.config
    }

    /// Completes a finished refresh: adopts its sorting map (re-sorting the retained
    /// readings) and, if it succeeded, its estimate. Returns whether the estimate changed.
    fn publish(&mut self, r: Refresh) -> bool {
        if let Some(m) = r.map {
            self.map = Some(m);
            self.slots
                .rekey(|p| slot_of(&m, p), self.sums.count, self.lifetime);
        }
        match r.outcome {
            Some(Ok(sol)) if self.estimate != Some(sol) => {
                self.estimate = Some(sol);
                true
            }
            _ => false,
        }
    }
}

impl Calibrator for OnlineEllipseCalibrator {
    type Sample = Mag2Sample;
    type Params = CompassCalibration2d;
    type Quality = CompassQuality;

    /// Adds a reading to the sums (and, when its direction slot is free, to the retained
    /// readings), and runs one stage of a refresh when one is due. O(1), no allocation; a
    /// non-finite sample is refused and changes nothing.
    fn push(&mut self, sample: &Mag2Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite2("magnetometer reading", &sample.mag)?;
        self.sums.add(&LAYOUT_2D, &sample.mag, self.decay)?;
        let now = self.sums.count;
        // Before the first refresh there is no calibration to sort by: the first readings
        // take the slots in order, and the first refresh sorts them.
        let slot = match &self.map {
            Some(m) => slot_of(m, &sample.mag),
            None => Some((now - 1) as usize),
        };
        if let Some(k) = slot {
            self.slots.offer(k, &sample.mag, now, self.lifetime);
        }
        if self.pending.is_none() && now >= self.next_refresh {
            self.pending = Some(Refresh::start(&self.sums, &self.slots));
            self.next_refresh = now + u64::from(self.config.refresh_interval_samples);
        }
        let done = match &mut self.pending {
            Some(r) => r.step(&self.config, self.lifetime),
            None => false,
        };
        if done
            && let Some(r) = self.pending.take()
            && self.publish(r)
        {
            return Ok(Pushed::NewEstimate);
        }
        Ok(Pushed::Accepted)
    }

    /// Samples accepted, coverage of the retained readings about the current calibration,
    /// and `ready` exactly when [`Calibrator::solve`] succeeds (it runs the solve: a few
    /// microseconds, independent of the number of readings).
    fn progress(&self) -> Progress {
        let coverage = self
            .map
            .map(|m| coverage_of(&self.slots, self.sums.count, self.lifetime, &m).fraction)
            .unwrap_or(0.0);
        Progress {
            samples: self.sums.count as usize,
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    /// A fresh solve from the current sums (all stages of a refresh at once), with the
    /// batch fit's refusals. Does not change the calibrator.
    fn solve(&self) -> Result<Solution<CompassCalibration2d>> {
        let mut r = Refresh::start(&self.sums, &self.slots);
        while !r.step(&self.config, self.lifetime) {}
        r.outcome.unwrap_or(Err(Error::NotReady {
            what: "online ellipse solution",
            hint: "push readings of a turn",
        }))
    }

    fn reset(&mut self) {
        *self = Self {
            config: self.config,
            decay: self.decay,
            lifetime: self.lifetime,
            sums: Sums::new(),
            slots: Slots::new(),
            map: None,
            estimate: None,
            next_refresh: u64::from(self.config.min_samples),
            pending: None,
        };
    }
}

impl OnlineCalibrator for OnlineEllipseCalibrator {
    /// The latest refresh's successful solution. A refresh that is refused (e.g. while
    /// forgetting, after a long straight drive) keeps the previous estimate;
    /// `progress().ready` says whether the current data would support a new one.
    fn estimate(&self) -> Option<Solution<CompassCalibration2d>> {
        self.estimate
    }
}

/// The saved state of an [`OnlineEllipseCalibrator`]: everything it learned and the
/// refresh in progress, so a restored calibrator continues bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OnlineEllipseState {
    /// The configuration.
    pub config: OnlineEllipseConfig,
    /// The running sums.
    pub sums: SumsSnapshot,
    /// The retained readings for coverage.
    pub retained: RetainedSnapshot,
    /// The calibration retained readings are sorted by.
    pub sorting: Option<CompassCalibration2d>,
    /// The current estimate.
    pub estimate: Option<Solution<CompassCalibration2d>>,
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

impl Persistent for OnlineEllipseCalibrator {
    type State = OnlineEllipseState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn snapshot(&self) -> Snapshot<OnlineEllipseState> {
        Snapshot {
            version: Self::SNAPSHOT_VERSION,
            state: OnlineEllipseState {
                config: self.config,
                sums: self.sums.snapshot(),
                retained: self.slots.snapshot(),
                sorting: self.map,
                estimate: self.estimate,
                next_refresh: self.next_refresh,
                pending: self.pending.as_ref().map(|r| PendingRefresh {
                    sums: r.sums.snapshot(),
                    retained: r.slots.snapshot(),
                    stage: r.stage,
                }),
            },
        }
    }

    fn restore(snapshot: Snapshot<OnlineEllipseState>) -> Result<Self> {
        check_snapshot_version(snapshot.version, Self::SNAPSHOT_VERSION)?;
        let s = snapshot.state;
        let mut cal = Self::new(s.config)?;
        cal.sums = Sums::restore(&s.sums)?;
        cal.slots = Slots::restore(&s.retained, cal.sums.count)?;
        let finite_cal = |m: &CompassCalibration2d| {
            m.hard_iron
                .iter()
                .chain(m.soft_iron.iter())
                .all(|x| x.is_finite())
        };
        if !s.sorting.as_ref().is_none_or(finite_cal)
            || !s.estimate.as_ref().is_none_or(|e| finite_cal(&e.params))
        {
            return Err(Error::InvalidSnapshot {
                reason: "a saved calibration is not finite",
            });
        }
        cal.map = s.sorting;
        cal.estimate = s.estimate;
        cal.next_refresh = s.next_refresh;
        if let Some(p) = s.pending {
            let sums = Sums::restore(&p.sums)?;
            if sums.count > cal.sums.count || p.stage >= STAGES {
                return Err(Error::InvalidSnapshot {
                    reason: "the saved refresh does not fit the saved sums",
                });
            }
            let slots = Slots::restore(&p.retained, sums.count)?;
            let mut r = Refresh::start(&sums, &slots);
            while r.stage < p.stage && !r.step(&cal.config, cal.lifetime) {}
            if r.outcome.is_some() || r.stage != p.stage {
                return Err(Error::InvalidSnapshot {
                    reason: "the saved refresh had already finished",
                });
            }
            cal.pending = Some(r);
        }
        Ok(cal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn turn(n: usize, span_deg: f64) -> impl Iterator<Item = Mag2Sample> {
        (0..n).map(move |k| {
            let psi = (span_deg * k as f64 / n as f64).to_radians();
            Mag2Sample {
                t_s: k as f64,
                mag: Vector2::new(3.0 + 2.0 * psi.cos(), -1.0 - 1.5 * psi.sin()),
            }
        })
    }

    #[test]
    fn coverage_of_a_full_and_a_half_turn() {
        let mut cal = OnlineEllipseCalibrator::new(OnlineEllipseConfig::default()).unwrap();
        for s in turn(180, 180.0) {
            cal.push(&s).unwrap();
        }
        assert!(matches!(
            cal.solve(),
            Err(Error::InsufficientCoverage { .. })
        ));
        for s in turn(360, 360.0) {
            cal.push(&s).unwrap();
        }
        let sol = cal.solve().unwrap();
        assert_eq!(sol.quality.fit.coverage, 1.0);
        assert!((sol.params.hard_iron - Vector2::new(3.0, -1.0)).norm() < 1e-9);
    }

    /// A refresh spread over pushes gives exactly the solve of the sums it started from.
    #[test]
    fn refresh_stages_give_the_solve() {
        let config = OnlineEllipseConfig {
            refresh_interval_samples: 1_000_000,
            ..Default::default()
        };
        let mut cal = OnlineEllipseCalibrator::new(config).unwrap();
        let mut at_start = None;
        // 12° per reading: the first refresh, at `min_samples`, sees a full turn.
        for (k, s) in turn(400, 4800.0).enumerate() {
            let pushed = cal.push(&s).unwrap();
            if k + 1 == config.min_samples as usize {
                at_start = Some(cal.solve());
            }
            if k + 1 < config.min_samples as usize + STAGES as usize - 1 {
                assert_eq!(pushed, Pushed::Accepted);
            } else if k + 1 == config.min_samples as usize + STAGES as usize - 1 {
                assert_eq!(pushed, Pushed::NewEstimate);
            }
        }
        assert_eq!(at_start.map(|r| r.ok()), Some(cal.estimate()));
        assert!(cal.estimate().is_some());
    }
}
