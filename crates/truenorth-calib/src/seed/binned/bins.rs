//! The heading bins of the binned ellipse (EP 0634001 claims 1, 3, 4): one reading (or a
//! running mean of readings) per direction about the current origin.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::quality::{SectorHint, sector};

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

/// The bin of direction `d` among `n`, or `None` for a zero or non-finite `d`: the sector
/// of `atan2(d)` in [0, 2π), bit for bit, found mostly without it ([`sector`]).
#[inline]
pub(crate) fn bin_index(d: &Vector2<f64>, n: usize) -> Option<usize> {
    if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
        return None;
    }
    Some(sector(d.y, d.x, n))
}

/// [`bin_index`] through `hint`, the bin of the direction before (see [`SectorHint`]): the
/// same bin.
#[inline(always)]
pub(crate) fn hinted_bin_index(d: &Vector2<f64>, n: usize, hint: &mut SectorHint) -> Option<usize> {
    if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
        return None;
    }
    Some(hint.sector(d.y, d.x, n))
}

/// Puts reading `p` in its bin about `origin` (claims 1, 3, 4): it replaces what a bin
/// that holds no measurement has; otherwise, with `memory` > 1, it enters the running mean
/// of the last `memory` readings, and with `memory` = 1 the bin keeps one reading (see
/// [`store_reading`]; `fresh` says, given the bin, whether it took no reading in the
/// current update interval nor in the one before). `index` gives the bin of a direction
/// ([`bin_index`], or [`hinted_bin_index`] for a stream of readings). Returns the bin, if
/// the reading has a direction.
///
/// Inlined into the calibrator's push, where the reading and the origin stay in
/// registers: passed through memory, each was stored in halves and loaded back whole,
/// which stalls (see [`crate::numerics::reading`]).
#[inline(always)]
pub(crate) fn bin_reading(
    bins: &mut Bins,
    centres: &BinCentres,
    origin: &Vector2<f64>,
    p: &Vector2<f64>,
    memory: u32,
    index: impl FnOnce(&Vector2<f64>) -> Option<usize>,
    fresh: impl FnOnce(usize) -> bool,
) -> Option<usize> {
    let i = index(&(p - origin))?;
    let fresh = fresh(i);
    store_reading(&mut bins[i], &centres[i], origin, p, memory, fresh);
    Some(i)
}

/// The unit centre direction of each of `n` bins (the first `n` entries).
pub(crate) type BinCentres = [Vector2<f64>; MAX_BINS];

/// The [`BinCentres`] of `n` bins.
pub(crate) fn bin_centres(n: usize) -> BinCentres {
    let mut c = [Vector2::zeros(); MAX_BINS];
    for (i, c) in c.iter_mut().enumerate().take(n) {
        let (sin, cos) = ((i as f64 + 0.5) * TAU / n as f64).sin_cos();
        *c = Vector2::new(cos, sin);
    }
    c
}

/// Whether direction `d` lies nearer the bin centre direction `c` (a unit vector) than `e`
/// does, both in that bin. Within a bin, at most π/8 from its centre (N ≥ 8), the nearer
/// direction has the smaller sine of its angle from the centre, `|c × d|/|d|`; compared
/// cross-multiplied, that takes no trigonometry per reading.
#[inline(always)]
fn nearer_centre(d: &Vector2<f64>, e: &Vector2<f64>, c: &Vector2<f64>) -> bool {
    c.perp(d).abs() * e.norm() < c.perp(e).abs() * d.norm()
}

/// Stores reading `p` in bin `b` (of centre direction `centre` about `origin`); `fresh` says whether the
/// bin took no reading in the current full-set update interval nor in the one before.
///
/// With `memory` = 1 the bin holds one reading (claim 1), and which one matters: a bin
/// takes a reading when the reading's *own* direction lies in it, so the newest reading a
/// turn leaves in a bin is the last whose noise threw it back across the edge the turn
/// crossed. Its true direction lies beyond that edge by an extreme of many noise draws,
/// which grows with the readings per bin; on an ellipse the radius there is the radius of
/// another direction, and as every bin lags the same way the fitted ellipse turns against
/// the true one. (At 5 % noise and 200 readings per degree the kept readings lagged by
/// 2.0–2.8 noise σ, see the calibrator's test
/// `a_dense_noisy_turn_keeps_readings_at_their_own_directions`, and the heading error
/// reached 7°, where the same readings binned in random order left 2.4°.) So a bin keeps
/// the reading nearest its centre direction: near the centre the noise that put a reading
/// there is as likely either way, so the kept reading's true direction is its own on
/// average, at any density. To follow a changed locus (claim 15) the first
/// reading of a fresh bin replaces the stored one whatever its direction: the update
/// intervals are counted in readings, a clock the noise does not set, and a bin must have
/// gone a whole interval without readings — the turn is away, not passing — so that the
/// last excursions back across its edge after the turn has left do not count as a new visit.
#[inline(always)]
fn store_reading(
    b: &mut Bin,
    centre: &Vector2<f64>,
    origin: &Vector2<f64>,
    p: &Vector2<f64>,
    memory: u32,
    fresh: bool,
) {
    if b.state != BinState::Measured {
        *b = Bin {
            value: *p,
            count: 1,
            state: BinState::Measured,
        };
        return;
    }
    b.count = b.count.saturating_add(1);
    if memory <= 1 {
        if fresh || nearer_centre(&(p - origin), &(b.value - origin), centre) {
            b.value = *p;
        }
        return;
    }
    let w = 1.0 / f64::from(b.count.min(memory));
    b.value += (p - b.value) * w;
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

/// One old bin's share of `rebin` (the tests' reference): moves `b` (if it holds a reading) into `bins`.
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
