//! The heading bins of the binned ellipse (EP 0634001 claims 1, 3, 4): one reading (or a
//! running mean of readings) per direction about the current origin.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_core::wrap_two_pi;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Most bins a calibrator can have (fixed arrays keep it allocation-free).
pub const MAX_BINS: usize = 128;

/// What a bin holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BinState {
    /// Nothing yet: the full set interpolates it.
    Empty,
    /// Real readings.
    Measured,
    /// Regenerated from stored parameters (claim 13); the next reading replaces it.
    Regenerated,
}

/// One direction bin: its reading (or running mean of readings), how many readings it
/// holds, and where they came from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct Bin {
    pub value: Vector2<f64>,
    pub count: u32,
    pub state: BinState,
}

pub(crate) const EMPTY: Bin = Bin {
    value: Vector2::new(0.0, 0.0),
    count: 0,
    state: BinState::Empty,
};

/// The bins of a calibrator (the first `n` are in use).
pub(crate) type Bins = [Bin; MAX_BINS];

/// The bin of direction `d` among `n`, or `None` for a zero or non-finite `d`.
pub(crate) fn bin_index(d: &Vector2<f64>, n: usize) -> Option<usize> {
    if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
        return None;
    }
    Some(((wrap_two_pi(d.y.atan2(d.x)) / TAU * n as f64) as usize).min(n - 1))
}

/// Puts reading `p` in its bin about `origin` (claims 1, 3, 4): it replaces what a bin
/// that holds no measurement has; otherwise it enters the running mean of the last
/// `memory` readings. Returns the bin, if the reading has a direction.
pub(crate) fn bin_reading(
    bins: &mut Bins,
    n: usize,
    origin: &Vector2<f64>,
    p: &Vector2<f64>,
    memory: u32,
) -> Option<usize> {
    let i = bin_index(&(p - origin), n)?;
    let b = &mut bins[i];
    if b.state != BinState::Measured {
        *b = Bin {
            value: *p,
            count: 1,
            state: BinState::Measured,
        };
    } else {
        b.count = b.count.saturating_add(1);
        let w = 1.0 / f64::from(b.count.min(memory));
        b.value += (p - b.value) * w;
    }
    Some(i)
}

/// Moves every stored reading to its bin about `new_origin`, merging readings that land in
/// one bin (weighted by their counts) — the "adjusting" of claim 1. (The job does it an old
/// bin at a time; this is the reference its tests compare with.)
#[cfg(test)]
pub(crate) fn rebin(bins: &mut Bins, n: usize, new_origin: &Vector2<f64>) {
    let old = *bins;
    *bins = [EMPTY; MAX_BINS];
    for b in &old[..n] {
        rebin_one(bins, n, b, new_origin);
    }
}

/// One old bin's share of [`rebin`]: moves `b` (if it holds a reading) into `bins`.
pub(crate) fn rebin_one(bins: &mut Bins, n: usize, b: &Bin, new_origin: &Vector2<f64>) {
    if b.state == BinState::Empty {
        return;
    }
    let Some(i) = bin_index(&(b.value - new_origin), n) else {
        return;
    };
    let t = &mut bins[i];
    if t.state == BinState::Empty {
        *t = *b;
    } else {
        let (wa, wb) = (f64::from(t.count.max(1)), f64::from(b.count.max(1)));
        t.value = (t.value * wa + b.value * wb) / (wa + wb);
        t.count = t.count.saturating_add(b.count);
        if b.state == BinState::Measured {
            t.state = BinState::Measured;
        }
    }
}

/// Bins holding real or regenerated readings.
pub(crate) fn filled(bins: &Bins, n: usize) -> usize {
    bins[..n]
        .iter()
        .filter(|b| b.state != BinState::Empty)
        .count()
}
