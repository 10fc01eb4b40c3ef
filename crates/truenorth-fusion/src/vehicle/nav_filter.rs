//! The error-state Kalman filter behind the vehicle estimator: nominal values of heading,
//! position and the sensors' calibration, the covariance of their errors, and the sparse
//! prediction and scalar updates that keep the per-sample path to a few hundred
//! multiply-adds with no allocation.
//!
//! Errors are `true − nominal`. After every update the estimated error is folded into the
//! nominal values and reset to zero (the usual error-state form, e.g. Groves, *Principles of
//! GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., §14.1.4), so
//! every innovation is a measurement minus its prediction from the nominal values.

use serde::{Deserialize, Serialize};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Heading, rad, clockwise from north (or from the start heading before alignment).
pub const PSI: usize = 0;
/// North position of the rear-axle centre, m.
pub const NORTH: usize = 1;
/// East position, m.
pub const EAST: usize = 2;
/// Gyro bias, rad/s.
pub const BIAS: usize = 3;
/// Gyro gain error for right turns (gain `1 + s₊`).
pub const GAIN_POS: usize = 4;
/// Gyro gain error for left turns.
pub const GAIN_NEG: usize = 5;
/// Differential wheel scale δ: left gain `1 + δ/2`, right gain `1 − δ/2`.
pub const WHEEL_DIFF: usize = 6;
/// Speed coefficient `a` of `1 + aV²` (US 4,788,645 eq. 8), s²/m².
pub const SPEED_COEFF: usize = 7;
/// Heading integrated from the wheels alone, rad (used when a gyro carries the heading).
pub const PSI_ODO: usize = 8;
/// Relative error ε of the wheels' effective track: the wheels' heading change is divided
/// by `T(1 + ε)`. It also takes up the odometer's mean scale error in the wheels' heading,
/// which scales both wheels and so their difference: only the distance needs
/// [`WHEEL_SCALE`].
pub const TRACK_SCALE: usize = 9;
/// The compass's slowly varying heading error, rad: what its calibration and the road
/// (grade, camber) leave in every reading alike for a while (first-order Gauss-Markov).
pub const COMPASS_BIAS: usize = 10;
/// The odometer's mean scale error k: the distance driven is the wheels' (or the speed's)
/// times `1 + k`. Only a measure of distance from outside the wheels — satellite fixes —
/// separates it; without them it stays at its prior and makes the along-track uncertainty.
pub const WHEEL_SCALE: usize = 11;
/// How far the wheels' readings trail the gyro's, s: a controller's speed filter, a bus and
/// a logger delay the wheels, so in a turn their heading lags by the rate times this.
/// Learned where the wheels are compared with a gyro in turns; kept non-negative.
pub const WHEEL_LAG: usize = 12;
/// Number of states.
pub const DIM: usize = 13;

/// A set of states, one bit per index: the states a measurement may correct.
pub type StateSet = u16;

/// Every state.
pub const ALL_STATES: StateSet = (1 << DIM) - 1;

/// The set holding state `i` alone.
pub const fn state(i: usize) -> StateSet {
    1 << i
}

/// The nominal state and the error covariance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NavFilter {
    /// Nominal values, indexed by the constants of this module.
    pub x: [f64; DIM],
    /// Covariance of the errors, same indexing; kept symmetric.
    pub p: [[f64; DIM]; DIM],
}

/// One off-diagonal entry of the transition matrix `F = I + E`: `(row, column, value)`.
pub type Coupling = (usize, usize, f64);

impl NavFilter {
    /// Nominal values `x` with independent errors of standard deviation `sigma`.
    pub fn new(x: [f64; DIM], sigma: [f64; DIM]) -> Self {
        let mut p = [[0.0; DIM]; DIM];
        for (i, s) in sigma.iter().enumerate() {
            p[i][i] = s * s;
        }
        Self { x, p }
    }

    /// Standard deviation of state `i`.
    #[inline]
    pub fn sigma(&self, i: usize) -> f64 {
        self.p[i][i].max(0.0).sqrt()
    }

    /// Propagates the covariance through `F = I + E` (the couplings of `E`) and adds the
    /// diagonal process noise `q`: `P ← F P Fᵀ + Q`.
    ///
    /// Couplings are applied in order, each reading the rows and columns it couples from as
    /// they were before it, so a state that is both coupled from and coupled to (the
    /// heading: position is coupled from it, it is coupled from the gyro states) must have
    /// its own couplings listed after those that read it. A coupling of a state to itself,
    /// `(i, i, f)`, scales it by `1 + f` (a decay).
    pub fn predict(&mut self, couplings: &[Coupling], q: &[f64; DIM]) {
        for &(i, j, f) in couplings {
            if f != 0.0 {
                for k in 0..DIM {
                    self.p[i][k] += f * self.p[j][k];
                }
            }
        }
        for &(i, j, f) in couplings {
            if f != 0.0 {
                for k in 0..DIM {
                    self.p[k][i] += f * self.p[k][j];
                }
            }
        }
        for (i, qi) in q.iter().enumerate() {
            self.p[i][i] += qi;
        }
    }

