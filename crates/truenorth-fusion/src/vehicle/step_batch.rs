//! Several steps' error propagation composed into one, so that the covariance is carried
//! forward a few times a second instead of at every sample.
//!
//! Each step moves the errors by `e ← (I + E)e + w` with a sparse `E`: the heading takes
//! the calibration states' errors (`ψ ← cal`, the gyro's or the wheels'), the wheels'
//! heading likewise (`ψ_w ← cal`), position takes the heading's (`N, E ← ψ`, with the
//! heading *before* the step, and the odometer's scale: `N, E ← ψ, k`) and the compass
//! error decays (`b_c ← λ b_c`). Since the calibration states do not move, the product over
//! `m` steps keeps that shape:
//!
//! * `ψ_m = ψ_0 + A_m·cal`, with `A_k = Σ_{j≤k} c_j`;
//! * `N_m = N_0 + (Σ_k a_k) ψ_0 + (Σ_k a_k A_{k−1})·cal + (Σ_k s_k) k`, and the same for E;
//! * `ψ_w,m = ψ_w,0 + (Σ_k d_k)·cal`; `b_c,m = (Π λ_k) b_c,0`;
//!
//! and the heading noise added at step `j` reaches position with weight `S_m − S_j`
//! (`S_j = Σ_{k≤j} a_k`), whose moments are summed as the steps come. Applying the composed
//! transition once gives the same covariance as applying each step (to rounding), for a
//! few dozen multiply-adds per step — except that the calibration states' own random walk
//! enters at the end of the batch rather than flowing into the heading within it, a
//! second-order difference over a fraction of a second (`q_b·(m·dt)²`).

use super::nav_filter::{
    BIAS, COMPASS_BIAS, Coupling, DIM, EAST, GAIN_NEG, GAIN_POS, NORTH, NavFilter, PSI, PSI_ODO,
    SPEED_COEFF, TRACK_SCALE, WHEEL_DIFF, WHEEL_SCALE,
};

/// The calibration states: the only ones the heading is coupled to.
const CAL: [usize; 6] = [
    BIAS,
    GAIN_POS,
    GAIN_NEG,
    WHEEL_DIFF,
    SPEED_COEFF,
    TRACK_SCALE,
];

/// One step's couplings and process noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// ∂N/∂ψ and ∂E/∂ψ of the step (the heading before it).
    pub north_from_psi: f64,
    /// See `north_from_psi`.
    pub east_from_psi: f64,
    /// ∂N/∂k and ∂E/∂k of the step: the odometer's scale error moves the track along it.
    pub north_from_scale: f64,
    /// See `north_from_scale`.
    pub east_from_scale: f64,
    /// The heading's couplings to calibration states (state, coefficient); unused slots
    /// have coefficient 0.
    pub psi_from: [(usize, f64); 3],
    /// The wheels' heading's couplings to calibration states.
    pub odo_from: [(usize, f64); 3],
    /// Decay of the compass error over the step.
    pub compass_decay: f64,
    /// Process noise added to each state (diagonal).
    pub q: [f64; DIM],
}

impl Default for Step {
    /// A step that moves nothing: no coupling, no noise, the compass error kept.
    fn default() -> Self {
        Self {
            north_from_psi: 0.0,
            east_from_psi: 0.0,
            north_from_scale: 0.0,
            east_from_scale: 0.0,
            psi_from: [(0, 0.0); 3],
            odo_from: [(0, 0.0); 3],
            compass_decay: 1.0,
            q: [0.0; DIM],
        }
    }
}

/// The composition of the steps since the last [`StepBatch::apply`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepBatch {
    steps: u32,
    /// `A`: the heading's accumulated couplings, by state.
    psi_from: [f64; DIM],
    odo_from: [f64; DIM],
    north_from_psi: f64,
    east_from_psi: f64,
    north_from: [f64; DIM],
    east_from: [f64; DIM],
    compass_decay: f64,
    q: [f64; DIM],
    compass_q: f64,
    // Moments of the heading noise against the position weights S_j.
    q_sum: f64,
    qs_n: f64,
    qs_e: f64,
    qs_nn: f64,
    qs_ee: f64,
    qs_ne: f64,
}

