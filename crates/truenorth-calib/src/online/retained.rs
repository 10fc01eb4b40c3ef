//! The readings an online least-squares calibrator retains for measuring coverage (at most
//! one per direction slot), and their serialisable form.

use alloc::vec::Vec;

use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Real, Result};

/// Readings kept for coverage: at most one per direction slot, so that how much of the
/// circle (sphere) the data cover can be measured about any centre without storing every
/// reading.
///
/// A reading's slot is its direction under the current calibration (the caller's key);
/// a slot keeps the first reading that reached it until that reading expires (forgetting),
/// so the ends of an arc are never replaced by readings from its middle. A coverage measured
/// on these readings is that of a subset of the data, so it never exceeds the batch fit's
/// coverage about the same centre.
///
/// The readings are kept in the calibrator's float type `T`, as they arrived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Retained<T: Real, const D: usize, const N: usize> {
    /// The reading in each slot.
    pub reading: [SVector<T, D>; N],
    /// Its sample number (1 for the first reading accepted); 0 for an empty slot.
    pub stamp: [u64; N],
    /// Number of empty slots (stamp 0), kept with the stamps so that a full set is known
    /// without a scan (see [`Retained::refuses_all`]).
    vacant: usize,
}

impl<T: Real, const D: usize, const N: usize> Retained<T, D, N> {
    /// No readings.
    pub fn new() -> Self {
        Self {
            reading: [SVector::zeros(); N],
            stamp: [0; N],
            vacant: N,
        }
    }

    /// Whether [`Retained::offer`] keeps nothing until the slots change otherwise, whatever
    /// the slot: every slot holds a reading and none expires (`lifetime` unlimited, no
    /// forgetting). A caller can then skip finding a reading's slot, most of what keeping
    /// the readings costs per sample.
    #[inline]
    pub fn refuses_all(&self, lifetime: u64) -> bool {
        // With `lifetime` u64::MAX a stored reading is live at every later sample:
        // `now - stamp < u64::MAX` as `stamp ≥ 1`.
        self.vacant == 0 && lifetime == u64::MAX
    }

    /// Whether slot `j` holds a reading younger than `lifetime` samples at sample `now`.
    #[inline]
    pub fn is_live(&self, j: usize, now: u64, lifetime: u64) -> bool {
        let s = self.stamp[j];
        s != 0 && now.saturating_sub(s) < lifetime
    }

    /// Keeps reading `p` (sample number `stamp`) in `slot` unless a live reading is there.
    #[inline]
    pub fn offer(&mut self, slot: usize, p: &SVector<T, D>, stamp: u64, lifetime: u64) {
        if slot < N && !self.is_live(slot, stamp, lifetime) {
            self.vacant -= usize::from(self.stamp[slot] == 0);
            self.reading[slot] = *p;
            self.stamp[slot] = stamp;
        }
    }

    /// Re-sorts the live readings into the slots of a new `key`; of two readings that meet
    /// in a slot the older stays. O(N), no allocation.
    pub fn rekey(
        &mut self,
        key: impl Fn(&SVector<T, D>) -> Option<usize>,
        now: u64,
        lifetime: u64,
    ) {
        let mut out = Self::new();
        for j in 0..N {
            if !self.is_live(j, now, lifetime) {
                continue;
            }
            if let Some(k) = key(&self.reading[j]).filter(|&k| k < N)
                && (out.stamp[k] == 0 || out.stamp[k] > self.stamp[j])
            {
                out.vacant -= usize::from(out.stamp[k] == 0);
                out.reading[k] = self.reading[j];
                out.stamp[k] = self.stamp[j];
            }
        }
        *self = out;
    }

    /// The live readings at sample `now`.
    pub fn live(&self, now: u64, lifetime: u64) -> impl Iterator<Item = &SVector<T, D>> {
        (0..N)
            .filter(move |&j| self.is_live(j, now, lifetime))
            .map(move |j| &self.reading[j])
    }

