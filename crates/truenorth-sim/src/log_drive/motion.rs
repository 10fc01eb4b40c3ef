//! How real drives move: they start in motion (a log begins when someone presses record,
//! not at a standstill), they do not stop for minutes, and their rests are short and rare;
//! or they circle from the first row, as a car on an empty car park does.

use core::f64::consts::PI;

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SplitMix64, check_range};

use super::span::Span;
use crate::RangeVehicle;
use crate::draw::either_sign;
use crate::range_route::{CAR_ACCEL_MPS2, EASE_S, ROBOT_ACCEL_MPS2, car_segment, robot_segment};
use crate::route::{Route, RouteBuilder};

/// The kind of route.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum RouteShape {
    /// Roads: city corners down to full lock, suburban bends, roundabouts, ramps and highway
    /// (robots: straight runs, turns in place and tight arcs).
    Roads,
    /// Circles of one radius, one way, at one speed, from the first row to the last.
    Circling {
        /// Turns driven (0.25–100).
        turns: f64,
        /// Radius of the circle, m, drawn uniformly (0.3–1000; cars at least their full lock).
        radius_m: Span,
        /// Lateral acceleration the circle is driven at, m/s², drawn uniformly (0.05–8): the
        /// speed is `√(a·r)` within the vehicle's speed range.
        lateral_mps2: Span,
    },
}

impl RouteShape {
    /// Three circles of 8–25 m at 1–3.5 m/s² (a period of 10–30 s; a real car log circled
    /// three times in 63 s).
    pub const THREE_CIRCLES: Self = Self::Circling {
        turns: 3.0,
        radius_m: Span::new(8.0, 25.0),
        lateral_mps2: Span::new(1.0, 3.5),
    };
}

/// Rests: when a drive stands still, and for how long.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rests {
    /// No rest before this time from the start, s (0–1e5).
    pub first_after_s: f64,
    /// Least time between the end of one rest and the start of the next, s (0–1e5).
    pub min_gap_s: f64,
    /// Mean of the further time between rests, exponentially distributed, s (0–1e5).
    pub mean_extra_gap_s: f64,
    /// Length of a rest, s, drawn uniformly (0.1–600).
    pub duration_s: Span,
}

impl Rests {
    /// A car in light traffic: no rest in the first two minutes, then one every five minutes
    /// on average, none sooner than two minutes after the last, each of 1–5 s.
    pub const CAR: Self = Self {
        first_after_s: 120.0,
        min_gap_s: 120.0,
        mean_extra_gap_s: 180.0,
        duration_s: Span::new(1.0, 5.0),
    };

    /// A working robot: at rest about 3 % of the time and never for long (a real skid-steer
    /// log): rests of 0.5–5 s, one to two minutes apart.
    pub const ROBOT: Self = Self {
        first_after_s: 60.0,
        min_gap_s: 60.0,
        mean_extra_gap_s: 30.0,
        duration_s: Span::new(0.5, 5.0),
    };

    fn check(&self) -> Result<()> {
        check_range("rests first_after_s", self.first_after_s, 0.0, 1e5)?;
        check_range("rests min_gap_s", self.min_gap_s, 0.0, 1e5)?;
        check_range("rests mean_extra_gap_s", self.mean_extra_gap_s, 0.0, 1e5)?;
        self.duration_s.check("rests duration_s", 0.1, 600.0)
    }

    /// The time of the next rest after one that ended at `t_s`.
    fn next_after(&self, t_s: f64, rng: &mut SplitMix64) -> f64 {
        t_s + self.min_gap_s - self.mean_extra_gap_s * (1.0 - rng.uniform()).ln()
    }
}

/// How a drive moves (defaults per vehicle kind in [`MotionConfig::for_car`] and
/// [`MotionConfig::for_robot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MotionConfig {
    /// The kind of route ([`RouteShape::Roads`]).
    pub shape: RouteShape,
    /// Length of the route's segments to aim for, m (cars 3000, robots 300; 1–1e6); a
    /// circling route's length is its turns'.
    pub length_m: f64,
    /// Whether the truth starts in motion (true); otherwise it starts with a standstill of
    /// 3–12 s.
    pub start_in_motion: bool,
    /// Whether the truth ends in motion (true: a log stopped while driving); otherwise it
    /// slows to a stop.
    pub end_in_motion: bool,
    /// The rests on the way ([`Rests::CAR`] or [`Rests::ROBOT`]); `None`: none at all.
    pub rests: Option<Rests>,
}

