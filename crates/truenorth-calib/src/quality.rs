//! Quality measures shared by every compass calibrator: how much of the circle (or sphere)
//! the data cover, how far the calibrated readings stray from a circle (sphere), how well
//! the geometry determines the calibration, and how large a heading error that allows.
//!
//! Every calibrator in this crate fills its [`CompassQuality`] through [`assess_2d`] /
//! [`quality_2d`] (or [`quality_3d`]), so the numbers mean the same thing whichever method
//! produced them.
//!
//! # The three parts of the heading error
//!
//! * `heading_error_3sigma_deg` — three standard deviations of the heading error caused by
//!   the uncertainty of the fitted parameters, at the worst heading (derived below). It is
//!   the error the calibration adds to every later heading; it shrinks as `1/√N` with more
//!   readings. Per-reading noise is **not** in it.
//! * `heading_error_systematic_deg` — the deterministic heading error the method's model
//!   leaves even with perfect data: 0 for the least-squares ellipse and ellipsoid (their
//!   model represents any symmetric soft iron); for the seed methods that fit a circle or an
//!   axis-aligned ellipse, the peak of the two-cycle error of an unremoved rotated soft iron
//!   (see the `seed_quality` module).
//! * `heading_noise_rms_deg` — the RMS heading noise of one calibrated reading, estimated
//!   from the residuals that remain once the model (and, for the seed methods, the
//!   systematic two-cycle part) is taken out: for isotropic sensor noise of standard
//!   deviation `σ·F` per axis the radial residual and the heading error of one reading both
//!   have standard deviation `σ` (radians). Averaging readings reduces it; recalibrating
//!   does not.
//!
//! [`CompassQuality::heading_error_bound_deg`] is the first two added: a bound on the error
//! of the calibration itself. A single reading's heading errs by that plus its own noise.
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
//! error at direction `u` then has variance `σ²·g(u)ᵀA⁻¹g(u)`, and the bound reported as
//! `heading_error_3sigma_deg` is
//!
//! `bound = 3 · σ · max_u √(g(u)ᵀ A⁻¹ g(u))`   (3 σ at the worst heading, in degrees),
//!
//! with `σ² = Σ rᵢ² / (N − 5)` from the calibrated residuals `rᵢ = |hᵢ|/F − 1`. So it grows
//! with the residuals, shrinks as `1/√N` with the point count, and grows steeply as the
//! coverage shrinks (the directions `uᵢ` fill `A`). For `N` points spread evenly round the
//! circle `g(u)ᵀA⁻¹g(u) = 4/N` at every heading, so the bound is `3·2σ/√N` radians. It is the
//! error the calibration adds to every later heading; each reading's own noise adds about
//! `σ` radians (RMS) on top, reported apart as `heading_noise_rms_deg`. It does not include
//! model errors the residuals cannot reveal (a rotated soft iron, a tilted sensor, a field
//! that changes during the turn); the seed methods report the part of those their model is
//! known to leave as `heading_error_systematic_deg`.
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
use truenorth_core::{CompassQuality, Error, FitQuality, Result, angle_diff};