impl Default for StepBatch {
    fn default() -> Self {
        Self {
            steps: 0,
            psi_from: [0.0; DIM],
            odo_from: [0.0; DIM],
            north_from_psi: 0.0,
            east_from_psi: 0.0,
            north_from: [0.0; DIM],
            east_from: [0.0; DIM],
            compass_decay: 1.0,
            q: [0.0; DIM],
            compass_q: 0.0,
            q_sum: 0.0,
            qs_n: 0.0,
            qs_e: 0.0,
            qs_nn: 0.0,
            qs_ee: 0.0,
            qs_ne: 0.0,
        }
    }
}

impl StepBatch {
    /// The heading's accumulated couplings to each state since the last apply (`A`).
    pub fn psi_from(&self) -> &[f64; DIM] {
        &self.psi_from
    }

    /// Heading variance added by noise since the last apply, rad².
    pub fn psi_noise(&self) -> f64 {
        self.q[PSI]
    }

    /// The heading's variance as [`StepBatch::apply`] would leave it, rad², without
    /// applying: `P_ψψ + 2 A·P_cal,ψ + Aᵀ P_cal A + q_ψ`. The calibration states' share
    /// matters while they are uncertain — at the start a gyro bias of σ 3°/s turns the
    /// heading by 0.6° (1σ) in the 0.2 s a batch may span.
    pub fn psi_variance(&self, filter: &NavFilter) -> f64 {
        let p = &filter.p;
        let a = &self.psi_from;
        let mut var = p[PSI][PSI] + self.q[PSI];
        for i in CAL {
            if a[i] == 0.0 {
                continue;
            }
            var += 2.0 * a[i] * p[i][PSI];
            for j in CAL {
                var += a[i] * a[j] * p[i][j];
            }
        }
        var
    }

    /// Composes one more step.
    pub fn add(&mut self, step: &Step) {
        self.steps += 1;
        // Position takes the heading before this step's increment: A_{k−1}.
        for i in CAL {
            self.north_from[i] += step.north_from_psi * self.psi_from[i];
            self.east_from[i] += step.east_from_psi * self.psi_from[i];
        }
        self.north_from_psi += step.north_from_psi;
        self.east_from_psi += step.east_from_psi;
        self.north_from[WHEEL_SCALE] += step.north_from_scale;
        self.east_from[WHEEL_SCALE] += step.east_from_scale;
        // Heading noise from earlier steps feeds this step's position weight S_k. The
        // moments keep Σ q_j S_j, Σ q_j S_j² … with S_j the weight after step j.
        for &(j, c) in &step.psi_from {
            self.psi_from[j] += c;
        }
        for &(j, c) in &step.odo_from {
            self.odo_from[j] += c;
        }
        let qp = step.q[PSI];
        let (sn, se) = (self.north_from_psi, self.east_from_psi);
        self.q_sum += qp;
        self.qs_n += qp * sn;
        self.qs_e += qp * se;
        self.qs_nn += qp * sn * sn;
        self.qs_ee += qp * se * se;
        self.qs_ne += qp * sn * se;
        self.compass_decay *= step.compass_decay;
        self.compass_q =
            self.compass_q * step.compass_decay * step.compass_decay + step.q[COMPASS_BIAS];
        for (a, b) in self.q.iter_mut().zip(&step.q) {
            *a += b;
        }
    }

