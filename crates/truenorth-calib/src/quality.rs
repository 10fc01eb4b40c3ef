//! Quality measures shared by every compass calibrator: how much of the circle (or sphere)
//! the data cover, how far the calibrated readings stray from a circle (sphere), how well
//! the geometry determines the calibration, and how large a heading error that allows.
//!
//! Every calibrator in this crate fills its [`Quality`] through [`assess_2d`] /
//! [`quality_2d`] (or [`quality_3d`]), so the numbers mean the same thing whichever method
//! produced them.
//!
//! # The heading-error bound (derivation)
//!
//! Write a calibrated reading as `h = F·u`, `u` a unit vector, `F` the field. Any 2-D
//! calibration differs from the truth, to first order, by a small centre error `F·d` and a
//! small symmetric matrix error `E` (the antisymmetric part of a soft-iron matrix is a pure
//! rotation that no circle or ellipse fit can see; it is assumed zero, which is why the fits
//! choose the symmetric square root). The estimate then maps a point on the true circle to
//! `(I + E)(h − F·d)`, so
//!
//! * its radial residual, relative to `F`, is `uᵀE u − uᵀd` = `φ(u)ᵀ p` with
//!   `p = (d_x, d_y, e₁₁, e₁₂, e₂₂)` and `φ(u) = (−u_x, −u_y, u_x², 2u_xu_y, u_y²)`;
//! * its angle (heading) error is `u⊥ᵀ(E u − d)` = `g(u)ᵀ p`, `u⊥` the unit vector 90°
//!   ahead of `u`.
//!
//! A least-squares calibration estimates `p` from the residuals of its `N` points; if those
//! are independent with standard deviation `σ` (relative to `F`), the estimate's covariance
//! is `σ²·A⁻¹` with the information matrix `A = Σᵢ φ(uᵢ)φ(uᵢ)ᵀ` (Gauss–Markov). The heading
//! error at direction `u` then has variance `σ²·g(u)ᵀA⁻¹g(u)`, and the bound reported is
//!
//! `bound = 3 · σ · max_u √(g(u)ᵀ A⁻¹ g(u))`   (3 σ at the worst heading, in degrees),
//!
//! with `σ² = Σ rᵢ² / (N − 5)` from the calibrated residuals `rᵢ = |hᵢ|/F − 1`. So it grows
//! with the residuals, shrinks as `1/√N` with the point count, and grows steeply as the
//! coverage shrinks (the directions `uᵢ` fill `A`). For `N` points spread evenly round the
//! circle `g(u)ᵀA⁻¹g(u) = 4/N` at every heading, so the bound is `3·2σ/√N` radians. It is the
//! error the calibration adds to every later heading; each reading's own noise adds about
//! `σ` radians (RMS) on top. It does not include model errors the residuals cannot reveal
//! (a rotated soft iron, a tilted sensor, a field that changes during the turn).
//!
//! The `condition` reported is the condition number of `A` (largest over smallest
//! eigenvalue): 2 for a full, evenly covered circle, growing without bound as the arc
//! shortens. It is the condition of the linearised least-squares problem every 2-D
//! calibration solves, in coordinates normalised by the field, so it does not depend on
//! units or on where the hard iron is.
//!
//! The 3-D report is the same with `p = (d, e₁₁, e₁₂, e₁₃, e₂₂, e₂₃, e₃₃)` (9 parameters,
//! condition 2.5 for an evenly covered sphere), the angle error being the component of
//! `E u − d` perpendicular to `u` (the error of the field *direction*); the bound is the
//! worst over the whole sphere of `3 σ √(trace of its covariance)`. The heading of a level
//! compass errs by at most that divided by `cos(dip)`.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use core::f64::consts::TAU;

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth_core::{Error, Quality, Result, angle_diff};

use crate::linalg::{condition_from_eigenvalues, sym_eigen5, sym_eigen9};
use crate::lm::NormalAccumulator;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// Number of fine bins (0.5° each) used to measure the largest empty arc.
const GAP_BINS: usize = 720;

/// Equal-area latitude bands of the direction cells on the sphere (uniform in `sin(lat)`,
/// so every band has the same area).
pub const SPHERE_BANDS: usize = 8;

