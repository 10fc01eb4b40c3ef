//! The joint least-squares problem of the magnetometer + accelerometer calibration (see
//! `mag_accel`): parameters, residuals, their Jacobian and the normal equations.
//!
//! In the coordinates of each sensor's normaliser, with `uᵢ = B_a(aᵢ − c_a)` and
//! `vᵢ = B_m(mᵢ − c_m)` (`B` symmetric), `R = R₀·exp([ω]×)` the rotation from the
//! magnetometer's calibrated frame into the accelerometer's, `s` the cosine of the angle
//! between gravity and the field, and `p` the pointing axis in the accelerometer's frame,
//! every reading contributes
//! * `|uᵢ| − 1` and `|vᵢ| − 1`: each sensor's readings lie on its ellipsoid (Li & Griffiths
//!   2004; Vasconcelos et al. 2011, "Geometric approach to strapdown magnetometer
//!   calibration in sensor frame", IEEE Trans. Aerospace and Electronic Systems 47(2));
//! * `ûᵢᵀ R v̂ᵢ − s`: the angle between gravity and the field is the same in every static
//!   reading (the dip-angle constraint; e.g. Kok & Schön 2016, "Magnetometer calibration
//!   using inertial sensors", IEEE Sensors Journal 16(14)).
//!
//! Every shot of a run aimed at one target also contributes `wᵢ − w̄`: the direction of `p`
//! in the level frame of the shot (built from `ûᵢ` and `R v̂ᵢ` by TRIAD: Black 1964, "A
//! passive system for determining the attitude of a satellite", AIAA Journal 2(7)) less
//! its mean over the run, since the pointing axis keeps its direction while the instrument
//! rolls about it.
//!
//! Each group is weighted by the inverse of its own standard deviation, estimated from its
//! residuals (Helmert's variance components; e.g. Koch 1999, *Parameter Estimation and
//! Hypothesis Testing in Linear Models*), so that neither sensor's unit nor noise decides
//! how much it counts.

use core::ops::Range;

use nalgebra::{Matrix3, Rotation3, SVector, Vector3};

use truenorth_core::Result;

use crate::fits::lm::{NormalAccumulator, NormalEquations};
use crate::fits::mag_accel::data::{Data, GroupSums, ReadingNormals, SENSOR, Weights, add_row};
use crate::fits::mag_accel::model::{BA, BM, CA, CM, Model, OMEGA, P, PAIRS, PT, S};
use crate::fits::mag_accel::run_rows::{RunSums, all_run_rows};
use crate::numerics::blocks::{BLOCK, sum_block};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// `∂x̂/∂x = (I − x̂x̂ᵀ)/|x|` applied to the row vector `g` (gives `(g − (g·x̂)x̂)/|x|`).
fn unit_gradient(g: &Vector3<f64>, x_hat: &Vector3<f64>, norm: f64) -> Vector3<f64> {
    (g - x_hat * g.dot(x_hat)) / norm
}

/// Adds to `row` the gradient with respect to `(c, B)` of a function of `u = B(x − c)`
/// whose gradient in `u` is `gu`: `∂/∂c = −B gu`, `∂/∂B_rs = gu_r d_s + gu_s d_r`
/// (`gu_r d_r` on the diagonal), `d = x − c`. For `|u| − 1`, `gu = û`.
fn chain_to_ellipsoid(
    row: &mut SVector<f64, P>,
    c0: usize,
    b0: usize,
    b: &Matrix3<f64>,
    d: &Vector3<f64>,
    gu: &Vector3<f64>,
) {
    let bc = -(b * gu);
    for k in 0..3 {
        row[c0 + k] += bc[k];
    }
    for (k, &(r, s)) in PAIRS.iter().enumerate() {
        row[b0 + k] += if r == s {
            gu[r] * d[r]
        } else {
            gu[r] * d[s] + gu[s] * d[r]
        };
    }
}

