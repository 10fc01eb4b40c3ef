//! Random routes across a vehicle's whole range of motion: for cars, opening circles from
//! full lock to 30 m (or none), city corners down to full lock, roundabouts, ramps and
//! highway up to 36 m/s on curves of 700–2000 m; for robots, straight runs, turns in place,
//! tight arcs and stops.

use core::f64::consts::PI;

use truenorth_core::{NoiseSource, Result, SplitMix64};

use crate::draw::{between, either_sign};
use crate::route::{Route, RouteBuilder};
use crate::vehicle_kind::RangeVehicle;

/// Comfortable longitudinal acceleration of a car, m/s².
pub(crate) const CAR_ACCEL_MPS2: f64 = 1.5;
/// Longitudinal acceleration of a robot, m/s².
pub(crate) const ROBOT_ACCEL_MPS2: f64 = 0.5;
/// Time the steering takes to wind in or out, s.
pub(crate) const EASE_S: f64 = 1.5;
/// Largest lateral acceleration a car is driven at in a tight turn, m/s².
const TIGHT_LATERAL_MPS2: f64 = 2.5;

/// How a drive opens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Opening {
    /// It sets off straight away.
    None,
    /// A circle of this radius (m) through this many turns, or for a robot a turn in
    /// place (radius 0).
    Circle {
        /// Radius, m (0: in place).
        radius_m: f64,
        /// Turns driven.
        turns: f64,
    },
}

impl Opening {
    /// An opening drawn for `v`: none a fifth of the time, otherwise 1.1–2 turns on a
    /// circle from the tightest the vehicle drives to 30 m (a robot may pivot instead).
    pub(crate) fn draw(v: &RangeVehicle, rng: &mut SplitMix64) -> Self {
        if rng.uniform() < 0.2 {
            return Self::None;
        }
        let turns = between(rng, 1.1, 2.0);
        if v.kind.is_car() {
            // Log-uniform between full lock and 30 m: tight circles as often as wide ones.
            let lo = v.min_radius_m.ln();
            let radius_m = (lo + (30f64.ln() - lo) * rng.uniform()).exp();
            Self::Circle { radius_m, turns }
        } else if rng.uniform() < 0.5 {
            Self::Circle {
                radius_m: 0.0,
                turns,
            }
        } else {
            Self::Circle {
                radius_m: between(rng, 0.5, 3.0),
                turns,
            }
        }
    }
}

/// A route for `v` about `length_m` long, opening with `opening`.
pub(crate) fn range_route(
    v: &RangeVehicle,
    opening: Opening,
    length_m: f64,
    rng: &mut SplitMix64,
) -> Result<Route> {
    let car = v.kind.is_car();
    let accel = if car {
        CAR_ACCEL_MPS2
    } else {
        ROBOT_ACCEL_MPS2
    };
    let mut b = RouteBuilder::new().stop(between(rng, 3.0, 12.0))?;
    let mut driven = 0.0;
    if let Opening::Circle { radius_m, turns } = opening {
        let angle = either_sign(rng) * 2.0 * PI * turns;
        if radius_m == 0.0 {
            b = b.pivot(angle, between(rng, 0.3, 1.0))?;
        } else {
            let speed = if car {
                (TIGHT_LATERAL_MPS2 * radius_m).sqrt().min(6.0)
            } else {
                between(rng, v.speed_range_mps.0, v.speed_range_mps.1).min(radius_m)
            };
            b = b
                .change_speed(speed, accel)?
                .eased_turn(angle, radius_m, EASE_S.min(radius_m / speed))?
                .change_speed(0.0, accel)?;
            driven += angle.abs() * radius_m;
        }
        b = b.stop(between(rng, 2.0, 8.0))?;
    }
    while driven < length_m {
        let (next, d) = if car {
            car_segment(v, rng, b, true)?
        } else {
            robot_segment(v, rng, b, true)?
        };
        b = next;
        driven += d;
    }
    Ok(b.change_speed(0.0, accel)?.stop(5.0)?.build())
}

