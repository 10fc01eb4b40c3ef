//! # truenorth-geomag
//!
//! The World Magnetic Model 2025 (WMM2025): what field the Earth has at a place and date.
//! A compass finds magnetic north; navigation wants true north, and a calibrator or a
//! disturbance detector wants to know what field to expect. This crate gives, for a WGS84
//! latitude, longitude, height and decimal year in 2025.0–2030.0:
//!
//! - the **declination** D (true north → magnetic north, positive east) as core's
//!   [`Declination`]. True heading = magnetic heading + declination, added exactly once via
//!   [`MagneticHeading::to_true`](truenorth_core::MagneticHeading::to_true);
//! - the **total intensity** F and **inclination** I: the radius a calibrated magnetometer
//!   should see and the dip it should measure, for calibration quality reports and
//!   magnetic-disturbance detection;
//! - the vector X, Y, Z (north, east, down), H, the grid variation near the poles, and the
//!   secular variation of each.
//!
//! ```
//! use truenorth_core::{MagneticHeading, deg_to_rad, rad_to_deg};
//! use truenorth_geomag::field_at_deg;
//!
//! // 80° N, 0° E, sea level, 2025.0: a row of the official WMM2025 test values.
//! let f = field_at_deg(80.0, 0.0, 0.0, 2025.0)?;
//! assert!((f.x_nt - 6521.6).abs() < 0.1 && (f.f_nt - 55178.5).abs() < 0.1);
//! assert!((f.declination_deg() - 1.28).abs() < 0.01);
//!
//! // A compass heading of 10° magnetic is 11.28° true here.
//! let true_heading = MagneticHeading::new(deg_to_rad(10.0)).to_true(f.declination());
//! assert!((rad_to_deg(true_heading.rad()) - 11.28).abs() < 0.01);
//!
//! // Dates the model does not cover are refused unless extrapolation is asked for.
//! assert!(field_at_deg(80.0, 0.0, 0.0, 2031.0).is_err());
//! # Ok::<(), truenorth_core::Error>(())
//! ```
//!
//! ## Method and sources
//! Everything follows *The US/UK World Magnetic Model for 2025–2030: Technical Report*
//! (NOAA NCEI / BGS), §1.2; equation numbers in the comments are that section's (the
//! numbering the WMM reports have kept since WMM2015): geodetic → spherical geocentric
//! coordinates on WGS84 (eqs. 7–8), time-adjusted Gauss coefficients (eq. 9), the field
//! sums with Schmidt semi-normalised associated Legendre functions to degree 12
//! (eqs. 10–15), rotation back to the geodetic frame (eqs. 16–17) and the elements
//! (eqs. 19–20). The coefficients (`data/WMM.COF`, public domain) are compiled in and
//! parsed at compile time.
//!
//! Radians, metres and nanotesla inside; degrees and kilometres only in the `*_deg` edge
//! functions. Nothing here allocates, reads files, or panics: bad input is an
//! [`Error`](truenorth_core::Error) — [`NonFinite`](truenorth_core::Error::NonFinite),
//! [`OutOfRange`](truenorth_core::Error::OutOfRange) (latitude beyond ±90°, height outside
//! [`MIN_HEIGHT_M`]..[`MAX_HEIGHT_M`]) or
//! [`DateOutOfRange`](truenorth_core::Error::DateOutOfRange).
#![cfg_attr(not(feature = "std"), no_std)]

mod coefficients;
mod cof_text;
mod date;
mod field;
mod geodetic;
mod legendre;
mod local_plane;
mod model;
mod synthesis;

pub use coefficients::{
    Coefficients, CofError, CofErrorKind, GaussTerm, MAX_DEGREE, VALIDITY_YEARS, WMM2025,
};
pub use date::{
    EXTRAPOLATION_LIMIT_YEARS, Extrapolated, Extrapolation, decimal_year_from_date,
    decimal_year_from_unix_seconds,
};
pub use field::{GRID_VARIATION_MIN_LAT_RAD, MagneticField, SecularVariation};
pub use geodetic::{
    GeocentricSpherical, Geodetic, MAX_HEIGHT_M, MIN_HEIGHT_M, WGS84_ECCENTRICITY_SQUARED,
    WGS84_FLATTENING, WGS84_SEMI_MAJOR_AXIS_M,
};
pub use legendre::SchmidtLegendre;
pub use local_plane::LocalTangentPlane;
pub use model::WorldMagneticModel;
pub use synthesis::{GEOMAGNETIC_REFERENCE_RADIUS_M, PreparedPoint};

use truenorth_core::{Declination, Result};

/// WMM2025 field at geodetic latitude and longitude (radians), height above the WGS84
/// ellipsoid (metres) and decimal year (2025.0–2030.0; no extrapolation — use
/// [`WorldMagneticModel::with_extrapolation`] to opt in).
pub fn field_at(lat_rad: f64, lon_rad: f64, height_m: f64, year: f64) -> Result<MagneticField> {
    WorldMagneticModel::WMM2025.field_at(lat_rad, lon_rad, height_m, year)
}

/// Edge function: WMM2025 field at latitude and longitude in degrees, height above the
/// WGS84 ellipsoid in kilometres, and decimal year (2025.0–2030.0, no extrapolation).
pub fn field_at_deg(lat_deg: f64, lon_deg: f64, alt_km: f64, year: f64) -> Result<MagneticField> {
    WorldMagneticModel::WMM2025.field_at_deg(lat_deg, lon_deg, alt_km, year)
}

/// WMM2025 declination at a place (radians, metres) and decimal year, as core's
/// [`Declination`]: true heading = `magnetic.to_true(declination)`.
pub fn declination(lat_rad: f64, lon_rad: f64, height_m: f64, year: f64) -> Result<Declination> {
    WorldMagneticModel::WMM2025.declination(lat_rad, lon_rad, height_m, year)
}

/// WMM2025 expected total intensity F (nT) at a place (radians, metres) and decimal year:
/// the field strength a calibrated magnetometer should report there (compare a fitted
/// calibration radius with it, in the same unit, to spot a disturbed site or a unit error).
pub fn total_intensity_nt(lat_rad: f64, lon_rad: f64, height_m: f64, year: f64) -> Result<f64> {
    WorldMagneticModel::WMM2025.total_intensity_nt(lat_rad, lon_rad, height_m, year)
}

/// WMM2025 expected inclination (dip) at a place (radians, metres) and decimal year,
/// radians, positive down: the angle a 3-D magnetometer should see below the horizontal.
pub fn inclination_rad(lat_rad: f64, lon_rad: f64, height_m: f64, year: f64) -> Result<f64> {
    WorldMagneticModel::WMM2025.inclination_rad(lat_rad, lon_rad, height_m, year)
}

/// The code blocks of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
