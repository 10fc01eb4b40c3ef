//! Where and when a recording was made, and what that says about north: [`Place`] (a place
//! and a date for the World Magnetic Model) and [`TrueNorth`], the one place where a
//! magnetic heading, a dead-reckoned track or an attitude is turned onto true north.
//!
//! ```
//! use truenorth::core::MagneticHeading;
//! use truenorth::{Place, TrueNorth};
//!
//! let london = Place { lat_deg: 51.5, lon_deg: -0.13, height_m: 0.0, year: 2026.5 };
//! let north = TrueNorth::at(&london)?;
//! // True = magnetic + declination (east positive); a track turns with the heading.
//! let h = north.heading(MagneticHeading::new(0.5));
//! assert!((h.rad() - (0.5 + north.declination().0)).abs() < 1e-12);
//! let (n, e) = north.north_east(100.0, 0.0);
//! assert!((e.atan2(n) - north.declination().0).abs() < 1e-12);
//! # Ok::<(), truenorth::core::Error>(())
//! ```

use nalgebra::{UnitQuaternion, Vector3};
use truenorth_core::{Declination, MagneticHeading, Result, TrueHeading};
use truenorth_geomag::{Geodetic, MagneticField, WorldMagneticModel};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// A place on the WGS84 ellipsoid and a date, where the World Magnetic Model gives the
/// field: its declination turns magnetic into true north, its strength and dip are what a
/// calibrated magnetometer should read there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Place {
    /// Geodetic latitude (WGS84), degrees north, −90 to 90.
    pub lat_deg: f64,
    /// Longitude, degrees east (west negative).
    pub lon_deg: f64,
    /// Height above the WGS84 ellipsoid, metres.
    pub height_m: f64,
    /// Decimal year, 2025.0–2030.0 (WMM2025's validity).
    pub year: f64,
}

impl Place {
    /// The WMM2025 field here (a place or a date the model does not cover is a typed error).
    pub fn field(&self) -> Result<MagneticField> {
        self.field_in(&WorldMagneticModel::WMM2025)
    }

    /// The field of `model` here (e.g. WMM2025 with extrapolation allowed past its years).
    pub fn field_in(&self, model: &WorldMagneticModel) -> Result<MagneticField> {
        let at = Geodetic::from_degrees(self.lat_deg, self.lon_deg, self.height_m)?;
        model.field(&at, self.year)
    }

    /// The WMM2025 declination here.
    pub fn declination(&self) -> Result<Declination> {
        Ok(self.field()?.declination())
    }
}

/// Magnetic north turned onto true north by a declination: a heading, a track on the
/// ground and an attitude, each as the commands and the library give it on true north.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueNorth {
    declination: Declination,
}

impl From<Declination> for TrueNorth {
    fn from(declination: Declination) -> Self {
        Self { declination }
    }
}

impl TrueNorth {
    /// True north at `place` (WMM2025).
    pub fn at(place: &Place) -> Result<Self> {
        Ok(Self::from(place.declination()?))
    }

    /// The declination applied (east positive: true = magnetic + declination).
    pub fn declination(&self) -> Declination {
        self.declination
    }

    /// A heading from magnetic north, from true north.
    pub fn heading(&self, magnetic: MagneticHeading) -> TrueHeading {
        magnetic.to_true(self.declination)
    }

    /// A displacement (north, east), metres, on magnetic north, turned onto true north: an
    /// estimator that integrates along magnetic heading draws its track on magnetic north.
    pub fn north_east(&self, north_m: f64, east_m: f64) -> (f64, f64) {
        // Magnetic north lies `d` east of true north, so a vector given in the magnetic
        // (north, east) frame turns by +d (clockwise seen from above) into the true one.
        let (s, c) = self.declination.0.sin_cos();
        (c * north_m - s * east_m, s * north_m + c * east_m)
    }

    /// An attitude body → NED on magnetic north, as body → NED on true north.
    pub fn attitude(&self, magnetic: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        // Magnetic NED is true NED turned by the declination about down (z).
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.declination.0) * magnetic
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{EulerZyx, angle_diff};

    fn place(lat_deg: f64, lon_deg: f64) -> Place {
        Place {
            lat_deg,
            lon_deg,
            height_m: 0.0,
            year: 2027.0,
        }
    }

    proptest! {
        #[test]
        fn true_track_follows_true_heading(
            heading in -3.1f64..3.1, dist in 1.0f64..1e4,
            lat in -60.0f64..60.0, lon in -180.0f64..180.0,
        ) {
            let p = place(lat, lon);
            let decl = p.declination().unwrap().0;
            let north = TrueNorth::at(&p).unwrap();
            let th = north.heading(MagneticHeading::new(heading)).rad();
            prop_assert!(angle_diff(th, heading + decl).abs() < 1e-9);
            // The true-north track points along the true heading and keeps its length.
            let (n, e) = north.north_east(dist * heading.cos(), dist * heading.sin());
            prop_assert!(angle_diff(e.atan2(n), th).abs() < 1e-9);
            prop_assert!(((n * n + e * e).sqrt() - dist).abs() < 1e-9 * dist);
        }

        #[test]
        fn true_attitude_adds_declination_to_yaw_only(
            yaw in -3.1f64..3.1, pitch in -1.4f64..1.4, roll in -3.1f64..3.1,
            lat in -60.0f64..60.0, lon in -180.0f64..180.0,
        ) {
            let p = place(lat, lon);
            let decl = p.declination().unwrap().0;
            let e = EulerZyx { yaw_rad: yaw, pitch_rad: pitch, roll_rad: roll };
            let t = EulerZyx::from_quaternion(&TrueNorth::at(&p).unwrap().attitude(&e.to_quaternion()));
            prop_assert!(angle_diff(t.yaw_rad, yaw + decl).abs() < 1e-9);
            prop_assert!((t.pitch_rad - pitch).abs() < 1e-9);
            prop_assert!(angle_diff(t.roll_rad, roll).abs() < 1e-9);
        }
    }

    #[test]
    fn a_place_outside_the_model_is_refused() {
        let p = Place {
            year: 2040.0,
            ..place(10.0, 10.0)
        };
        assert!(TrueNorth::at(&p).is_err());
        let nan = place(f64::NAN, 0.0);
        assert!(nan.declination().is_err());
        assert!(place(95.0, 0.0).field().is_err());
        // With extrapolation allowed, a year past the model's is evaluated.
        let extra =
            WorldMagneticModel::WMM2025.with_extrapolation(truenorth_geomag::Extrapolation::Allow);
        assert!(
            Place {
                year: 2031.0,
                ..place(10.0, 10.0)
            }
            .field_in(&extra)
            .is_ok()
        );
    }
}