    /// Carries `filter`'s covariance through the composed steps and starts a new batch.
    pub fn apply(&mut self, filter: &mut NavFilter) {
        if self.steps == 0 {
            return;
        }
        let mut couplings = [(0, 0, 0.0); 4 * CAL.len() + 5];
        let mut n = 0;
        let mut push = |c: Coupling| {
            if c.2 != 0.0 {
                couplings[n] = c;
                n += 1;
            }
        };
        // Position first: it reads the heading's row as it was before the batch.
        push((NORTH, PSI, self.north_from_psi));
        push((EAST, PSI, self.east_from_psi));
        for i in CAL.into_iter().chain([WHEEL_SCALE]) {
            push((NORTH, i, self.north_from[i]));
            push((EAST, i, self.east_from[i]));
        }
        for i in CAL {
            push((PSI, i, self.psi_from[i]));
            push((PSI_ODO, i, self.odo_from[i]));
        }
        push((COMPASS_BIAS, COMPASS_BIAS, self.compass_decay - 1.0));
        let mut q = self.q;
        q[COMPASS_BIAS] = self.compass_q;
        // Heading noise of step j reaches position with weight S_m − S_j.
        let (sn, se) = (self.north_from_psi, self.east_from_psi);
        q[NORTH] += sn * sn * self.q_sum - 2.0 * sn * self.qs_n + self.qs_nn;
        q[EAST] += se * se * self.q_sum - 2.0 * se * self.qs_e + self.qs_ee;
        let ne = sn * se * self.q_sum - sn * self.qs_e - se * self.qs_n + self.qs_ne;
        let n_psi = sn * self.q_sum - self.qs_n;
        let e_psi = se * self.q_sum - self.qs_e;
        filter.predict(&couplings[..n], &q);
        filter.p[NORTH][EAST] += ne;
        filter.p[EAST][NORTH] += ne;
        filter.p[NORTH][PSI] += n_psi;
        filter.p[PSI][NORTH] += n_psi;
        filter.p[EAST][PSI] += e_psi;
        filter.p[PSI][EAST] += e_psi;
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn step_couplings(s: &Step) -> Vec<Coupling> {
        let mut c = vec![
            (NORTH, PSI, s.north_from_psi),
            (EAST, PSI, s.east_from_psi),
            (NORTH, WHEEL_SCALE, s.north_from_scale),
            (EAST, WHEEL_SCALE, s.east_from_scale),
        ];
        c.extend(s.psi_from.iter().map(|&(j, v)| (PSI, j, v)));
        c.extend(s.odo_from.iter().map(|&(j, v)| (PSI_ODO, j, v)));
        c.push((COMPASS_BIAS, COMPASS_BIAS, s.compass_decay - 1.0));
        c
    }

    proptest! {
        /// Composing steps gives the covariance of applying them one by one.
        #[test]
        fn a_batch_equals_its_steps(
            steps in proptest::collection::vec(
                (-5.0f64..5.0, -5.0f64..5.0, -0.1f64..0.1, -0.1f64..0.1, -3.0f64..3.0,
                 0.9f64..1.0, 0.0f64..1e-3, 0.0f64..1e-3, 0.0f64..1e-2),
                1..12),
            sigma in proptest::array::uniform13(0.01f64..2.0),
        ) {
            let mut one = NavFilter::new([0.0; DIM], sigma);
            one.p[BIAS][GAIN_POS] = 0.3 * sigma[BIAS] * sigma[GAIN_POS];
            one.p[GAIN_POS][BIAS] = one.p[BIAS][GAIN_POS];
            one.p[WHEEL_SCALE][TRACK_SCALE] = -0.2 * sigma[WHEEL_SCALE] * sigma[TRACK_SCALE];
            one.p[TRACK_SCALE][WHEEL_SCALE] = one.p[WHEEL_SCALE][TRACK_SCALE];
            let mut batched = one;
            let mut batch = StepBatch::default();
            for &(an, ae, cb, cg, cd, decay, qp, qc, qn) in &steps {
                let mut q = [0.0; DIM];
                q[PSI] = qp;
                q[COMPASS_BIAS] = qc;
                q[NORTH] = qn;
                let s = Step {
                    north_from_psi: an,
                    east_from_psi: ae,
                    north_from_scale: 0.3 * ae,
                    east_from_scale: -0.7 * an,
                    psi_from: [(BIAS, cb), (GAIN_POS, cg), (TRACK_SCALE, 0.0)],
                    odo_from: [(WHEEL_DIFF, cd), (SPEED_COEFF, 0.1 * cd), (TRACK_SCALE, cg)],
                    compass_decay: decay,
                    q,
                };
                one.predict(&step_couplings(&s), &q);
                batch.add(&s);
            }
            batch.apply(&mut batched);
            for i in 0..DIM {
                for j in 0..DIM {
                    let scale = 1.0 + one.p[i][i].abs().max(one.p[j][j].abs());
                    prop_assert!((one.p[i][j] - batched.p[i][j]).abs() < 1e-9 * scale,
                        "P[{i}][{j}]: {} vs {}", one.p[i][j], batched.p[i][j]);
                }
            }
        }
    }
}
