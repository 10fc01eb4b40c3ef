//! The support stages of the refresh (6 onwards, before the report): the information matrix
//! of the support (one retained reading per direction cell), its condition by the staged
//! Jacobi solver, the heading-error bound and the support's dilution over a lattice of
//! directions, and what the readings determine.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::jacobi::Jacobi9;
use super::{BOUND_CHUNK, BOUND_DIRECTIONS, PARAMS, Refresh, SUPPORT_STAGES, SWEEPS_PER_STAGE};
use crate::numerics::linalg::condition_from_eigenvalues;
use crate::online::conic_sums::inverse_factor;
use crate::quality::{self, CompassUncertainty, SPHERE_CELLS};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

impl Refresh {
    /// Stages 6–7: the information matrix of the support (see `crate::quality`'s `support`
    /// module): the live retained readings, one per direction cell, each counted once, so
    /// that its condition and dilution say what the orientations determine, whatever the
    /// time spent in each; half of the cells per stage, the upper triangle only. The last
    /// starts the Jacobi solver on it and keeps its inverse factor.
    pub(super) fn support(&mut self, half: usize, lifetime: u64) {
        let now = self.base.sums.count;
        let cells = SPHERE_CELLS / SUPPORT_STAGES as usize;
        for j in half * cells..(half + 1) * cells {
            if !self.base.slots.is_live(j, now, lifetime) {
                continue;
            }
            let h = self.cal.correct(&self.base.slots.reading[j]);
            let rho = h.norm();
            if !(rho > 0.0 && rho.is_finite()) {
                continue;
            }
            let phi = quality::regressor_3d(&(h / rho));
            let mut k = 0;
            for r in 0..PARAMS {
                for c in r..PARAMS {
                    self.support_sums[k] += phi[r] * phi[c];
                    k += 1;
                }
            }
            self.support_cells += 1;
        }
        if half + 1 == SUPPORT_STAGES as usize {
            let mut a = SMatrix::<f64, PARAMS, PARAMS>::zeros();
            let mut k = 0;
            for r in 0..PARAMS {
                for c in r..PARAMS {
                    (a[(r, c)], a[(c, r)]) = (self.support_sums[k], self.support_sums[k]);
                    k += 1;
                }
            }
            self.jacobi = Jacobi9::new(&a);
            self.support_l_inv = (self.support_cells >= PARAMS)
                .then(|| inverse_factor(&a))
                .flatten();
        }
    }

    /// Stages 8–11: condition number of the support's information matrix, a few Jacobi
    /// sweeps per stage (the last stage finishes the solver should it not have converged).
    pub(super) fn condition(&mut self, last: bool) {
        let converged = if last {
            self.jacobi.finish()
        } else {
            (0..SWEEPS_PER_STAGE).any(|_| self.jacobi.sweep())
        };
        if converged || last {
            self.condition = self
                .jacobi
                .ascending()
                .map(|l| condition_from_eigenvalues(l.as_slice()))
                .unwrap_or(f64::INFINITY);
        }
    }

    /// Stages 12–27: the worst of `trace(G A⁻¹ Gᵀ)` over 16 of the lattice directions,
    /// `G(u)` the Jacobian of the direction error `(I − uuᵀ)(E u − d)` (see
    /// `crate::quality`), for the bound (`A` of every reading) and for the support's
    /// dilution.
    pub(super) fn bound_chunk(&mut self, chunk: usize) {
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
            if let Some(ls) = self.support_l_inv {
                self.support_worst = self.support_worst.max((ls * g.transpose()).norm_squared());
            }
        }
    }

    /// What the readings determine: the support's dilution (see `crate::quality`) and the
    /// parameters' σ from the information factor.
    pub(super) fn uncertainty(&self) -> CompassUncertainty {
        let dilution = match self.support_l_inv {
            Some(_) => (self.support_cells as f64 * self.support_worst).sqrt(),
            None => f64::INFINITY,
        };
        quality::uncertainty_from_factor(self.l_inv.as_ref(), self.sigma, self.field, 3, dilution)
    }
}