/// One stretch of road: a city corner down to full lock (with a stop at the lights half the
/// time if `stops`), a suburban bend, a roundabout, a ramp or a highway.
pub(crate) fn car_segment(
    v: &RangeVehicle,
    rng: &mut SplitMix64,
    b: RouteBuilder,
    stops: bool,
) -> Result<(RouteBuilder, f64)> {
    let a = CAR_ACCEL_MPS2;
    Ok(match (rng.uniform() * 6.0) as u32 {
        0 | 1 => {
            let block = between(rng, 60.0, 250.0);
            let radius = between(rng, v.min_radius_m * 1.2, 15.0);
            let corner_speed = (TIGHT_LATERAL_MPS2 * radius).sqrt().min(7.0);
            let mut b = b
                .change_speed(between(rng, 8.0, 15.0), a)?
                .straight(block)?
                .change_speed(corner_speed, a)?
                .eased_turn(either_sign(rng) * PI / 2.0, radius, EASE_S)?;
            if stops && rng.uniform() < 0.5 {
                b = b.change_speed(0.0, a)?.stop(between(rng, 2.0, 30.0))?;
            }
            (b, block + radius * PI / 2.0)
        }
        2 => {
            let angle = between(rng, 30.0, 120.0).to_radians();
            let radius = between(rng, 25.0, 120.0);
            let (s1, s2) = (between(rng, 50.0, 300.0), between(rng, 50.0, 300.0));
            let speed = between(rng, 8.0, 17.0).min((4.0 * radius).sqrt());
            let b = b
                .change_speed(speed, a)?
                .straight(s1)?
                .eased_turn(either_sign(rng) * angle, radius, EASE_S)?
                .straight(s2)?;
            (b, s1 + s2 + angle * radius)
        }
        3 => {
            let dir = either_sign(rng);
            let radius = between(rng, 10.0, 25.0);
            let around = between(rng, 180.0, 450.0).to_radians();
            let swerve = 30f64.to_radians();
            let b = b
                .change_speed(between(rng, 5.0, 8.0), a)?
                .straight(30.0)?
                .eased_turn(-dir * swerve, 15.0, EASE_S)?
                .eased_turn(dir * (around + 2.0 * swerve), radius, EASE_S)?
                .eased_turn(-dir * swerve, 15.0, EASE_S)?
                .straight(30.0)?;
            (
                b,
                60.0 + 2.0 * swerve * 15.0 + (around + 2.0 * swerve) * radius,
            )
        }
        4 => {
            let angle = between(rng, 90.0, 270.0).to_radians();
            let radius = between(rng, 35.0, 90.0);
            let b = b
                .change_speed(between(rng, 9.0, 18.0), a)?
                .straight(100.0)?
                .eased_turn(either_sign(rng) * angle, radius, EASE_S)?
                .straight(100.0)?;
            (b, 200.0 + angle * radius)
        }
        _ => {
            let length = between(rng, 800.0, 2500.0);
            let radius = between(rng, 700.0, 2000.0);
            let bend = between(rng, 5.0, 40.0).to_radians();
            let straight = 0.5 * (length - bend * radius).max(100.0);
            let b = b
                .change_speed(between(rng, 22.0, v.speed_range_mps.1), a)?
                .straight(straight)?
                .eased_turn(either_sign(rng) * bend, radius, EASE_S)?
                .straight(straight)?;
            (b, 2.0 * straight + bend * radius)
        }
    })
}

/// One piece of a robot's work: a straight run (with a stop at its end if `stops`), a turn
/// in place, an arc.
pub(crate) fn robot_segment(
    v: &RangeVehicle,
    rng: &mut SplitMix64,
    b: RouteBuilder,
    stops: bool,
) -> Result<(RouteBuilder, f64)> {
    let a = ROBOT_ACCEL_MPS2;
    let speed = between(rng, v.speed_range_mps.0, v.speed_range_mps.1);
    Ok(match (rng.uniform() * 4.0) as u32 {
        0 => {
            let run = between(rng, 3.0, 30.0);
            let mut b = b.change_speed(speed, a)?.straight(run)?;
            if stops {
                b = b.change_speed(0.0, a)?.stop(between(rng, 0.5, 5.0))?;
            }
            (b, run)
        }
        1 => {
            let angle = either_sign(rng) * between(rng, 45.0, 180.0).to_radians();
            let b = b
                .change_speed(0.0, a)?
                .pivot(angle, between(rng, 0.3, 1.2))?;
            (b, 0.5)
        }
        2 => {
            let radius = between(rng, 0.5, 5.0);
            let angle = either_sign(rng) * between(rng, 30.0, 180.0).to_radians();
            let speed = speed.min(radius);
            let run = between(rng, 2.0, 10.0);
            let b = b
                .change_speed(speed, a)?
                .straight(run)?
                .eased_turn(angle, radius, 0.5)?
                .straight(run)?
                .change_speed(0.0, a)?;
            (b, 2.0 * run + angle.abs() * radius)
        }
        _ => {
            let run = between(rng, 10.0, 60.0);
            let b = b.change_speed(speed, a)?.straight(run)?;
            (b, run)
        }
    })
}