/// Longitude sectors per band of the direction cells on the sphere.
pub const SPHERE_SECTORS: usize = 16;

/// Number of equal-area direction cells on the sphere (`SPHERE_BANDS × SPHERE_SECTORS`,
/// each about 320 square degrees, roughly 18° × 18° at the equator).
pub const SPHERE_CELLS: usize = SPHERE_BANDS * SPHERE_SECTORS;

/// The shortest arc of a turn, degrees, from which a 2-D calibration is accepted.
///
/// A half circle does not determine an ellipse (the missing half is extrapolated, and a
/// small noise at its ends moves the centre a lot), so every 2-D calibrator refuses spans up
/// to a little beyond 180°; the margin keeps a noisy half circle from slipping through.
pub const MIN_ARC_DEG: f64 = 200.0;

/// The smallest share of the direction cells on the sphere ([`SPHERE_CELLS`]) from which a
/// 3-D calibration is accepted.
///
/// One turn about a single axis traces a great circle, which passes through about 20–25 %
/// of the cells and does not determine an ellipsoid; turns about two or more axes reach
/// well beyond this.
pub const MIN_SPHERE_COVERAGE: f64 = 0.3;

/// How many standard deviations the heading-error bound spans.
pub const BOUND_SIGMAS: f64 = 3.0;

/// How much of the circle a set of points covers, seen from a centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    /// Share of the [`COVERAGE_BINS`] direction bins that hold at least one point, in [0, 1].
    pub fraction: f64,
    /// The largest empty arc between consecutive occupied directions, radians (measured in
    /// bins of 0.5°).
    pub largest_gap_rad: f64,
}

impl Coverage {
    /// The arc covered: 2π minus the largest gap, radians.
    pub fn span_rad(&self) -> f64 {
        TAU - self.largest_gap_rad
    }
}

/// Direction of `(x, y)` (not both zero) as a share of a full turn in [0, 1), counted
/// counter-clockwise from +x.
///
/// Bins only need the angle to a small fraction of a bin, and `atan2` was the largest cost
/// of the whole quality pass, so this uses the minimax polynomial of Abramowitz & Stegun
/// (1964) 4.4.49 for `atan z` on [0, 1] (|error| ≤ 2·10⁻⁸ rad) with an octant reduction.
#[inline]
fn turns(y: f64, x: f64) -> f64 {
    use core::f64::consts::{FRAC_PI_2, PI};
    const A: [f64; 8] = [
        -0.333_331_452_8,
        0.199_935_508_5,
        -0.142_088_994_4,
        0.106_562_639_3,
        -0.075_289_640_0,
        0.042_909_613_8,
        -0.016_165_736_7,
        0.002_866_225_7,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let z = if swap { ax / ay } else { ay / ax };
    let z2 = z * z;
    let mut poly = A[7];
    for &a in A[..7].iter().rev() {
        poly = poly * z2 + a;
    }
    let first = z + z * z2 * poly;
    let mut a = if swap { FRAC_PI_2 - first } else { first };
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        a = TAU - a;
    }
    let t = a / TAU;
    if t >= 1.0 { 0.0 } else { t }
}

/// Occupancy of coarse (coverage) and fine (gap) direction bins.
struct AngleBins {
    coarse: [bool; COVERAGE_BINS],
    fine: [bool; GAP_BINS],
    any: bool,
}

impl AngleBins {
    fn new() -> Self {
        Self {
            coarse: [false; COVERAGE_BINS],
            fine: [false; GAP_BINS],
            any: false,
        }
    }

