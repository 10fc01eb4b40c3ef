//! The joint fit's readings as the solver sees them (each sensor in its normaliser's
//! coordinates, replayed rather than copied), the residual groups' weights and sums, and
//! the rank-one update every residual row makes to the normal equations.

extern crate alloc;

use alloc::vec::Vec;
use core::cell::RefCell;
use core::ops::Range;

use nalgebra::{Rotation3, SMatrix, SVector, Vector3};
use truenorth_core::Result;

use crate::fits::lm::NormalEquations;
use crate::fits::mag_accel::model::{CA, CM, Limits, P, PT};
use crate::fits::mag_accel::readings::{MagAccelReading, Sensor};
use crate::fits::normalise::Normaliser;
use crate::numerics::readings::Readings;
use crate::numerics::segments::{self, RunFold};

/// The readings, each sensor in its normaliser's coordinates: normalised as they are
/// replayed, so that the fit keeps no copy of them.
pub(crate) struct Data<'a> {
    pub readings: &'a dyn Readings<6>,
    pub na: Normaliser<3>,
    pub nm: Normaliser<3>,
    pub limits: Limits,
    /// The readings' normals at the last point asked for (see [`ReadingNormals`]).
    pub(crate) last: RefCell<Option<ReadingNormals>>,
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

/// Parameters of one sensor's ellipsoid: its centre (3) and symmetric matrix (6).
pub(crate) const SENSOR: usize = 9;

/// The unweighted normal equations of the reading rows at one point, per group, and the
/// group sums.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReadingNormals {
    pub theta: SVector<f64, P>,
    pub r0: Rotation3<f64>,
    pub acc: NormalEquations<SENSOR>,
    pub mag: NormalEquations<SENSOR>,
    pub dip: NormalEquations<PT>,
    pub sums: GroupSums,
}

impl ReadingNormals {
    /// The normal equations of the rows weighted by `w`, in every parameter (upper triangle
    /// and diagonal; the caller mirrors them), and the group sums.
    pub fn weighted(&self, w: &Weights) -> (NormalEquations<P>, GroupSums) {
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
