//! Levenberg–Marquardt for small dense least-squares problems (Levenberg 1944; Marquardt
//! 1963, with Marquardt's diagonal scaling `JᵀJ + λ·diag(JᵀJ)`), as used to refine the
//! direct ellipse and ellipsoid fits on a geometric residual.
//!
//! The problem supplies one function that, for a parameter vector, returns the cost
//! `Σ rᵢ²` together with the normal equations `JᵀJ` and `Jᵀr` — one pass over the data per
//! trial point, so an accepted step needs no second pass.

use nalgebra::{SMatrix, SVector};
use truenorth_core::{Error, Result};

use crate::numerics::blocks::{BLOCK, dot_block};

/// Cost and normal equations at one parameter vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NormalEquations<const P: usize> {
    /// `Σ rᵢ²`.
    pub cost: f64,
    /// `JᵀJ`.
    pub jtj: SMatrix<f64, P, P>,
    /// `Jᵀr`.
    pub jtr: SVector<f64, P>,
}

impl<const P: usize> NormalEquations<P> {
    /// The normal equations in other parameters `θ`, given `m = ∂φ/∂θ` for the parameters
    /// `φ` these were accumulated in: by the chain rule `J_θ = J_φ m`, so `J_θᵀJ_θ =
    /// mᵀ(J_φᵀJ_φ)m` and `J_θᵀr = mᵀ(J_φᵀr)`; the cost is the same. `None` if anything
    /// overflowed.
    pub fn reparametrised(&self, m: &SMatrix<f64, P, P>) -> Option<Self> {
        let jtj = m.transpose() * self.jtj * m;
        // Mirror the upper triangle: JᵀJ is symmetric, the rounding of the products not
        // quite, and the Cholesky factorisation reads one triangle only.
        let jtj = SMatrix::<f64, P, P>::from_fn(|i, j| jtj[(i.min(j), i.max(j))]);
        let ne = Self {
            cost: self.cost,
            jtj,
            jtr: m.transpose() * self.jtr,
        };
        ne.is_finite().then_some(ne)
    }

    /// Whether the cost and `JᵀJ` are finite (a non-finite `Jᵀr` gives a non-finite step,
    /// which [`minimise`] rejects).
    fn is_finite(&self) -> bool {
        self.cost.is_finite() && self.jtj.iter().all(|x| x.is_finite())
    }
}

/// Accumulates `JᵀJ` (upper triangle only, mirrored at the end), `Jᵀr` and `Σ r²` a block
/// of residuals at a time: the caller fills [`Self::cols`] — column `k < P` with the `k`-th
/// gradient component of each residual of the block, column `P` with the residuals — and
/// calls [`Self::add_block`]. Rows past the end of the data must be zeros, which add
/// nothing.
pub(crate) struct NormalAccumulator<const P: usize, const K: usize> {
    /// The block being filled: `K = P + 1` columns of [`BLOCK`] rows.
    pub cols: [[f64; BLOCK]; K],
    sums: [[f64; K]; K],
}

impl<const P: usize, const K: usize> NormalAccumulator<P, K> {
    /// Nothing accumulated.
    #[inline(always)]
    pub fn new() -> Self {
        const { assert!(K == P + 1) };
        Self {
            cols: [[0.0; BLOCK]; K],
            sums: [[0.0; K]; K],
        }
    }

    /// Adds the block in [`Self::cols`]: every product of two columns, summed over the rows.
    #[inline(always)]
    pub fn add_block(&mut self) {
        for a in 0..K {
            for b in a..K {
                self.sums[a][b] += dot_block(&self.cols[a], &self.cols[b]);
            }
        }
    }

    /// Adds the sums of `later`, the accumulator of the residuals that follow these.
    pub fn merge(&mut self, later: &Self) {
        for a in 0..K {
            for b in a..K {
                self.sums[a][b] += later.sums[a][b];
            }
        }
    }

    /// The normal equations, or `None` if anything overflowed.
    pub fn finish(&self) -> Option<NormalEquations<P>> {
        let mut jtj = SMatrix::<f64, P, P>::zeros();
        let mut jtr = SVector::<f64, P>::zeros();
        for a in 0..P {
            for b in a..P {
                jtj[(a, b)] = self.sums[a][b];
                jtj[(b, a)] = self.sums[a][b];
            }
            jtr[a] = self.sums[a][P];
        }
        let ne = NormalEquations {
            cost: self.sums[P][P],
            jtj,
            jtr,
        };
        ne.is_finite().then_some(ne)
    }
}

/// Levenberg–Marquardt one trial at a time (the steps of [`minimise`] without its
/// convergence test), for a refinement spread over several pushes: each [`Self::step`]
/// evaluates one point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LmSteps<const P: usize> {
    /// The best parameters so far.
    pub params: SVector<f64, P>,
    cur: Option<NormalEquations<P>>,
    lambda: f64,
}