    /// Marks the direction of `d` (skipped if zero or not finite).
    #[inline]
    fn add(&mut self, d: &Vector2<f64>) {
        if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
            return;
        }
        let t = turns(d.y, d.x);
        let c = (t * COVERAGE_BINS as f64) as usize;
        let f = (t * GAP_BINS as f64) as usize;
        self.coarse[c.min(COVERAGE_BINS - 1)] = true;
        self.fine[f.min(GAP_BINS - 1)] = true;
        self.any = true;
    }

    fn coverage(&self) -> Coverage {
        if !self.any {
            return Coverage {
                fraction: 0.0,
                largest_gap_rad: TAU,
            };
        }
        let n = self.coarse.iter().filter(|&&f| f).count();
        // Largest run of empty fine bins, going once round the circle from an occupied one.
        let start = self.fine.iter().position(|&f| f).unwrap_or(0);
        let (mut gap, mut run) = (0usize, 0usize);
        for k in 1..=GAP_BINS {
            if self.fine[(start + k) % GAP_BINS] {
                run = 0;
            } else {
                run += 1;
                gap = gap.max(run);
            }
        }
        Coverage {
            fraction: n as f64 / COVERAGE_BINS as f64,
            largest_gap_rad: gap as f64 * TAU / GAP_BINS as f64,
        }
    }
}

/// Coverage of `points` seen from `centre`: share of 10° bins filled and the largest empty
/// arc. Non-finite points are skipped. Allocates nothing.
pub fn coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    centre: &Vector2<f64>,
) -> Coverage {
    let mut bins = AngleBins::new();
    for p in points {
        bins.add(&(p - centre));
    }
    bins.coverage()
}

/// The equal-area cell of a direction (any non-zero finite vector), in `0..SPHERE_CELLS`.
#[inline]
fn sphere_cell(d: &Vector3<f64>) -> Option<usize> {
    let n = d.norm();
    if !(n > 0.0 && n.is_finite()) {
        return None;
    }
    // Archimedes: the area of a band of the unit sphere is 2π·Δz, so equal steps in z give
    // equal-area bands.
    let z = (d.z / n).clamp(-1.0, 1.0);
    let band = (((z + 1.0) * 0.5 * SPHERE_BANDS as f64) as usize).min(SPHERE_BANDS - 1);
    let t = if d.x == 0.0 && d.y == 0.0 {
        0.0
    } else {
        turns(d.y, d.x)
    };
    let sector = ((t * SPHERE_SECTORS as f64) as usize).min(SPHERE_SECTORS - 1);
    Some(band * SPHERE_SECTORS + sector)
}

/// Share of the [`SPHERE_CELLS`] equal-area direction cells that hold at least one point,
/// seen from `centre`, in [0, 1]. Non-finite points are skipped. Allocates nothing.
pub fn sphere_coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector3<f64>>,
    centre: &Vector3<f64>,
) -> f64 {
    let mut filled = [false; SPHERE_CELLS];
    for p in points {
        if let Some(c) = sphere_cell(&(p - centre)) {
            filled[c] = true;
        }
    }
    filled.iter().filter(|&&f| f).count() as f64 / SPHERE_CELLS as f64
}

/// How far the tangent of the locus turns along `points` taken in order, radians (≥ 0).
///
/// A centre-free measure of the arc that a set of readings covers. Tangents at opposite ends
/// of a diameter of any ellipse are parallel, so over half a turn the tangent of the raw
/// locus turns by exactly π whatever the hard and soft iron; over a shorter arc it turns by
/// less. A calibrator whose own centre is wrong sees its readings spread over more of the
/// circle than they are; this measure cannot be fooled that way.
///
/// The directions of successive chords stand in for the tangent at chord midpoints; their
/// wrapped differences telescope, so noise enters only at the two ends, and half the end
/// chords' turn is added at each end to reach the first and last points. Chords shorter than
/// 10⁻¹² of the locus size are skipped. Fewer than three usable points give 0.
pub fn locus_turning_rad<'a>(points: impl IntoIterator<Item = &'a Vector2<f64>>) -> f64 {
    let mut prev_point: Option<Vector2<f64>> = None;
    let mut dir: Option<f64> = None;
    let (mut turned, mut first_turn, mut last_turn) = (0.0, None, 0.0);
    for p in points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let Some(q) = prev_point else {
            prev_point = Some(*p);
            continue;
        };
        let d = p - q;
        if d.norm() <= 1e-12 * p.norm().max(q.norm()).max(f64::MIN_POSITIVE) {
            continue;
        }
        let a = d.y.atan2(d.x);
        if let Some(prev) = dir {
            let turn = angle_diff(a, prev);
            turned += turn;
            first_turn.get_or_insert(turn);
            last_turn = turn;
        }
        dir = Some(a);
        prev_point = Some(*p);
    }
    // End correction: the chords' directions are the tangent half a chord in from each end;
    // the turning there is about half the turn between the two end chords. Local, so it
    // holds where the turning bunches up (the ends of a long axis).
    match first_turn {
        Some(first) => (turned + 0.5 * (first + last_turn)).abs(),
        None => 0.0,
    }
}

