//! Running monomial sums of magnetometer readings: everything a direct conic (2-D) or
//! quadric (3-D) fit needs, in O(1) memory, updated in O(1) per reading.
//!
//! An algebraic fit minimises `Σ (kᵀ ξ(q))²` over the coefficients `k` of a conic or quadric,
//! `ξ(q)` the design vector of the monomials of degree ≤ 2 of a reading `q`. The sum is
//! `kᵀ S k` with the scatter matrix `S = Σ ξ ξᵀ`, whose entries are sums of the monomials
//! of degree ≤ 4 (15 distinct ones in 2-D, 35 in 3-D). Keeping those sums is keeping the
//! whole fit (Fitzgibbon, Pilu & Fisher 1999, §3: "the scatter matrix is all the algorithm
//! needs").
//!
//! Numerical conditioning: the sums are taken in coordinates `q = (p − origin)/scale`, with
//! the first reading as `origin` (it lies on the locus, so every reading is within one
//! diameter of it and no large offset cancels later) and its norm as `scale`. Before a fit
//! the scatter matrix is carried to the coordinates the batch fits use (centroid at the
//! origin, RMS radius 1; see the `normalise` module) by the congruence `S' = T S Tᵀ`: under
//! an affine change of coordinates `q' = A q + b` the design vector of `q'` is a fixed linear
//! combination of that of `q`, `ξ(q') = T ξ(q)`. The same congruence gives the scatter
//! matrix of the calibrated directions, from which the quality report is computed.
//!
//! Forgetting: with a factor `λ < 1` every sum is multiplied by `λ` before a reading is
//! added, so a reading `k` samples old weighs `λᵏ` (a weighted least-squares fit).

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Real, Result};

pub(crate) use crate::online::retained::Retained;
pub use crate::online::retained::RetainedSnapshot;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// A term of a design vector: a constant factor times the monomial with these exponents.
pub(crate) type Term<const D: usize> = (f64, [u8; D]);

/// The conic design vector `(x², xy, y², x, y, 1)` of the 2-D fit (the batch fit's order).
pub(crate) const TERMS_2D: [Term<2>; 6] = [
    (1.0, [2, 0]),
    (1.0, [1, 1]),
    (1.0, [0, 2]),
    (1.0, [1, 0]),
    (1.0, [0, 1]),
    (1.0, [0, 0]),
];

/// The quadric design vector `(x², y², z², 2yz, 2xz, 2xy, 2x, 2y, 2z, 1)` of the 3-D fit
/// (the batch fit's order and factors, after Li & Griffiths 2004).
pub(crate) const TERMS_3D: [Term<3>; 10] = [
    (1.0, [2, 0, 0]),
    (1.0, [0, 2, 0]),
    (1.0, [0, 0, 2]),
    (2.0, [0, 1, 1]),
    (2.0, [1, 0, 1]),
    (2.0, [1, 1, 0]),
    (2.0, [1, 0, 0]),
    (2.0, [0, 1, 0]),
    (2.0, [0, 0, 1]),
    (1.0, [0, 0, 0]),
];

/// Number of monomials of degree ≤ 4 in 2 variables.
pub(crate) const MONOMIALS_2D: usize = 15;
/// Number of monomials of degree ≤ 4 in 3 variables.
pub(crate) const MONOMIALS_3D: usize = 35;

/// The monomials of degree ≤ 4 in `D` variables, by degree, and for each (but the first,
/// `1`) its parent and the variable that multiplies it: `m_j = m_parent · q_var`, so all of
/// them cost one product each.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout<const D: usize, const K: usize, const M: usize> {
    /// The design vector.
    pub terms: [Term<D>; K],
    /// Exponents of each monomial.
    pub exps: [[u8; D]; M],
    /// `(parent, variable)` of each monomial (unused for the first).
    pub parent: [(u8, u8); M],
    /// Index of the first monomial of each degree 0..=4, and `M` after the last.
    pub first: [usize; 6],
    /// Index of the monomial of scatter entry `(a, b)` (the product of terms `a` and `b`).
    pub scatter: [[u8; K]; K],
}

