//! Effective track from a look-up table (US 4,788,645 claims 15, 16, 20, 21): the square roots
//! of eq. 14 were too slow for a 1980s navigation computer once a second, so T_E is tabulated
//! at evenly spaced curvature ratios 0..c_max and looked up. Here the look-up interpolates
//! linearly between entries. The table is a fixed-size array: building and looking up
//! allocate nothing.
//!
//! Interpolation error: in a cell of width h it is at most `h²/8 · max|T_E″|` over the cell,
//! which is smallest on gentle curves (7e-6 of the track up to 0.9 c_max with 256 entries
//! on a typical car) and unbounded in the last cell before the formula's limit, where the
//! inner root's slope is; there the monotone fall of T_E bounds it by the drop across the
//! cell. `tests/patent_vs_exact.rs` derives both bounds and checks the table against them.

use truenorth_core::{Error, Result, check_finite};

use crate::EffectiveTrack;

/// T_E tabulated at `N` evenly spaced ratios from 0 to `max_ratio`, interpolated linearly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectiveTrackTable<const N: usize> {
    max_ratio: f64,
    step: f64,
    values_m: [f64; N],
}

impl<const N: usize> EffectiveTrackTable<N> {
    /// Tabulates `source` (usually [`crate::PatentAckermannTrack`], but any
    /// [`EffectiveTrack`], e.g. the exact geometry) on `0..=max_ratio`. Needs N ≥ 2 and
    /// `0 < max_ratio ≤ source.max_ratio()`.
    pub fn build<S: EffectiveTrack>(source: &S, max_ratio: f64) -> Result<Self> {
        if N < 2 {
            return Err(Error::TooFewPoints { got: N, need: 2 });
        }
        check_finite("table max_ratio", max_ratio)?;
        if !(max_ratio > 0.0 && max_ratio <= source.max_ratio()) {
            return Err(Error::OutOfRange {
                what: "table max_ratio (must be positive and within the source's range)",
                value: max_ratio,
                min: 0.0,
                max: source.max_ratio(),
            });
        }
        let step = max_ratio / (N - 1) as f64;
        let mut values_m = [0.0; N];
        for (i, v) in values_m.iter_mut().enumerate() {
            // min(): i·step may round past max_ratio at the last entry.
            *v = source.effective_track_m((step * i as f64).min(max_ratio))?;
        }
        Ok(Self {
            max_ratio,
            step,
            values_m,
        })
    }

    /// Spacing of the entries in ratio.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The tabulated values, m, at ratios `0, step, 2·step, …`.
    pub fn values_m(&self) -> &[f64; N] {
        &self.values_m
    }
}

impl<const N: usize> EffectiveTrack for EffectiveTrackTable<N> {
    fn effective_track_m(&self, ratio: f64) -> Result<f64> {
        let c = check_finite("curvature ratio ΔD/AD", ratio)?.abs();
        if c > self.max_ratio {
            return Err(Error::OutOfRange {
                what: "curvature ratio ΔD/AD (beyond the look-up table)",
                value: ratio,
                min: -self.max_ratio,
                max: self.max_ratio,
            });
        }
        let x = c / self.step;
        // Cell index, kept inside 0..N-1 so that i + 1 is an entry (c = max lands in the last
        // cell with fraction 1). The float→usize cast saturates, and x ≤ N − 1 here anyway.
        let i = (x as usize).min(N - 2);
        let frac = x - i as f64;
        match (self.values_m.get(i), self.values_m.get(i + 1)) {
            (Some(a), Some(b)) => Ok(a + (b - a) * frac),
            _ => Err(Error::Degenerate {
                reason: "effective-track table has fewer than two entries",
            }),
        }
    }

    fn max_ratio(&self) -> f64 {
        self.max_ratio
    }
}