/// Refuses a 2-D calibration whose data span less than `need_deg` of heading (see
/// [`MIN_ARC_DEG`]) with [`Error::InsufficientCoverage`].
pub fn require_arc(coverage: &Coverage, need_deg: f64) -> Result<()> {
    let covered_deg = coverage.span_rad().to_degrees();
    if covered_deg < need_deg {
        Err(Error::InsufficientCoverage {
            // Rounded down, so a refusal never prints a span equal to the one it needs.
            covered_deg: covered_deg.floor(),
            need_deg,
        })
    } else {
        Ok(())
    }
}

/// Refuses a 3-D calibration whose data fill less than `need` of the direction cells (see
/// [`MIN_SPHERE_COVERAGE`]) with [`Error::InsufficientCoverage`]; the degrees reported are
/// the solid angle covered, as an equivalent share of 360°.
pub fn require_sphere_coverage(fraction: f64, need: f64) -> Result<()> {
    if fraction < need {
        Err(Error::InsufficientSphereCoverage {
            covered_fraction: fraction,
            need_fraction: need,
        })
    } else {
        Ok(())
    }
}

/// A 2-D quality report and the coverage behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assessment2d {
    /// The report to return with the solution.
    pub quality: Quality,
    /// Coverage of the calibrated headings (seen from the origin of the calibrated circle).
    pub coverage: Coverage,
}

/// Everything the 2-D report needs, in one pass over the raw readings: the calibrated
/// readings' residuals against `field`, their heading bins, and the information matrix
/// of the module documentation. `field` is the radius of the calibrated circle (for a
/// calibrator that does not define one, pass [`mean_corrected_norm_2d`]).
///
/// Non-finite readings are skipped. Allocates nothing.
pub fn assess_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d, field: f64) -> Assessment2d {
    let mut bins = AngleBins::new();
    let mut acc = NormalAccumulator::<5>::new();
    let (mut n, mut ss) = (0usize, 0.0);
    let inv_f = 1.0 / field;
    for p in points {
        let h = cal.correct(p);
        let rho = h.norm();
        if !(rho > 0.0 && rho.is_finite()) {
            continue;
        }
        bins.add(&h);
        let r = rho * inv_f - 1.0;
        ss += r * r;
        n += 1;
        let u = h / rho;
        acc.add(&[-u.x, -u.y, u.x * u.x, 2.0 * u.x * u.y, u.y * u.y], 0.0);
    }
    let info = information(&acc);
    let coverage = bins.coverage();
    let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
    let condition = sym_eigen5(&info)
        .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
        .unwrap_or(f64::INFINITY);
    let heading_error_bound_deg = bound_2d(&info, ss, n);
    Assessment2d {
        quality: Quality {
            points: n,
            coverage: coverage.fraction,
            residual_rms_rel,
            condition,
            heading_error_bound_deg,
            field_magnitude: field,
            field_ratio_to_expected: None,
        },
        coverage,
    }
}

/// The 2-D quality report of `cal` on `points` (see [`assess_2d`]).
pub fn quality_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d, field: f64) -> Quality {
    assess_2d(points, cal, field).quality
}

/// `3 σ max_u √(gᵀA⁻¹g)` in degrees over 72 headings; infinite when `A` is singular or
/// there are no more points than parameters.
fn bound_2d(info: &SMatrix<f64, 5, 5>, sum_sq: f64, n: usize) -> f64 {
    if n <= 5 {
        return f64::INFINITY;
    }
    let Some(chol) = info.cholesky() else {
        return f64::INFINITY;
    };
    let sigma = (sum_sq / (n - 5) as f64).sqrt();
    let mut worst: f64 = 0.0;
    for k in 0..72 {
        let th = TAU * k as f64 / 72.0;
        let (s, c) = th.sin_cos();
        let (ux, uy, px, py) = (c, s, -s, c);
        let g = SVector::<f64, 5>::new(-px, -py, px * ux, px * uy + py * ux, py * uy);
        worst = worst.max(g.dot(&chol.solve(&g)));
    }
    let b = (BOUND_SIGMAS * sigma * worst.sqrt()).to_degrees();
    if b.is_finite() { b } else { f64::INFINITY }
}

