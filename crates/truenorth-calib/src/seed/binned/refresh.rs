//! The full-set update of the binned ellipse (EP 0634001 claims 1–2, 5, 7–9, 12), written so
//! that it can run in bounded slices: interpolation of the full set, origin iteration with
//! re-binning, and the search for the ellipse parameters.
//!
//! [`RefreshJob`] does exactly the arithmetic of a refresh run in one go, in the same order,
//! but stops after a given amount of work and resumes on the next call. A calibrator starts a
//! job on a copy of its bins and lets each push advance it by one slice, so no push pays for
//! the whole update; the copy keeps the estimate in use consistent until the job completes
//! (double buffering). The work is counted in *bin operations* (one bin's share of one pass:
//! one interpolation partner tested, one bin re-binned, one bin's term of `S(θ)`), which
//! makes the slicing deterministic: the same pushes give the same slices on every machine.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use truenorth_compass::EllipsePhasors;
use truenorth_core::{Error, Result, angle_diff};

use crate::seed::binned::bins::{BinState, Bins, EMPTY, MAX_BINS, rebin_one};
use crate::seed::binned::params::{EVALUATIONS, ParamSearch};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Cost, in bin operations, of one bin's share of a pass that needs a trigonometric
/// function per bin (polar form, re-binning, placing a full-set value): about eight times
/// one bin's term of `S(θ)`.
const TRIG_COST: usize = 8;

/// `RefreshJob::slot` of a bin that holds no reading off the origin.
const NO_READING: u8 = u8::MAX;

/// Where a refresh stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stage {
    /// Building the full set of pass `pass` (passes `0..iterations` iterate the origin; pass
    /// `iterations` is the final one): while `polar_ready` is false the polar form of the
    /// filled bins, a bin at a time from `next`, then the output bins from `next`.
    FullSet {
        pass: usize,
        polar_ready: bool,
        next: usize,
    },
    /// Re-binning about the mean of the full set of pass `pass`, an old bin at a time from
    /// `next`.
    Rebin {
        pass: usize,
        mean: Vector2<f64>,
        next: usize,
    },
    /// Searching the ellipse parameters of the final full set.
    Params,
    /// Finished.
    Done,
}

/// A refresh in progress on its own copy of the bins (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RefreshJob {
    n: usize,
    iterations: usize,
    min_filled: usize,
    /// The bins being refreshed and their origin.
    pub bins: Bins,
    pub origin: Vector2<f64>,
    polar: [(f64, f64); MAX_BINS],
    k: usize,
    /// For each bin, the index in `polar` of the reading it holds (`NO_READING` if none),
    /// and of the last reading in the bins at or before it, going round.
    slot: [u8; MAX_BINS],
    last_at_or_before: [u8; MAX_BINS],
    full: [Vector2<f64>; MAX_BINS],
    /// The bins before the re-binning in progress.
    rebin_from: Bins,
    search: Option<ParamSearch>,
    stage: Stage,
    /// The outcome, once [`Self::advance`] returned `true`.
    pub result: Option<Result<EllipsePhasors>>,
}

/// The refusal of bins of which only `directions` (fewer than two) hold a reading off the
/// origin: a reading at the origin has no direction, and interpolating the full set needs
/// two, so at least two bins (and the calibrator's `min_filled`) are needed.
fn too_few_bins(directions: usize, n: usize, min_filled: usize) -> Error {
    Error::TooFewBins {
        filled: directions,
        need: min_filled.max(2),
        bins: n,
    }
}

impl RefreshJob {
    /// Upper bound of the bin operations of a refresh of `n` bins with `iterations` origin
    /// iterations (every pass with all bins filled).
    pub fn work_bound(n: usize, iterations: usize) -> usize {
        let passes = iterations + 1;
        passes * (TRIG_COST * n + TRIG_COST * n) + iterations * TRIG_COST * n + EVALUATIONS * n
    }

    /// A refresh of `bins` (the first `n` in use) about `origin`; `min_filled` is the count
    /// of filled bins a refusal for too few says is needed.
    pub fn start(
        bins: &Bins,
        n: usize,
        origin: &Vector2<f64>,
        iterations: usize,
        min_filled: usize,
    ) -> Self {
        Self {
            n,
            iterations,
            min_filled,
            bins: *bins,
            origin: *origin,
            polar: [(0.0, 0.0); MAX_BINS],
            k: 0,
            slot: [NO_READING; MAX_BINS],
            last_at_or_before: [0; MAX_BINS],
            full: [Vector2::zeros(); MAX_BINS],
            rebin_from: [EMPTY; MAX_BINS],
            search: None,
            stage: Stage::FullSet {
                pass: 0,
                polar_ready: false,
                next: 0,
            },
            result: None,
        }
    }