use crate::linalg::{condition_from_eigenvalues, sym_eigen5, sym_eigen9};
use crate::lm::{BLOCK, blocks, dot_block, sum_block};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// Number of fine bins (0.5° each) used to measure the largest empty arc.
pub(crate) const GAP_BINS: usize = 720;

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
pub(crate) fn turns(y: f64, x: f64) -> f64 {
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
    // Written as one division of selected operands so that it compiles without branches
    // (and vectorises in the quality pass); the value is the same.
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let z = num / den;
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
        self.mark(turns(d.y, d.x));
    }

    /// Marks the direction `t` (a share of a full turn in [0, 1), from [`turns`]).
    #[inline]
    fn mark(&mut self, t: f64) {
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

/// Marks the equal-area cells of the directions `d` (a block of vectors, one array per
/// coordinate, with their norms `n`) in `filled`, for the first `len` rows whose norm is
/// positive and finite.
///
/// The cell: Archimedes — the area of a band of the unit sphere is 2π·Δz, so equal steps in
/// `z = d_z/|d|` give equal-area bands — and equal sectors of longitude in each band. The
/// arithmetic goes over the whole block first, in a loop the compiler vectorises; only the
/// marking is done point by point.
#[inline(always)]
fn mark_sphere_cells(
    d: &[[f64; BLOCK]; 3],
    n: &[f64; BLOCK],
    len: usize,
    filled: &mut [bool; SPHERE_CELLS],
) -> usize {
    let mut cell = [0u32; BLOCK];
    for i in 0..BLOCK {
        let band = ((d[2][i] / n[i]).clamp(-1.0, 1.0) + 1.0) * 0.5 * SPHERE_BANDS as f64;
        // Computed either way and then chosen, so that the loop has no branch.
        let ti = turns(d[1][i], d[0][i]);
        let t = if d[0][i] == 0.0 && d[1][i] == 0.0 {
            0.0
        } else {
            ti
        };
        // Both in [0, 8] and [0, 16] (or NaN, for a row that is skipped), where `as u32`
        // truncates like `as usize`; u32 keeps the conversion in SIMD registers.
        let b = (band as u32).min(SPHERE_BANDS as u32 - 1);
        let sector = ((t * SPHERE_SECTORS as f64) as u32).min(SPHERE_SECTORS as u32 - 1);
        cell[i] = b * SPHERE_SECTORS as u32 + sector;
    }
    let mut marked = 0;
    for i in 0..len {
        if n[i] > 0.0 && n[i].is_finite() {
            filled[cell[i] as usize] = true;
            marked += 1;
        }
    }
    marked
}

/// Share of the [`SPHERE_CELLS`] equal-area direction cells that hold at least one point,
/// seen from `centre`, in [0, 1]. Non-finite points are skipped. Allocates nothing.
pub fn sphere_coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector3<f64>>,
    centre: &Vector3<f64>,
) -> f64 {
    let mut filled = [false; SPHERE_CELLS];
    let mut points = points.into_iter();
    // A block of points at a time (see `crate::lm::BLOCK`).
    loop {
        let mut d = [[0.0; BLOCK]; 3];
        let mut len = 0;
        for p in points.by_ref().take(BLOCK) {
            for (k, dk) in d.iter_mut().enumerate() {
                dk[len] = p[k] - centre[k];
            }
            len += 1;
        }
        if len == 0 {
            break;
        }
        let n: [f64; BLOCK] = core::array::from_fn(|i| {
            (d[0][i] * d[0][i] + d[1][i] * d[1][i] + d[2][i] * d[2][i]).sqrt()
        });
        mark_sphere_cells(&d, &n, len, &mut filled);
    }
    filled.iter().filter(|&&f| f).count() as f64 / SPHERE_CELLS as f64
}

