//! Passes over the readings cut into fixed segments, summed on several threads when the
//! readings allow it, with a result that does not depend on how many.
//!
//! A pass of a fit (a moment sum, the normal equations of one refinement step, a coverage
//! count) folds every reading into an accumulator. Here the readings are cut into
//! segments of [`SEGMENT`] readings, counted from the first; each segment is folded into a
//! fresh accumulator, in order, and the segments' accumulators are merged from the first
//! to the last. The arithmetic is fixed by the readings alone: which thread folds a
//! segment, and how many threads there are, changes nothing, bit for bit. Floating-point
//! addition is not associative, so a sum merged from partial sums differs in rounding
//! from one running sum: the cut is fixed so that the rounding is too. Readings that fit
//! in one segment are folded exactly as one running sum.
//!
//! Segments go to threads (`std` only) when the readings are in one slice or in a store
//! that lets several threads replay ranges at once ([`Readings::in_memory`],
//! [`Readings::shared`]), and there are two segments or more. Without `std` every
//! segment is folded on the caller's thread, in the same order, with the same result.

extern crate alloc;

use nalgebra::SVector;
use truenorth_core::Result;

use crate::numerics::blocks::{BLOCK, blocks};
use crate::numerics::readings::Readings;

/// Readings per segment: a multiple of [`BLOCK`] (so that no block straddles two
/// segments, and the blocks fall where one slice would have them), large enough that a
/// segment's work (0.1–1 ms) dwarfs the cost of handing it to a thread and merging its
/// accumulator, small enough that a recording of a few hundred thousand readings is
/// shared among threads.
pub(crate) const SEGMENT: usize = 1 << 16;

const _: () = assert!(SEGMENT.is_multiple_of(BLOCK));

/// How a pass folds readings: a fresh accumulator, the addition of a run of consecutive
/// readings to one, and the merge of the accumulator of the next segment into the
/// accumulator of those before it.
pub(crate) trait Fold<const D: usize>: Sync {
    /// What a segment's readings are folded into.
    type Acc: Send;

    /// An accumulator of no readings.
    fn start(&self) -> Self::Acc;

    /// Adds consecutive readings (a multiple of [`BLOCK`] long unless they end the segment).
    fn add(&self, acc: &mut Self::Acc, run: &[SVector<f64, D>]);

    /// Adds to `acc` the accumulator of the readings that follow it.
    fn merge(&self, acc: &mut Self::Acc, later: Self::Acc);
}

/// A [`Fold`] a run of consecutive readings at a time.
pub(crate) struct RunFold<S, A, M> {
    /// The fresh accumulator.
    pub start: S,
    /// Adds a run of readings.
    pub add: A,
    /// Merges the next segment's accumulator.
    pub merge: M,
}

impl<const D: usize, T: Send, S, A, M> Fold<D> for RunFold<S, A, M>
where
    S: Fn() -> T + Sync,
    A: Fn(&mut T, &[SVector<f64, D>]) + Sync,
    M: Fn(&mut T, T) + Sync,
{
    type Acc = T;

    fn start(&self) -> T {
        (self.start)()
    }

    #[inline]
    fn add(&self, acc: &mut T, run: &[SVector<f64, D>]) {
        (self.add)(acc, run);
    }

    fn merge(&self, acc: &mut T, later: T) {
        (self.merge)(acc, later);
    }
}

/// The `add` of a [`RunFold`] that takes a block of readings at a time (see [`BLOCK`]):
/// `add_block` is given the coordinates of a block as arrays and how many of its rows are
/// readings (the rest are zeros).
pub(crate) fn by_blocks<const D: usize, T>(
    add_block: impl Fn(&mut T, &[[f64; BLOCK]; D], usize) + Sync,
) -> impl Fn(&mut T, &[SVector<f64, D>]) + Sync {
    move |acc, run| {
        for (q, len) in blocks(run) {
            add_block(acc, &q, len);
        }
    }
}

/// Adds `later` to `acc` element by element: the merge of accumulators that are plain sums.
pub(crate) fn add_sums<const N: usize>(acc: &mut [f64; N], later: [f64; N]) {
    for (a, b) in acc.iter_mut().zip(later) {
        *a += b;
    }
}

