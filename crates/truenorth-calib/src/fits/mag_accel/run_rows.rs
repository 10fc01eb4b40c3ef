//! The rows of the runs of shots aimed at one target in the joint least-squares problem
//! (see `mag_accel_solve`): each shot's pointing direction in the level frame less its mean
//! over the run, with Jacobians by forward differences, summed a run at a time from the
//! readings replayed (a run too long to keep, in two more passes).

extern crate alloc;

use alloc::vec::Vec;
use core::ops::Range;

use nalgebra::{Rotation3, SMatrix, SVector, Vector3};
use truenorth_core::Result;

use crate::fits::mag_accel::data::{Data, GroupSums, Weights, add_row};
use crate::fits::mag_accel::model::{Model, P, level_direction};

/// The level-frame direction of the pointing axis for the shot `(a, mg)` (normalised)
/// under `theta`.
fn shot_direction(
    a: &Vector3<f64>,
    mg: &Vector3<f64>,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Option<Vector3<f64>> {
    let m = Model::of(theta, r0);
    let u = (m.b_a * (a - m.c_a)).try_normalize(1e-12)?;
    let v = (m.b_m * (mg - m.c_m)).try_normalize(1e-12)?;
    level_direction(&u, &(m.rot * v), &m.p)
}

/// Forward-difference step of the run rows' Jacobians: the parameters are of order one in
/// normalised coordinates; √ε balances truncation and rounding of a forward difference.
const RUN_H: f64 = 1.5e-8;

/// The level-frame direction of the pointing axis for the shot `(a, mg)` and its Jacobian
/// in the parameters, by forward differences (the TRIAD frame's derivatives are long to
/// write out and a run is a few shots).
fn shot_rows(
    a: &Vector3<f64>,
    mg: &Vector3<f64>,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
) -> Option<(Vector3<f64>, SMatrix<f64, 3, P>)> {
    let d0 = shot_direction(a, mg, r0, theta)?;
    let mut j = SMatrix::<f64, 3, P>::zeros();
    for k in 0..P {
        let mut t = *theta;
        t[k] += RUN_H;
        let dk = shot_direction(a, mg, r0, &t)?;
        j.set_column(k, &((dk - d0) / RUN_H));
    }
    Some((d0, j))
}

/// The normal equations and group sums being summed, for the run rows.
pub(crate) struct RunSums<'a> {
    pub jtj: &'a mut SMatrix<f64, P, P>,
    pub jtr: &'a mut SVector<f64, P>,
    pub cost: &'a mut f64,
    pub sums: &'a mut GroupSums,
}

impl RunSums<'_> {
    /// Adds the rows `d − mean` of one shot (direction `d`, Jacobian `j`), weighted by `w`.
    fn add_shot(
        &mut self,
        (d, j): (&Vector3<f64>, &SMatrix<f64, 3, P>),
        (mean, mean_j): (&Vector3<f64>, &SMatrix<f64, 3, P>),
        w: f64,
    ) {
        let r = d - mean;
        let jc = j - mean_j;
        for c in 0..3 {
            let row: SVector<f64, P> = jc.row(c).transpose();
            add_row(self.jtj, self.jtr, self.cost, &(row * w), r[c] * w);
            self.sums.aim.0 += r[c] * r[c];
        }
        self.sums.aim.1 += 3;
    }
}

/// The rows `wᵢ − w̄` of one run's `shots` (normalised accelerometer and magnetometer
/// readings), centred like the residuals.
fn run_rows(
    shots: &[(Vector3<f64>, Vector3<f64>)],
    w: &Weights,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    out: &mut RunSums,
) -> Option<()> {
    let n = shots.len();
    let mut dirs: Vec<Vector3<f64>> = Vec::with_capacity(n);
    let mut jac: Vec<SMatrix<f64, 3, P>> = Vec::with_capacity(n);
    for (a, mg) in shots {
        let (d0, j) = shot_rows(a, mg, r0, theta)?;
        dirs.push(d0);
        jac.push(j);
    }
    let inv = 1.0 / n as f64;
    let mean: Vector3<f64> = dirs.iter().sum::<Vector3<f64>>() * inv;
    let mean_j: SMatrix<f64, 3, P> = jac.iter().sum::<SMatrix<f64, 3, P>>() * inv;
    for (d, j) in dirs.iter().zip(&jac) {
        out.add_shot((d, j), (&mean, &mean_j), w.aim);
    }
    Some(())
}

/// [`run_rows`] of a run longer than the readings a pass may keep: one pass over the
/// readings sums the shots' directions and Jacobians (in order, from zero, as `sum` does),
/// another computes them again, the same to the bit, and adds the rows.
fn long_run_rows(
    data: &Data,
    run: &Range<usize>,
    w: &Weights,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    out: &mut RunSums,
) -> Result<Option<()>> {
    let mut sum = Vector3::<f64>::zeros();
    let mut sum_j = SMatrix::<f64, 3, P>::zeros();
    let mut defined = true;
    data.replay_range(run, |a, mg| match shot_rows(a, mg, r0, theta) {
        Some((d, j)) if defined => {
            sum += d;
            sum_j += j;
        }
        _ => defined = false,
    })?;
    if !defined {
        return Ok(None);
    }
    let inv = 1.0 / run.len() as f64;
    let (mean, mean_j) = (sum * inv, sum_j * inv);
    data.replay_range(run, |a, mg| {
        if let Some((d, j)) = shot_rows(a, mg, r0, theta) {
            out.add_shot((&d, &j), (&mean, &mean_j), w.aim);
        }
    })?;
    Ok(Some(()))
}

/// The rows of every run, in order: the runs that fit in memory a replay at a time, each
/// longer one by [`long_run_rows`]. `None` where a shot's direction is undefined.
pub(crate) fn all_run_rows(
    data: &Data,
    runs: &[Range<usize>],
    w: &Weights,
    r0: &Rotation3<f64>,
    theta: &SVector<f64, P>,
    out: &mut RunSums,
) -> Result<Option<()>> {
    let mut defined = true;
    let mut k = 0;
    while k < runs.len() && defined {
        let long = runs[k..]
            .iter()
            .position(|r| r.len() > data.limits.run_shots)
            .map_or(runs.len(), |p| k + p);
        if long > k {
            data.replay_runs(&runs[k..long], |shots| {
                if defined {
                    defined = run_rows(shots, w, r0, theta, out).is_some();
                }
            })?;
        }
        if long < runs.len() && defined {
            defined = long_run_rows(data, &runs[long], w, r0, theta, out)?.is_some();
        }
        k = long + 1;
    }
    Ok(defined.then_some(()))
}