impl<const P: usize> LmSteps<P> {
    /// Starting at `start` (evaluated by the first step).
    pub(crate) fn new(start: SVector<f64, P>) -> Self {
        Self {
            params: start,
            cur: None,
            lambda: 1e-4,
        }
    }

    /// One evaluation: of the start, then of a damped step, taken when it lowers the cost
    /// (and the damping lowered) or refused (and the damping raised). `false` once nothing
    /// can be evaluated (the start is undefined, or the damping passed [`LAMBDA_MAX`]).
    pub(crate) fn step(
        &mut self,
        mut eval: impl FnMut(&SVector<f64, P>) -> Option<NormalEquations<P>>,
    ) -> bool {
        let Some(cur) = &self.cur else {
            self.cur = eval(&self.params);
            return self.cur.is_some();
        };
        if self.lambda > LAMBDA_MAX {
            return false;
        }
        let trial = damped_step(cur, self.lambda).map(|d| self.params + d);
        match trial.and_then(|t| eval(&t).map(|ne| (t, ne))) {
            Some((t, ne)) if ne.cost <= cur.cost => {
                self.params = t;
                self.cur = Some(ne);
                self.lambda = (self.lambda * 0.1).max(1e-12);
            }
            _ => self.lambda *= 10.0,
        }
        true
    }
}

impl<const P: usize> LmSteps<P> {
    /// Whether the best point so far is as good as converged for `residuals` residuals:
    /// the Newton step left is shorter than [`NEGLIGIBLE_STEP_SIGMAS`] of a standard
    /// deviation of the parameters (the test [`minimise`] ends on when its iterations run
    /// out), so further trials cannot move them by anything the data tell apart.
    pub(crate) fn settled(&self, residuals: usize) -> bool {
        self.cur.as_ref().is_some_and(|cur| {
            let variance = cur.cost / residuals.saturating_sub(P).max(1) as f64;
            gauss_newton_decrement(cur)
                .is_some_and(|d| d <= NEGLIGIBLE_STEP_SIGMAS * NEGLIGIBLE_STEP_SIGMAS * variance)
        })
    }
}

/// The result of a converged run.
pub(crate) struct LmOutcome<const P: usize> {
    /// The parameters at the minimum.
    pub params: SVector<f64, P>,
}

/// The step, in standard deviations of the parameters, below which [`minimise`] takes a
/// point that has not converged to rounding after its iterations: 1 %, a hundredth of what
/// the readings can resolve.
const NEGLIGIBLE_STEP_SIGMAS: f64 = 0.01;

/// Damping above which no step can reduce the cost any more: the current point is a
/// minimum to rounding precision.
const LAMBDA_MAX: f64 = 1e16;

/// The largest decrease of the cost that any step can bring according to the Gauss–Newton
/// model `Σ (rᵢ + Jᵢδ)²`: `gᵀ(JᵀJ)⁻¹g` with `g = Jᵀr` (the squared Newton decrement of
/// Boyd & Vandenberghe 2004, *Convex Optimization*, §9.5.1, for this model). `None` when
/// `JᵀJ` is not positive definite.
fn gauss_newton_decrement<const P: usize>(ne: &NormalEquations<P>) -> Option<f64> {
    let g = &ne.jtr;
    let d = g.dot(&ne.jtj.cholesky()?.solve(g));
    d.is_finite().then_some(d)
}

/// The Levenberg–Marquardt step `−(JᵀJ + λ·D)⁻¹Jᵀr`, `D` the diagonal of `JᵀJ` with a floor
/// (Marquardt's scaling), or `None` if it is not finite.
fn damped_step<const P: usize>(ne: &NormalEquations<P>, lambda: f64) -> Option<SVector<f64, P>> {
    let mut h = ne.jtj;
    let dmax = (0..P).map(|i| h[(i, i)]).fold(0.0_f64, f64::max);
    for i in 0..P {
        // Marquardt's scaling, with a floor so a parameter the data do not touch still gets
        // a finite, damped step.
        h[(i, i)] += lambda * h[(i, i)].max(1e-12 * dmax);
    }
    let step = -h.cholesky()?.solve(&ne.jtr);
    step.iter().all(|x| x.is_finite()).then_some(step)
}