    /// Whether the refresh is over ([`Self::result`] is set).
    pub fn done(&self) -> bool {
        self.stage == Stage::Done
    }

    /// Does at least `budget` bin operations of work (or what is left), in whole units of
    /// at most `n` operations; returns whether the refresh is over.
    pub fn advance(&mut self, budget: usize) -> bool {
        let mut spent = 0usize;
        while spent < budget && !self.done() {
            spent += self.unit();
        }
        self.done()
    }

    /// Runs the refresh to its end.
    pub fn finish(&mut self) {
        while !self.done() {
            self.unit();
        }
    }

    /// One unit of work; returns its cost in bin operations.
    fn unit(&mut self) -> usize {
        match self.stage {
            Stage::FullSet {
                pass,
                polar_ready: false,
                next,
            } => self.polar_unit(pass, next),
            Stage::FullSet { pass, next, .. } => {
                self.full[next] = self.full_set_bin(next);
                self.stage = if next + 1 < self.n {
                    Stage::FullSet {
                        pass,
                        polar_ready: true,
                        next: next + 1,
                    }
                } else {
                    self.full_set_done(pass)
                };
                TRIG_COST
            }
            Stage::Rebin { pass, mean, next } => self.rebin_unit(pass, mean, next),
            Stage::Params => {
                let r = match self.search.as_mut() {
                    Some(s) => s.step(),
                    None => Some(Err(Error::NotReady {
                        what: "the binned-ellipse parameter search",
                        hint: "push more readings",
                    })),
                };
                if let Some(r) = r {
                    self.result = Some(r);
                    self.stage = Stage::Done;
                }
                self.n
            }
            Stage::Done => 0,
        }
    }

    /// One bin `i` of pass `pass` into polar form: (angle, magnitude) of each filled bin's
    /// reading about the origin, in bin order, and, after the last bin, where each bin's
    /// nearest readings are in that list.
    fn polar_unit(&mut self, pass: usize, i: usize) -> usize {
        let n = self.n;
        if i == 0 {
            self.k = 0;
        }
        let b = self.bins[i];
        self.slot[i] = NO_READING;
        if b.state != BinState::Empty {
            let d = b.value - self.origin;
            if d.norm() > 0.0 {
                self.polar[self.k] = (d.y.atan2(d.x), d.norm());
                self.slot[i] = self.k as u8;
                self.k += 1;
            }
        }
        if i + 1 < n {
            self.stage = Stage::FullSet {
                pass,
                polar_ready: false,
                next: i + 1,
            };
            return TRIG_COST;
        }
        let k = self.k;
        if k > 0 {
            // Before the first reading (going round) the last one is the latest.
            let mut last = (k - 1) as u8;
            for i in 0..n {
                if self.slot[i] != NO_READING {
                    last = self.slot[i];
                }
                self.last_at_or_before[i] = last;
            }
        }
        self.stage = if k < 2 {
            self.no_full_set()
        } else {
            Stage::FullSet {
                pass,
                polar_ready: true,
                next: 0,
            }
        };
        TRIG_COST
    }

    /// Old bin `next` of pass `pass` re-binned about `mean` (as `rebin`, an old bin at a
    /// time); after the last, the next pass starts about `mean`.
    fn rebin_unit(&mut self, pass: usize, mean: Vector2<f64>, next: usize) -> usize {
        let n = self.n;
        if next == 0 {
            self.rebin_from = self.bins;
            self.bins = [EMPTY; MAX_BINS];
        }
        let b = self.rebin_from[next];
        rebin_one(&mut self.bins, n, &b, &mean);
        self.stage = if next + 1 < n {
            Stage::Rebin {
                pass,
                mean,
                next: next + 1,
            }
        } else {
            self.origin = mean;
            Stage::FullSet {
                pass: pass + 1,
                polar_ready: false,
                next: 0,
            }
        };
        TRIG_COST
    }

    /// No full set (fewer than two readings off the origin). In an iteration pass this ends
    /// the iteration, and the final pass would see the same bins about the same origin, so
    /// either way the refresh ends here.
    fn no_full_set(&mut self) -> Stage {
        self.result = Some(Err(too_few_bins(self.k, self.n, self.min_filled)));
        Stage::Done
    }