/// The 3-D quality report of `cal` on `points`: share of the sphere's direction cells
/// filled, residual RMS relative to `field` (the radius of the calibrated sphere; see
/// [`mean_corrected_norm_3d`] if the calibrator defines none), the condition number of the
/// 9-parameter information matrix and the direction-error bound of the module
/// documentation. Non-finite readings are skipped. Allocates nothing.
pub fn quality_3d(points: &[Vector3<f64>], cal: &CompassCalibration3d, field: f64) -> Quality {
    let mut filled = [false; SPHERE_CELLS];
    let mut acc = NormalAccumulator::<9>::new();
    let (mut n, mut ss) = (0usize, 0.0);
    let inv_f = 1.0 / field;
    for p in points {
        let h = cal.correct(p);
        let rho = h.norm();
        if !(rho > 0.0 && rho.is_finite()) {
            continue;
        }
        if let Some(c) = sphere_cell(&h) {
            filled[c] = true;
        }
        let r = rho * inv_f - 1.0;
        ss += r * r;
        n += 1;
        acc.add(&phi3(&(h / rho)), 0.0);
    }
    let info = information(&acc);
    let coverage = filled.iter().filter(|&&f| f).count() as f64 / SPHERE_CELLS as f64;
    let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
    let condition = sym_eigen9(&info)
        .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
        .unwrap_or(f64::INFINITY);
    Quality {
        points: n,
        coverage,
        residual_rms_rel,
        condition,
        heading_error_bound_deg: bound_3d(&info, ss, n),
        field_magnitude: field,
        field_ratio_to_expected: None,
    }
}

/// The information matrix `Σ φφᵀ` (NaN if it overflowed, which makes the condition and
/// the bound infinite).
fn information<const P: usize>(acc: &NormalAccumulator<P>) -> SMatrix<f64, P, P> {
    acc.finish()
        .map(|ne| ne.jtj)
        .unwrap_or_else(|| SMatrix::from_element(f64::NAN))
}

/// `φ(u)` of the 3-D model: radial residual = `φ(u)ᵀ (d, e₁₁, e₁₂, e₁₃, e₂₂, e₂₃, e₃₃)`.
#[inline]
fn phi3(u: &Vector3<f64>) -> [f64; 9] {
    [
        -u.x,
        -u.y,
        -u.z,
        u.x * u.x,
        2.0 * u.x * u.y,
        2.0 * u.x * u.z,
        u.y * u.y,
        2.0 * u.y * u.z,
        u.z * u.z,
    ]
}

/// Number of test directions (a Fibonacci lattice) over which the 3-D bound takes its worst.
const BOUND_DIRECTIONS_3D: usize = 256;

/// `3 σ max_u √trace(G(u) A⁻¹ G(u)ᵀ)` in degrees, `G(u)` the 3×9 Jacobian of the direction
/// error `(I − uuᵀ)(E u − d)`; infinite when `A` is singular or `N ≤ 9`.
fn bound_3d(info: &SMatrix<f64, 9, 9>, sum_sq: f64, n: usize) -> f64 {
    if n <= 9 {
        return f64::INFINITY;
    }
    let Some(chol) = info.cholesky() else {
        return f64::INFINITY;
    };
    let sigma = (sum_sq / (n - 9) as f64).sqrt();
    let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let mut worst: f64 = 0.0;
    for k in 0..BOUND_DIRECTIONS_3D {
        let z = 1.0 - (2.0 * k as f64 + 1.0) / BOUND_DIRECTIONS_3D as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (golden * k as f64).sin_cos();
        let u = Vector3::new(r * c, r * s, z);
        let proj = nalgebra::Matrix3::identity() - u * u.transpose();
        let mut g = SMatrix::<f64, 3, 9>::zeros();
        for kk in 0..3 {
            g.set_column(kk, &(-proj.column(kk)));
        }
        // E_kl u for (11, 12, 13, 22, 23, 33): the symmetric basis matrices applied to u.
        let pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
        for (j, &(a, b)) in pairs.iter().enumerate() {
            let mut eu = Vector3::zeros();
            eu[a] += u[b];
            if a != b {
                eu[b] += u[a];
            }
            g.set_column(3 + j, &(proj * eu));
        }
        let x = chol.solve(&g.transpose());
        worst = worst.max((g * x).trace());
    }
    let b = (BOUND_SIGMAS * sigma * worst.sqrt()).to_degrees();
    if b.is_finite() { b } else { f64::INFINITY }
}

