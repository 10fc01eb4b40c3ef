//! A local tangent plane at a chosen origin: north, east and down metres from it, to and from
//! WGS84 latitude, longitude and height, through Earth-centred Earth-fixed (ECEF) coordinates.
//!
//! The ellipsoid and the geodetic ↔ geocentric conversions are this crate's (WGS84,
//! NGA.STND.0036; WMM2025 Technical Report eqs. 7–8). The plane's axes in ECEF are the
//! local-level frame's at the origin's geodetic latitude φ and longitude λ, as navigation
//! texts write them (e.g. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated
//! Navigation Systems*, 2nd ed., 2013, chapter 2): north `(−sin φ cos λ, −sin φ sin λ, cos φ)`,
//! east `(−sin λ, cos λ, 0)`, down `(−cos φ cos λ, −cos φ sin λ, −sin φ)`.

use nalgebra::{Matrix3, Vector3};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result};

use crate::{GeocentricSpherical, Geodetic};

/// The tangent plane at an origin on (or above) the WGS84 ellipsoid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalTangentPlane {
    origin: Geodetic,
    origin_ecef: Vector3<f64>,
    /// Columns: the north, east and down axes in ECEF.
    ned_to_ecef: Matrix3<f64>,
}

/// A point's ECEF coordinates, m.
fn ecef(g: &Geodetic) -> Vector3<f64> {
    let s = g.to_spherical();
    let (sin_lon, cos_lon) = s.lon_rad().sin_cos();
    s.radius_m() * Vector3::new(s.cos_lat() * cos_lon, s.cos_lat() * sin_lon, s.sin_lat())
}

impl LocalTangentPlane {
    /// The plane at latitude and longitude `lat_deg`, `lon_deg` (WGS84, degrees; latitude
    /// within ±90°) and `height_m` above the ellipsoid.
    pub fn new(lat_deg: f64, lon_deg: f64, height_m: f64) -> Result<Self> {
        let origin = Geodetic::from_degrees(lat_deg, lon_deg, height_m)?;
        let (sin_lat, cos_lat) = origin.lat_rad().sin_cos();
        let (sin_lon, cos_lon) = origin.lon_rad().sin_cos();
        let north = Vector3::new(-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat);
        let east = Vector3::new(-sin_lon, cos_lon, 0.0);
        let down = Vector3::new(-cos_lat * cos_lon, -cos_lat * sin_lon, -sin_lat);
        Ok(Self {
            origin,
            origin_ecef: ecef(&origin),
            ned_to_ecef: Matrix3::from_columns(&[north, east, down]),
        })
    }

    /// The origin.
    pub fn origin(&self) -> Geodetic {
        self.origin
    }

    /// The point `north_m`, `east_m`, `down_m` from the origin along the plane's axes, as
    /// WGS84 geodetic coordinates. Errors for non-finite input or a point too far from the
    /// Earth's surface for the ellipsoid's heights.
    pub fn to_geodetic(&self, north_m: f64, east_m: f64, down_m: f64) -> Result<Geodetic> {
        let p = self.origin_ecef + self.ned_to_ecef * Vector3::new(north_m, east_m, down_m);
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFinite {
                what: "point in the local tangent plane (m)",
                value: north_m + east_m + down_m,
            });
        }
        let r = p.norm();
        GeocentricSpherical::new(p.z.atan2(p.x.hypot(p.y)), p.y.atan2(p.x), r)?.to_geodetic()
    }

    /// `point` as north, east and down metres from the origin along the plane's axes.
    pub fn from_geodetic(&self, point: &Geodetic) -> [f64; 3] {
        let d = self.ned_to_ecef.transpose() * (ecef(point) - self.origin_ecef);
        [d.x, d.y, d.z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{WGS84_ECCENTRICITY_SQUARED, WGS84_SEMI_MAJOR_AXIS_M};
    use proptest::prelude::*;

    /// A small step north or east changes latitude by `dn / (M + h)` and longitude by
    /// `de / ((N + h) cos φ)`, with the meridian radius `M = a(1 − e²)/(1 − e² sin²φ)^{3/2}`
    /// and the prime-vertical radius `N = a/√(1 − e² sin²φ)`.
    #[test]
    fn small_steps_follow_the_ellipsoid_s_radii_of_curvature() {
        for (lat, lon, h) in [
            (52.5, 13.37, 34.0),
            (0.0, -70.0, 0.0),
            (-33.9, 151.2, 500.0),
        ] {
            let plane = LocalTangentPlane::new(lat, lon, h).unwrap();
            let phi = lat.to_radians();
            let w = 1.0 - WGS84_ECCENTRICITY_SQUARED * phi.sin().powi(2);
            let m = WGS84_SEMI_MAJOR_AXIS_M * (1.0 - WGS84_ECCENTRICITY_SQUARED) / w.powf(1.5);
            let n = WGS84_SEMI_MAJOR_AXIS_M / w.sqrt();
            let step = 10.0;
            let north = plane.to_geodetic(step, 0.0, 0.0).unwrap();
            let dlat = north.lat_rad() - phi;
            assert!(
                (dlat / (step / (m + h)) - 1.0).abs() < 1e-6,
                "{lat}: {dlat}"
            );
            let east = plane.to_geodetic(0.0, step, 0.0).unwrap();
            let dlon = east.lon_rad() - lon.to_radians();
            assert!((dlon / (step / ((n + h) * phi.cos())) - 1.0).abs() < 1e-6);
            let down = plane.to_geodetic(0.0, 0.0, step).unwrap();
            assert!((down.height_m() - (h - step)).abs() < 1e-6);
        }
    }

    proptest! {
        #[test]
        fn a_point_goes_to_geodetic_and_back(
            lat in -80.0f64..80.0, lon in -180.0f64..180.0, h in -100.0f64..3000.0,
            n in -50e3f64..50e3, e in -50e3f64..50e3, d in -100.0f64..100.0,
        ) {
            let plane = LocalTangentPlane::new(lat, lon, h).unwrap();
            let g = plane.to_geodetic(n, e, d).unwrap();
            let back = plane.from_geodetic(&g);
            for (a, b) in back.iter().zip([n, e, d]) {
                prop_assert!((a - b).abs() < 1e-6, "{:?} vs {:?}", back, [n, e, d]);
            }
        }
    }

    #[test]
    fn bad_origins_and_points_are_typed_errors() {
        assert!(LocalTangentPlane::new(91.0, 0.0, 0.0).is_err());
        assert!(LocalTangentPlane::new(f64::NAN, 0.0, 0.0).is_err());
        let plane = LocalTangentPlane::new(45.0, 7.0, 0.0).unwrap();
        assert!(plane.to_geodetic(f64::INFINITY, 0.0, 0.0).is_err());
        assert!(plane.to_geodetic(0.0, 0.0, 1e9).is_err());
    }
}
