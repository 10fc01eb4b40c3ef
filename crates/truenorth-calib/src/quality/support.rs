//! The support of a set of readings: the directions they were taken in, each counted once.
//!
//! The information matrix `A = Σ φ(uᵢ)φ(uᵢ)ᵀ` of the module documentation of `quality`
//! weighs every reading alike, which is right for the noise of the fit (its 3σ bound) but
//! wrong for judging the geometry: a sensor left lying still for an hour after a good tumble
//! piles thousands of readings into one direction, and `A` — its condition number, and the
//! dilution normalised per reading — then says that the geometry got worse, although the
//! same orientations were seen as before. The geometry is a property of *which* directions
//! were seen, not of how long each was held.
//!
//! So the geometry is judged on the support: the directions binned into cells, each
//! occupied cell counted once with the mean of `φφᵀ` over its readings (2-D: the centre
//! direction of each occupied 0.5° bin, which lies within 0.25° of every reading in it;
//! 3-D: the mean over the readings of each of the [`super::SPHERE_CELLS`] equal-area cells,
//! which keeps readings on a great circle exactly on it, so that a single-axis turn stays
//! exactly undetermined). More readings in directions already seen change nothing; readings
//! in a new cell add a positive semi-definite term. Normalised by the number of occupied
//! cells `K`, the dilution `G = √(K · max_u g(u)ᵀ A_K⁻¹ g(u))` of the support is 2 for an
//! evenly covered circle and √13.5 for an evenly covered sphere, as the per-reading one, and
//! does not depend on how many readings each direction holds. A new cell can raise `G²` by
//! at most the factor `(K + 1)/K` (the information never decreases, the normalisation grows
//! by one), and only where the new direction adds nothing the others had not given.

use core::f64::consts::TAU;

use nalgebra::SMatrix;

use super::bounds::{MONOMIALS_2D, MONOMIALS_3D, information_2d, information_3d};

/// Number of fine bins (0.5° each) used to measure the largest empty arc.
pub(crate) const GAP_BINS: usize = 720;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Fine bins in a quarter turn.
const QUARTER: usize = GAP_BINS / 4;
const _: () = assert!(GAP_BINS.is_multiple_of(4));

/// `(cos kθⱼ, sin kθⱼ)` for `k = 1..=4` at the centre `θⱼ = (j + ½)·2π/GAP_BINS` of each fine
/// bin of the first quarter turn, built at compile time: `e^{iθⱼ}` by rotating `e^{iδ/2}` on
/// by `e^{iδ}` (whose sine and cosine come from their Taylor series, exact to rounding at
/// `δ = 0.5°`; the rotations add ~10⁻¹⁴, far below anything judged with it), then its
/// powers.
static CENTRE_HARMONICS: [[f64; 8]; QUARTER] = centre_harmonics();

/// `(sin x, cos x)` for a small `x` (|x| ≤ 0.01) by their Taylor series to `x¹⁵`.
const fn small_sin_cos(x: f64) -> (f64, f64) {
    let (mut s, mut c) = (0.0, 0.0);
    let (mut ts, mut tc) = (x, 1.0);
    let mut k = 0;
    while k < 8 {
        s += ts;
        c += tc;
        let n = 2.0 * k as f64;
        ts *= -x * x / ((n + 2.0) * (n + 3.0));
        tc *= -x * x / ((n + 1.0) * (n + 2.0));
        k += 1;
    }
    (s, c)
}

const fn centre_harmonics() -> [[f64; 8]; QUARTER] {
    let delta = TAU / GAP_BINS as f64;
    let (sd, cd) = small_sin_cos(delta);
    let (mut s, mut c) = small_sin_cos(0.5 * delta);
    let mut out = [[0.0; 8]; QUARTER];
    let mut j = 0;
    while j < QUARTER {
        let (mut sk, mut ck) = (s, c);
        let mut k = 0;
        while k < 4 {
            out[j][2 * k] = ck;
            out[j][2 * k + 1] = sk;
            (ck, sk) = (ck * c - sk * s, sk * c + ck * s);
            k += 1;
        }
        (c, s) = (c * cd - s * sd, s * cd + c * sd);
        j += 1;
    }
    out
}

/// The support of a 2-D set: the monomial sums of the information matrix over the centre
/// directions of the occupied 0.5° bins, and how many bins are occupied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Support2d {
    /// `Σ xⁱ yʲ` over the occupied bins' centre directions, in the order of
    /// `information_2d`.
    pub sums: [f64; MONOMIALS_2D],
    /// Occupied bins.
    pub cells: usize,
}