    /// The full set of pass `pass` is complete.
    fn full_set_done(&mut self, pass: usize) -> Stage {
        let n = self.n;
        if pass < self.iterations {
            let mean = self.full[..n].iter().sum::<Vector2<f64>>() / n as f64;
            if mean.x.is_finite() && mean.y.is_finite() {
                return Stage::Rebin {
                    pass,
                    mean,
                    next: 0,
                };
            }
            // The iteration stops; the final pass would rebuild this very set.
        }
        match ParamSearch::new(&self.full[..n], &self.origin) {
            Ok(s) => {
                self.search = Some(s);
                Stage::Params
            }
            Err(e) => {
                self.result = Some(Err(e));
                Stage::Done
            }
        }
    }

    /// The full set (claim 1) at the centre direction of bin `i`: the magnitude there is
    /// interpolated linearly, in direction, between the two nearest stored readings on
    /// either side (claim 2) — for an empty bin these are its filled neighbours; for a
    /// filled bin its own reading is one of them. Placing every value at its bin's direction
    /// keeps the set uniform in direction whatever the readings' positions within their bins,
    /// which the mean (claim 5) and the R²-weighted sums of the parameters rely on.
    fn full_set_bin(&self, i: usize) -> Vector2<f64> {
        let dir = (i as f64 + 0.5) * TAU / self.n as f64;
        // Nearest reading at or before `dir` (within half a turn) and nearest after it,
        // going round the circle. Each reading lies in its own bin's sector about the
        // origin (it was binned about it), so the list is in order of direction and the
        // nearest ones are the neighbours of `dir` in it: the candidate on each side is
        // the first reading met going that way, and if it is more than half a turn away
        // (its wrapped difference has the other sign) no reading is within half a turn.
        let k = self.k;
        let (jb, ja) = match self.slot[i] {
            NO_READING => {
                let j = usize::from(self.last_at_or_before[i]);
                (j, (j + 1) % k)
            }
            j => {
                let j = usize::from(j);
                if angle_diff(self.polar[j].0, dir) <= 0.0 {
                    (j, (j + 1) % k)
                } else {
                    ((j + k - 1) % k, j)
                }
            }
        };
        let (mut before, mut after) = ((-TAU, 0.0), (TAU, 0.0));
        let (ab, rb) = self.polar[jb];
        let delta_b = angle_diff(ab, dir);
        if delta_b <= 0.0 {
            before = (delta_b, rb);
        }
        let (aa, ra) = self.polar[ja];
        let delta_a = angle_diff(aa, dir);
        if delta_a > 0.0 {
            after = (delta_a, ra);
        }
        interpolate(self.origin, dir, before, after)
    }
}