/// The fold `f` of every reading (see the module documentation): the same value however
/// the readings are stored and however many threads fold them.
///
/// # Errors
/// An error replaying the readings, as [`Readings::replay`] gives it (of the first
/// segment that failed).
pub(crate) fn fold<const D: usize, R, F>(readings: &R, f: &F) -> Result<F::Acc>
where
    R: Readings<D> + ?Sized,
    F: Fold<D>,
{
    #[cfg(feature = "std")]
    {
        let n = readings.len();
        if n > SEGMENT {
            let threads = threads::available().min(n.div_ceil(SEGMENT));
            if threads > 1 {
                if let Some(slice) = readings.in_memory() {
                    return threads::fold(slice, threads, f);
                }
                if let Some(shared) = readings.shared() {
                    return threads::fold(shared, threads, f);
                }
            }
        }
    }
    fold_here(readings, f)
}

/// [`fold`] on the caller's thread: one replay, cut at the segment boundaries.
fn fold_here<const D: usize, R, F>(readings: &R, f: &F) -> Result<F::Acc>
where
    R: Readings<D> + ?Sized,
    F: Fold<D>,
{
    let mut total: Option<F::Acc> = None;
    let mut acc = f.start();
    let mut filled = 0usize;
    readings.replay(&mut |mut run| {
        while !run.is_empty() {
            let take = (SEGMENT - filled).min(run.len());
            f.add(&mut acc, &run[..take]);
            run = &run[take..];
            filled += take;
            if filled == SEGMENT {
                let done = core::mem::replace(&mut acc, f.start());
                merge_into(f, &mut total, done);
                filled = 0;
            }
        }
    })?;
    Ok(match total {
        Some(mut t) => {
            if filled > 0 {
                f.merge(&mut t, acc);
            }
            t
        }
        None => acc,
    })
}

/// Merges `next` into `total` (it becomes `total` when there is none yet).
fn merge_into<const D: usize, F: Fold<D>>(f: &F, total: &mut Option<F::Acc>, next: F::Acc) {
    match total {
        Some(t) => f.merge(t, next),
        None => *total = Some(next),
    }
}

#[cfg(feature = "std")]
mod threads {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{Mutex, PoisonError};
    use std::vec::Vec;

    use nalgebra::SVector;
    use truenorth_core::{Error, Result};

    use super::{Fold, SEGMENT, merge_into};
    use crate::numerics::readings::Readings;

    /// Threads a pass may use: what the system offers (`available_parallelism`), asked
    /// once per process, as the answer reads the cgroup's quota from files.
    pub(super) fn available() -> usize {
        static THREADS: AtomicUsize = AtomicUsize::new(0);
        match THREADS.load(Ordering::Relaxed) {
            0 => {
                let n = std::thread::available_parallelism().map_or(1, |n| n.get());
                THREADS.store(n, Ordering::Relaxed);
                n
            }
            n => n,
        }
    }

    /// The segments folded so far and not yet merged, and the merge of those before them.
    struct Merged<A> {
        /// The merge of segments `0..next`.
        total: Option<A>,
        /// The segment to merge next.
        next: usize,
        /// Segments folded ahead of one not yet done: as many as the other threads fold
        /// meanwhile, about one each when segments take alike.
        waiting: Vec<(usize, A)>,
        /// The error of the first segment whose replay failed.
        failed: Option<(usize, Error)>,
    }