/// How far the tangent of the locus turns along `points` taken in order, radians (≥ 0): a
/// lower bound that errs short.
///
/// A centre-free measure of the arc that a set of readings covers. Tangents at opposite ends
/// of a diameter of any ellipse are parallel, so over half a turn the tangent of the raw
/// locus turns by exactly π whatever the hard and soft iron; over a shorter arc it turns by
/// less. A calibrator whose own centre is wrong sees its readings spread over more of the
/// circle than they are; this measure cannot be fooled that way.
///
/// The turning is taken between successive chords. On a convex curve each chord's direction
/// lies between the tangents at its two ends (mean value theorem), so the result never exceeds
/// the tangent's turning from the first point to the last: half an ellipse never reads as
/// more than π. It falls short by up to one chord's turning at each end. The wrapped
/// differences telescope, so noise enters only through the two end chords; chords shorter
/// than `min_chord` (and than 10⁻¹² of the locus size) are skipped, the next point being
/// taken from the last one kept, so that noisy points a short way apart cannot turn the
/// chords at random. Fewer than three usable points give 0.
pub fn locus_turning_rad<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    min_chord: f64,
) -> f64 {
    let mut prev_point: Option<Vector2<f64>> = None;
    let mut dir: Option<f64> = None;
    let mut turned = 0.0;
    for p in points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let Some(q) = prev_point else {
            prev_point = Some(*p);
            continue;
        };
        let d = p - q;
        if d.norm() <= min_chord.max(1e-12 * p.norm().max(q.norm()).max(f64::MIN_POSITIVE)) {
            continue;
        }
        let a = d.y.atan2(d.x);
        if let Some(prev) = dir {
            turned += angle_diff(a, prev);
        }
        dir = Some(a);
        prev_point = Some(*p);
    }
    turned.abs()
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
    pub quality: CompassQuality,
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
    // Sums of the squared residuals and of the monomials of `u` that make up the
    // information matrix (see `information_2d`).
    let mut sums = [0.0; MONOMIALS_2D];
    let mut ss = 0.0;
    let mut n = 0usize;
    let inv_f = 1.0 / field;
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    // A block of points at a time (see `crate::lm::BLOCK`): first every point's direction,
    // its products, its residual and its heading, then the sums and the bins.
    let mut ux = [0.0; BLOCK];
    let mut uy = [0.0; BLOCK];
    let mut xx = [0.0; BLOCK];
    let mut xy = [0.0; BLOCK];
    let mut yy = [0.0; BLOCK];
    let mut r2 = [0.0; BLOCK];
    let mut t = [0.0; BLOCK];
    for ([px, py], len) in blocks(points) {
        for i in 0..BLOCK {
            // h = soft_iron · (p − hard_iron), as `CompassCalibration2d::correct`.
            let (dx, dy) = (px[i] - c.x, py[i] - c.y);
            let (hx, hy) = (
                s[(0, 0)] * dx + s[(0, 1)] * dy,
                s[(1, 0)] * dx + s[(1, 1)] * dy,
            );
            let rho = (hx * hx + hy * hy).sqrt();
            // Non-finite readings are skipped, and the rows past the end of the data: their
            // direction is set to zero, which adds nothing to the sums and marks the row
            // as skipped for the bins (a kept row's direction is a unit vector).
            let keep = rho > 0.0 && rho.is_finite() && i < len;
            let inv_rho = 1.0 / rho;
            let (x, y) = if keep {
                (hx * inv_rho, hy * inv_rho)
            } else {
                (0.0, 0.0)
            };
            let r = rho * inv_f - 1.0;
            ux[i] = x;
            uy[i] = y;
            xx[i] = x * x;
            xy[i] = x * y;
            yy[i] = y * y;
            r2[i] = if keep { r * r } else { 0.0 };
            t[i] = turns(hy, hx);
        }
        // In the order of `information_2d`: x², xy, y², x³, x²y, xy², y³, x⁴, x³y, x²y²,
        // xy³, y⁴.
        let products = [
            (&ux, &ux),
            (&ux, &uy),
            (&uy, &uy),
            (&xx, &ux),
            (&xx, &uy),
            (&yy, &ux),
            (&yy, &uy),
            (&xx, &xx),
            (&xx, &xy),
            (&xx, &yy),
            (&xy, &yy),
            (&yy, &yy),
        ];
        for (sk, (a, b)) in sums.iter_mut().zip(products) {
            *sk += dot_block(a, b);
        }
        ss += sum_block(&r2);
        for i in 0..len {
            if ux[i] != 0.0 || uy[i] != 0.0 {
                bins.mark(t[i]);
                n += 1;
            }
        }
    }
    let info = information_2d(&sums);
    let coverage = bins.coverage();
    let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
    let condition = sym_eigen5(&info)
        .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
        .unwrap_or(f64::INFINITY);
    Assessment2d {
        quality: CompassQuality {
            fit: FitQuality {
                points: n,
                coverage: coverage.fraction,
                residual_rms_rel,
                condition,
            },
            heading_error_3sigma_deg: bound_2d(&info, ss, n),
            heading_error_systematic_deg: 0.0,
            heading_noise_rms_deg: noise_rms_deg(ss, n, 5),
            field_magnitude: field,
            field_ratio_to_expected: None,
        },
        coverage,
    }
}

/// Coverage of the calibrated readings `cal(p)` of `points` about the origin, with the same
/// arithmetic as [`assess_2d`] (so a calibrator that refuses on it and reports
/// [`assess_2d`]'s coverage sees the same bins). Non-finite readings are skipped. Allocates
/// nothing.
pub fn calibrated_coverage_2d(points: &[Vector2<f64>], cal: &CompassCalibration2d) -> Coverage {
    let mut bins = AngleBins::new();
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    for p in points {
        let (dx, dy) = (p.x - c.x, p.y - c.y);
        let (hx, hy) = (
            s[(0, 0)] * dx + s[(0, 1)] * dy,
            s[(1, 0)] * dx + s[(1, 1)] * dy,
        );
        let rho = (hx * hx + hy * hy).sqrt();
        if rho > 0.0 && rho.is_finite() {
            bins.mark(turns(hy, hx));
        }
    }
    bins.coverage()
}

