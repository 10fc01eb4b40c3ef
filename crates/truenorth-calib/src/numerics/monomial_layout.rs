//! The monomials of a direct conic (2-D) or quadric (3-D) fit: the design vector of a
//! reading, the monomials of degree ≤ 4 whose sums make its scatter matrix, and the linear
//! map of design vectors under an affine change of coordinates.
//!
//! An algebraic fit minimises `Σ (kᵀ ξ(q))²` over the coefficients `k`, `ξ(q)` the design
//! vector of the monomials of degree ≤ 2 of a reading `q`; the scatter matrix `S = Σ ξ ξᵀ`
//! has the sums of the monomials of degree ≤ 4 as entries (15 distinct ones in 2-D, 35 in
//! 3-D). Under `q' = A q + b` the design vector is a fixed linear combination of the old
//! one, `ξ(q') = T ξ(q)`, so `S' = T S Tᵀ` (see the `conic_sums` module, which keeps the
//! sums).

use nalgebra::{SMatrix, SVector};
use truenorth_core::Real;

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

/// The 2-D design vector of `q`, written out, for the tests of the layout and the sums.
#[cfg(test)]
pub(crate) fn design2(q: &nalgebra::Vector2<f64>) -> SVector<f64, 6> {
    SVector::from([q.x * q.x, q.x * q.y, q.y * q.y, q.x, q.y, 1.0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2, Vector3};

    #[test]
    fn layouts_have_every_monomial_once() {
        for (j, e) in LAYOUT_3D.exps.iter().enumerate() {
            assert_eq!(LAYOUT_3D.exps.iter().filter(|x| *x == e).count(), 1, "{j}");
            assert!(e.iter().sum::<u8>() <= 4);
        }
        assert_eq!(LAYOUT_2D.exps[0], [0, 0]);
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
}