impl Default for MotionConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl MotionConfig {
    /// A car on roads, in motion from the first row to the last, with rare short rests.
    pub const fn for_car() -> Self {
        Self {
            shape: RouteShape::Roads,
            length_m: 3000.0,
            start_in_motion: true,
            end_in_motion: true,
            rests: Some(Rests::CAR),
        }
    }

    /// A robot at work, in motion from the first row to the last, with rare short rests.
    pub const fn for_robot() -> Self {
        Self {
            length_m: 300.0,
            rests: Some(Rests::ROBOT),
            ..Self::for_car()
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        check_range("motion length_m", self.length_m, 1.0, 1e6)?;
        if let RouteShape::Circling {
            turns,
            radius_m,
            lateral_mps2,
        } = self.shape
        {
            check_range("circling turns", turns, 0.25, 100.0)?;
            radius_m.check("circling radius_m", 0.3, 1000.0)?;
            lateral_mps2.check("circling lateral_mps2", 0.05, 8.0)?;
        }
        if let Some(r) = self.rests {
            r.check()?;
        }
        Ok(())
    }

    /// A route for `v` as configured.
    pub(crate) fn route(&self, v: &RangeVehicle, rng: &mut SplitMix64) -> Result<Route> {
        let accel = if v.kind.is_car() {
            CAR_ACCEL_MPS2
        } else {
            ROBOT_ACCEL_MPS2
        };
        let (lo, hi) = v.speed_range_mps;
        let mut b = match self.shape {
            RouteShape::Circling {
                turns,
                radius_m,
                lateral_mps2,
            } => {
                let r = radius_m.draw(rng).max(v.min_radius_m);
                let speed = (lateral_mps2.draw(rng) * r).sqrt().min(hi);
                let angle = either_sign(rng) * 2.0 * PI * turns;
                let b = self.opening(speed, accel, rng)?;
                if self.start_in_motion {
                    b.turn(angle, r)?
                } else {
                    b.eased_turn(angle, r, EASE_S.min(r / speed))?
                }
            }
            RouteShape::Roads => {
                let speed = if v.kind.is_car() {
                    8.0 + 7.0 * rng.uniform()
                } else {
                    lo + (hi - lo) * rng.uniform()
                };
                let b = self.opening(speed, accel, rng)?;
                self.roads(b, v, accel, rng)?
            }
        };
        if !self.end_in_motion && b.speed_mps() > 0.0 {
            b = b.change_speed(0.0, accel)?.stop(2.0)?;
        }
        Ok(b.build())
    }

    /// The start: at `speed` from the first instant, or a standstill and a run-up to it.
    fn opening(&self, speed: f64, accel: f64, rng: &mut SplitMix64) -> Result<RouteBuilder> {
        if self.start_in_motion {
            RouteBuilder::at_speed(speed)
        } else {
            let rest = 3.0 + 9.0 * rng.uniform();
            RouteBuilder::new().stop(rest)?.change_speed(speed, accel)
        }
    }

    /// Road segments until the length is driven, with the configured rests between them.
    fn roads(
        &self,
        mut b: RouteBuilder,
        v: &RangeVehicle,
        accel: f64,
        rng: &mut SplitMix64,
    ) -> Result<RouteBuilder> {
        let mut next_rest = self.rests.map(|r| r.first_after_s);
        let mut driven = 0.0;
        while driven < self.length_m {
            let (next, d) = if v.kind.is_car() {
                car_segment(v, rng, b, false)?
            } else {
                robot_segment(v, rng, b, false)?
            };
            b = next;
            driven += d;
            if let (Some(r), Some(at)) = (self.rests, next_rest)
                && b.duration_s() >= at
            {
                b = b.change_speed(0.0, accel)?.stop(r.duration_s.draw(rng))?;
                next_rest = Some(r.next_after(b.duration_s(), rng));
            }
        }
        if b.speed_mps() == 0.0 && self.end_in_motion {
            // A robot's segment may end at rest (before a turn in place): drive off again.
            let (lo, hi) = v.speed_range_mps;
            b = b.change_speed(0.5 * (lo + hi), accel)?.straight(1.0)?;
        }
        Ok(b)
    }
}
