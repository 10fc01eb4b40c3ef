//! Unit conversions used at the edges (config, CLI, docs). Inside, everything is SI/radians.

/// Standard gravity, m/s² (CGPM 1901; also the WGS84 normal-gravity reference value).
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;

/// Degrees to radians.
#[inline]
pub fn deg_to_rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians to degrees.
#[inline]
pub fn rad_to_deg(rad: f64) -> f64 {
    rad.to_degrees()
}

/// Miles per hour to metres per second (1 mile = 1609.344 m exactly).
#[inline]
pub fn mph_to_mps(mph: f64) -> f64 {
    mph * 1609.344 / 3600.0
}

/// Metres per second to miles per hour.
#[inline]
pub fn mps_to_mph(mps: f64) -> f64 {
    mps * 3600.0 / 1609.344
}
