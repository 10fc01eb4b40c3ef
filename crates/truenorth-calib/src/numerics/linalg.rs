//! Small dense linear-algebra helpers for the least-squares fits: a guarded symmetric
//! eigen-decomposition, the symmetric positive-definite square root, condition numbers, and
//! the constrained minimum `min aᵀMa subject to aᵀCa = 1` that the direct conic and quadric
//! fits reduce to.
//!
//! Everything here works on stack matrices (no allocation) and never panics: every routine
//! that can fail on non-finite or singular input returns `None`.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::{SMatrix, SVector};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Upper bound on the QR sweeps of the symmetric eigen-decomposition. nalgebra's default
/// (`0`) means "until convergence", which never ends on NaN input; a finite bound turns
/// that into `None`. Small symmetric matrices converge in a few dozen sweeps.
const EIGEN_MAX_ITERATIONS: usize = 10_000;

macro_rules! sym_eigen_fn {
    ($name:ident, $n:literal) => {
        /// Eigenvalues and eigenvectors (as columns) of a symmetric matrix, sorted by
        /// ascending eigenvalue. `None` on non-finite input or if the iteration fails.
        pub(crate) fn $name(
            m: &SMatrix<f64, $n, $n>,
        ) -> Option<(SVector<f64, $n>, SMatrix<f64, $n, $n>)> {
            if !m.iter().all(|x| x.is_finite()) {
                return None;
            }
            // Symmetrise: the algorithm reads one triangle only, so make both agree.
            let sym = (m + m.transpose()) * 0.5;
            let e = nalgebra::SymmetricEigen::try_new(sym, f64::EPSILON, EIGEN_MAX_ITERATIONS)?;
            let mut order = [0usize; $n];
            for (i, o) in order.iter_mut().enumerate() {
                *o = i;
            }
            order.sort_unstable_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
            let mut vals = SVector::<f64, $n>::zeros();
            let mut vecs = SMatrix::<f64, $n, $n>::zeros();
            for (k, &i) in order.iter().enumerate() {
                vals[k] = e.eigenvalues[i];
                vecs.set_column(k, &e.eigenvectors.column(i));
            }
            Some((vals, vecs))
        }
    };
}

sym_eigen_fn!(sym_eigen2, 2);
sym_eigen_fn!(sym_eigen3, 3);
sym_eigen_fn!(sym_eigen5, 5);
sym_eigen_fn!(sym_eigen6, 6);
sym_eigen_fn!(sym_eigen9, 9);

macro_rules! constrained_min_fn {
    ($name:ident, $eig:ident, $n:literal) => {
        /// Minimises `aᵀ M a` subject to `aᵀ C a = 1`, for `M` symmetric positive
        /// semi-definite and `C` symmetric with exactly one positive eigenvalue.
        ///
        /// This is the generalised eigenproblem `M a = λ C a` of Fitzgibbon, Pilu & Fisher
        /// (1999, eq. 7) in the reduced form of Halíř & Flusser (1998, eq. 21). Instead of
        /// the non-symmetric `C⁻¹M` used there, it is made symmetric: with
        /// `W = M^{-1/2}` and `a = W z`, the problem becomes `W C W z = (1/λ) z`, a
        /// symmetric eigenproblem. By Sylvester's law of inertia `W C W` has exactly one
        /// positive eigenvalue, like `C`, and its eigenvector gives the unique admissible
        /// solution (the smallest positive λ).
        ///
        /// When `M` is singular (the points lie exactly on a conic) the null vector of `M`
        /// is the answer if it satisfies `aᵀCa > 0`. Returns `None` if `M` has more than one
        /// null direction (too few distinct points) or no admissible solution exists. The
        /// result is scaled so that `aᵀ C a = 1`.
        pub(crate) fn $name(
            m: &SMatrix<f64, $n, $n>,
            c: &SMatrix<f64, $n, $n>,
        ) -> Option<SVector<f64, $n>> {
            let (lam, v) = $eig(m)?;
            let lmax = lam[$n - 1];
            if !(lmax > 0.0) {
                return None;
            }
            // Relative size below which an eigenvalue of M counts as zero: the points then
            // lie on the conic to rounding precision.
            let tol = lmax * 1e-13;
            let nulls = lam.iter().filter(|&&l| l <= tol).count();
            if nulls >= 2 {
                return None;
            }
            if nulls == 1 {
                let a = v.column(0).into_owned();
                let q = (a.transpose() * c * a)[0];
                return if q > 0.0 { Some(a / q.sqrt()) } else { None };
            }
            let mut w = SMatrix::<f64, $n, $n>::zeros();
            for k in 0..$n {
                let col = v.column(k);
                w += col * col.transpose() / lam[k].sqrt();
            }
            let k_mat = w * c * w;
            let (mu, z) = $eig(&k_mat)?;
            if !(mu[$n - 1] > 0.0) {
                return None;
            }
            let a = w * z.column($n - 1);
            let q = (a.transpose() * c * a)[0];
            if !(q > 0.0) || !q.is_finite() {
                return None;
            }
            Some(a / q.sqrt())
        }
    };
}