/// The normal equations of the weighted residuals at `theta`, and the group sums of the
/// unweighted ones; `None` where the model is undefined (a reading at a centre, a
/// non-finite value). `runs` are index ranges of shots aimed at one target; without any,
/// the pointing axis is held at x by a stiff prior.
pub(crate) fn normal_equations(
    data: &Data,
    runs: &[Range<usize>],
    w: &Weights,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Result<Option<(NormalEquations<P>, GroupSums)>> {
    let Some(normals) = reading_normals(data, r0, theta)? else {
        return Ok(None);
    };
    let (
        NormalEquations {
            mut cost,
            mut jtj,
            mut jtr,
        },
        mut sums,
    ) = normals.weighted(w);
    if runs.is_empty() {
        // No run: the pointing axis is x. A stiff prior keeps the normal equations regular.
        for k in [PT, PT + 1] {
            let mut row = SVector::<f64, P>::zeros();
            row[k] = 1e4;
            add_row(&mut jtj, &mut jtr, &mut cost, &row, 1e4 * theta[k]);
        }
    }
    let mut out = RunSums {
        jtj: &mut jtj,
        jtr: &mut jtr,
        cost: &mut cost,
        sums: &mut sums,
    };
    if all_run_rows(data, runs, w, r0, theta, &mut out)?.is_none() {
        return Ok(None);
    }
    for a in 0..P {
        for b in 0..a {
            jtj[(a, b)] = jtj[(b, a)];
        }
    }
    let ne = NormalEquations { cost, jtj, jtr };
    Ok((ne.cost.is_finite() && ne.jtj.iter().all(|x| x.is_finite())).then_some((ne, sums)))
}

/// The reading rows' normal equations at `theta`, each group's unweighted, from the pass
/// over the readings or, when the last pass was at the same point, from it: a round of the
/// variance components reweights at the point the previous round ended, and the report at
/// the point the last round ended, so weighting after the sums instead of in them spares
/// those passes (the weights scale each group's sums by `w²`).
fn reading_normals(
    data: &Data,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Result<Option<ReadingNormals>> {
    if let Some(last) = data.last.borrow().as_ref()
        && last.theta == *theta
        && last.r0 == *r0
    {
        return Ok(Some(*last));
    }
    let m = Model::of(theta, r0);
    let (groups, defined) = data.fold(
        || (ReadingGroups::new(), true),
        |(groups, defined): &mut (ReadingGroups, bool), a, mg| {
            if !*defined {
                return;
            }
            match reading_rows(&m, a, mg) {
                Some(rows) => groups.add(&rows),
                None => *defined = false,
            }
        },
        |(groups, defined), (later, later_defined)| {
            *defined &= later_defined;
            groups.merge(later);
        },
    )?;
    let normals = if defined {
        groups.finish(*theta, *r0)
    } else {
        None
    };
    *data.last.borrow_mut() = normals;
    Ok(normals)
}

/// The reading rows' normal equations, gathered a [`BLOCK`] of readings at a time (see the
/// `blocks` module), each group with only the parameters its rows touch: the
/// accelerometer's `(c_a, B_a)`, the magnetometer's `(c_m, B_m)`, the dip's everything but
/// the pointing axis. A dense rank-one update per row would spend most of its time adding
/// zeros, one scalar at a time.
struct ReadingGroups {
    acc: NormalAccumulator<SENSOR, { SENSOR + 1 }>,
    mag: NormalAccumulator<SENSOR, { SENSOR + 1 }>,
    dip: NormalAccumulator<PT, { PT + 1 }>,
    /// The unweighted squared residuals of the block, per group.
    squares: [[f64; BLOCK]; 3],
    /// The group sums of the blocks added so far.
    sums: GroupSums,
    /// Readings in the block being filled.
    filled: usize,
}

impl ReadingGroups {
    fn new() -> Self {
        Self {
            acc: NormalAccumulator::new(),
            mag: NormalAccumulator::new(),
            dip: NormalAccumulator::new(),
            squares: [[0.0; BLOCK]; 3],
            sums: GroupSums::default(),
            filled: 0,
        }
    }

    /// Adds one reading's rows (from [`reading_rows`]), unweighted.
    fn add(&mut self, [acc, mag, dip]: &[(SVector<f64, P>, f64); 3]) {
        let i = self.filled;
        for (cols, (row, r), first) in [
            (&mut self.acc.cols[..], acc, CA),
            (&mut self.mag.cols[..], mag, CM),
            (&mut self.dip.cols[..], dip, 0),
        ] {
            let n = cols.len() - 1;
            for (k, col) in cols[..n].iter_mut().enumerate() {
                col[i] = row[first + k];
            }
            cols[n][i] = *r;
        }
        for (g, (_, r)) in [acc, mag, dip].into_iter().enumerate() {
            self.squares[g][i] = r * r;
        }
        self.filled += 1;
        if self.filled == BLOCK {
            self.add_block();
        }
    }

    /// Adds the block filled so far (rows past `filled` zeroed: they add nothing).
    fn add_block(&mut self) {
        let i = self.filled;
        for col in self
            .acc
            .cols
            .iter_mut()
            .chain(self.mag.cols.iter_mut())
            .chain(self.dip.cols.iter_mut())
            .chain(self.squares.iter_mut())
        {
            col[i..].fill(0.0);
        }
        self.acc.add_block();
        self.mag.add_block();
        self.dip.add_block();
        for (group, squares) in [&mut self.sums.acc, &mut self.sums.mag, &mut self.sums.dip]
            .into_iter()
            .zip(&self.squares)
        {
            group.0 += sum_block(squares);
            group.1 += i;
        }
        self.filled = 0;
    }

    /// Adds the sums of `later`, the groups of the readings that follow these (its block
    /// in progress first: the blocks of a segment are its own).
    fn merge(&mut self, mut later: Self) {
        for g in [&mut *self, &mut later] {
            if g.filled > 0 {
                g.add_block();
            }
        }
        self.acc.merge(&later.acc);
        self.mag.merge(&later.mag);
        self.dip.merge(&later.dip);
        for (group, more) in [
            (&mut self.sums.acc, later.sums.acc),
            (&mut self.sums.mag, later.sums.mag),
            (&mut self.sums.dip, later.sums.dip),
        ] {
            group.0 += more.0;
            group.1 += more.1;
        }
    }

    /// The groups' normal equations at `theta` (with `r0`) and the group sums; `None` if
    /// anything overflowed.
    fn finish(mut self, theta: SVector<f64, P>, r0: Rotation3<f64>) -> Option<ReadingNormals> {
        if self.filled > 0 {
            self.add_block();
        }
        Some(ReadingNormals {
            theta,
            r0,
            acc: self.acc.finish()?,
            mag: self.mag.finish()?,
            dip: self.dip.finish()?,
            sums: self.sums,
        })
    }
}

/// The unweighted Jacobian rows and residuals of one reading `(a, mg)` under the model `m`:
/// the accelerometer's `|u| − 1`, the magnetometer's `|v| − 1` and the dip's `ûᵀ R v̂ − s`;
/// `None` for a reading at a sensor's centre.
pub(crate) fn reading_rows(
    m: &Model,
    a: &Vector3<f64>,
    mg: &Vector3<f64>,
) -> Option<[(SVector<f64, P>, f64); 3]> {
    let da = a - m.c_a;
    let u = m.b_a * da;
    let nu = u.norm();
    let dm = mg - m.c_m;
    let v = m.b_m * dm;
    let nv = v.norm();
    if !(nu > 1e-12 && nv > 1e-12) {
        return None;
    }
    let (u_hat, v_hat) = (u / nu, v / nv);
    // |u| − 1.
    let mut acc = SVector::<f64, P>::zeros();
    chain_to_ellipsoid(&mut acc, CA, BA, &m.b_a, &da, &u_hat);
    // |v| − 1.
    let mut mag = SVector::<f64, P>::zeros();
    chain_to_ellipsoid(&mut mag, CM, BM, &m.b_m, &dm, &v_hat);
    // ûᵀ R v̂ − s.
    let g = m.rot * v_hat;
    let r = u_hat.dot(&g) - m.s;
    let mut dip = SVector::<f64, P>::zeros();
    chain_to_ellipsoid(
        &mut dip,
        CA,
        BA,
        &m.b_a,
        &da,
        &unit_gradient(&g, &u_hat, nu),
    );
    let rtu = m.rot.transpose() * u_hat;
    chain_to_ellipsoid(
        &mut dip,
        CM,
        BM,
        &m.b_m,
        &dm,
        &unit_gradient(&rtu, &v_hat, nv),
    );
    // d/dδ ûᵀR exp([δ]×) v̂ at δ = 0 is v̂ × Rᵀû. At ω ≠ 0 this is the derivative in
    // the right-perturbation of R, which differs from ∂/∂ω by an invertible 3×3 factor:
    // the stationary points, and so the solution, are the same.
    let dw = v_hat.cross(&rtu);
    for k in 0..3 {
        dip[OMEGA + k] = dw[k];
    }
    dip[S] = -1.0;
    Some([(acc, nu - 1.0), (mag, nv - 1.0), (dip, r)])
}

/// RMS of the run residuals. An error replaying the readings is returned as it is.
pub(crate) fn aim_rms(
    data: &Data,
    runs: &[Range<usize>],
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Result<f64> {
    let w = Weights {
        acc: 0.0,
        mag: 0.0,
        dip: 0.0,
        aim: 1.0,
    };
    Ok(normal_equations(data, runs, &w, r0, theta)?
        .map(|(_, s)| (s.aim.0 / s.aim.1.max(1) as f64).sqrt())
        .unwrap_or(1.0))
}