/// [`minimise`] of a problem whose passes over the data can fail (readings replayed from a
/// store): the first failure stops the evaluations (each later one is an undefined point,
/// which costs no pass) and is the outer error; the inner result is [`minimise`]'s.
pub(crate) fn minimise_replayed<const P: usize>(
    what: &'static str,
    start: SVector<f64, P>,
    max_iterations: usize,
    residuals: usize,
    mut eval: impl FnMut(&SVector<f64, P>) -> Result<Option<NormalEquations<P>>>,
) -> Result<Result<LmOutcome<P>>> {
    let mut failed = None;
    let out = minimise(what, start, max_iterations, residuals, |p| {
        if failed.is_some() {
            return None;
        }
        eval(p).unwrap_or_else(|e| {
            failed = Some(e);
            None
        })
    });
    match failed {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// Minimises the cost from `start`. `eval` returns `None` where the model is undefined
/// (e.g. a matrix became singular); such trial points are rejected like uphill ones.
///
/// Converges when an accepted step lowers the cost by less than `1e-12` of itself or moves
/// the parameters by less than `1e-12` of their norm. Before each step the Gauss–Newton
/// model is asked how much any step could lower the cost: when that is at most `1e-12` of
/// it, the step about to be tried would be the last, and it is taken without evaluating
/// it, as evaluating it could only confirm a change the test does not resolve (often below
/// the rounding of the cost, where the test would reject it by chance and retry with ever
/// more damping).
///
/// After `max_iterations` accepted steps without that, the point is still taken when the
/// step left is statistically nothing: the parameters' covariance is `σ²(JᵀJ)⁻¹` with
/// `σ² = cost/(residuals − P)`, so the Newton step, of squared Mahalanobis length `d/σ²`
/// (`d` the decrement above), is shorter than [`NEGLIGIBLE_STEP_SIGMAS`] of a standard
/// deviation when `d ≤ NEGLIGIBLE_STEP_SIGMAS² · σ²`. Residual groups of very different
/// weights (a noise-free magnetometer beside a real accelerometer) make a slow, curved valley
/// where the cost falls by more than `1e-12` of itself per step for hundreds of steps, long
/// after the parameters stopped moving by anything the data could tell apart (found by
/// `tests/more_data.rs`). Otherwise refuses with [`Error::NoConvergence`].
pub(crate) fn minimise<const P: usize>(
    what: &'static str,
    start: SVector<f64, P>,
    max_iterations: usize,
    residuals: usize,
    mut eval: impl FnMut(&SVector<f64, P>) -> Option<NormalEquations<P>>,
) -> Result<LmOutcome<P>> {
    let mut p = start;
    let Some(mut cur) = eval(&p) else {
        return Err(Error::Degenerate {
            reason: "the initial fit is not a valid starting point for the geometric refinement",
        });
    };
    let mut lambda = 1e-4;
    for _ in 0..max_iterations {
        if gauss_newton_decrement(&cur).is_some_and(|d| d <= 1e-12 * cur.cost) {
            // No step can lower the cost by more than 1e-12 of itself, so the next accepted
            // step meets the test below and is the last. Take it without the pass over the
            // data, which would only confirm a change of the cost below what that test
            // resolves (and at this size often only rounding noise).
            return Ok(LmOutcome {
                params: damped_step(&cur, lambda).map_or(p, |delta| p + delta),
            });
        }
        loop {
            if let Some(delta) = damped_step(&cur, lambda) {
                let trial = p + delta;
                if let Some(next) = eval(&trial).filter(|next| next.cost <= cur.cost) {
                    let converged = cur.cost - next.cost <= 1e-12 * cur.cost
                        || delta.norm() <= 1e-12 * p.norm().max(1e-300);
                    p = trial;
                    cur = next;
                    lambda = (lambda * 0.1).max(1e-12);
                    if converged {
                        return Ok(LmOutcome { params: p });
                    }
                    break;
                }
            }
            lambda *= 10.0;
            if lambda > LAMBDA_MAX {
                // No direction lowers the cost: we are at a minimum to rounding precision.
                return Ok(LmOutcome { params: p });
            }
        }
    }
    let variance = cur.cost / residuals.saturating_sub(P).max(1) as f64;
    if gauss_newton_decrement(&cur)
        .is_some_and(|d| d <= NEGLIGIBLE_STEP_SIGMAS * NEGLIGIBLE_STEP_SIGMAS * variance)
    {
        return Ok(LmOutcome { params: p });
    }
    Err(Error::NoConvergence {
        what,
        iterations: max_iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    /// Rosenbrock as a least-squares problem: r = (10 (y − x²), 1 − x).
    fn rosenbrock(p: &Vector2<f64>) -> Option<NormalEquations<2>> {
        let (x, y) = (p[0], p[1]);
        let r = Vector2::new(10.0 * (y - x * x), 1.0 - x);
        let j = Matrix2::new(-20.0 * x, 10.0, -1.0, 0.0);
        Some(NormalEquations {
            cost: r.norm_squared(),
            jtj: j.transpose() * j,
            jtr: j.transpose() * r,
        })
    }

    #[test]
    fn finds_rosenbrock_minimum() {
        let out = minimise("rosenbrock", Vector2::new(-1.2, 1.0), 200, 2, rosenbrock).unwrap();
        assert!((out.params - Vector2::new(1.0, 1.0)).norm() < 1e-6);
    }

    #[test]
    fn reports_no_convergence() {
        let e = minimise("rosenbrock", Vector2::new(-1.2, 1.0), 1, 2, rosenbrock);
        assert!(matches!(e, Err(Error::NoConvergence { .. })));
    }
}
