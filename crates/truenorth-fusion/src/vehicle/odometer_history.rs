//! The odometer's last readings, kept so that its distance can be read at an earlier
//! time: a satellite fix describes the vehicle some time before its row.

use serde::{Deserialize, Serialize};

/// Odometer readings kept to find its distance at a fix's epoch, a delay before its stamp:
/// a third of a second of wheels at 100 Hz, three seconds at 10 Hz.
const HISTORY: usize = 32;

/// The odometer's last [`HISTORY`] readings: time, s, and distance before its scale, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct OdometerHistory {
    readings: [(f64, f64); HISTORY],
    next: usize,
    len: usize,
}

impl Default for OdometerHistory {
    fn default() -> Self {
        Self {
            readings: [(0.0, 0.0); HISTORY],
            next: 0,
            len: 0,
        }
    }
}

impl OdometerHistory {
    /// Adds a reading.
    pub fn push(&mut self, t_s: f64, odometer_m: f64) {
        self.readings[self.next] = (t_s, odometer_m);
        self.next = (self.next + 1) % HISTORY;
        self.len = (self.len + 1).min(HISTORY);
    }

    /// The distance at `t_s`, interpolated between the readings around it; `None` outside
    /// the readings kept.
    pub fn at(&self, t_s: f64) -> Option<f64> {
        let mut later: Option<(f64, f64)> = None;
        for k in 1..=self.len {
            let (t, d) = self.readings[(self.next + HISTORY - k) % HISTORY];
            if t <= t_s {
                let (t1, d1) = later?;
                let w = if t1 > t { (t_s - t) / (t1 - t) } else { 0.0 };
                return Some(d + w * (d1 - d));
            }
            later = Some((t, d));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_distance_between_readings_is_interpolated_and_none_outside_them() {
        let mut h = OdometerHistory::default();
        assert_eq!(h.at(0.0), None);
        for k in 0..40 {
            let t = 0.1 * f64::from(k);
            h.push(t, 2.0 * t);
        }
        // Kept: the last 32 readings, 0.8 s to 3.9 s.
        assert!((h.at(3.85).unwrap() - 7.7).abs() < 1e-9);
        assert!((h.at(0.8).unwrap() - 1.6).abs() < 1e-9);
        assert_eq!(h.at(0.75), None);
        assert_eq!(h.at(3.95), None);
    }

    proptest! {
        /// Whatever the readings, a distance found lies between two kept readings'.
        #[test]
        fn an_interpolated_distance_lies_between_readings(
            readings in proptest::collection::vec((0.0f64..1.0, 0.0f64..5.0), 1..80),
            at in -1.0f64..100.0,
        ) {
            let mut h = OdometerHistory::default();
            let (mut t, mut d) = (0.0, 0.0);
            let mut kept = Vec::new();
            for (dt, dd) in readings {
                t += dt;
                d += dd;
                h.push(t, d);
                kept.push(d);
            }
            let kept = &kept[kept.len().saturating_sub(HISTORY)..];
            if let Some(x) = h.at(at) {
                prop_assert!(x >= kept[0] - 1e-9 && x <= kept[kept.len() - 1] + 1e-9);
            }
        }
    }
}