const fn same<const D: usize>(a: &[u8; D], b: &[u8; D]) -> bool {
    let mut i = 0;
    while i < D {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn find<const D: usize, const M: usize>(exps: &[[u8; D]; M], e: &[u8; D]) -> usize {
    let mut k = 0;
    while k < M {
        if same(&exps[k], e) {
            return k;
        }
        k += 1;
    }
    // Unreachable for the layouts built below (every product of two design terms has
    // degree ≤ 4); evaluated at compile time, so an inconsistent layout fails to build.
    panic!("monomial not in layout")
}

impl<const D: usize, const K: usize, const M: usize> Layout<D, K, M> {
    /// The layout of `terms`, built at compile time. `M` must be the number of monomials of
    /// degree ≤ 4 in `D` variables.
    pub const fn new(terms: [Term<D>; K]) -> Self {
        let mut exps = [[0u8; D]; M];
        let mut parent = [(0u8, 0u8); M];
        let mut first = [0usize; 6];
        let mut k = 1;
        let mut deg = 1u8;
        while deg <= 4 {
            first[deg as usize] = k;
            // Every exponent vector in [0, 4]^D, in counting order, with this degree.
            let mut code = 0usize;
            let mut total = 1usize;
            let mut i = 0;
            while i < D {
                total *= 5;
                i += 1;
            }
            while code < total {
                let mut e = [0u8; D];
                let mut c = code;
                let mut s = 0u8;
                let mut i = 0;
                while i < D {
                    e[D - 1 - i] = (c % 5) as u8;
                    s += (c % 5) as u8;
                    c /= 5;
                    i += 1;
                }
                if s == deg {
                    let mut v = 0;
                    while e[v] == 0 {
                        v += 1;
                    }
                    let mut p = e;
                    p[v] -= 1;
                    let pi = find(&exps, &p);
                    exps[k] = e;
                    parent[k] = (pi as u8, v as u8);
                    k += 1;
                }
                code += 1;
            }
            deg += 1;
        }
        assert!(k == M, "M is not the number of monomials of degree <= 4");
        first[5] = M;
        let mut scatter = [[0u8; K]; K];
        let mut a = 0;
        while a < K {
            let mut b = 0;
            while b < K {
                let mut e = [0u8; D];
                let mut i = 0;
                while i < D {
                    e[i] = terms[a].1[i] + terms[b].1[i];
                    i += 1;
                }
                scatter[a][b] = find(&exps, &e) as u8;
                b += 1;
            }
            a += 1;
        }
        Self {
            terms,
            exps,
            parent,
            first,
            scatter,
        }
    }

    /// The monomials of degree ≤ 4 of `q`, each the product of its parent and a
    /// coordinate.
    ///
    /// One loop per degree rather than one over them all: each is short enough for the
    /// compiler to unroll in full, after which the layout's lookups are constants and the
    /// products stay in registers. A single loop over the 34 products of the 3-D layout
    /// stayed a loop, through memory, with a bounds check per lookup: over half of what
    /// a 3-D push cost.
    #[inline(always)]
    pub fn monomials<T: Real>(&self, q: &SVector<T, D>) -> [T; M] {
        let mut m = [T::one(); M];
        self.extend(&mut m, q, 1);
        self.extend(&mut m, q, 2);
        self.extend(&mut m, q, 3);
        self.extend(&mut m, q, 4);
        m
    }

    /// The monomials of degree `deg` from those of `deg - 1`.
    #[inline(always)]
    fn extend<T: Real>(&self, m: &mut [T; M], q: &SVector<T, D>, deg: usize) {
        for j in self.first[deg]..self.first[deg + 1] {
            let (pa, v) = self.parent[j];
            m[j] = m[pa as usize] * q[v as usize];
        }
    }

    /// The scatter matrix `Σ w ξ ξᵀ` from the monomial sums.
    pub fn scatter_matrix(&self, sums: &[f64; M]) -> SMatrix<f64, K, K> {
        SMatrix::from_fn(|a, b| {
            self.terms[a].0 * self.terms[b].0 * sums[self.scatter[a][b] as usize]
        })
    }

    /// `T` with `ξ(A q + b) = T ξ(q)` for every `q`: each term of the design vector of the
    /// image is a product of at most two affine forms of `q`, expanded over the monomials of
    /// degree ≤ 2, which are the design terms up to their factors.
    pub fn design_map(&self, a: &SMatrix<f64, D, D>, b: &SVector<f64, D>) -> SMatrix<f64, K, K> {
        let mut t = SMatrix::<f64, K, K>::zeros();
        // Design-term index of each monomial of degree ≤ 2 (0, unit i, unit i + unit j).
        let idx = |e: [u8; D]| -> usize {
            let mut k = 0;
            while k < K && self.terms[k].1 != e {
                k += 1;
            }
            k.min(K - 1)
        };
        let unit = |i: usize| -> [u8; D] {
            let mut e = [0u8; D];
            e[i] = 1;
            e
        };
        let one = idx([0u8; D]);
        for (row, (f, e)) in self.terms.iter().enumerate() {
            // The variables of the term, with multiplicity.
            let mut vars = [0usize; 2];
            let mut n = 0;
            for (i, &ei) in e.iter().enumerate() {
                for _ in 0..ei {
                    vars[n.min(1)] = i;
                    n += 1;
                }
            }
            // Coefficient of monomial `e_c` goes to column c divided by its factor.
            let mut add = |col: usize, v: f64| t[(row, col)] += f * v / self.terms[col].0;
            match n {
                0 => add(one, 1.0),
                1 => {
                    let i = vars[0];
                    for j in 0..D {
                        add(idx(unit(j)), a[(i, j)]);
                    }
                    add(one, b[i]);
                }
                _ => {
                    let (i, k) = (vars[0], vars[1]);
                    for j in 0..D {
                        for l in j..D {
                            let mut e = unit(j);
                            e[l] += 1;
                            let c = if j == l {
                                a[(i, j)] * a[(k, j)]
                            } else {
                                a[(i, j)] * a[(k, l)] + a[(i, l)] * a[(k, j)]
                            };
                            add(idx(e), c);
                        }
                        add(idx(unit(j)), a[(i, j)] * b[k] + a[(k, j)] * b[i]);
                    }
                    add(one, b[i] * b[k]);
                }
            }
        }
        t
    }
}

/// The 2-D layout.
pub(crate) const LAYOUT_2D: Layout<2, 6, MONOMIALS_2D> = Layout::new(TERMS_2D);
/// The 3-D layout.
pub(crate) const LAYOUT_3D: Layout<3, 10, MONOMIALS_3D> = Layout::new(TERMS_3D);

/// Weighted sums of the monomials of degree ≤ 4 of the readings, in coordinates relative
/// to a reference fixed by the first reading, in the calibrator's float type `T` (a fit
/// converts them to `f64` first, see [`ConicSums::widened`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ConicSums<T: Real, const D: usize, const M: usize> {
    /// The first reading (the coordinates' origin).
    pub origin: SVector<T, D>,
    /// Unit of the coordinates: the norm of the first reading (1 if it was zero).
    pub scale: T,
    /// `Σ w q^α` for every monomial `α` of degree ≤ 4 (the first is `Σ w`).
    pub sums: [T; M],
    /// `Σ w²`, for the effective number of readings under forgetting.
    pub sum_w2: T,
    /// Readings accepted.
    pub count: u64,
}

/// The largest coordinate, relative to the first reading and in its unit, whose fourth
/// power summed over 2⁶⁴ readings stays finite: about 1e61 (the fourth root of 1e308/2⁶⁴ is
/// 1.9e72; the margin keeps the congruences of the fit finite as well).
pub(crate) const MAX_RELATIVE_COORDINATE: f64 = 1e60;

/// [`MAX_RELATIVE_COORDINATE`] for sums in `f32`: the fourth root of 3.4e38/2⁶⁴ is 6.6e4;
/// 1e4 leaves a factor of 1,900 for the products of the fit's first congruences.
pub(crate) const MAX_RELATIVE_COORDINATE_F32: f64 = 1e4;

/// The largest relative coordinate sums in `T` take: [`MAX_RELATIVE_COORDINATE`] where `T`
/// holds it (`f64`), [`MAX_RELATIVE_COORDINATE_F32`] otherwise. A constant once
/// monomorphised.
#[inline(always)]
pub(crate) fn max_relative_coordinate<T: Real>() -> T {
    let wide = T::of(MAX_RELATIVE_COORDINATE);
    if wide.is_finite() {
        wide
    } else {
        T::of(MAX_RELATIVE_COORDINATE_F32)
    }
}

impl<T: Real, const D: usize, const M: usize> ConicSums<T, D, M> {
    /// No readings yet.
    pub fn new() -> Self {
        Self {
            origin: SVector::zeros(),
            scale: T::one(),
            sums: [T::zero(); M],
            sum_w2: T::zero(),
            count: 0,
        }
    }

    /// Adds the finite reading `p` with weight 1 after multiplying the sums by `decay`
    /// (1 for no forgetting). Refuses, changing nothing, a reading so far from the first that
    /// its fourth power would overflow (see [`max_relative_coordinate`]). No allocation; one
    /// product per monomial, all in `T`.
    #[inline]
    pub fn add<const K: usize>(
        &mut self,
        layout: &Layout<D, K, M>,
        p: &SVector<T, D>,
        decay: T,
    ) -> Result<()> {
        if self.count == 0 {
            let n = p.norm();
            self.origin = *p;
            self.scale = if n > T::zero() && n.is_finite() {
                n
            } else {
                T::one()
            };
        }
        let q = (p - self.origin) / self.scale;
        let limit = max_relative_coordinate::<T>();
        // Each coordinate against the limit, the largest found only for the refusal. The
        // same test as `amax() <= limit`: `q` is never NaN (a finite reading, a finite
        // origin, a positive finite scale), and an infinite coordinate fails both.
        if !q.iter().all(|x| x.abs() <= limit) {
            let far = q.amax();
            return Err(Error::OutOfRange {
                what: "magnetometer reading, relative to the first reading and in its unit",
                value: far.to_f64(),
                min: -limit.to_f64(),
                max: limit.to_f64(),
            });
        }
        let m = layout.monomials(&q);
        if decay == T::one() {
            // Without forgetting: `s · 1 + m` is `s + m`, exactly, without the products.
            for (s, mj) in self.sums.iter_mut().zip(m) {
                *s += mj;
            }
            self.sum_w2 += T::one();
        } else {
            for (s, mj) in self.sums.iter_mut().zip(m) {
                *s = *s * decay + mj;
            }
            self.sum_w2 = self.sum_w2 * decay * decay + T::one();
        }
        self.count += 1;
        Ok(())
    }

    /// The sums in `f64` (exact), for a fit: the fit runs in `f64` whatever `T` is, see
    /// the `online_ellipse` module.
    pub fn widened(&self) -> ConicSums<f64, D, M> {
        ConicSums {
            origin: self.origin.map(T::to_f64),
            scale: self.scale.to_f64(),
            sums: self.sums.map(T::to_f64),
            sum_w2: self.sum_w2.to_f64(),
            count: self.count,
        }
    }
}

impl<const D: usize, const M: usize> ConicSums<f64, D, M> {
    /// Sum of the weights.
    pub fn weight(&self) -> f64 {
        self.sums[0]
    }

    /// Effective number of readings, `(Σw)²/Σw²` (Kish 1965): the count itself without
    /// forgetting.
    pub fn effective_count(&self) -> f64 {
        if self.sum_w2 > 0.0 {
            self.sums[0] * self.sums[0] / self.sum_w2
        } else {
            0.0
        }
    }

    /// The weighted scatter matrix in normalised coordinates (centroid at the origin, RMS
    /// radius 1, as the batch fits use) and the map from those coordinates back to the
    /// readings' (`p = centre + scale · q`). `None` when there are no readings or they are
    /// all equal (to rounding).
    pub fn normalised<const K: usize>(
        &self,
        layout: &Layout<D, K, M>,
    ) -> Option<(SMatrix<f64, K, K>, SVector<f64, D>, f64)> {
        let w = self.sums[0];
        if !(w > 0.0) {
            return None;
        }
        // First and second moments: the monomials of degree 1 and 2 are indices 1..=D and
        // the next D(D+1)/2; find the squares by their exponents.
        let mut mean = SVector::<f64, D>::zeros();
        let mut sq = 0.0;
        for (j, e) in layout.exps.iter().enumerate() {
            let deg: u8 = e.iter().sum();
            if deg == 1 {
                let i = e.iter().position(|&x| x == 1).unwrap_or(0);
                mean[i] = self.sums[j] / w;
            } else if deg == 2 && e.contains(&2) {
                sq += self.sums[j] / w;
            }
        }
        let var = sq - mean.norm_squared();
        let r = var.sqrt();
        if !(r > 1e-14 * (1.0 + mean.amax())) || !r.is_finite() {
            return None;
        }
        let a = SMatrix::<f64, D, D>::identity() / r;
        let t = layout.design_map(&a, &(-mean / r));
        let s = t * layout.scatter_matrix(&self.sums) * t.transpose();
        let s = (s + s.transpose()) * 0.5;
        let centre = self.origin + mean * self.scale;
        Some((s, centre, r * self.scale))
    }
}

/// Serialisable running sums of an online least-squares calibrator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SumsSnapshot {
    /// The first reading, origin of the sums' coordinates, input unit.
    pub origin: Vec<f64>,
    /// Unit of the sums' coordinates (the first reading's norm, or 1), input unit.
    pub scale: f64,
    /// Weighted sums of the monomials of degree ≤ 4 of the coordinates.
    pub sums: Vec<f64>,
    /// Sum of the squared weights.
    pub sum_w2: f64,
    /// Readings accepted.
    pub count: u64,
}

