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

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

extern crate alloc;

use alloc::vec::Vec;
use core::cell::RefCell;
use core::ops::Range;

use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};

use truenorth_core::Result;

use crate::fits::lm::{NormalAccumulator, NormalEquations};
use crate::fits::mag_accel::readings::{MagAccelReading, Sensor};
use crate::fits::mag_accel::run_rows::{RunSums, all_run_rows};
use crate::fits::normalise::Normaliser;
use crate::fits::readings::Readings;
use crate::numerics::blocks::{BLOCK, sum_block};
use crate::numerics::segments::{self, RunFold};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Number of parameters: `c_a` (3), `B_a` (6), `c_m` (3), `B_m` (6), `ω` (3), `s`, and the
/// pointing axis's two offsets from x.
pub(crate) const P: usize = 24;
pub(crate) const CA: usize = 0;
pub(crate) const BA: usize = 3;
pub(crate) const CM: usize = 9;
pub(crate) const BM: usize = 12;
pub(crate) const OMEGA: usize = 18;
pub(crate) const S: usize = 21;
pub(crate) const PT: usize = 22;

/// Index pairs of the six free entries of a symmetric matrix, in parameter order.
pub(crate) const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The symmetric matrix of six parameters.
pub(crate) fn sym(b: &[f64]) -> Matrix3<f64> {
    let mut m = Matrix3::zeros();
    for (k, &(r, c)) in PAIRS.iter().enumerate() {
        m[(r, c)] = b[k];
        m[(c, r)] = b[k];
    }
    m
}

/// The six parameters of a symmetric matrix.
pub(crate) fn unsym(m: &Matrix3<f64>) -> [f64; 6] {
    PAIRS.map(|(r, c)| 0.5 * (m[(r, c)] + m[(c, r)]))
}

/// The pointing axis with offsets `(α, β)` from x: `(1, α, β)/|·|`.
pub(crate) fn pointing(alpha: f64, beta: f64) -> Vector3<f64> {
    Vector3::new(1.0, alpha, beta).normalize()
}

/// The parameters, unpacked.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Model {
    pub c_a: Vector3<f64>,
    pub b_a: Matrix3<f64>,
    pub c_m: Vector3<f64>,
    pub b_m: Matrix3<f64>,
    pub rot: Matrix3<f64>,
    pub s: f64,
    pub p: Vector3<f64>,
}

impl Model {
    pub fn of(theta: &SVector<f64, P>, r0: &Rotation3<f64>) -> Self {
        let t = theta.as_slice();
        Self {
            c_a: Vector3::new(t[CA], t[CA + 1], t[CA + 2]),
            b_a: sym(&t[BA..BA + 6]),
            c_m: Vector3::new(t[CM], t[CM + 1], t[CM + 2]),
            b_m: sym(&t[BM..BM + 6]),
            rot: (r0 * Rotation3::new(Vector3::new(t[OMEGA], t[OMEGA + 1], t[OMEGA + 2])))
                .into_inner(),
            s: t[S],
            p: pointing(t[PT], t[PT + 1]),
        }
    }
}

/// The direction of `p` in the level frame of a reading whose unit specific force is `u`
/// and unit field (in the same frame) `g`: `(e₁·p, e₂·p, e₃·p)` with `e₃ = u`,
/// `e₂ = u × g/|u × g|`, `e₁ = e₂ × e₃`. For a specific force (pointing up) the frame is
/// (north, west, up). `None` when gravity and the field are parallel.
pub(crate) fn level_direction(
    u: &Vector3<f64>,
    g: &Vector3<f64>,
    p: &Vector3<f64>,
) -> Option<Vector3<f64>> {
    let n = u.cross(g);
    let nn = n.norm();
    if !(nn > 1e-9) {
        return None;
    }
    let e2 = n / nn;
    let e1 = e2.cross(u);
    Some(Vector3::new(e1.dot(p), e2.dot(p), u.dot(p)))
}

/// How much of the readings a pass of the joint fit keeps at once; past that, it passes
/// over them again instead.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Limits {
    /// The most shots of a run kept for its rows (about 650 bytes each with their
    /// Jacobians); a longer run takes two more passes.
    pub run_shots: usize,
    /// The most level frames the run search keeps (80 bytes each); a stretch of shots
    /// aimed one way longer than twice that takes more passes.
    pub stretch_frames: usize,
}

/// The limits of the fit: a few megabytes each.
pub(crate) const LIMITS: Limits = Limits {
    run_shots: 1 << 12,
    stretch_frames: 1 << 16,
};

/// The readings, each sensor in its normaliser's coordinates: normalised as they are
/// replayed, so that the fit keeps no copy of them.
pub(crate) struct Data<'a> {
    pub readings: &'a dyn Readings<6>,
    pub na: Normaliser<3>,
    pub nm: Normaliser<3>,
    pub limits: Limits,
    /// The readings' normals at the last point asked for (see [`ReadingNormals`]).
    last: RefCell<Option<ReadingNormals>>,
}

impl<'a> Data<'a> {
    /// The readings in the normalisers' coordinates, nothing remembered yet.
    pub fn new(
        readings: &'a dyn Readings<6>,
        na: Normaliser<3>,
        nm: Normaliser<3>,
        limits: Limits,
    ) -> Self {
        Self {
            readings,
            na,
            nm,
            limits,
            last: RefCell::new(None),
        }
    }

    /// How many readings there are.
    pub fn len(&self) -> usize {
        self.readings.len()
    }

