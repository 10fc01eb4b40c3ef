//! The largest readings and gaps the [`crate::QuaternionFilter`] accepts: within them no
//! product in its update can overflow.

use nalgebra::Vector3;
use truenorth_core::{Error, Real, Result};

/// Largest gyro rate accepted, rad/s (far beyond any MEMS gyro's ±2000°/s = 35 rad/s).
const MAX_RATE_RPS: f64 = 1e4;
/// Largest specific force accepted, m/s² (10⁵ g).
const MAX_ACCEL_MPS2: f64 = 1e6;
/// Largest magnetometer component accepted (any unit: 10¹² nT is 1000 T).
const MAX_FIELD: f64 = 1e12;
/// Longest time between samples accepted, s.
const MAX_DT_S: f64 = 1e6;

/// Refuses readings and gaps beyond the limits above: within them no product in the update
/// can overflow. The readings are compared in their float type `T`, against each limit
/// converted to `T` (which leaves it or rounds it down, so the comparison decides as it
/// would in `f64`: held by `the_limits_round_down_in_f32`).
pub(crate) fn check_bounds<T: Real>(
    gyr: &Vector3<T>,
    acc: Option<&Vector3<T>>,
    mag: Option<&Vector3<T>>,
    dt_s: Option<f64>,
) -> Result<()> {
    let check = |what: &'static str, v: T, max: f64| {
        if v <= T::of(max) {
            Ok(())
        } else {
            Err(Error::OutOfRange {
                what,
                value: v.to_f64(),
                min: 0.0,
                max,
            })
        }
    };
    check(
        "gyro rate (largest component, rad/s)",
        gyr.amax(),
        MAX_RATE_RPS,
    )?;
    if let Some(a) = acc {
        check(
            "specific force (largest component, m/s²)",
            a.amax(),
            MAX_ACCEL_MPS2,
        )?;
    }
    if let Some(m) = mag {
        check("magnetic field (largest component)", m.amax(), MAX_FIELD)?;
    }
    if let Some(dt) = dt_s
        && dt > MAX_DT_S
    {
        return Err(Error::OutOfRange {
            what: "time between samples, s",
            value: dt,
            min: 0.0,
            max: MAX_DT_S,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limits_round_down_in_f32() {
        for max in [MAX_RATE_RPS, MAX_ACCEL_MPS2, MAX_FIELD] {
            assert!(f64::from(max as f32) <= max, "{max}");
        }
    }
}