constrained_min_fn!(constrained_min3, sym_eigen3, 3);
constrained_min_fn!(constrained_min6, sym_eigen6, 6);

macro_rules! sym_sqrt_fn {
    ($name:ident, $eig:ident, $n:literal) => {
        /// The symmetric positive-definite square root of a symmetric positive-definite
        /// matrix, i.e. the unique SPD `R` with `R R = A`. Choosing this root (rather than,
        /// say, a Cholesky factor) introduces no arbitrary rotation. `None` unless every
        /// eigenvalue is positive.
        pub(crate) fn $name(a: &SMatrix<f64, $n, $n>) -> Option<SMatrix<f64, $n, $n>> {
            let (lam, v) = $eig(a)?;
            if !(lam[0] > 0.0) {
                return None;
            }
            let mut r = SMatrix::<f64, $n, $n>::zeros();
            for k in 0..$n {
                let col = v.column(k);
                r += col * col.transpose() * lam[k].sqrt();
            }
            Some(r)
        }
    };
}

sym_sqrt_fn!(sym_sqrt2, sym_eigen2, 2);
sym_sqrt_fn!(sym_sqrt3, sym_eigen3, 3);

/// Condition number (largest / smallest eigenvalue) of a symmetric positive semi-definite
/// matrix given its ascending eigenvalues; infinite when the smallest is not positive.
pub(crate) fn condition_from_eigenvalues(ascending: &[f64]) -> f64 {
    match (ascending.first(), ascending.last()) {
        (Some(&lo), Some(&hi)) if lo > 0.0 && hi.is_finite() => hi / lo,
        _ => f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn sqrt_squares_back() {
        let a = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let r = sym_sqrt3(&a).unwrap();
        assert!((r * r - a).norm() < 1e-12);
        assert!((r - r.transpose()).norm() < 1e-14);
        assert!(sym_sqrt2(&Matrix2::new(1.0, 0.0, 0.0, -1.0)).is_none());
    }

    #[test]
    fn nan_gives_none_not_a_hang() {
        let a = Matrix3::from_element(f64::NAN);
        assert!(sym_eigen3(&a).is_none());
        assert!(constrained_min3(&a, &Matrix3::identity()).is_none());
    }

    #[test]
    fn constrained_min_matches_brute_force() {
        // M positive definite, C with inertia (1 positive, 2 negative), as in the ellipse fit.
        let m = Matrix3::new(3.0, 0.4, 0.1, 0.4, 2.0, 0.3, 0.1, 0.3, 1.5);
        let c = Matrix3::new(0.0, 0.0, 2.0, 0.0, -1.0, 0.0, 2.0, 0.0, 0.0);
        let a = constrained_min3(&m, &c).unwrap();
        let best = (a.transpose() * m * a)[0];
        assert!(((a.transpose() * c * a)[0] - 1.0).abs() < 1e-12);
        // Every admissible direction on a grid must do no better.
        let n = 60;
        for i in 0..n {
            for j in 0..n {
                let th = core::f64::consts::PI * i as f64 / n as f64;
                let ph = core::f64::consts::TAU * j as f64 / n as f64;
                let d = nalgebra::Vector3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                let q = (d.transpose() * c * d)[0];
                if q > 1e-6 {
                    let val = (d.transpose() * m * d)[0] / q;
                    assert!(val >= best - 1e-9, "{val} < {best}");
                }
            }
        }
    }
}
