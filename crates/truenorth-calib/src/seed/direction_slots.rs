//! A fixed-size sample of raw readings spread by direction, kept by the seed calibrators so
//! that their quality report can be computed on real readings without storing every sample.

extern crate alloc;

use nalgebra::Vector2;

use crate::quality::SectorHint;

/// Number of direction slots (5° each).
pub(crate) const SLOTS: usize = 72;

/// The latest raw reading in each 5° direction slot about a provisional centre.
///
/// The centre may move between pushes (it is the calibrator's current estimate); the readings
/// kept are real ones whatever the slot, so a report computed on them about the final centre is
/// honest — at worst it undercounts coverage (two readings landed in one slot), never
/// overcounts it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DirectionSlots {
    points: [Vector2<f64>; SLOTS],
    filled: [bool; SLOTS],
    /// The slot of the last reading, which the next one is almost always in.
    hint: SectorHint,
}

impl DirectionSlots {
    pub(crate) fn new() -> Self {
        Self {
            points: [Vector2::zeros(); SLOTS],
            filled: [false; SLOTS],
            hint: SectorHint::new(),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.filled = [false; SLOTS];
    }

    /// Keeps `p` in the slot of its direction about `centre` (skipped if not finite or at the
    /// centre). The slot is that of `atan2` of `p − centre`, found mostly without it
    /// ([`SectorHint`]).
    #[inline(always)]
    pub(crate) fn push(&mut self, p: &Vector2<f64>, centre: &Vector2<f64>) {
        if let Some(d) = direction_about(p, centre) {
            let i = self.hint.sector(d.y, d.x, SLOTS);
            self.keep(i, p);
        }
    }

    /// Stores `p` in slot `i`.
    fn keep(&mut self, i: usize, p: &Vector2<f64>) {
        self.points[i] = *p;
        self.filled[i] = true;
    }

    /// The slots in order, `None` where empty (for saving).
    pub(crate) fn to_vec(&self) -> alloc::vec::Vec<Option<Vector2<f64>>> {
        self.points
            .iter()
            .zip(self.filled.iter())
            .map(|(p, &f)| f.then_some(*p))
            .collect()
    }

    /// Slots from [`Self::to_vec`]'s output; `None` unless there are exactly [`SLOTS`]
    /// entries, all finite.
    pub(crate) fn from_slice(saved: &[Option<Vector2<f64>>]) -> Option<Self> {
        if saved.len() != SLOTS {
            return None;
        }
        let mut s = Self::new();
        for (i, p) in saved.iter().enumerate() {
            if let Some(p) = p {
                if !(p.x.is_finite() && p.y.is_finite()) {
                    return None;
                }
                s.points[i] = *p;
                s.filled[i] = true;
            }
        }
        Some(s)
    }

    /// Copies the kept readings to the front of `buf`; returns how many.
    pub(crate) fn collect(&self, buf: &mut [Vector2<f64>; SLOTS]) -> usize {
        let mut n = 0;
        for (p, _) in self
            .points
            .iter()
            .zip(self.filled.iter())
            .filter(|(_, f)| **f)
        {
            buf[n] = *p;
            n += 1;
        }
        n
    }
}

/// `p − centre`, or `None` if it is not finite or zero (no direction).
fn direction_about(p: &Vector2<f64>, centre: &Vector2<f64>) -> Option<Vector2<f64>> {
    let d = p - centre;
    ((d.x.is_finite() && d.y.is_finite()) && (d.x != 0.0 || d.y != 0.0)).then_some(d)
}
