//! Named driving scenarios: the manoeuvres a navigation system meets and must be tested on.

use core::f64::consts::PI;

use truenorth_core::Result;

use crate::route::{Route, RouteBuilder};

/// Comfortable longitudinal acceleration for scenarios, m/s².
const ACCEL_MPS2: f64 = 1.5;

/// A standstill (for a gyro zero), then `turns` full circles of `radius_m` at `speed_mps`,
/// then a stop: the calibration run of EP 0640207 (at least 360°).
pub fn calibration_circle(radius_m: f64, speed_mps: f64, turns: f64) -> Result<Route> {
    Ok(RouteBuilder::new()
        .stop(5.0)?
        .change_speed(speed_mps, ACCEL_MPS2)?
        .turn(2.0 * PI * turns, radius_m)?
        .change_speed(0.0, ACCEL_MPS2)?
        .stop(2.0)?
        .build())
}

/// City driving: `blocks` blocks of `block_m` at 12 m/s, a 90° turn at each corner on a 8 m
/// radius at 5 m/s (right, right, left, … so the route wanders), and a stop at every second
/// corner.
pub fn city_blocks(blocks: usize, block_m: f64) -> Result<Route> {
    let mut b = RouteBuilder::new().stop(3.0)?;
    for k in 0..blocks {
        b = b.change_speed(12.0, ACCEL_MPS2)?.straight(block_m)?;
        b = b.change_speed(5.0, ACCEL_MPS2)?;
        let dir = if k % 3 == 2 { -1.0 } else { 1.0 };
        b = b.turn(dir * PI / 2.0, 8.0)?;
        if k % 2 == 1 {
            b = b.change_speed(0.0, ACCEL_MPS2)?.stop(4.0)?;
        }
    }
    Ok(b.change_speed(0.0, ACCEL_MPS2)?.stop(2.0)?.build())
}

/// Highway: on-ramp, then `length_m` at 30 m/s with long gentle curves (radius 1500 m),
/// then off.
pub fn highway(length_m: f64) -> Result<Route> {
    let quarter = length_m / 4.0;
    let bend = quarter / 1500.0; // angle of a bend that lasts a quarter of the stretch
    Ok(RouteBuilder::new()
        .stop(2.0)?
        .change_speed(8.0, ACCEL_MPS2)?
        .turn(PI / 2.0, 40.0)? // the on-ramp loop
        .change_speed(30.0, ACCEL_MPS2)?
        .straight(quarter)?
        .turn(bend, 1500.0)?
        .straight(quarter)?
        .turn(-bend, 1500.0)?
        .change_speed(0.0, ACCEL_MPS2)?
        .stop(2.0)?
        .build())
}

/// Parking: slow, tight manoeuvres near full lock (radius 5 m at 1.5 m/s), forward only.
pub fn parking() -> Result<Route> {
    Ok(RouteBuilder::new()
        .stop(2.0)?
        .change_speed(1.5, 1.0)?
        .straight(5.0)?
        .turn(PI / 2.0, 5.0)?
        .turn(-PI / 2.0, 5.0)?
        .straight(3.0)?
        .turn(PI, 5.0)?
        .straight(4.0)?
        .change_speed(0.0, 1.0)?
        .stop(2.0)?
        .build())
}

/// The demo drive: calibration circle, city blocks, a highway stretch, then parking.
pub fn demo_drive() -> Result<Route> {
    let parts = [
        calibration_circle(12.0, 5.0, 1.25)?,
        city_blocks(8, 150.0)?,
        highway(3000.0)?,
        parking()?,
    ];
    let mut commands = Vec::new();
    for p in parts {
        commands.extend(p.commands);
    }
    Ok(Route {
        start_speed_mps: 0.0,
        commands,
    })
}