    /// The readings in `f64` (exact), for a refresh, which computes in `f64`.
    pub fn widened(&self) -> Retained<f64, D, N> {
        Retained {
            reading: self.reading.map(|p| p.map(T::to_f64)),
            stamp: self.stamp,
            vacant: self.vacant,
        }
    }

    /// The serialisable form (`f64`, exact for either float type).
    pub fn snapshot(&self) -> RetainedSnapshot {
        RetainedSnapshot {
            readings: self
                .reading
                .iter()
                .flat_map(|p| p.iter().map(|x| x.to_f64()))
                .collect(),
            stamps: self.stamp.to_vec(),
        }
    }

    /// Back from the serialisable form, refusing wrong lengths, readings not finite in `T`
    /// and stamps from the future.
    pub fn restore(s: &RetainedSnapshot, count: u64) -> Result<Self> {
        if s.readings.len() != N * D || s.stamps.len() != N {
            return Err(Error::InvalidSnapshot {
                reason: "the retained readings do not have the layout of this calibrator",
            });
        }
        if !s.readings.iter().all(|&x| T::of(x).is_finite()) || s.stamps.iter().any(|&t| t > count)
        {
            return Err(Error::InvalidSnapshot {
                reason: "a retained reading is not finite or is newer than the sample count",
            });
        }
        let mut out = Self::new();
        for j in 0..N {
            out.reading[j] = SVector::from_fn(|i, _| T::of(s.readings[j * D + i]));
            out.stamp[j] = s.stamps[j];
        }
        out.vacant = out.stamp.iter().filter(|&&t| t == 0).count();
        Ok(out)
    }
}

/// Serialisable retained readings: `readings` holds the slots' coordinates one slot
/// after another, `stamps` their sample numbers (0 for an empty slot).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RetainedSnapshot {
    /// Coordinates of the slots' readings, flattened, input unit.
    pub readings: Vec<f64>,
    /// Sample number of each slot's reading, 0 for an empty slot.
    pub stamps: Vec<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    type Slots = Retained<f64, 2, 8>;

    fn empty(r: &Slots) -> usize {
        r.stamp.iter().filter(|&&s| s == 0).count()
    }

    /// The count of empty slots follows every change of the stamps, and once every slot is
    /// taken without forgetting, every offer is refused, as `refuses_all` lets a caller
    /// assume.
    #[test]
    fn vacant_slots_are_counted_through_offers_rekeys_and_restores() {
        let mut r = Slots::new();
        let mut now = 0;
        // Slot 9 is out of range, slot 3 offered twice.
        for k in [3, 3, 5, 0, 9, 7, 1, 2, 4] {
            now += 1;
            r.offer(k, &Vector2::new(now as f64, 0.0), now, u64::MAX);
            assert_eq!(r.vacant, empty(&r));
            assert!(!r.refuses_all(u64::MAX));
        }
        now += 1;
        r.offer(6, &Vector2::new(now as f64, 0.0), now, u64::MAX);
        assert_eq!(r.vacant, 0);
        assert!(r.refuses_all(u64::MAX));
        // With forgetting a reading may expire: nothing is refused for sure.
        assert!(!r.refuses_all(1_000));
        let before = r;
        for k in 0..8 {
            r.offer(k, &Vector2::new(-1.0, 0.0), now + 1, u64::MAX);
        }
        assert_eq!(r, before);
        // An expired reading is replaced: the slot stays taken.
        r.offer(3, &Vector2::new(-1.0, 0.0), now + 100, 10);
        assert_eq!((r.stamp[3], r.vacant), (now + 100, 0));
        // Re-sorted into the first four slots, of which two readings meet in one: the
        // other half of the slots is empty.
        r.rekey(|p| Some(p.x.abs() as usize % 4), now + 100, u64::MAX);
        assert_eq!(r.vacant, empty(&r));
        assert_eq!(r.vacant, 4);
        let back = Slots::restore(&r.snapshot(), now + 100).unwrap();
        assert_eq!(back.vacant, empty(&back));
        assert_eq!(back, r);
    }
}