impl Support2d {
    /// The support of the occupied fine bins `occupied` (one flag per 0.5° bin).
    ///
    /// Every monomial of degree 2 to 4 in `(cos θ, sin θ)` is a sum of harmonics `cos kθ`,
    /// `sin kθ` with `k ≤ 4`, so eight sums over the occupied bins' centres give all twelve.
    /// A quarter turn on multiplies `e^{ikθ}` by `iᵏ`, so the four bins a quarter turn apart
    /// share one entry of the table [`CENTRE_HARMONICS`] (the first quarter's), weighted by
    /// their flags: one loop over a quarter of the bins, without branches.
    pub(crate) fn of_bins(occupied: &[bool; GAP_BINS]) -> Self {
        let flag = |j: usize| f64::from(u8::from(occupied[j]));
        let (mut c, mut s) = ([0.0; 5], [0.0; 5]);
        let mut n = 0.0;
        for (j, t) in CENTRE_HARMONICS.iter().enumerate() {
            let o: [f64; 4] = core::array::from_fn(|q| flag(j + q * QUARTER));
            // Σ_q o_q i^{kq}: a + b (k = 4), a − b (k = 2), d + ie (k = 1), d − ie (k = 3).
            let (a, b, d, e) = (o[0] + o[2], o[1] + o[3], o[0] - o[2], o[1] - o[3]);
            c[1] += d * t[0] - e * t[1];
            s[1] += d * t[1] + e * t[0];
            c[2] += (a - b) * t[2];
            s[2] += (a - b) * t[3];
            c[3] += d * t[4] + e * t[5];
            s[3] += d * t[5] - e * t[4];
            c[4] += (a + b) * t[6];
            s[4] += (a + b) * t[7];
            n += a + b;
        }
        let cells = n as usize;
        // The monomials in the order of `information_2d`, by the product formulas
        // (x = cos θ, y = sin θ).
        let sums = [
            0.5 * (n + c[2]),
            0.5 * s[2],
            0.5 * (n - c[2]),
            0.25 * (3.0 * c[1] + c[3]),
            0.25 * (s[1] + s[3]),
            0.25 * (c[1] - c[3]),
            0.25 * (3.0 * s[1] - s[3]),
            0.125 * (3.0 * n + 4.0 * c[2] + c[4]),
            0.125 * (2.0 * s[2] + s[4]),
            0.125 * (n - c[4]),
            0.125 * (2.0 * s[2] - s[4]),
            0.125 * (3.0 * n - 4.0 * c[2] + c[4]),
        ];
        Self { sums, cells }
    }

    /// The information matrix of the support.
    pub(crate) fn information(&self) -> SMatrix<f64, 5, 5> {
        information_2d(&self.sums)
    }
}

/// The support of a 3-D set: the monomial sums of the information matrix, each reading
/// weighted by one over the number of readings in its equal-area cell, and how many cells
/// are occupied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Support3d {
    /// `Σ wᵢ · (monomial of uᵢ)` in the order of `monomial_tuples_3d`, `wᵢ = 1/n(cell of i)`.
    pub sums: [f64; MONOMIALS_3D],
    /// Occupied cells.
    pub cells: usize,
}

impl Support3d {
    /// The information matrix of the support.
    pub(crate) fn information(&self) -> SMatrix<f64, 9, 9> {
        information_3d(&self.sums)
    }
}

/// `√(cells · worst(L⁻¹))`, the dilution of a support whose information matrix is
/// `info = L Lᵀ` (infinite when it is singular or has fewer cells than parameters).
pub(crate) fn support_dilution<const P: usize>(
    info: &SMatrix<f64, P, P>,
    cells: usize,
    worst: impl Fn(&SMatrix<f64, P, P>) -> f64,
) -> f64 {
    if cells < P {
        return f64::INFINITY;
    }
    let l_inv = info.cholesky().and_then(|c| {
        c.l()
            .solve_lower_triangular(&SMatrix::<f64, P, P>::identity())
    });
    let g = l_inv.map_or(f64::INFINITY, |l| (cells as f64 * worst(&l)).sqrt());
    if g.is_finite() { g } else { f64::INFINITY }
}

#[cfg(test)]
mod tests {
    use super::super::bounds::{monomials_2d, worst_2d};
    use super::*;

    /// The harmonic sums from the table give the monomial sums of the occupied centres
    /// computed one by one with the library's trigonometry.
    #[test]
    fn harmonic_sums_match_the_sums_over_bins() {
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        for trial in 0..200 {
            let mut occupied = [false; GAP_BINS];
            // Runs of random lengths, sparse to nearly full, wrapping round the end.
            let density = (trial % 10) as u64 + 1;
            for o in occupied.iter_mut() {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                *o = rng % 11 < density;
            }
            let got = Support2d::of_bins(&occupied);
            let mut want = [0.0; MONOMIALS_2D];
            let mut cells = 0;
            for (j, _) in occupied.iter().enumerate().filter(|(_, o)| **o) {
                let (y, x) = ((j as f64 + 0.5) * TAU / GAP_BINS as f64).sin_cos();
                for (w, v) in want.iter_mut().zip(monomials_2d(x, y)) {
                    *w += v;
                }
                cells += 1;
            }
            assert_eq!(got.cells, cells);
            for (g, w) in got.sums.iter().zip(want) {
                assert!((g - w).abs() < 1e-9, "{g} against {w}");
            }
        }
    }

    /// Every bin occupied: the support of an even circle, dilution 2 (the per-reading value
    /// of evenly spread readings), condition 2.
    #[test]
    fn a_full_circle_of_bins_has_the_even_dilution() {
        let s = Support2d::of_bins(&[true; GAP_BINS]);
        assert_eq!(s.cells, GAP_BINS);
        let g = support_dilution(&s.information(), s.cells, worst_2d);
        assert!((g - super::super::DILUTION_EVEN_CIRCLE).abs() < 1e-9, "{g}");
        // Four bins a quarter turn apart do not determine the five parameters.
        let mut four = [false; GAP_BINS];
        for k in 0..4 {
            four[k * GAP_BINS / 4] = true;
        }
        let s = Support2d::of_bins(&four);
        assert!(support_dilution(&s.information(), s.cells, worst_2d).is_infinite());
    }
}