/// Sets [`Quality::field_ratio_to_expected`]: the fitted field over `expected_field` (e.g.
/// from the World Magnetic Model, in the input unit). Leaves it `None` when no positive
/// finite expectation is given.
pub fn with_expected_field(mut quality: Quality, expected_field: Option<f64>) -> Quality {
    quality.field_ratio_to_expected = expected_field
        .filter(|e| e.is_finite() && *e > 0.0)
        .map(|e| quality.field_magnitude / e);
    quality
}

/// How far the fitted field may stray from the expected one before [`field_mismatch`] warns:
/// ±15 %. The WMM's own uncertainty is about 1 %, so beyond this the site is disturbed, the
/// unit is wrong, or a 2-axis sensor is tilted (it then sees part of the vertical field).
pub const FIELD_RATIO_TOLERANCE: f64 = 0.15;

/// A fitted field that disagrees with the expected one (e.g. the World Magnetic Model's
/// field at the place and date, converted to the input unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldMismatch {
    /// The fitted field, input unit.
    pub fitted: f64,
    /// The expected field, input unit.
    pub expected: f64,
}

impl FieldMismatch {
    /// fitted / expected.
    pub fn ratio(&self) -> f64 {
        self.fitted / self.expected
    }
}

impl core::fmt::Display for FieldMismatch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "the fitted field {:.4} is {:.2} x the expected {:.4}: a magnetically disturbed site, a wrong unit, or a tilted 2-axis sensor",
            self.fitted,
            self.ratio(),
            self.expected
        )
    }
}

/// A warning when the report's fitted field differs from `expected_field` by more than
/// [`FIELD_RATIO_TOLERANCE`]; `None` when it agrees or no positive finite expectation is given.
pub fn field_mismatch(quality: &Quality, expected_field: f64) -> Option<FieldMismatch> {
    if !(expected_field.is_finite() && expected_field > 0.0) {
        return None;
    }
    let m = FieldMismatch {
        fitted: quality.field_magnitude,
        expected: expected_field,
    };
    // Written so that a NaN ratio (no fitted field) is a mismatch too.
    if (m.ratio() - 1.0).abs() <= FIELD_RATIO_TOLERANCE {
        None
    } else {
        Some(m)
    }
}

/// Mean radius of the calibrated readings, for calibrators that do not fit a radius.
/// Non-finite readings are skipped; 0 if none remain.
pub fn mean_corrected_norm_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> f64 {
    mean_norm(points.iter().map(|p| cal.correct(p).norm()))
}

/// Mean magnitude of the calibrated readings, for calibrators that do not fit a radius.
/// Non-finite readings are skipped; 0 if none remain.
pub fn mean_corrected_norm_3d(points: &[Vector3<f64>], cal: &CompassCalibration3d) -> f64 {
    mean_norm(points.iter().map(|p| cal.correct(p).norm()))
}