    /// Calls `f` with every reading, in order: the accelerometer's and the magnetometer's,
    /// normalised. An error replaying the readings is returned as it is.
    pub fn replay(&self, mut f: impl FnMut(&Vector3<f64>, &Vector3<f64>)) -> Result<()> {
        self.readings.replay(&mut |run| {
            for r in run {
                f(
                    &self.na.apply(&Sensor::Acc.of(r)),
                    &self.nm.apply(&Sensor::Mag.of(r)),
                );
            }
        })
    }

    /// Folds every reading (normalised, accelerometer then magnetometer) with `add`, a
    /// segment at a time, merging the segments' accumulators in order with `merge` (see
    /// the `numerics::segments` module): on several threads where the store allows it,
    /// with the same result on any number. An error replaying the readings is returned as
    /// it is.
    pub fn fold<A: Send>(
        &self,
        start: impl Fn() -> A + Sync,
        add: impl Fn(&mut A, &Vector3<f64>, &Vector3<f64>) + Sync,
        merge: impl Fn(&mut A, A) + Sync,
    ) -> Result<A> {
        let (na, nm) = (&self.na, &self.nm);
        segments::fold(
            self.readings,
            &RunFold {
                start,
                add: |acc: &mut A, run: &[MagAccelReading]| {
                    for r in run {
                        add(
                            acc,
                            &na.apply(&Sensor::Acc.of(r)),
                            &nm.apply(&Sensor::Mag.of(r)),
                        );
                    }
                },
                merge,
            },
        )
    }

    /// Calls `f` with every reading of `range` (normalised), in order: a whole replay.
    pub fn replay_range(
        &self,
        range: &Range<usize>,
        mut f: impl FnMut(&Vector3<f64>, &Vector3<f64>),
    ) -> Result<()> {
        let mut i = 0usize;
        self.replay(|a, m| {
            if range.contains(&i) {
                f(a, m);
            }
            i += 1;
        })
    }

    /// Calls `f` with the normalised readings `(accelerometer, magnetometer)` of each of
    /// `runs` (index ranges, increasing and disjoint, as `mag_accel_runs` finds them), in
    /// order, one run at a time: only the run at hand is kept.
    pub fn replay_runs(
        &self,
        runs: &[Range<usize>],
        mut f: impl FnMut(&[(Vector3<f64>, Vector3<f64>)]),
    ) -> Result<()> {
        let mut shots = Vec::new();
        let (mut i, mut next) = (0usize, 0usize);
        self.replay(|a, m| {
            while runs.get(next).is_some_and(|r| r.end <= i) {
                next += 1;
            }
            if let Some(run) = runs.get(next).filter(|r| r.contains(&i)) {
                shots.push((*a, *m));
                if i + 1 == run.end {
                    f(&shots);
                    shots.clear();
                    next += 1;
                }
            }
            i += 1;
        })
    }
}

/// Inverse standard deviations of the residual groups.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Weights {
    pub acc: f64,
    pub mag: f64,
    pub dip: f64,
    pub aim: f64,
}

/// Sums of squared (unweighted) residuals and counts per group.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct GroupSums {
    pub acc: (f64, usize),
    pub mag: (f64, usize),
    pub dip: (f64, usize),
    pub aim: (f64, usize),
}

/// A rank-one update of the normal equations by the row `j` with residual `r`, both
/// already weighted.
pub(crate) fn add_row(
    jtj: &mut SMatrix<f64, P, P>,
    jtr: &mut SVector<f64, P>,
    cost: &mut f64,
    j: &SVector<f64, P>,
    r: f64,
) {
    for a in 0..P {
        if j[a] == 0.0 {
            continue;
        }
        for b in a..P {
            jtj[(a, b)] += j[a] * j[b];
        }
        jtr[a] += j[a] * r;
    }
    *cost += r * r;
}

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

/// The unweighted normal equations of the reading rows at one point, per group, and the
/// group sums.
#[derive(Debug, Clone, Copy)]
struct ReadingNormals {
    theta: SVector<f64, P>,
    r0: Rotation3<f64>,
    acc: NormalEquations<SENSOR>,
    mag: NormalEquations<SENSOR>,
    dip: NormalEquations<PT>,
    sums: GroupSums,
}

impl ReadingNormals {
    /// The normal equations of the rows weighted by `w`, in every parameter (upper triangle
    /// and diagonal; the caller mirrors them), and the group sums.
    fn weighted(&self, w: &Weights) -> (NormalEquations<P>, GroupSums) {
        let mut all = NormalEquations {
            cost: 0.0,
            jtj: SMatrix::<f64, P, P>::zeros(),
            jtr: SVector::<f64, P>::zeros(),
        };
        place(&mut all, CA, &self.acc, w.acc);
        place(&mut all, CM, &self.mag, w.mag);
        place(&mut all, 0, &self.dip, w.dip);
        (all, self.sums)
    }
}

/// Adds the normal equations `group` of the parameters from `first` on, weighted by `w`
/// (each row's, so the sums' by `w²`), to `all` (upper triangle and diagonal).
fn place<const N: usize>(
    all: &mut NormalEquations<P>,
    first: usize,
    group: &NormalEquations<N>,
    w: f64,
) {
    let w2 = w * w;
    for a in 0..N {
        for b in a..N {
            all.jtj[(first + a, first + b)] += w2 * group.jtj[(a, b)];
        }
        all.jtr[first + a] += w2 * group.jtr[a];
    }
    all.cost += w2 * group.cost;
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

/// Parameters of one sensor's ellipsoid: its centre (3) and symmetric matrix (6).
const SENSOR: usize = 9;

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
