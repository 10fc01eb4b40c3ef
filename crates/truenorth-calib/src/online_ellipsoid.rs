//! Online least-squares ellipsoid calibration of a three-axis magnetometer, in bounded
//! memory: the direct ellipsoid fit of [`crate::EllipsoidCalibrator`] (Li & Griffiths 2004)
//! solved from the 35 running monomial sums of degree ≤ 4 (see the `conic_sums` module),
//! optionally forgetting old readings.
//!
//! It works as the two-axis [`crate::OnlineEllipseCalibrator`] does (see that module for
//! the approximations the sums imply): O(1) per push, and a refresh every
//! [`OnlineEllipsoidConfig::refresh_interval_samples`] readings split into short stages, one
//! per push — here more of them, since the 3-D algebra is larger (the heading-error bound
//! alone visits 256 directions, 16 per stage). Coverage is the share of the equal-area
//! direction cells of [`crate::quality`] holding a retained reading, at most one per cell.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::{
    Calibrator, CompassQuality, Error, FitQuality, Mag3Sample, OnlineCalibrator, Persistent,
    Progress, Pushed, Result, Snapshot, Solution, Validate, check_finite, check_finite3,
    check_positive, check_range, check_snapshot_version,
};

use crate::conic_sums::{
    ConicSums, LAYOUT_3D, MONOMIALS_3D, Retained, RetainedSnapshot, SumsSnapshot, forgetting,
    inverse_factor, sigma_kappa, t_factor,
};
use crate::ellipsoid_fit::{Ellipsoid, MIN_POINTS_3D, quadric_to_ellipsoid, solve_direct};
use crate::linalg::{condition_from_eigenvalues, sym_eigen3, sym_eigen9};
use crate::online_ellipse::PendingRefresh;
use crate::quality::{
    self, BOUND_SIGMAS, MIN_SPHERE_COVERAGE, SPHERE_BANDS, SPHERE_CELLS, SPHERE_SECTORS, turns,
};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Parameters of the direction-error model (centre 3, symmetric soft iron 6).
const PARAMS: usize = 9;

/// Test directions of the bound (a Fibonacci lattice, as the batch report), and how many a
/// refresh stage visits.
const BOUND_DIRECTIONS: usize = 256;
const BOUND_CHUNK: usize = 16;

/// Stages of a refresh: pre-check, normalise, direct fit, coverage, information matrix,
/// condition, the bound in chunks, and the report.
const BOUND_FIRST_STAGE: u8 = 6;
const STAGES: u8 = BOUND_FIRST_STAGE + (BOUND_DIRECTIONS / BOUND_CHUNK) as u8 + 1;

/// Configuration of [`OnlineEllipsoidCalibrator`]. The refusal limits are those of
/// [`crate::EllipsoidConfig`], with the same defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OnlineEllipsoidConfig {
    /// Smallest share of the sphere's direction cells accepted, 0..=1
    /// ([`MIN_SPHERE_COVERAGE`]).
    pub min_coverage: f64,
    /// Fewest readings a solution is accepted from, MIN_POINTS_3D..=10⁶ (50). More than the
    /// fit's minimum ([`MIN_POINTS_3D`]): a refresh runs unattended, and with few residuals
    /// beyond the parameters the noise, and so the heading-error bound, is estimated from
    /// so few residuals that a chance fit of a short arc can pass every other check.
    pub min_samples: u32,
    /// Readings between the starts of two refreshes of the estimate, 1..=10⁶ (64). A
    /// refresh runs over the next 23 pushes, one stage each.
    pub refresh_interval_samples: u32,
    /// Half-life of a reading's weight, in readings, 50..=10⁹ (`None`: never forget).
    /// Readings older than four half-lives no longer count towards coverage.
    pub forgetting_half_life_samples: Option<f64>,
    /// Largest ratio of longest to shortest semi-axis accepted, ≥ 1 (10).
    pub max_axis_ratio: f64,
    /// Largest condition number of the information matrix accepted, ≥ 1 (1e4).
    pub max_condition: f64,
    /// Largest residual RMS, relative to the fitted field, accepted, > 0 (0.2).
    pub max_residual_rel: f64,
    /// Largest direction-error bound of the calibration accepted, degrees, > 0 (10).
    pub max_heading_error_bound_deg: f64,
    /// The expected total field, input unit, > 0, reported as
    /// [`CompassQuality::field_ratio_to_expected`] (`None`).
    pub expected_field: Option<f64>,
}