    /// Scalar update with measurement row `h` (sparse: `(state, coefficient)`), innovation
    /// `nu` (measurement minus its prediction) and noise variance `r`. Returns the
    /// innovation variance `h P hᵀ + r`, or `None` (and changes nothing) when it is not
    /// positive and finite.
    pub fn update(&mut self, h: &[(usize, f64)], nu: f64, r: f64) -> Option<f64> {
        self.update_some(h, nu, r, ALL_STATES)
    }

    /// [`NavFilter::update`] that corrects only the states in `learn` (a Schmidt, or
    /// "consider", update: Schmidt 1966; Brown & Hwang, *Introduction to Random Signals and
    /// Applied Kalman Filtering*, 4th ed., §7.6). The others keep their value and their
    /// variance, and the covariance stays that of the estimate's actual error: a state the
    /// data cannot separate from another is not learned from them, and its uncertainty
    /// still reaches every estimate it affects. With gain `K'` zero outside `learn`,
    /// `P ← P − K'(Ph)ᵀ − (Ph)K'ᵀ + K's K'ᵀ`, which is `P_ij − (Ph)_i(Ph)_j/s` wherever `i` or
    /// `j` is learned and `P_ij` where neither is.
    pub fn update_some(
        &mut self,
        h: &[(usize, f64)],
        nu: f64,
        r: f64,
        learn: StateSet,
    ) -> Option<f64> {
        let mut ph = [0.0; DIM];
        for &(j, c) in h {
            for (phk, row) in ph.iter_mut().zip(&self.p) {
                *phk += row[j] * c;
            }
        }
        let s: f64 = h.iter().map(|&(j, c)| c * ph[j]).sum::<f64>() + r;
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let inv = 1.0 / s;
        // P ← P − (P hᵀ)(P hᵀ)ᵀ/s as w wᵀ with w = P hᵀ/√s: each product w_i·w_j is the
        // same float as w_j·w_i, so P stays exactly symmetric.
        let root = inv.sqrt();
        let w = ph.map(|v| v * root);
        for (i, row) in self.p.iter_mut().enumerate() {
            let learned_i = learn & state(i) != 0;
            if learned_i {
                self.x[i] += ph[i] * inv * nu;
            }
            let wi = w[i];
            for (j, (pij, wj)) in row.iter_mut().zip(&w).enumerate() {
                if learned_i || learn & state(j) != 0 {
                    *pij -= wi * wj;
                }
            }
            // Rounding may take a variance a hair below zero after a very precise update.
            if row[i] < 0.0 {
                row[i] = 0.0;
            }
        }
        Some(s)
    }

    /// Keeps state `i` at or above `floor`: a value below it is moved to it, and every
    /// state correlated with it by the regression on it (the estimate projected onto the
    /// constraint, Simon & Chia, "Kalman filtering with state equality constraints", IEEE
    /// Trans. AES 38(1), 2002). The covariance is left as it is.
    pub fn project_at_least(&mut self, i: usize, floor: f64) {
        let d = floor - self.x[i];
        if d <= 0.0 || self.p[i][i] <= 0.0 {
            self.x[i] = self.x[i].max(floor);
            return;
        }
        let inv = 1.0 / self.p[i][i];
        for k in 0..DIM {
            self.x[k] += self.p[k][i] * inv * d;
        }
        self.x[i] = floor;
    }

    /// Adds `sigma² · g gᵀ`: an error common to several states in fixed proportion (the
    /// heading offset found at alignment, which turns heading and track together).
    pub fn add_common_error(&mut self, g: &[f64; DIM], sigma: f64) {
        let v = sigma * sigma;
        for i in 0..DIM {
            for j in 0..DIM {
                self.p[i][j] += v * g[i] * g[j];
            }
        }
    }

