//! The staged eigen-solver of the refresh: Jacobi sweeps on a symmetric 9×9 matrix, a few
//! per push.

use nalgebra::{SMatrix, SVector};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Size of the matrix (the parameters of the direction-error model).
const N: usize = 9;

/// Eigenvalues of a symmetric 9×9 matrix by the cyclic Jacobi method (Golub & Van Loan,
/// *Matrix Computations*, 4th ed., §8.5.2–8.5.3), one sweep of the 36 rotations at a time, so
/// that a refresh can spread the work over several pushes. Each rotation zeroes one
/// off-diagonal pair; a sweep that finds nothing above rounding to rotate ends it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Jacobi9 {
    a: SMatrix<f64, N, N>,
    sweeps: u32,
    /// `None` while running; `Some(true)` converged, `Some(false)` failed (non-finite).
    state: Option<bool>,
}

/// Most sweeps before the Jacobi solver gives up (it converges quadratically: a 9×9 matrix
/// needs well under ten).
const JACOBI_MAX_SWEEPS: u32 = 50;

impl Jacobi9 {
    pub(super) fn new(m: &SMatrix<f64, N, N>) -> Self {
        let finite = m.iter().all(|x| x.is_finite());
        Self {
            a: (m + m.transpose()) * 0.5,
            sweeps: 0,
            state: (!finite).then_some(false),
        }
    }

    /// One sweep; returns whether the solver has ended (converged or failed).
    pub(super) fn sweep(&mut self) -> bool {
        if self.state.is_some() {
            return true;
        }
        if self.sweeps >= JACOBI_MAX_SWEEPS {
            self.state = Some(false);
            return true;
        }
        self.sweeps += 1;
        let a = &mut self.a;
        let mut rotated = false;
        for p in 0..N - 1 {
            for q in p + 1..N {
                let apq = a[(p, q)];
                // Negligible against both diagonal entries: rounding level, leave it.
                if apq == 0.0
                    || apq.abs() <= f64::EPSILON * 0.5 * (a[(p, p)].abs() * a[(q, q)].abs()).sqrt()
                {
                    a[(p, q)] = 0.0;
                    a[(q, p)] = 0.0;
                    continue;
                }
                rotated = true;
                let tau = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = t * c;
                for k in 0..N {
                    let (akp, akq) = (a[(k, p)], a[(k, q)]);
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..N {
                    let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                a[(p, q)] = 0.0;
                a[(q, p)] = 0.0;
            }
        }
        if !a.iter().all(|x| x.is_finite()) {
            self.state = Some(false);
        } else if !rotated {
            self.state = Some(true);
        }
        self.state.is_some()
    }

    /// Sweeps to the end; returns whether it converged.
    pub(super) fn finish(&mut self) -> bool {
        while !self.sweep() {}
        self.state == Some(true)
    }

    /// The eigenvalues in ascending order, once converged.
    pub(super) fn ascending(&self) -> Option<SVector<f64, N>> {
        if self.state != Some(true) {
            return None;
        }
        let mut l = self.a.diagonal();
        l.as_mut_slice().sort_unstable_by(f64::total_cmp);
        Some(l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::linalg::sym_eigen9;
    use proptest::prelude::*;

    proptest! {
        /// The staged Jacobi solver gives the eigenvalues of the QR-based decomposition the
        /// batch fit uses, to rounding relative to the matrix's norm, on symmetric matrices
        /// of any conditioning.
        #[test]
        fn jacobi_eigenvalues_match_the_batch_decomposition(
            entries in proptest::collection::vec(-1.0f64..1.0, 81),
            log_spread in 0.0f64..8.0,
        ) {
            let g = SMatrix::<f64, N, N>::from_iterator(entries);
            // A Gram matrix with eigenvalues spread over `log_spread` decades.
            let d = SMatrix::<f64, N, N>::from_fn(|i, j| {
                if i == j { 10f64.powf(-log_spread * i as f64 / 8.0) } else { 0.0 }
            });
            let m = g * d * g.transpose();
            let (expect, _) = sym_eigen9(&m).unwrap();
            let mut j = Jacobi9::new(&m);
            let mut sweeps = 0;
            while !j.sweep() {
                sweeps += 1;
            }
            // It converges (rather than giving up at the sweep limit); on the information
            // matrix of a refresh that takes four or five sweeps, here up to about ten.
            prop_assert!(j.state == Some(true) && sweeps < JACOBI_MAX_SWEEPS as usize, "{} sweeps", sweeps);
            let got = j.ascending().unwrap();
            let scale = m.norm();
            for i in 0..N {
                prop_assert!((got[i] - expect[i]).abs() <= 1e-13 * scale, "{}: {} vs {}", i, got[i], expect[i]);
            }
        }
    }

    #[test]
    fn jacobi_refuses_non_finite_input() {
        let mut m = SMatrix::<f64, N, N>::identity();
        m[(2, 3)] = f64::NAN;
        let mut j = Jacobi9::new(&m);
        assert!(j.sweep());
        assert!(j.ascending().is_none());
    }
}