/// The point at direction `dir` from `origin` whose radius is interpolated linearly in
/// angle between the nearest readings `before` (angle offset ≤ 0, radius) and `after`
/// (offset > 0). A side with no reading (offset ∓2π) takes the other side's, a full turn
/// away: with k ≥ 2 readings at distinct angles both exist; if all share one angle, it is
/// used.
fn interpolate(
    origin: Vector2<f64>,
    dir: f64,
    mut before: (f64, f64),
    mut after: (f64, f64),
) -> Vector2<f64> {
    if before.0 <= -TAU {
        before = (after.0 - TAU, after.1);
    }
    if after.0 >= TAU {
        after = (before.0 + TAU, before.1);
    }
    let span = after.0 - before.0;
    let r = if span > 0.0 {
        before.1 + (after.1 - before.1) * (-before.0) / span
    } else {
        before.1
    };
    origin + Vector2::new(dir.cos(), dir.sin()) * r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::binned::bins::{bin_centres, bin_index, bin_reading, rebin};
    use crate::seed::binned::params::ellipse_parameters;
    use proptest::prelude::*;

    /// The full-set update in one go, as a plain loop (the reference the sliced job must
    /// reproduce bit for bit).
    fn refresh_at_once(
        bins: &mut Bins,
        n: usize,
        origin: &mut Vector2<f64>,
        iterations: usize,
    ) -> Result<EllipsePhasors> {
        let full_set = |bins: &Bins, origin: &Vector2<f64>| {
            let mut job = RefreshJob::start(bins, n, origin, 0, 0);
            job.polar();
            if job.k < 2 {
                return Err(too_few_bins(job.k, n, 0));
            }
            let mut out = [Vector2::zeros(); MAX_BINS];
            for (i, o) in out[..n].iter_mut().enumerate() {
                *o = job.full_set_bin(i);
            }
            Ok(out)
        };
        for _ in 0..iterations {
            let Ok(full) = full_set(bins, origin) else {
                break;
            };
            let mean = full[..n].iter().sum::<Vector2<f64>>() / n as f64;
            if !(mean.x.is_finite() && mean.y.is_finite()) {
                break;
            }
            rebin(bins, n, &mean);
            *origin = mean;
        }
        let full = full_set(bins, origin)?;
        ellipse_parameters(&full[..n], origin)
    }

    impl RefreshJob {
        /// Runs the polar pass of the first full set.
        fn polar(&mut self) {
            while matches!(
                self.stage,
                Stage::FullSet {
                    polar_ready: false,
                    ..
                }
            ) {
                self.unit();
            }
        }
    }

    fn bins_of(points: &[(f64, f64)], n: usize, origin: &Vector2<f64>) -> Bins {
        let mut bins = [EMPTY; MAX_BINS];
        let centres = bin_centres(n);
        for &(a, r) in points {
            let p = origin + Vector2::new(a.cos(), a.sin()) * r;
            let _ = bin_reading(
                &mut bins,
                &centres,
                origin,
                &p,
                1,
                |d| bin_index(d, n),
                |_| true,
            );
        }
        bins
    }

    /// The full-set value of bin `i` by searching every reading for the nearest on either
    /// side (the definition the neighbour lookup of `full_set_bin` must agree with).
    fn full_set_bin_by_search(job: &RefreshJob, i: usize) -> Vector2<f64> {
        let dir = (i as f64 + 0.5) * TAU / job.n as f64;
        let (mut before, mut after) = ((-TAU, 0.0), (TAU, 0.0));
        for &(a, r) in &job.polar[..job.k] {
            let delta = angle_diff(a, dir);
            if delta <= 0.0 && delta > before.0 {
                before = (delta, r);
            }
            if delta > 0.0 && delta < after.0 {
                after = (delta, r);
            }
        }
        interpolate(job.origin, dir, before, after)
    }

    proptest! {
        /// On bins filled about the job's origin (as a calibrator's are), the neighbour
        /// lookup finds exactly the readings a search of all of them finds, on any arc.
        #[test]
        fn neighbour_lookup_equals_the_full_search(
            pts in proptest::collection::vec((0.0f64..6.3, 0.5f64..1.5), 2..200),
            half_bins in 4usize..=64, arc in 0.05f64..1.0,
            ox in -0.5f64..0.5, oy in -0.5f64..0.5,
        ) {
            let n = 2 * half_bins;
            let origin = Vector2::new(ox, oy);
            let pts: Vec<_> = pts.iter().map(|&(a, r)| (a * arc, r)).collect();
            let bins = bins_of(&pts, n, &origin);
            let mut job = RefreshJob::start(&bins, n, &origin, 0, 0);
            job.polar();
            prop_assume!(job.k >= 2);
            for i in 0..n {
                prop_assert_eq!(job.full_set_bin(i), full_set_bin_by_search(&job, i), "bin {}", i);
            }
        }
    }

    proptest! {
        /// Sliced with any budget, the job gives exactly the bins, origin and parameters of
        /// the update done at once.
        #[test]
        fn slices_reproduce_the_update_at_once(
            pts in proptest::collection::vec((0.0f64..6.3, 0.5f64..1.5), 2..200),
            half_bins in 4usize..=64, iterations in 0usize..6, budget in 1usize..5000,
            ox in -0.5f64..0.5, oy in -0.5f64..0.5,
        ) {
            let n = 2 * half_bins;
            let start_origin = Vector2::new(ox, oy);
            let bins = bins_of(&pts, n, &Vector2::zeros());
            let (mut ref_bins, mut ref_origin) = (bins, start_origin);
            let expect = refresh_at_once(&mut ref_bins, n, &mut ref_origin, iterations);
            let mut job = RefreshJob::start(&bins, n, &start_origin, iterations, 0);
            let mut pushes = 0usize;
            while !job.advance(budget) {
                pushes += 1;
            }
            let bound = RefreshJob::work_bound(n, iterations);
            prop_assert!(pushes <= bound.div_ceil(budget));
            prop_assert_eq!(job.origin, ref_origin);
            prop_assert_eq!(&job.bins[..n], &ref_bins[..n]);
            match (job.result.unwrap(), expect) {
                (Ok(a), Ok(b)) => prop_assert_eq!(a, b),
                (Err(a), Err(b)) => prop_assert_eq!(a, b),
                (a, b) => prop_assert!(false, "{:?} vs {:?}", a, b),
            }
        }
    }
}