    /// Forgets everything known about state `i` beyond standard deviation `sigma`: its
    /// correlations are dropped and its variance set.
    pub fn reset_state(&mut self, i: usize, sigma: f64) {
        for k in 0..DIM {
            self.p[i][k] = 0.0;
            self.p[k][i] = 0.0;
        }
        self.p[i][i] = sigma * sigma;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn filter(sigma: [f64; DIM]) -> NavFilter {
        NavFilter::new([0.0; DIM], sigma)
    }

    #[test]
    fn predict_matches_the_dense_product() {
        let mut f = filter([
            0.1, 1.0, 2.0, 0.01, 0.02, 0.03, 0.004, 1e-4, 0.2, 0.01, 0.005, 0.003, 0.1,
        ]);
        f.p[BIAS][GAIN_POS] = 1e-4;
        f.p[GAIN_POS][BIAS] = 1e-4;
        let couplings = [
            (NORTH, PSI, -3.0),
            (EAST, PSI, 4.0),
            (NORTH, WHEEL_SCALE, 2.0),
            (PSI, BIAS, -0.1),
            (PSI, GAIN_POS, -0.5),
            (PSI_ODO, WHEEL_DIFF, -7.0),
            (COMPASS_BIAS, COMPASS_BIAS, -0.1),
        ];
        let mut dense = nalgebra::SMatrix::<f64, DIM, DIM>::identity();
        for &(i, j, v) in &couplings {
            dense[(i, j)] += v;
        }
        let p = nalgebra::SMatrix::<f64, DIM, DIM>::from_fn(|i, j| f.p[i][j]);
        let expect = dense * p * dense.transpose();
        f.predict(&couplings, &[0.0; DIM]);
        for i in 0..DIM {
            for j in 0..DIM {
                assert!((f.p[i][j] - expect[(i, j)]).abs() < 1e-12, "{i} {j}");
            }
        }
    }

    proptest! {
        #[test]
        fn an_update_never_raises_a_variance_and_keeps_p_symmetric(
            sig in proptest::array::uniform13(1e-3f64..10.0),
            corr in -0.9f64..0.9,
            c in -3.0f64..3.0,
            nu in -10.0f64..10.0,
            r in 1e-6f64..10.0,
        ) {
            let mut f = filter(sig);
            let v = corr * sig[PSI] * sig[BIAS];
            f.p[PSI][BIAS] = v;
            f.p[BIAS][PSI] = v;
            let before = f;
            f.update(&[(PSI, 1.0), (PSI_ODO, c)], nu, r).unwrap();
            for i in 0..DIM {
                prop_assert!(f.p[i][i] <= before.p[i][i] * (1.0 + 1e-12) + 1e-15);
                for j in 0..DIM {
                    prop_assert_eq!(f.p[i][j], f.p[j][i]);
                }
            }
        }

        #[test]
        fn no_update_from_a_non_finite_or_non_positive_variance(
            r in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -10.0f64..=-1.0],
            nu in any::<f64>(),
        ) {
            let mut f = filter([0.0; DIM]);
            let before = f;
            prop_assert!(f.update(&[(PSI, 1.0)], nu, r).is_none());
            prop_assert_eq!(f, before);
        }
    }

    proptest! {
        #[test]
        fn a_schmidt_update_leaves_what_it_does_not_learn_and_equals_the_full_one_otherwise(
            sig in proptest::array::uniform13(1e-3f64..10.0),
            corr in -0.9f64..0.9,
            nu in -10.0f64..10.0,
            r in 1e-6f64..10.0,
            learn in 0u16..(1 << DIM),
        ) {
            let mut f = filter(sig);
            let v = corr * sig[PSI] * sig[BIAS];
            f.p[PSI][BIAS] = v;
            f.p[BIAS][PSI] = v;
            let mut full = f;
            let mut some = f;
            let h = [(PSI, 1.0), (BIAS, 2.0), (PSI_ODO, -1.0)];
            full.update(&h, nu, r).unwrap();
            some.update_some(&h, nu, r, learn).unwrap();
            for i in 0..DIM {
                let li = learn & state(i) != 0;
                prop_assert_eq!(some.x[i], if li { full.x[i] } else { f.x[i] });
                for j in 0..DIM {
                    let lj = learn & state(j) != 0;
                    let expect = if li || lj { full.p[i][j] } else { f.p[i][j] };
                    prop_assert_eq!(some.p[i][j], expect);
                    prop_assert_eq!(some.p[i][j], some.p[j][i]);
                }
            }
        }

        #[test]
        fn a_projection_keeps_the_state_at_its_floor_and_moves_the_correlated_ones(
            x in -1.0f64..1.0, corr in -0.9f64..0.9,
        ) {
            let mut f = filter([1.0; DIM]);
            f.x[SPEED_COEFF] = x;
            f.p[SPEED_COEFF][TRACK_SCALE] = corr;
            f.p[TRACK_SCALE][SPEED_COEFF] = corr;
            let before = f;
            f.project_at_least(SPEED_COEFF, 0.0);
            prop_assert_eq!(f.x[SPEED_COEFF], x.max(0.0));
            let moved = (x.min(0.0)).abs() * corr;
            prop_assert!((f.x[TRACK_SCALE] - moved).abs() < 1e-12);
            prop_assert_eq!(f.p, before.p);
        }
    }

    #[test]
    fn a_measurement_pulls_towards_it_in_proportion_to_trust() {
        let mut f = filter([
            1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ]);
        f.update(&[(PSI, 1.0)], 2.0, 1.0).unwrap();
        // Equal trust: half way, variance halved.
        assert!((f.x[PSI] - 1.0).abs() < 1e-12);
        assert!((f.p[PSI][PSI] - 0.5).abs() < 1e-12);
    }
}