impl Default for OnlineEllipsoidConfig {
    fn default() -> Self {
        Self {
            min_coverage: MIN_SPHERE_COVERAGE,
            min_samples: 50,
            refresh_interval_samples: 64,
            forgetting_half_life_samples: None,
            max_axis_ratio: 10.0,
            max_condition: 1e4,
            max_residual_rel: 0.2,
            max_heading_error_bound_deg: 10.0,
            expected_field: None,
        }
    }
}

impl Validate for OnlineEllipsoidConfig {
    fn validate(&self) -> Result<()> {
        check_range("online ellipsoid min_coverage", self.min_coverage, 0.0, 1.0)?;
        check_range(
            "online ellipsoid min_samples",
            self.min_samples as f64,
            MIN_POINTS_3D as f64,
            1e6,
        )?;
        check_range(
            "online ellipsoid refresh_interval_samples",
            self.refresh_interval_samples as f64,
            1.0,
            1e6,
        )?;
        if let Some(h) = self.forgetting_half_life_samples {
            check_range(
                "online ellipsoid forgetting_half_life_samples",
                h,
                50.0,
                1e9,
            )?;
        }
        check_range(
            "online ellipsoid max_axis_ratio",
            self.max_axis_ratio,
            1.0,
            f64::MAX,
        )?;
        check_range(
            "online ellipsoid max_condition",
            self.max_condition,
            1.0,
            f64::MAX,
        )?;
        check_positive("online ellipsoid max_residual_rel", self.max_residual_rel)?;
        check_positive(
            "online ellipsoid max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        if let Some(f) = self.expected_field {
            check_positive("online ellipsoid expected_field", f)?;
        }
        Ok(())
    }
}

type Sums = ConicSums<3, MONOMIALS_3D>;
type Slots = Retained<3, SPHERE_CELLS>;

/// The equal-area direction cell of `h` (as [`quality::sphere_coverage`]: bands uniform in
/// `z/|h|`, sectors of longitude). `None` at the centre or for non-finite values.
#[inline]
fn cell(h: &Vector3<f64>) -> Option<usize> {
    let n = h.norm();
    if !(n > 0.0 && n.is_finite()) {
        return None;
    }
    let band = (((h.z / n).clamp(-1.0, 1.0) + 1.0) * 0.5 * SPHERE_BANDS as f64) as usize;
    let t = if h.x == 0.0 && h.y == 0.0 {
        0.0
    } else {
        turns(h.y, h.x)
    };
    let sector = ((t * SPHERE_SECTORS as f64) as usize).min(SPHERE_SECTORS - 1);
    Some(band.min(SPHERE_BANDS - 1) * SPHERE_SECTORS + sector)
}

