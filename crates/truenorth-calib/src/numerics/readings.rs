//! The readings a batch fit passes over, replayed in order as runs of slices, and the store
//! a batch calibrator keeps them in.
//!
//! The least-squares fits pass over every reading several times (normalisation, the direct
//! fit's moments, every Levenberg–Marquardt trial, the quality report). They see the
//! readings through [`Readings`], so that the readings need not sit in one slice: a store
//! may keep the first ones in memory and the rest on disk, and hand them back a run at a
//! time. The fits give the same result, bit for bit, whichever way the readings are cut,
//! as long as every run but the last holds a multiple of [`READINGS_RUN_MULTIPLE`]
//! readings: their sums go a fixed block of readings at a time, and such runs keep the
//! blocks' boundaries where one slice would have them.

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::SVector;
use truenorth_core::Result;

use crate::numerics::blocks::BLOCK;

/// Every run a [`Readings::replay`] hands over, except the last, holds a multiple of this
/// many readings.
pub const READINGS_RUN_MULTIPLE: usize = BLOCK;

/// `D`-dimensional readings, replayed in the order they were recorded.
///
/// A slice (and a `Vec`) is readings in one run. An implementation that keeps its
/// readings elsewhere (a file) replays them in several runs, each but the last a multiple
/// of [`READINGS_RUN_MULTIPLE`] long, so that a fit through it gives exactly the result of
/// the same readings in one slice.
pub trait Readings<const D: usize> {
    /// How many readings there are.
    fn len(&self) -> usize;

    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Calls `run` with every reading, in order, in consecutive runs (every run but the
    /// last a multiple of [`READINGS_RUN_MULTIPLE`] long, none empty).
    ///
    /// # Errors
    /// Whatever stopped the replay (readings kept in memory never fail; a store on disk
    /// fails when it cannot read them back, with
    /// [`Error::ReadingsUnavailable`](truenorth_core::Error::ReadingsUnavailable)). A replay that failed may have called `run`
    /// with only part of the readings; a fit that sees the error returns it.
    fn replay(&self, run: &mut dyn FnMut(&[SVector<f64, D>])) -> Result<()>;

    /// Calls `run` with the readings `start..end`, in order, in consecutive runs as
    /// [`Self::replay`] does (every run but the last a multiple of
    /// [`READINGS_RUN_MULTIPLE`] long). `start` is a multiple of [`READINGS_RUN_MULTIPLE`]
    /// and `end` at most [`Self::len`]; an empty range calls nothing.
    ///
    /// The default replays every reading and hands on those in the range; a store that
    /// can seek overrides it.
    ///
    /// # Errors
    /// As [`Self::replay`].
    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[SVector<f64, D>]),
    ) -> Result<()> {
        let mut at = 0usize;
        self.replay(&mut |r| {
            let (lo, hi) = (start.max(at), end.min(at + r.len()));
            if lo < hi {
                run(&r[lo - at..hi - at]);
            }
            at += r.len();
        })
    }

    /// The readings as one slice, when they are kept in one: the fits then cut it among
    /// threads without a replay. `None` (the default) otherwise.
    fn in_memory(&self) -> Option<&[SVector<f64, D>]> {
        None
    }

    /// The readings as readings that several threads may replay ranges of at once
    /// ([`Self::replay_range`]), when the store allows it. `None` (the default) keeps every
    /// pass of a fit on one thread; the result is the same either way (see the
    /// `numerics::segments` module).
    fn shared(&self) -> Option<&(dyn Readings<D> + Sync)> {
        None
    }
}

impl<const D: usize> Readings<D> for [SVector<f64, D>] {
    fn len(&self) -> usize {
        <[SVector<f64, D>]>::len(self)
    }

    fn replay(&self, run: &mut dyn FnMut(&[SVector<f64, D>])) -> Result<()> {
        if !<[SVector<f64, D>]>::is_empty(self) {
            run(self);
        }
        Ok(())
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[SVector<f64, D>]),
    ) -> Result<()> {
        let end = end.min(<[SVector<f64, D>]>::len(self));
        if start < end {
            run(&self[start..end]);
        }
        Ok(())
    }

    fn in_memory(&self) -> Option<&[SVector<f64, D>]> {
        Some(self)
    }
}

impl<const D: usize> Readings<D> for Vec<SVector<f64, D>> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[SVector<f64, D>])) -> Result<()> {
        self.as_slice().replay(run)
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[SVector<f64, D>]),
    ) -> Result<()> {
        self.as_slice().replay_range(start, end, run)
    }

    fn in_memory(&self) -> Option<&[SVector<f64, D>]> {
        Some(self.as_slice())
    }
}

/// Where a batch calibrator keeps the readings pushed to it: [`Readings`] that grow.
///
/// `Vec` keeps them in memory (the default of [`crate::EllipseCalibrator`] and
/// [`crate::EllipsoidCalibrator`]); a store of its own lets a program bound the memory a
/// long recording takes, by keeping most of the readings elsewhere.
pub trait ReadingStore<const D: usize>: Readings<D> {
    /// Adds a reading after the others.
    ///
    /// # Errors
    /// When the reading cannot be stored (a disk full:
    /// [`Error::ReadingsUnavailable`](truenorth_core::Error::ReadingsUnavailable)); the
    /// store then holds the readings before it.
    fn push(&mut self, reading: SVector<f64, D>) -> Result<()>;

    /// Forgets every reading.
    fn clear(&mut self);
}

impl<const D: usize> ReadingStore<D> for Vec<SVector<f64, D>> {
    fn push(&mut self, reading: SVector<f64, D>) -> Result<()> {
        Vec::push(self, reading);
        Ok(())
    }

    fn clear(&mut self) {
        Vec::clear(self);
    }
}

/// The points of `readings` one by one, in order.
pub(crate) fn replay_points<const D: usize, R: Readings<D> + ?Sized>(
    readings: &R,
    mut f: impl FnMut(&SVector<f64, D>),
) -> Result<()> {
    readings.replay(&mut |run| run.iter().for_each(&mut f))
}

/// Centre of the axis-aligned bounding box of `readings` (zero for none).
pub(crate) fn bbox_centre<const D: usize, R: Readings<D> + ?Sized>(
    readings: &R,
) -> Result<SVector<f64, D>> {
    let mut lo = SVector::<f64, D>::repeat(f64::INFINITY);
    let mut hi = SVector::<f64, D>::repeat(f64::NEG_INFINITY);
    replay_points(readings, |p| {
        lo = lo.inf(p);
        hi = hi.sup(p);
    })?;
    Ok(if readings.is_empty() {
        SVector::zeros()
    } else {
        (lo + hi) * 0.5
    })
}
