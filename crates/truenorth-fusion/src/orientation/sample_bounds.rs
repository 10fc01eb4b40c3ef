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
/// can overflow.
pub(crate) fn check_bounds<T: Real>(
    gyr: &Vector3<T>,
    acc: Option<&Vector3<T>>,
    mag: Option<&Vector3<T>>,
    dt_s: Option<f64>,
) -> Result<()> {
    let check = |what: &'static str, v: f64, max: f64| {
        if v <= max {
            Ok(())
        } else {
            Err(Error::OutOfRange {
                what,
                value: v,
                min: 0.0,
                max,
            })
        }
    };
    check(
        "gyro rate (largest component, rad/s)",
        gyr.amax().to_f64(),
        MAX_RATE_RPS,
    )?;
    if let Some(a) = acc {
        check(
            "specific force (largest component, m/s²)",
            a.amax().to_f64(),
            MAX_ACCEL_MPS2,
        )?;
    }
    if let Some(m) = mag {
        check(
            "magnetic field (largest component)",
            m.amax().to_f64(),
            MAX_FIELD,
        )?;
    }
    if let Some(dt) = dt_s {
        check("time between samples, s", dt, MAX_DT_S)?;
    }
    Ok(())
}