/// Share of the cells holding a live retained reading, seen through calibration `m`.
fn coverage_of(slots: &Slots, now: u64, lifetime: u64, m: &CompassCalibration3d) -> f64 {
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
struct Refresh {
    sums: Sums,
    slots: Slots,
    stage: u8,
    scatter: SMatrix<f64, 10, 10>,
    centre: Vector3<f64>,
    scale: f64,
    ellipsoid: Option<Ellipsoid>,
    cal: CompassCalibration3d,
    field: f64,
    coverage: f64,
    residual_rms_rel: f64,
    info: SMatrix<f64, PARAMS, PARAMS>,
    condition: f64,
    sigma: f64,
    l_inv: Option<SMatrix<f64, PARAMS, PARAMS>>,
    worst: f64,
    map: Option<CompassCalibration3d>,
    outcome: Option<Result<Solution<CompassCalibration3d>>>,
}

impl Refresh {
    fn start(sums: &Sums, slots: &Slots) -> Self {
        Self {
            sums: *sums,
            slots: *slots,
            stage: 0,
            scatter: SMatrix::zeros(),
            centre: Vector3::zeros(),
            scale: 1.0,
            ellipsoid: None,
            cal: CompassCalibration3d::identity(),
            field: 0.0,
            coverage: 0.0,
            residual_rms_rel: 0.0,
            info: SMatrix::zeros(),
            condition: f64::INFINITY,
            sigma: f64::INFINITY,
            l_inv: None,
            worst: 0.0,
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

    fn step(&mut self, cfg: &OnlineEllipsoidConfig, lifetime: u64) -> bool {
        if self.outcome.is_some() {
            return true;
        }
        match self.stage {
            0 => self.pre_check(cfg, lifetime),
            1 => self.normalise(),
            2 => self.fit(cfg),
            3 => self.cover(lifetime),
            4 => self.inform(),
            5 => self.condition(),
            s if s < STAGES - 1 => self.bound_chunk(usize::from(s - BOUND_FIRST_STAGE)),
            _ => self.finish(cfg),
        }
        self.stage += 1;
        self.outcome.is_some()
    }

    /// Stage 0: too few readings; as the batch fit, refuse before fitting when, seen from
    /// the centre of their bounding box, the readings fill too few direction cells.
    fn pre_check(&mut self, cfg: &OnlineEllipsoidConfig, lifetime: u64) {
        let count = self.sums.count;
        if count < u64::from(cfg.min_samples) {
            return self.fail(Error::TooFewPoints {
                got: count as usize,
                need: cfg.min_samples as usize,
            });
        }
        let now = self.sums.count;
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in self.slots.live(now, lifetime) {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let centre = (lo + hi) * 0.5;
        let pre = quality::sphere_coverage(self.slots.live(now, lifetime), &centre);
        if let Err(e) = quality::require_sphere_coverage(pre, cfg.min_coverage) {
            self.map = Some(CompassCalibration3d {
                hard_iron: centre,
                soft_iron: Matrix3::identity(),
            })
            .filter(|m| m.hard_iron.iter().all(|x| x.is_finite()));
            self.fail(e);
        }
    }

    /// Stage 1: normalise; refuse equal and coplanar readings.
    fn normalise(&mut self) {
        let Some((s, centre, scale)) = self.sums.normalised(&LAYOUT_3D) else {
            return self.fail(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            });
        };
        (self.scatter, self.centre, self.scale) = (s, centre, scale);
        // Σ qqᵀ from the quadratic terms' entries in the constant term's column (the
        // off-diagonal terms carry a factor 2).
        let w = self.sums.weight();
        let cov = Matrix3::new(
            s[(0, 9)],
            0.5 * s[(5, 9)],
            0.5 * s[(4, 9)],
            0.5 * s[(5, 9)],
            s[(1, 9)],
            0.5 * s[(3, 9)],
            0.5 * s[(4, 9)],
            0.5 * s[(3, 9)],
            s[(2, 9)],
        ) / w;
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

    /// Stage 2: the direct fit and its calibration.
    fn fit(&mut self, cfg: &OnlineEllipsoidConfig) {
        let e = match solve_direct(&self.scatter)
            .and_then(|k| quadric_to_ellipsoid(&k, cfg.max_axis_ratio))
        {
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
        self.map = Some(cal);
    }

    /// Stage 3: coverage of the calibrated directions.
    fn cover(&mut self, lifetime: u64) {
        self.coverage = coverage_of(&self.slots, self.sums.count, lifetime, &self.cal);
    }

    /// Stage 4: residual and information matrix from the scatter of the calibrated
    /// readings' design vector (see the two-axis module), and its inverse factor.
    fn inform(&mut self) {
        let Some(e) = self.ellipsoid else { return };
        let t = LAYOUT_3D.design_map(&e.unit_map, &(-(e.unit_map * e.centre)));
        let su = t * self.scatter * t.transpose();
        let mut k0 = SVector::<f64, 10>::zeros();
        (k0[0], k0[1], k0[2], k0[9]) = (1.0, 1.0, 1.0, -1.0);
        let ss = 0.25 * (k0.transpose() * su * k0)[0].max(0.0);
        let w = self.sums.weight();
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
        match sigma_kappa(ss, w, self.sums.effective_count(), PARAMS) {
            Some((sigma, kappa)) => {
                self.sigma = sigma;
                self.l_inv = inverse_factor(&self.info).map(|l| l * kappa.sqrt());
            }
            None => {
                self.sigma = f64::INFINITY;
                self.l_inv = None;
            }
        }
    }

    /// Stage 5: condition number of the information matrix.
    fn condition(&mut self) {
        self.condition = sym_eigen9(&self.info)
            .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
            .unwrap_or(f64::INFINITY);
    }

    /// Stages 6–21: the worst of `trace(G A⁻¹ Gᵀ)` over 16 of the lattice directions,
    /// `G(u)` the Jacobian of the direction error `(I − uuᵀ)(E u − d)` (see
    /// `crate::quality`).
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
        }
    }

    /// Last stage: the report and the refusals, in the order of the batch fit.
    fn finish(&mut self, cfg: &OnlineEllipsoidConfig) {
        let bound = if self.l_inv.is_some() {
            let b = (BOUND_SIGMAS * self.sigma * self.worst.sqrt()).to_degrees();
            if b.is_finite() { b } else { f64::INFINITY }
        } else {
            f64::INFINITY
        };
        let quality = quality::with_expected_field(
            CompassQuality {
                fit: FitQuality {
                    points: self.sums.count as usize,
                    coverage: self.coverage,
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
        let checked = quality::require_sphere_coverage(self.coverage, cfg.min_coverage)
            .and_then(|()| {
                if !(quality.fit.condition <= cfg.max_condition) {
                    Err(Error::Degenerate {
                        reason: "the orientations seen do not determine the ellipsoid (information matrix ill-conditioned); tumble the sensor about a third axis",
                    })
                } else if !(quality.fit.residual_rms_rel <= cfg.max_residual_rel) {
                    Err(Error::NotAnEllipse {
                        detail: " (the readings stray from the best ellipsoid by more than max_residual_rel of the field)",
                    })
                } else if !(quality.heading_error_bound_deg() * self.t_factor() <= cfg.max_heading_error_bound_deg)
                {
                    Err(Error::Degenerate {
                        reason: "the predicted heading error exceeds max_heading_error_bound_deg: too few readings or too much noise for the part of the sphere covered; record a full tumble away from magnetic disturbances",
                    })
                } else {
                    Ok(())
                }
            });
        self.outcome = Some(checked.map(|()| Solution {
            params: self.cal,
            quality,
        }));
    }
}

/// Online least-squares ellipsoid calibrator: the direct fit of
/// [`crate::EllipsoidCalibrator`] from running sums, O(1) memory and O(1) per push.
///
/// ```
/// use nalgebra::Vector3;
/// use truenorth_calib::{OnlineEllipsoidCalibrator, OnlineEllipsoidConfig};
/// use truenorth_core::{Calibrator, Mag3Sample};
///
/// let mut cal = OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default())?;
/// let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
/// for k in 0..500 {
///     // Directions spread over the sphere, a 50-unit field, a (5, −2, 8) hard iron.
///     let z = 1.0 - (2.0 * k as f64 + 1.0) / 500.0;
///     let r = (1.0 - z * z).sqrt();
///     let (s, c) = (golden * k as f64).sin_cos();
///     let mag = Vector3::new(5.0, -2.0, 8.0) + 50.0 * Vector3::new(r * c, r * s, z);
///     cal.push(&Mag3Sample { t_s: k as f64, mag })?;
/// }
/// let sol = cal.solve()?;
/// assert!((sol.params.hard_iron - Vector3::new(5.0, -2.0, 8.0)).norm() < 1e-6);
/// assert!((sol.quality.field_magnitude - 50.0).abs() < 1e-6);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct OnlineEllipsoidCalibrator {
    config: OnlineEllipsoidConfig,
    decay: f64,
    lifetime: u64,
    sums: Sums,
    slots: Slots,
    map: Option<CompassCalibration3d>,
    estimate: Option<Solution<CompassCalibration3d>>,
    next_refresh: u64,
    pending: Option<Refresh>,
}

impl OnlineEllipsoidCalibrator {
    /// A calibrator with the given configuration, or the first invalid parameter, named.
    pub fn new(config: OnlineEllipsoidConfig) -> Result<Self> {
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
    pub fn config(&self) -> &OnlineEllipsoidConfig {
        &self.config
    }

    fn publish(&mut self, r: Refresh) -> bool {
        if let Some(m) = r.map {
            self.map = Some(m);
            self.slots
                .rekey(|p| cell(&m.correct(p)), self.sums.count, self.lifetime);
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

impl Calibrator for OnlineEllipsoidCalibrator {
    type Sample = Mag3Sample;
    type Params = CompassCalibration3d;
    type Quality = CompassQuality;

    /// Adds a reading to the sums (and, when its direction cell is free, to the retained
    /// readings), and runs one stage of a refresh when one is due. O(1), no allocation; a
    /// non-finite sample is refused and changes nothing.
    fn push(&mut self, sample: &Mag3Sample) -> Result<Pushed> {
        check_finite("timestamp t_s", sample.t_s)?;
        check_finite3("magnetometer reading", &sample.mag)?;
        self.sums.add(&LAYOUT_3D, &sample.mag, self.decay)?;
        let now = self.sums.count;
        let slot = match &self.map {
            Some(m) => cell(&m.correct(&sample.mag)),
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

    /// Samples accepted, direction-cell coverage of the retained readings about the current
    /// calibration, and `ready` exactly when [`Calibrator::solve`] succeeds (it runs the
    /// solve: tens of microseconds, independent of the number of readings).
    fn progress(&self) -> Progress {
        let coverage = self
            .map
            .map(|m| coverage_of(&self.slots, self.sums.count, self.lifetime, &m))
            .unwrap_or(0.0);
        Progress {
            samples: self.sums.count as usize,
            coverage,
            ready: self.solve().is_ok(),
        }
    }

    fn solve(&self) -> Result<Solution<CompassCalibration3d>> {
        let mut r = Refresh::start(&self.sums, &self.slots);
        while !r.step(&self.config, self.lifetime) {}
        r.outcome.unwrap_or(Err(Error::NotReady {
            what: "online ellipsoid solution",
            hint: "push readings of a tumble",
        }))
    }

    fn reset(&mut self) {
        self.sums = Sums::new();
        self.slots = Slots::new();
        self.map = None;
        self.estimate = None;
        self.next_refresh = u64::from(self.config.min_samples);
        self.pending = None;
    }
}

impl OnlineCalibrator for OnlineEllipsoidCalibrator {
    /// The latest refresh's successful solution (a refused refresh keeps the previous one).
    fn estimate(&self) -> Option<Solution<CompassCalibration3d>> {
        self.estimate
    }
}

/// The saved state of an [`OnlineEllipsoidCalibrator`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OnlineEllipsoidState {
    /// The configuration.
    pub config: OnlineEllipsoidConfig,
    /// The running sums.
    pub sums: SumsSnapshot,
    /// The retained readings for coverage.
    pub retained: RetainedSnapshot,
    /// The calibration retained readings are sorted by.
    pub sorting: Option<CompassCalibration3d>,
    /// The current estimate.
    pub estimate: Option<Solution<CompassCalibration3d>>,
    /// Sample count at which the next refresh starts.
    pub next_refresh: u64,
    /// A refresh in progress (its stages are run again on restore, with the same result).
    pub pending: Option<PendingRefresh>,
}

impl Persistent for OnlineEllipsoidCalibrator {
    type State = OnlineEllipsoidState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn snapshot(&self) -> Snapshot<OnlineEllipsoidState> {
        Snapshot {
            version: Self::SNAPSHOT_VERSION,
            state: OnlineEllipsoidState {
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

    fn restore(snapshot: Snapshot<OnlineEllipsoidState>) -> Result<Self> {
        check_snapshot_version(snapshot.version, Self::SNAPSHOT_VERSION)?;
        let s = snapshot.state;
        let mut cal = Self::new(s.config)?;
        cal.sums = Sums::restore(&s.sums)?;
        cal.slots = Slots::restore(&s.retained, cal.sums.count)?;
        let finite_cal = |m: &CompassCalibration3d| {
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