/// The 2-D quality report of `cal` on `points` (see [`assess_2d`]).
pub fn quality_2d(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> CompassQuality {
    assess_2d(points, cal, field).quality
}

/// For an information matrix `A = L Lᵀ` of `P` parameters fitted to `n` points with residual
/// sum of squares `sum_sq`: `L⁻¹`, formed once so that every test direction costs one small
/// product instead of two triangular solves, and the residual standard deviation
/// `σ = √(sum_sq / (n − P))`. `None` when `n ≤ P` or `A` is not positive definite.
fn whitened<const P: usize>(
    info: &SMatrix<f64, P, P>,
    sum_sq: f64,
    n: usize,
) -> Option<(SMatrix<f64, P, P>, f64)> {
    if n <= P {
        return None;
    }
    let l_inv = info
        .cholesky()?
        .l()
        .solve_lower_triangular(&SMatrix::<f64, P, P>::identity())?;
    Some((l_inv, (sum_sq / (n - P) as f64).sqrt()))
}

/// `3 σ max_u √(gᵀA⁻¹g)` in degrees over 72 headings; infinite when `A` is singular or
/// there are no more points than parameters.
fn bound_2d(info: &SMatrix<f64, 5, 5>, sum_sq: f64, n: usize) -> f64 {
    // gᵀA⁻¹g = ‖L⁻¹g‖²: each heading costs one small matrix-vector product.
    let Some((l_inv, sigma)) = whitened(info, sum_sq, n) else {
        return f64::INFINITY;
    };
    let mut worst: f64 = 0.0;
    for k in 0..72 {
        let th = TAU * k as f64 / 72.0;
        let (s, c) = th.sin_cos();
        let (ux, uy, px, py) = (c, s, -s, c);
        let g = SVector::<f64, 5>::new(-px, -py, px * ux, px * uy + py * ux, py * uy);
        worst = worst.max((l_inv * g).norm_squared());
    }
    let b = (BOUND_SIGMAS * sigma * worst.sqrt()).to_degrees();
    if b.is_finite() { b } else { f64::INFINITY }
}

/// The 3-D quality report of `cal` on `points`: share of the sphere's direction cells
/// filled, residual RMS relative to `field` (the radius of the calibrated sphere; see
/// [`mean_corrected_norm_3d`] if the calibrator defines none), the condition number of the
/// 9-parameter information matrix and the direction-error bound of the module
/// documentation. Non-finite readings are skipped. Allocates nothing.
pub fn quality_3d(
    points: &[Vector3<f64>],
    cal: &CompassCalibration3d,
    field: f64,
) -> CompassQuality {
    let mut filled = [false; SPHERE_CELLS];
    // Sums of the squared residuals and of the monomials of `u` that make up the
    // information matrix (see `information_3d`).
    let mut sums = [0.0; MONOMIALS_3D];
    let mut ss = 0.0;
    let mut n = 0usize;
    let inv_f = 1.0 / field;
    let (s, c) = (&cal.soft_iron, &cal.hard_iron);
    let plan = monomial_plan_3d();
    // A block of points at a time (see `crate::lm::BLOCK`): first every point's direction,
    // its products and its residual, then the sums and the cells. `cols` holds `u_a` in
    // columns 0–2 and the products `u_a u_b` of `QUAD_3D` in columns 3–8.
    let mut cols = [[0.0; BLOCK]; 9];
    let mut h = [[0.0; BLOCK]; 3];
    let mut rho = [0.0; BLOCK];
    let mut r2 = [0.0; BLOCK];
    for (p, len) in blocks(points) {
        for i in 0..BLOCK {
            // h = soft_iron · (p − hard_iron), as `CompassCalibration3d::correct`.
            let d = [p[0][i] - c.x, p[1][i] - c.y, p[2][i] - c.z];
            let hi: [f64; 3] =
                core::array::from_fn(|a| s[(a, 0)] * d[0] + s[(a, 1)] * d[1] + s[(a, 2)] * d[2]);
            let rh = (hi[0] * hi[0] + hi[1] * hi[1] + hi[2] * hi[2]).sqrt();
            // Non-finite readings are skipped, and the rows past the end of the data: a row
            // of zeros adds nothing.
            let k = rh > 0.0 && rh.is_finite() && i < len;
            let inv_rho = 1.0 / rh;
            let ui = hi.map(|x| if k { x * inv_rho } else { 0.0 });
            for a in 0..3 {
                cols[a][i] = ui[a];
                h[a][i] = hi[a];
            }
            for (j, &(a, b)) in QUAD_3D.iter().enumerate() {
                cols[3 + j][i] = ui[a] * ui[b];
            }
            let r = rh * inv_f - 1.0;
            r2[i] = if k { r * r } else { 0.0 };
            rho[i] = rh;
        }
        for (sk, &(a, b)) in sums.iter_mut().zip(&plan) {
            *sk += dot_block(&cols[a], &cols[b]);
        }
        ss += sum_block(&r2);
        n += mark_sphere_cells(&h, &rho, len, &mut filled);
    }
    let info = information_3d(&sums);
    let coverage = filled.iter().filter(|&&f| f).count() as f64 / SPHERE_CELLS as f64;
    let residual_rms_rel = if n > 0 { (ss / n as f64).sqrt() } else { 0.0 };
    let condition = sym_eigen9(&info)
        .map(|(l, _)| condition_from_eigenvalues(l.as_slice()))
        .unwrap_or(f64::INFINITY);
    CompassQuality {
        fit: FitQuality {
            points: n,
            coverage,
            residual_rms_rel,
            condition,
        },
        heading_error_3sigma_deg: bound_3d(&info, ss, n),
        heading_error_systematic_deg: 0.0,
        heading_noise_rms_deg: noise_rms_deg(ss, n, 9),
        field_magnitude: field,
        field_ratio_to_expected: None,
    }
}

/// Per-reading noise, degrees: the residual standard deviation `√(sum_sq / (n − p))` of a
/// fit of `p` parameters (relative to the field, so radians of heading; see the module
/// documentation), or the plain RMS when there are no more points than parameters.
fn noise_rms_deg(sum_sq: f64, n: usize, p: usize) -> f64 {
    let dof = if n > p { n - p } else { n.max(1) };
    (sum_sq / dof as f64).sqrt().to_degrees()
}

/// Number of distinct monomials of degree 2 to 4 in `(u_x, u_y)`.
const MONOMIALS_2D: usize = 12;

/// The 2-D information matrix `A = Σ φ(u)φ(u)ᵀ`, `φ = (−u_x, −u_y, u_x², 2u_xu_y, u_y²)`,
/// from the sums over the points of the monomials it is made of, in the order
/// `(x², xy, y², x³, x²y, xy², y³, x⁴, x³y, x²y², xy³, y⁴)` of `u = (x, y)`.
///
/// Every entry of `φφᵀ` is a monomial of degree 2, 3 or 4 in `u` times a constant, and 12
/// distinct monomials fill its 15 distinct entries: summing those is the same matrix with
/// fewer products per point. NaN if a sum overflowed, which makes the condition and the
/// bound infinite.
fn information_2d(m: &[f64; MONOMIALS_2D]) -> SMatrix<f64, 5, 5> {
    let [x2, xy, y2, x3, x2y, xy2, y3, x4, x3y, x2y2, xy3, y4] = *m;
    #[rustfmt::skip]
    let a = SMatrix::<f64, 5, 5>::from_row_slice(&[
        x2,         xy,         -x3,        -2.0 * x2y, -xy2,
        xy,         y2,         -x2y,       -2.0 * xy2, -y3,
        -x3,        -x2y,       x4,         2.0 * x3y,  x2y2,
        -2.0 * x2y, -2.0 * xy2, 2.0 * x3y,  4.0 * x2y2, 2.0 * xy3,
        -xy2,       -y3,        x2y2,       2.0 * xy3,  y4,
    ]);
    finite_or_nan(a)
}

/// Number of distinct monomials of degree 2 to 4 in `(u_x, u_y, u_z)`: 6 + 10 + 15.
const MONOMIALS_3D: usize = 31;

/// The index pairs `(a, b)` of the quadratic terms `u_a u_b` of `φ` in the 3-D model, in
/// the parameter order `(e₁₁, e₁₂, e₁₃, e₂₂, e₂₃, e₃₃)` of the module documentation.
const QUAD_3D: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The monomials of degree 2, 3 and 4 in `u = (u₀, u₁, u₂)`, each once, as sorted index
/// tuples `(a, b)`, `(a, b, c)`, `(a, b, c, d)` (unused places zero) with their degree, in
/// lexicographic order within each degree: the order of the sums behind
/// [`information_3d`].
fn monomial_tuples_3d() -> [([usize; 4], usize); MONOMIALS_3D] {
    let mut out = [([0; 4], 0); MONOMIALS_3D];
    let mut k = 0;
    for a in 0..3 {
        for b in a..3 {
            out[k] = ([a, b, 0, 0], 2);
            k += 1;
        }
    }
    for a in 0..3 {
        for b in a..3 {
            for c in b..3 {
                out[k] = ([a, b, c, 0], 3);
                k += 1;
            }
        }
    }
    for a in 0..3 {
        for b in a..3 {
            for c in b..3 {
                for d in c..3 {
                    out[k] = ([a, b, c, d], 4);
                    k += 1;
                }
            }
        }
    }
    out
}

/// For each monomial of [`monomial_tuples_3d`], two columns of the quality pass whose
/// product it is (columns 0–2: `u_a`; 3–8: `u_a u_b` in the order of [`QUAD_3D`]): degree 2
/// is `u_a · u_b`, degree 3 `(u_a u_b) · u_c`, degree 4 `(u_a u_b) · (u_c u_d)`.
fn monomial_plan_3d() -> [(usize, usize); MONOMIALS_3D] {
    let quad = |a: usize, b: usize| 3 + QUAD_3D.iter().position(|&p| p == (a, b)).unwrap_or(0);
    monomial_tuples_3d().map(|(t, deg)| match deg {
        2 => (t[0], t[1]),
        3 => (quad(t[0], t[1]), t[2]),
        _ => (quad(t[0], t[1]), quad(t[2], t[3])),
    })
}

/// The 3-D information matrix `A = Σ φ(u)φ(u)ᵀ`,
/// `φ = (−u_x, −u_y, −u_z, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²)`, from the sums of
/// the monomials of [`monomial_tuples_3d`]: 31 distinct monomials fill its 45 distinct
/// entries (see [`information_2d`]). NaN if a sum overflowed.
fn information_3d(m: &[f64; MONOMIALS_3D]) -> SMatrix<f64, 9, 9> {
    // φ_i = factor_i · (the monomial with indices idx_i): −u_a for i < 3, then the
    // quadratic terms, with factor 1 on the diagonal pairs and 2 off it.
    let term = |i: usize| -> (f64, [usize; 2], usize) {
        if i < 3 {
            (-1.0, [i, 0], 1)
        } else {
            let (a, b) = QUAD_3D[i - 3];
            (if a == b { 1.0 } else { 2.0 }, [a, b], 2)
        }
    };
    let tuples = monomial_tuples_3d();
    let mut a = SMatrix::<f64, 9, 9>::zeros();
    for i in 0..9 {
        for j in i..9 {
            let (si, ii, ni) = term(i);
            let (sj, ij, nj) = term(j);
            let mut idx = [0usize; 4];
            idx[..ni].copy_from_slice(&ii[..ni]);
            idx[ni..ni + nj].copy_from_slice(&ij[..nj]);
            idx[..ni + nj].sort_unstable();
            let k = tuples
                .iter()
                .position(|&(t, deg)| deg == ni + nj && t[..deg] == idx[..deg])
                .unwrap_or(0);
            let v = si * sj * m[k];
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
    finite_or_nan(a)
}

/// `a`, or all NaN if any entry is not finite.
fn finite_or_nan<const P: usize>(a: SMatrix<f64, P, P>) -> SMatrix<f64, P, P> {
    if a.iter().all(|x| x.is_finite()) {
        a
    } else {
        SMatrix::from_element(f64::NAN)
    }
}

/// Number of test directions (a Fibonacci lattice) over which the 3-D bound takes its worst.
const BOUND_DIRECTIONS_3D: usize = 256;

/// `3 σ max_u √trace(G(u) A⁻¹ G(u)ᵀ)` in degrees, `G(u)` the 3×9 Jacobian of the direction
/// error `(I − uuᵀ)(E u − d)`; infinite when `A` is singular or `N ≤ 9`.
fn bound_3d(info: &SMatrix<f64, 9, 9>, sum_sq: f64, n: usize) -> f64 {
    // trace(G A⁻¹ Gᵀ) = ‖L⁻¹ Gᵀ‖²_F: each direction costs one small matrix product.
    let Some((l_inv, sigma)) = whitened(info, sum_sq, n) else {
        return f64::INFINITY;
    };
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
        worst = worst.max((l_inv * g.transpose()).norm_squared());
    }
    let b = (BOUND_SIGMAS * sigma * worst.sqrt()).to_degrees();
    if b.is_finite() { b } else { f64::INFINITY }
}

/// Sets [`CompassQuality::field_ratio_to_expected`]: the fitted field over `expected_field` (e.g.
/// from the World Magnetic Model, in the input unit). Leaves it `None` when no positive
/// finite expectation is given.
pub fn with_expected_field(
    mut quality: CompassQuality,
    expected_field: Option<f64>,
) -> CompassQuality {
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
pub fn field_mismatch(quality: &CompassQuality, expected_field: f64) -> Option<FieldMismatch> {
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
        assert_eq!(q.fit.coverage, 1.0);
        assert!(q.fit.residual_rms_rel < 1e-12);
        assert!((q.fit.condition - 2.0).abs() < 1e-2, "{}", q.fit.condition);
        assert!(q.heading_error_3sigma_deg < 1e-9);
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
            (q.heading_error_3sigma_deg / expect - 1.0).abs() < 0.1,
            "{} vs {expect}",
            q.heading_error_3sigma_deg
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
            assert!(q.fit.condition > last.0 && q.heading_error_3sigma_deg > last.1);
            last = (q.fit.condition, q.heading_error_3sigma_deg);
        }
    }

    /// The 3-D bound through `L⁻¹` equals the one from solving with `A` for each direction.
    #[test]
    fn bound_3d_matches_solving_with_the_information_matrix() {
        let mut rng = SplitMix64::new(13);
        let m = SMatrix::<f64, 9, 9>::from_fn(|_, _| rng.normal(1.0));
        let info = m * m.transpose() + SMatrix::<f64, 9, 9>::identity();
        let chol = info.cholesky().unwrap();
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
            for (j, &(a, b)) in QUAD_3D.iter().enumerate() {
                let mut eu = Vector3::zeros();
                eu[a] += u[b];
                if a != b {
                    eu[b] += u[a];
                }
                g.set_column(3 + j, &(proj * eu));
            }
            worst = worst.max((g * chol.solve(&g.transpose())).trace());
        }
        let (sum_sq, n) = (0.5, 100);
        let expect = (BOUND_SIGMAS * (sum_sq / (n - 9) as f64).sqrt() * worst.sqrt()).to_degrees();
        let got = bound_3d(&info, sum_sq, n);
        assert!((got / expect - 1.0).abs() < 1e-12, "{got} vs {expect}");
    }

    /// The information matrices built from monomial sums equal `Σ φφᵀ` summed directly.
    #[test]
    fn information_from_monomials_matches_outer_products() {
        let mut rng = SplitMix64::new(11);
        let dirs3: Vec<Vector3<f64>> = (0..37)
            .map(|_| {
                let v = Vector3::new(rng.normal(1.0), rng.normal(1.0), rng.normal(1.0));
                v / v.norm()
            })
            .collect();

        let mut direct2 = SMatrix::<f64, 5, 5>::zeros();
        let mut sums2 = [0.0; MONOMIALS_2D];
        for d in &dirs3 {
            let u = d.xy() / d.xy().norm();
            let phi = SVector::<f64, 5>::new(-u.x, -u.y, u.x * u.x, 2.0 * u.x * u.y, u.y * u.y);
            direct2 += phi * phi.transpose();
            let (x, y) = (u.x, u.y);
            let m = [
                x * x,
                x * y,
                y * y,
                x * x * x,
                x * x * y,
                x * y * y,
                y * y * y,
                x.powi(4),
                x.powi(3) * y,
                x * x * y * y,
                x * y.powi(3),
                y.powi(4),
            ];
            for (s, v) in sums2.iter_mut().zip(m) {
                *s += v;
            }
        }
        assert!((information_2d(&sums2) - direct2).amax() < 1e-12);

        let mut direct3 = SMatrix::<f64, 9, 9>::zeros();
        let mut sums3 = [0.0; MONOMIALS_3D];
        for u in &dirs3 {
            let phi = SVector::<f64, 9>::from([
                -u.x,
                -u.y,
                -u.z,
                u.x * u.x,
                2.0 * u.x * u.y,
                2.0 * u.x * u.z,
                u.y * u.y,
                2.0 * u.y * u.z,
                u.z * u.z,
            ]);
            direct3 += phi * phi.transpose();
            for (s, (idx, deg)) in sums3.iter_mut().zip(monomial_tuples_3d()) {
                *s += idx[..deg].iter().map(|&a| u[a]).product::<f64>();
            }
        }
        assert!((information_3d(&sums3) - direct3).amax() < 1e-12);
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
        assert_eq!(q.fit.coverage, 1.0);
        assert!((q.fit.condition - 2.5).abs() < 0.01, "{}", q.fit.condition);
        assert!(q.fit.residual_rms_rel < 1e-12);
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
        // One-degree chords: short by about a degree, never long.
        let full = locus_turning_rad(&ellipse_arc(360.0, 0.0, &m, 361), 0.0).to_degrees();
        assert!((358.5..=360.0).contains(&full), "{full}");
        let half = locus_turning_rad(&ellipse_arc(180.0, 10.0, &m, 181), 0.0).to_degrees();
        assert!((178.5..=180.0 + 1e-9).contains(&half), "{half}");
        assert_eq!(locus_turning_rad(&[Vector2::new(1.0, 1.0); 5], 0.0), 0.0);
    }

    proptest! {
        /// Over at most half an ellipse the chords turn by at most π, whatever the affine
        /// distortion.
        #[test]
        fn half_an_ellipse_or_less_never_reads_as_more(
            span in 20.0f64..180.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 200), 0.0).to_degrees();
            prop_assert!(t <= 180.0 + 1e-9, "span {span} turned {t}");
        }

        /// Skipping short chords keeps half an ellipse at most half, and loses at most two
        /// chords' turning on a full one.
        #[test]
        fn a_minimum_chord_keeps_the_laws(
            span in 20.0f64..180.0,
            start in 0.0f64..360.0,
            a in 0.7f64..1.5, b in 0.7f64..1.5, c in -0.3f64..0.3,
            min_chord in 0.0f64..0.3,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.3);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 300), min_chord).to_degrees();
            prop_assert!(t <= 180.0 + 1e-9, "span {span} turned {t}");
            // Skipping errs short, by at most the last chord's turning at each end: two chord
            // angles at the smallest radius of curvature, b²/a at the ends of the major axis.
            let e = m.symmetric_eigenvalues();
            let rho_min = e.min().powi(2) / e.max();
            let chord_deg = 2.0 * (min_chord / (2.0 * rho_min)).min(1.0).asin().to_degrees();
            let full = locus_turning_rad(&ellipse_arc(360.0, start, &m, 721), min_chord).to_degrees();
            prop_assert!(full >= 360.0 - 2.0 * chord_deg - 1.0, "a full turn read as {full} (chord {chord_deg}°)");
        }

        #[test]
        fn more_than_half_an_ellipse_reads_as_more_than_half(
            span in 190.0f64..359.0,
            start in 0.0f64..360.0,
            a in 0.5f64..2.0, b in 0.5f64..2.0, c in -0.5f64..0.5,
        ) {
            let m = Matrix2::new(a, c, c, b);
            prop_assume!(m.determinant() > 0.1);
            let t = locus_turning_rad(&ellipse_arc(span, start, &m, 400), 0.0).to_degrees();
            prop_assert!(t >= 180.0, "span {span} turned {t}");
        }

        #[test]
        fn any_input_is_finite(pts in proptest::collection::vec((proptest::num::f64::ANY, proptest::num::f64::ANY), 0..20)) {
            let v: Vec<Vector2<f64>> = pts.into_iter().map(|(x, y)| Vector2::new(x, y)).collect();
            let t = locus_turning_rad(&v, 0.0);
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
            let q = CompassQuality { field_magnitude: fitted, ..CompassQuality::default() };
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
            let q = CompassQuality { field_magnitude: fitted, ..CompassQuality::default() };
            prop_assert!(field_mismatch(&q, expected).is_none());
        }
    }
}