impl<T: Real, const D: usize, const M: usize> ConicSums<T, D, M> {
    /// The serialisable form (`f64`, exact for either float type).
    pub fn snapshot(&self) -> SumsSnapshot {
        let wide = self.widened();
        SumsSnapshot {
            origin: wide.origin.iter().copied().collect(),
            scale: wide.scale,
            sums: wide.sums.to_vec(),
            sum_w2: wide.sum_w2,
            count: wide.count,
        }
    }

    /// Back from the serialisable form, refusing wrong lengths and values not finite in `T`
    /// (a state saved in `f64` and restored in `f32` is rounded to nearest).
    pub fn restore(s: &SumsSnapshot) -> Result<Self> {
        if s.origin.len() != D || s.sums.len() != M {
            return Err(Error::InvalidSnapshot {
                reason: "the running sums do not have the layout of this calibrator",
            });
        }
        let finite = s
            .origin
            .iter()
            .chain(&s.sums)
            .all(|&x| T::of(x).is_finite())
            && T::of(s.sum_w2).is_finite()
            && T::of(s.scale).is_finite();
        let (scale, weight) = (T::of(s.scale), T::of(s.sums[0]));
        if !finite
            || !(scale > T::zero())
            || s.sum_w2 < 0.0
            || (s.count == 0) != (weight == T::zero())
        {
            return Err(Error::InvalidSnapshot {
                reason: "the running sums are not finite or do not agree with the sample count",
            });
        }
        let mut sums = [T::zero(); M];
        for (to, &from) in sums.iter_mut().zip(&s.sums) {
            *to = T::of(from);
        }
        Ok(Self {
            origin: SVector::from_fn(|i, _| T::of(s.origin[i])),
            scale: T::of(s.scale),
            sums,
            sum_w2: T::of(s.sum_w2),
            count: s.count,
        })
    }
}