    /// [`super::fold`] of `readings` on `threads` threads (the caller's among them): each
    /// takes the next segment not yet taken and folds it into a fresh accumulator, which
    /// is merged into the total as soon as every segment before it is: the merges go in
    /// index order, and few accumulators wait (not one per segment).
    pub(super) fn fold<const D: usize, R, F>(readings: &R, threads: usize, f: &F) -> Result<F::Acc>
    where
        R: Readings<D> + Sync + ?Sized,
        F: Fold<D>,
    {
        let n = readings.len();
        let segments = n.div_ceil(SEGMENT);
        let next = AtomicUsize::new(0);
        let merged = Mutex::new(Merged {
            total: None,
            next: 0,
            waiting: Vec::with_capacity(threads),
            failed: None,
        });
        let work = || {
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= segments {
                    break;
                }
                let mut acc = f.start();
                let end = n.min((k + 1) * SEGMENT);
                let r =
                    readings.replay_range(k * SEGMENT, end, &mut |run: &[SVector<f64, D>]| {
                        f.add(&mut acc, run);
                    });
                let mut m = merged.lock().unwrap_or_else(PoisonError::into_inner);
                if let Err(e) = r {
                    // The pass fails anyway; the other threads stop at their next segment.
                    next.store(segments, Ordering::Relaxed);
                    if m.failed.as_ref().is_none_or(|(j, _)| k < *j) {
                        m.failed = Some((k, e));
                    }
                    break;
                }
                m.waiting.push((k, acc));
                while let Some(i) = m.waiting.iter().position(|(j, _)| *j == m.next) {
                    let (_, part) = m.waiting.swap_remove(i);
                    merge_into(f, &mut m.total, part);
                    m.next += 1;
                }
            }
        };
        std::thread::scope(|s| {
            let helpers: Vec<_> = (1..threads).map(|_| s.spawn(work)).collect();
            work();
            for h in helpers {
                if let Err(e) = h.join() {
                    // A panic in a fold is a fault of the fold itself: it goes on as it
                    // would have on one thread.
                    std::panic::resume_unwind(e);
                }
            }
        });
        let m = merged.into_inner().unwrap_or_else(PoisonError::into_inner);
        if let Some((_, e)) = m.failed {
            return Err(e);
        }
        // Every segment was folded and merged (none failed), so there was at least one.
        Ok(m.total.unwrap_or_else(|| f.start()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::readings_tests::{Cut, FAILED};
    use nalgebra::Vector2;
    use proptest::prelude::*;

    /// Sums whose rounding depends on the order of the additions: a running sum of squares
    /// and of cubes of readings of very different sizes, and a count.
    fn rounding_fold() -> impl Fold<2, Acc = [f64; 3]> {
        RunFold {
            start: || [0.0; 3],
            add: |s: &mut [f64; 3], run: &[Vector2<f64>]| {
                for p in run {
                    s[0] += p.x * p.x + p.y;
                    s[1] += p.x * p.x * p.x - p.y;
                    s[2] += 1.0;
                }
            },
            merge: add_sums,
        }
    }

    fn readings(n: usize, seed: u64) -> Vec<Vector2<f64>> {
        let mut state = seed | 1;
        (0..n)
            .map(|_| {
                // xorshift64: values spread over many binades, so that every rounding counts.
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                Vector2::new((u * 40.0).exp() - 1.0, u - 0.5)
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(12))]

        /// The same bits on the caller's thread, on two, three or seven threads, and through
        /// a replay cut anyhow (the trait's default ranged replay).
        #[test]
        fn threads_and_cuts_change_nothing(
            segments in 0usize..4,
            extra in 0usize..SEGMENT,
            seed in any::<u64>(),
            runs in prop::collection::vec(1usize..3000, 1..4),
        ) {
            let points = readings(segments * SEGMENT + extra, seed);
            let f = rounding_fold();
            let here = fold_here(points.as_slice(), &f).unwrap();
            prop_assert_eq!(here[2], points.len() as f64);
            prop_assert_eq!(fold(points.as_slice(), &f).unwrap(), here);
            let cut = Cut { points: points.clone(), runs, ..Cut::default() };
            prop_assert_eq!(fold(&cut, &f).unwrap(), here);
            #[cfg(feature = "std")]
            for t in [2, 3, 7] {
                prop_assert_eq!(threads::fold(points.as_slice(), t, &f).unwrap(), here);
                prop_assert_eq!(threads::fold(&cut, t, &f).unwrap(), here);
            }
        }
    }

    /// Within one segment the fold is the plain running sum; beyond it, the merge of the
    /// segments' sums, which rounds differently (so the cut is a real, fixed choice).
    #[test]
    fn one_segment_is_one_running_sum() {
        let f = rounding_fold();
        let points = readings(2 * SEGMENT, 7);
        let mut running = [0.0; 3];
        f.add(&mut running, &points[..SEGMENT]);
        assert_eq!(fold(&points[..SEGMENT], &f).unwrap(), running);
        f.add(&mut running, &points[SEGMENT..]);
        let folded = fold(points.as_slice(), &f).unwrap();
        assert_eq!(folded[2], running[2]);
        assert_ne!(
            folded, running,
            "the merge rounded exactly as the running sum"
        );
    }

    /// A replay that fails fails the fold with its error, on any number of threads.
    #[test]
    fn a_failed_replay_fails_the_fold() {
        let f = rounding_fold();
        let cut = Cut {
            points: readings(3 * SEGMENT + 5, 3),
            runs: vec![1000],
            fail_at: Some(0),
            ..Cut::default()
        };
        assert_eq!(fold_here(&cut, &f).unwrap_err(), FAILED);
        #[cfg(feature = "std")]
        for t in [1, 2, 4] {
            cut.replays.store(0, core::sync::atomic::Ordering::Relaxed);
            assert_eq!(threads::fold(&cut, t, &f).unwrap_err(), FAILED);
        }
    }
}
