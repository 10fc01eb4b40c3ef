//! The dead-reckoned path's last seconds, kept so that a satellite fix stamped well after its
//! epoch (a logger's queue, a receiver on another clock: `GnssConfig::latency_s` of seconds)
//! is compared with where the vehicle was then, not with a line drawn back along the heading
//! of now, which a turn bends away from the path.
//!
//! What is kept is the path's own increments — the distance driven and the heading's turns,
//! summed — not positions: the filter's corrections turn and move the estimate (referring it
//! to true north turns the whole track), and the path since an earlier time is drawn back from
//! the heading now less the turns since, in whatever frame the estimate is in now.

use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Snapshots kept, one per [`STEP_S`] or a little more (at the first step after it): 12.8 s
/// of path at least, in rows of [`ROW`] (serde derives arrays of up to 32 elements).
const LEN: usize = ROW * 4;
const ROW: usize = 32;
/// Shortest time between two snapshots, s.
const STEP_S: f64 = 0.1;

/// The path's sums at one time: distance driven, m, and heading turned, rad.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct PathPoint {
    pub t_s: f64,
    pub distance_m: f64,
    pub turn_rad: f64,
}

/// The path driven since a time: m north and east, and the heading's turn, rad.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct PathSince {
    pub north_m: f64,
    pub east_m: f64,
    pub turn_rad: f64,
}

/// The running sums and their last snapshots.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct PathTrail {
    /// The sums now (at the last wheel reading).
    pub now: PathPoint,
    points: [[PathPoint; ROW]; LEN / ROW],
    next: usize,
    len: usize,
}

impl Default for PathTrail {
    fn default() -> Self {
        Self {
            now: PathPoint::default(),
            points: [[PathPoint::default(); ROW]; LEN / ROW],
            next: 0,
            len: 0,
        }
    }
}

impl PathTrail {
    fn point(&self, i: usize) -> PathPoint {
        self.points[i / ROW][i % ROW]
    }

    /// Adds a turn of the heading, rad.
    pub fn turn(&mut self, dpsi: f64) {
        self.now.turn_rad += dpsi;
    }

    /// Adds a step of `distance_m` along the track at `t_s`; a snapshot is kept every
    /// [`STEP_S`].
    pub fn step(&mut self, t_s: f64, distance_m: f64) {
        self.now.t_s = t_s;
        self.now.distance_m += distance_m;
        let last = self.point((self.next + LEN - 1) % LEN);
        if self.len == 0 || t_s - last.t_s >= STEP_S || t_s < last.t_s {
            if self.len > 0 && t_s < last.t_s {
                // Time went back (a replay): the trail starts again.
                self.len = 0;
            }
            self.points[self.next / ROW][self.next % ROW] = self.now;
            self.next = (self.next + 1) % LEN;
            self.len = (self.len + 1).min(LEN);
        }
    }

    /// The path driven from `t_s` to now, the heading now being `heading_rad`: each stretch
    /// between snapshots a chord along the heading at its middle (the heading now less the
    /// turns since); `None` outside the snapshots kept.
    pub fn since(&self, t_s: f64, heading_rad: f64) -> Option<PathSince> {
        let mut out = PathSince::default();
        let mut later = self.now;
        for k in 1..=self.len {
            let p = self.point((self.next + LEN - k) % LEN);
            let span = later.t_s - p.t_s;
            // The stretch's part after `t_s`, as a share of it.
            let share = if p.t_s >= t_s || span <= 0.0 {
                1.0
            } else {
                (later.t_s - t_s) / span
            };
            let from = PathPoint {
                t_s: p.t_s.max(t_s),
                distance_m: later.distance_m - share * (later.distance_m - p.distance_m),
                turn_rad: later.turn_rad - share * (later.turn_rad - p.turn_rad),
            };
            let middle = 0.5 * (from.turn_rad + later.turn_rad);
            let (s, c) = (heading_rad - (self.now.turn_rad - middle)).sin_cos();
            let d = later.distance_m - from.distance_m;
            out.north_m += d * c;
            out.east_m += d * s;
            if p.t_s <= t_s {
                out.turn_rad = self.now.turn_rad - from.turn_rad;
                return Some(out);
            }
            later = p;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle driven at 10 m/s and 0.2 rad/s with steps at 50 Hz: the path since any time
    /// in the trail is the chord and the turn of the arc since, to the chords' error; and it
    /// turns with the heading it is drawn from.
    #[test]
    fn the_path_since_a_time_is_the_arc_driven() {
        let mut trail = PathTrail::default();
        let (v, w, dt) = (10.0, 0.2, 0.02);
        for k in 1..=1000 {
            let t = k as f64 * dt;
            trail.turn(w * dt);
            trail.step(t, v * dt);
        }
        let now = 1000.0 * dt;
        for back in [0.5, 2.0, 7.3, 12.0] {
            let s = trail.since(now - back, w * now).unwrap();
            let (psi0, psi1) = (w * (now - back), w * now);
            let r = v / w;
            let (n, e) = (r * (psi1.sin() - psi0.sin()), r * (psi0.cos() - psi1.cos()));
            assert!((s.turn_rad - w * back).abs() < 1e-9, "{back}: {s:?}");
            assert!(
                (s.north_m - n).abs() < 0.02 && (s.east_m - e).abs() < 0.02,
                "{back}: {s:?} vs {n} {e}"
            );
        }
        assert!(trail.since(now - 16.0, 0.0).is_none(), "beyond the trail");
        assert_eq!(trail.since(now, 0.0).unwrap().north_m, 0.0);
        // Turned with the heading: the same path in a frame a quarter turn on.
        let turned = trail
            .since(now - 2.0, w * now + 0.5 * core::f64::consts::PI)
            .unwrap();
        let plain = trail.since(now - 2.0, w * now).unwrap();
        assert!(
            (turned.north_m + plain.east_m).abs() < 1e-9
                && (turned.east_m - plain.north_m).abs() < 1e-9
        );
    }

    proptest::proptest! {
        /// Whatever the steps (time going back, gaps, any distances and turns), the path
        /// since a time is finite, and no longer than all the distance driven.
        #[test]
        fn the_path_since_is_never_longer_than_the_distance(
            steps in proptest::collection::vec((-0.5f64..2.0, -3.0f64..3.0, -1.0f64..1.0), 1..300),
            back in 0.0f64..20.0,
            heading in -4.0f64..4.0,
        ) {
            let mut trail = PathTrail::default();
            let mut t = 0.0;
            for (dt, ds, dpsi) in &steps {
                t += dt;
                trail.turn(*dpsi);
                trail.step(t, *ds);
            }
            let total: f64 = steps.iter().map(|s| s.1.abs()).sum();
            if let Some(p) = trail.since(t - back, heading) {
                proptest::prop_assert!(p.north_m.is_finite() && p.east_m.is_finite() && p.turn_rad.is_finite());
                proptest::prop_assert!(p.north_m.hypot(p.east_m) <= total + 1e-9);
            }
        }
    }
}
