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

pub(crate) use crate::numerics::monomial_layout::{
    LAYOUT_2D, LAYOUT_3D, Layout, MONOMIALS_2D, MONOMIALS_3D,
};

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
    /// the `ellipse` module.
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
    use crate::numerics::monomial_layout::design2;
    use nalgebra::Vector2;

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
    fn far_readings_are_refused_and_change_nothing() {
        let mut s = ConicSums::<f64, 2, MONOMIALS_2D>::new();
        s.add(&LAYOUT_2D, &Vector2::new(1.0, 0.0), 1.0).unwrap();
        let before = s;
        assert!(s.add(&LAYOUT_2D, &Vector2::new(1e300, 0.0), 1.0).is_err());
        assert_eq!(s, before);
    }
}