/// The factor by which every sum is multiplied per reading for a forgetting half-life of
/// `half_life` readings (`None`: no forgetting, factor 1), and the lifetime of a retained
/// reading: four half-lives (its weight has then fallen below 1/16), or unlimited.
pub(crate) fn forgetting(half_life: Option<f64>) -> (f64, u64) {
    match half_life {
        Some(h) if h.is_finite() && h > 0.0 => {
            let life = (4.0 * h).ceil();
            (
                (-core::f64::consts::LN_2 / h).exp(),
                if life < u64::MAX as f64 {
                    life as u64
                } else {
                    u64::MAX
                },
            )
        }
        _ => (1.0, u64::MAX),
    }
}

/// For an information matrix `A = L Lᵀ`: `L⁻¹`, so that `gᵀA⁻¹g = ‖L⁻¹g‖²` costs one
/// small product per test direction. `None` unless `A` is positive definite.
pub(crate) fn inverse_factor<const P: usize>(
    info: &SMatrix<f64, P, P>,
) -> Option<SMatrix<f64, P, P>> {
    if !info.iter().all(|x| x.is_finite()) {
        return None;
    }
    (*info)
        .cholesky()?
        .l()
        .solve_lower_triangular(&SMatrix::<f64, P, P>::identity())
}

/// Residual standard deviation and covariance factor of a weighted least-squares fit of `P`
/// parameters: `σ² = (Σw r²/Σw) · n/(n − P)` with `n` the effective number of readings
/// (the unbiased `Σr²/(N − P)` without forgetting), and `κ = Σw/n`, by which the
/// covariance `σ² A⁻¹` of an unweighted fit grows when `A = Σ w φφᵀ` is weighted
/// (`Cov = σ² A⁻¹ (Σ w² φφᵀ) A⁻¹ ≈ σ² κ A⁻¹`; exactly 1 without forgetting). `None` when
/// `n ≤ P`.
pub(crate) fn sigma_kappa(
    weighted_ss: f64,
    weight: f64,
    n_eff: f64,
    p: usize,
) -> Option<(f64, f64)> {
    let p = p as f64;
    if !(n_eff > p) || !(weight > 0.0) {
        return None;
    }
    let var = (weighted_ss / weight).max(0.0) * n_eff / (n_eff - p);
    Some((var.sqrt(), weight / n_eff))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2, Vector3};

    fn design2(q: &Vector2<f64>) -> SVector<f64, 6> {
        SVector::from([q.x * q.x, q.x * q.y, q.y * q.y, q.x, q.y, 1.0])
    }

    #[test]
    fn layouts_have_every_monomial_once() {
        for (j, e) in LAYOUT_3D.exps.iter().enumerate() {
            assert_eq!(LAYOUT_3D.exps.iter().filter(|x| *x == e).count(), 1, "{j}");
            assert!(e.iter().sum::<u8>() <= 4);
        }
        assert_eq!(LAYOUT_2D.exps[0], [0, 0]);
    }

    #[test]
    fn scatter_from_sums_matches_outer_products() {
        let pts: Vec<Vector2<f64>> = (0..40)
            .map(|k| {
                let a = k as f64 * 0.37;
                Vector2::new(3.0 + 2.0 * a.cos() + 0.1 * a, -1.0 + a.sin())
            })
            .collect();
        let mut s = ConicSums::<f64, 2, MONOMIALS_2D>::new();
        for p in &pts {
            s.add(&LAYOUT_2D, p, 1.0).unwrap();
        }
        let direct: SMatrix<f64, 6, 6> = pts
            .iter()
            .map(|p| {
                let d = design2(&((p - s.origin) / s.scale));
                d * d.transpose()
            })
            .sum();
        let got = LAYOUT_2D.scatter_matrix(&s.sums);
        assert!((got - direct).amax() < 1e-10 * direct.amax());
    }

    #[test]
    fn design_map_is_exact() {
        let a = Matrix2::new(0.3, -1.2, 0.7, 2.0);
        let b = Vector2::new(0.5, -0.25);
        let t = LAYOUT_2D.design_map(&a, &b);
        let q = Vector2::new(1.3, -0.4);
        assert!((design2(&(a * q + b)) - t * design2(&q)).amax() < 1e-12);

        let a3 = nalgebra::Matrix3::new(0.3, -1.2, 0.1, 0.7, 2.0, -0.5, 0.2, 0.4, 1.1);
        let b3 = Vector3::new(0.5, -0.25, 2.0);
        let d3 = |q: &Vector3<f64>| {
            SVector::<f64, 10>::from_iterator(TERMS_3D.iter().map(|(f, e)| {
                f * q.x.powi(e[0] as i32) * q.y.powi(e[1] as i32) * q.z.powi(e[2] as i32)
            }))
        };
        let t3 = LAYOUT_3D.design_map(&a3, &b3);
        let q3 = Vector3::new(1.3, -0.4, 0.8);
        assert!((d3(&(a3 * q3 + b3)) - t3 * d3(&q3)).amax() < 1e-12);
    }

    #[test]
    fn far_readings_are_refused_and_change_nothing() {
        let mut s = ConicSums::<f64, 2, MONOMIALS_2D>::new();
        s.add(&LAYOUT_2D, &Vector2::new(1.0, 0.0), 1.0).unwrap();
        let before = s;
        assert!(s.add(&LAYOUT_2D, &Vector2::new(1e300, 0.0), 1.0).is_err());
        assert_eq!(s, before);
    }
}