fn mean_norm(norms: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for r in norms.filter(|r| r.is_finite()) {
        s += r;
        n += 1;
    }
    if n > 0 { s / n as f64 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;
    use truenorth_core::{NoiseSource, SplitMix64};

    fn circle(n: usize, from_deg: f64, to_deg: f64, radius: f64) -> Vec<Vector2<f64>> {
        (0..n)
            .map(|k| {
                let a = (from_deg + (to_deg - from_deg) * k as f64 / (n - 1) as f64).to_radians();
                Vector2::new(radius * a.cos(), radius * a.sin())
            })
            .collect()
    }

    #[test]
    fn fast_turns_match_atan2() {
        let mut worst: f64 = 0.0;
        for k in 0..100_000 {
            let a = TAU * k as f64 / 100_000.0;
            for r in [1e-3, 1.0, 1e6] {
                let (y, x) = (r * a.sin(), r * a.cos());
                let exact = y.atan2(x).rem_euclid(TAU) / TAU;
                let mut d = (turns(y, x) - exact).abs();
                d = d.min(1.0 - d);
                worst = worst.max(d);
                assert!((0.0..1.0).contains(&turns(y, x)));
            }
        }
        assert!(worst * TAU < 1e-7, "{}", worst * TAU);
        assert_eq!(turns(0.0, 1.0), 0.0);
        assert_eq!(turns(-0.0, 1.0), 0.0);
        assert!((turns(1.0, 0.0) - 0.25).abs() < 1e-12);
        assert!((turns(0.0, -1.0) - 0.5).abs() < 1e-12);
        assert!((turns(-1.0, 0.0) - 0.75).abs() < 1e-12);
    }

    #[test]
    fn coverage_of_full_and_half_circle() {
        let full = circle(360, 0.0, 359.0, 1.0);
        let c = coverage(&full, &Vector2::zeros());
        assert_eq!(c.fraction, 1.0);
        assert!(c.span_rad().to_degrees() > 358.0);
        let half = circle(181, 0.0, 180.0, 1.0);
        let c = coverage(&half, &Vector2::zeros());
        let span = c.span_rad().to_degrees();
        assert!((179.0..=182.0).contains(&span), "{span}");
        assert!(require_arc(&c, MIN_ARC_DEG).is_err());
        assert_eq!(coverage(&[], &Vector2::zeros()).fraction, 0.0);
    }

    #[test]
    fn perfect_circle_report() {
        let pts = circle(3601, 0.0, 360.0, 2.0);
        let q = quality_2d(&pts, &CompassCalibration2d::identity(), 2.0);
        assert_eq!(q.coverage, 1.0);
        assert!(q.residual_rms_rel < 1e-12);
        assert!((q.condition - 2.0).abs() < 1e-2, "{}", q.condition);
        assert!(q.heading_error_bound_deg < 1e-9);
        assert!(with_expected_field(q, Some(4.0)).field_ratio_to_expected == Some(0.5));
    }

    #[test]
    fn bound_matches_closed_form_for_even_coverage() {
        // σ = 1 % radial noise, N evenly spread: bound = 3 · 2σ/√N rad.
        let mut rng = SplitMix64::new(3);
        let n = 2000;
        let pts: Vec<_> = circle(n, 0.0, 360.0 * (n - 1) as f64 / n as f64, 1.0)
            .into_iter()
            .map(|p| p * (1.0 + rng.normal(0.01)))
            .collect();
        let q = quality_2d(&pts, &CompassCalibration2d::identity(), 1.0);
        let expect = (3.0 * 2.0 * 0.01 / (n as f64).sqrt()).to_degrees();
        assert!(
            (q.heading_error_bound_deg / expect - 1.0).abs() < 0.1,
            "{} vs {expect}",
            q.heading_error_bound_deg
        );
    }

    #[test]
    fn shorter_arcs_have_worse_condition_and_bound() {
        let mut rng = SplitMix64::new(5);
        let mut last = (0.0, 0.0);
        for span in [360.0, 270.0, 210.0] {
            let pts: Vec<_> = circle(500, 0.0, span, 1.0)
                .into_iter()
                .map(|p| p * (1.0 + rng.normal(0.01)))
                .collect();
            let q = quality_2d(&pts, &CompassCalibration2d::identity(), 1.0);
            assert!(q.condition > last.0 && q.heading_error_bound_deg > last.1);
            last = (q.condition, q.heading_error_bound_deg);
        }
    }

    #[test]
    fn sphere_report() {
        // Fibonacci sphere: even coverage, condition 2.5.
        let n = 4000;
        let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
        let pts: Vec<_> = (0..n)
            .map(|k| {
                let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let (s, c) = (golden * k as f64).sin_cos();
                Vector3::new(r * c, r * s, z) * 3.0
            })
            .collect();
        let q = quality_3d(&pts, &CompassCalibration3d::identity(), 3.0);
        assert_eq!(q.coverage, 1.0);
        assert!((q.condition - 2.5).abs() < 0.01, "{}", q.condition);
        assert!(q.residual_rms_rel < 1e-12);
        assert_eq!(sphere_coverage(&pts, &Vector3::zeros()), 1.0);
        // A great circle fills few cells.
        let ring: Vec<_> = (0..360)
            .map(|k| {
                let a = (k as f64).to_radians();
                Vector3::new(a.cos(), 0.0, a.sin())
            })
            .collect();
        let f = sphere_coverage(&ring, &Vector3::zeros());
        assert!(f < MIN_SPHERE_COVERAGE, "{f}");
        assert!(require_sphere_coverage(f, MIN_SPHERE_COVERAGE).is_err());
    }
}

#[cfg(test)]
mod turning_tests {
    use super::*;
    use nalgebra::Matrix2;
    use proptest::prelude::*;

    fn ellipse_arc(span_deg: f64, start_deg: f64, m: &Matrix2<f64>, n: usize) -> Vec<Vector2<f64>> {
        (0..n)
            .map(|k| {
                let t = (start_deg + span_deg * k as f64 / (n - 1) as f64).to_radians();
                m * Vector2::new(t.cos(), t.sin()) + Vector2::new(3.0, -2.0)
            })
            .collect()
    }

    #[test]
    fn full_and_half_circles() {
        let m = Matrix2::identity();
        let full = locus_turning_rad(&ellipse_arc(360.0, 0.0, &m, 361)).to_degrees();
        assert!((full - 360.0).abs() < 1.5, "{full}");
        let half = locus_turning_rad(&ellipse_arc(180.0, 10.0, &m, 181)).to_degrees();
        assert!((half - 180.0).abs() < 0.5, "{half}");
        assert_eq!(locus_turning_rad(&[Vector2::new(1.0, 1.0); 5]), 0.0);
    }

    proptest! {
        /// Over at most half an ellipse the tangent turns by at most π, whatever the affine
        /// distortion; over more than half it turns by more.
        #[test]
        fn half_an_ellipse_or_less_never_reads_as_more(
            span in 20.0f64..180.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 200)).to_degrees();
            prop_assert!(t <= 180.0 + 0.5, "span {span} turned {t}");
        }

        #[test]
        fn more_than_half_an_ellipse_reads_as_more_than_half(
            span in 181.0f64..359.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 400)).to_degrees();
            prop_assert!(t >= 180.0 - 0.5, "span {span} turned {t}");
        }

        #[test]
        fn any_input_is_finite(pts in proptest::collection::vec((proptest::num::f64::ANY, proptest::num::f64::ANY), 0..20)) {
            let v: Vec<Vector2<f64>> = pts.into_iter().map(|(x, y)| Vector2::new(x, y)).collect();
            let t = locus_turning_rad(&v);
            prop_assert!(t.is_finite() && t >= 0.0);
        }
    }
}

#[cfg(test)]
mod field_mismatch_tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn warns_exactly_outside_the_tolerance(fitted in 0.0f64..100.0, expected in 1e-3f64..100.0) {
            let q = Quality { field_magnitude: fitted, ..Quality::default() };
            let ratio = fitted / expected;
            let warned = field_mismatch(&q, expected);
            prop_assert_eq!(warned.is_some(), (ratio - 1.0).abs() > FIELD_RATIO_TOLERANCE);
            if let Some(w) = warned {
                prop_assert!((w.ratio() - ratio).abs() < 1e-12);
            }
        }

        #[test]
        fn no_expectation_no_warning(
            fitted in proptest::num::f64::ANY,
            expected in prop_oneof![
                Just(f64::NAN),
                Just(f64::INFINITY),
                Just(f64::NEG_INFINITY),
                Just(0.0),
                -1e9f64..0.0,
            ],
        ) {
            let q = Quality { field_magnitude: fitted, ..Quality::default() };
            prop_assert!(field_mismatch(&q, expected).is_none());
        }
    }
}
