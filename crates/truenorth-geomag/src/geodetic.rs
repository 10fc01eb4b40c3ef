//! Positions: WGS84 geodetic coordinates (what a GNSS receiver reports) and the spherical
//! geocentric coordinates the spherical-harmonic model is written in, with conversions both
//! ways (WMM2025 Technical Report, §1.2, eqs. 7–8).

use core::f64::consts::FRAC_PI_2;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, check_finite, deg_to_rad, wrap_pi};

/// WGS84 semi-major axis (equatorial radius) A, metres (NGA.STND.0036, WGS84 definition).
pub const WGS84_SEMI_MAJOR_AXIS_M: f64 = 6_378_137.0;

/// WGS84 flattening f = 1/298.257223563 (NGA.STND.0036).
pub const WGS84_FLATTENING: f64 = 1.0 / 298.257_223_563;

/// WGS84 first eccentricity squared e² = f (2 − f).
pub const WGS84_ECCENTRICITY_SQUARED: f64 = WGS84_FLATTENING * (2.0 - WGS84_FLATTENING);

/// Lowest accepted height above the ellipsoid, metres (−1000 km).
///
/// The WMM is specified from 1 km below to 850 km above the WGS84 ellipsoid (WMM2025
/// Technical Report, introduction). The series itself converges anywhere above the Earth's core
/// (≈ 2900 km deep), so heights a little outside the specification are still evaluated;
/// this bound only keeps the arithmetic meaningful.
pub const MIN_HEIGHT_M: f64 = -1.0e6;

/// Highest accepted height above the ellipsoid, metres (100 000 km, well beyond
/// geostationary orbit; far out the model's internal field is tiny and external fields
/// dominate, so results there describe the model, not the sky).
pub const MAX_HEIGHT_M: f64 = 1.0e8;

/// A WGS84 geodetic position: latitude φ and longitude λ in radians, height above the
/// ellipsoid in metres. Always valid once built: finite, |φ| ≤ π/2, λ wrapped into (−π, π],
/// height within [`MIN_HEIGHT_M`, `MAX_HEIGHT_M`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geodetic {
    lat_rad: f64,
    lon_rad: f64,
    height_m: f64,
}

impl Geodetic {
    /// A position from radians and metres.
    ///
    /// Errors: [`Error::NonFinite`] for NaN or infinite input; [`Error::OutOfRange`] for a
    /// latitude outside ±π/2 or a height outside [`MIN_HEIGHT_M`, `MAX_HEIGHT_M`]. Any finite
    /// longitude is accepted and wrapped into (−π, π].
    pub fn new(lat_rad: f64, lon_rad: f64, height_m: f64) -> Result<Self> {
        check_finite("latitude (rad)", lat_rad)?;
        check_finite("longitude (rad)", lon_rad)?;
        check_height(height_m)?;
        if !(-FRAC_PI_2..=FRAC_PI_2).contains(&lat_rad) {
            return Err(Error::OutOfRange {
                what: "latitude (rad)",
                value: lat_rad,
                min: -FRAC_PI_2,
                max: FRAC_PI_2,
            });
        }
        Ok(Self {
            lat_rad,
            lon_rad: wrap_pi(lon_rad),
            height_m,
        })
    }

    /// Edge constructor from degrees (latitude within ±90°, any finite longitude) and a
    /// height in metres. Errors name the quantity in degrees.
    pub fn from_degrees(lat_deg: f64, lon_deg: f64, height_m: f64) -> Result<Self> {
        check_finite("latitude (deg)", lat_deg)?;
        check_finite("longitude (deg)", lon_deg)?;
        if !(-90.0..=90.0).contains(&lat_deg) {
            return Err(Error::OutOfRange {
                what: "latitude (deg)",
                value: lat_deg,
                min: -90.0,
                max: 90.0,
            });
        }
        // ±90° converts to ±π/2 up to one rounding; clamp so the radian check cannot refuse it.
        let lat_rad = deg_to_rad(lat_deg).clamp(-FRAC_PI_2, FRAC_PI_2);
        // Reduce the longitude into (−180°, 180°] in degrees first. Every step is exact
        // (fmod, and a subtraction of numbers within a factor of two), so 180°, −180° and
        // 540° give bit-identical points.
        let mut lon = lon_deg % 360.0;
        if lon > 180.0 {
            lon -= 360.0;
        } else if lon <= -180.0 {
            lon += 360.0;
        }
        let lon_rad = deg_to_rad(lon);
        Self::new(lat_rad, lon_rad, height_m)
    }

    /// Geodetic latitude φ, radians, in [−π/2, π/2].
    pub fn lat_rad(&self) -> f64 {
        self.lat_rad
    }

    /// Longitude λ, radians, in (−π, π].
    pub fn lon_rad(&self) -> f64 {
        self.lon_rad
    }

    /// Height above the WGS84 ellipsoid, metres.
    pub fn height_m(&self) -> f64 {
        self.height_m
    }

    /// The same point in spherical geocentric coordinates (WMM2025 Technical Report, eqs. 7–8):
    /// R_c = A / √(1 − e² sin²φ), p = (R_c + h) cos φ, z = (R_c (1 − e²) + h) sin φ,
    /// r = √(p² + z²), φ′ = arcsin(z / r).
    pub fn to_spherical(&self) -> GeocentricSpherical {
        let (sin_lat, cos_lat) = self.lat_rad.sin_cos();
        let rc =
            WGS84_SEMI_MAJOR_AXIS_M / (1.0 - WGS84_ECCENTRICITY_SQUARED * sin_lat * sin_lat).sqrt();
        // p ≥ 0 because R_c + h > 0 for every accepted height and cos φ ≥ 0 for |φ| ≤ π/2.
        let p = (rc + self.height_m) * cos_lat;
        let z = (rc * (1.0 - WGS84_ECCENTRICITY_SQUARED) + self.height_m) * sin_lat;
        let r = (p * p + z * z).sqrt();
        GeocentricSpherical {
            // atan2 rather than arcsin(z/r): the same angle, without arcsin's loss of
            // precision next to the poles.
            lat_rad: z.atan2(p),
            lon_rad: self.lon_rad,
            radius_m: r,
            sin_lat: z / r,
            cos_lat: p / r,
        }
    }
}

fn check_height(height_m: f64) -> Result<f64> {
    check_finite("height (m)", height_m)?;
    if !(MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&height_m) {
        return Err(Error::OutOfRange {
            what: "height above the WGS84 ellipsoid (m)",
            value: height_m,
            min: MIN_HEIGHT_M,
            max: MAX_HEIGHT_M,
        });
    }
    Ok(height_m)
}

/// A point in spherical geocentric coordinates: geocentric latitude φ′ and longitude λ in
/// radians, distance r from the Earth's centre in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeocentricSpherical {
    lat_rad: f64,
    lon_rad: f64,
    radius_m: f64,
    sin_lat: f64,
    cos_lat: f64,
}

impl GeocentricSpherical {
    /// A point from geocentric latitude (within ±π/2), longitude (any finite value, wrapped)
    /// and radius (finite, > 0).
    pub fn new(lat_rad: f64, lon_rad: f64, radius_m: f64) -> Result<Self> {
        check_finite("geocentric latitude (rad)", lat_rad)?;
        check_finite("longitude (rad)", lon_rad)?;
        check_finite("geocentric radius (m)", radius_m)?;
        if !(-FRAC_PI_2..=FRAC_PI_2).contains(&lat_rad) {
            return Err(Error::OutOfRange {
                what: "geocentric latitude (rad)",
                value: lat_rad,
                min: -FRAC_PI_2,
                max: FRAC_PI_2,
            });
        }
        if radius_m <= 0.0 {
            return Err(Error::OutOfRange {
                what: "geocentric radius (m)",
                value: radius_m,
                min: f64::MIN_POSITIVE,
                max: f64::MAX,
            });
        }
        let (sin_lat, cos_lat) = lat_rad.sin_cos();
        Ok(Self {
            lat_rad,
            lon_rad: wrap_pi(lon_rad),
            radius_m,
            sin_lat,
            // cos(±π/2) rounds to ±6e-17; a latitude inside ±π/2 has cos ≥ 0.
            cos_lat: cos_lat.max(0.0),
        })
    }

    /// Geocentric latitude φ′, radians.
    pub fn lat_rad(&self) -> f64 {
        self.lat_rad
    }

    /// Longitude λ (the same as the geodetic one), radians, in (−π, π].
    pub fn lon_rad(&self) -> f64 {
        self.lon_rad
    }

    /// Distance from the Earth's centre r, metres.
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// sin φ′ (kept from the conversion, so no precision is lost near the poles).
    pub fn sin_lat(&self) -> f64 {
        self.sin_lat
    }

    /// cos φ′ ≥ 0.
    pub fn cos_lat(&self) -> f64 {
        self.cos_lat
    }

    /// Back to WGS84 geodetic coordinates, inverting eqs. 7–8 by fixed-point iteration on
    /// the geodetic latitude: φ ← atan2(z, p (1 − e² N/(N + h))), h = p cos φ + z sin φ − A²/N,
    /// with N = A / √(1 − e² sin²φ). Each step shrinks the error by about e² ≈ 0.0067, so a
    /// few steps reach full precision; the pole (p = 0) is exact from the first step.
    ///
    /// Errors: [`Error::OutOfRange`] if the point is not within the accepted heights.
    pub fn to_geodetic(&self) -> Result<Geodetic> {
        let p = self.radius_m * self.cos_lat;
        let z = self.radius_m * self.sin_lat;
        let a = WGS84_SEMI_MAJOR_AXIS_M;
        let e2 = WGS84_ECCENTRICITY_SQUARED;
        // Start from the latitude of the surface point on the same normal-ish line.
        let mut lat = z.atan2(p * (1.0 - e2));
        for _ in 0..12 {
            let (s, c) = lat.sin_cos();
            let n = a / (1.0 - e2 * s * s).sqrt();
            let h = p * c + z * s - a * a / n;
            let next = z.atan2(p * (1.0 - e2 * n / (n + h)));
            let done = (next - lat).abs() <= 1e-15;
            lat = next;
            if done {
                break;
            }
        }
        let (s, c) = lat.sin_cos();
        // A²/N = A √(1 − e² sin²φ): no division, well behaved at the poles.
        let h = p * c + z * s - a * (1.0 - e2 * s * s).sqrt();
        Geodetic::new(lat.clamp(-FRAC_PI_2, FRAC_PI_2), self.lon_rad, h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn equator_and_pole_radii() {
        let eq = Geodetic::new(0.0, 0.0, 0.0).unwrap().to_spherical();
        assert!((eq.radius_m() - WGS84_SEMI_MAJOR_AXIS_M).abs() < 1e-6);
        assert_eq!(eq.lat_rad(), 0.0);
        // Polar radius b = A (1 − f) = 6 356 752.314 245 m.
        let pole = Geodetic::new(FRAC_PI_2, 0.3, 0.0).unwrap().to_spherical();
        assert!((pole.radius_m() - 6_356_752.314_245).abs() < 1e-3);
        assert!((pole.lat_rad() - FRAC_PI_2).abs() < 1e-15);
    }

    /// At 45° the geocentric latitude is about 11.5′ smaller than the geodetic one (a
    /// textbook figure: the difference peaks near 45° at ≈ 0.1924°).
    #[test]
    fn geocentric_latitude_difference_at_45_degrees() {
        let s = Geodetic::from_degrees(45.0, 0.0, 0.0)
            .unwrap()
            .to_spherical();
        let diff_deg = 45.0 - s.lat_rad().to_degrees();
        assert!((diff_deg - 0.1924).abs() < 0.0005, "{diff_deg}");
    }

    #[test]
    fn invalid_inputs_are_typed_errors() {
        assert!(matches!(
            Geodetic::new(f64::NAN, 0.0, 0.0),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            Geodetic::new(0.0, f64::INFINITY, 0.0),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            Geodetic::new(2.0, 0.0, 0.0),
            Err(Error::OutOfRange { .. })
        ));
        assert!(matches!(
            Geodetic::new(0.0, 0.0, -2e6),
            Err(Error::OutOfRange { .. })
        ));
        assert!(matches!(
            Geodetic::from_degrees(90.5, 0.0, 0.0),
            Err(Error::OutOfRange { .. })
        ));
        assert!(Geodetic::from_degrees(90.0, 0.0, 0.0).is_ok());
        assert!(Geodetic::from_degrees(-90.0, 0.0, 0.0).is_ok());
        assert!(matches!(
            GeocentricSpherical::new(0.0, 0.0, 0.0),
            Err(Error::OutOfRange { .. })
        ));
        // The Earth's centre is far below the lowest accepted height.
        let centre = GeocentricSpherical::new(0.0, 0.0, 1.0).unwrap();
        assert!(matches!(
            centre.to_geodetic(),
            Err(Error::OutOfRange { .. })
        ));
    }

    #[test]
    fn longitude_is_wrapped_and_the_date_line_is_one_meridian() {
        let a = Geodetic::from_degrees(10.0, 180.0, 0.0).unwrap();
        let b = Geodetic::from_degrees(10.0, -180.0, 0.0).unwrap();
        let c = Geodetic::from_degrees(10.0, 540.0, 0.0).unwrap();
        assert_eq!(a.lon_rad(), b.lon_rad());
        assert_eq!(a.lon_rad(), c.lon_rad());
        let d = Geodetic::from_degrees(10.0, 300.0, 0.0).unwrap();
        assert!((d.lon_rad().to_degrees() + 60.0).abs() < 1e-12);
    }

    proptest! {
        #[test]
        fn geodetic_spherical_round_trip(
            lat in -FRAC_PI_2..=FRAC_PI_2,
            lon in -4.0f64..4.0,
            h in -1.0e5f64..1.0e6,
        ) {
            let g = Geodetic::new(lat, lon, h).unwrap();
            let s = g.to_spherical();
            prop_assert!(s.cos_lat() >= 0.0);
            prop_assert!((s.sin_lat().powi(2) + s.cos_lat().powi(2) - 1.0).abs() < 1e-15);
            let back = s.to_geodetic().unwrap();
            prop_assert!((back.lat_rad() - g.lat_rad()).abs() < 1e-12, "lat {} vs {}", back.lat_rad(), g.lat_rad());
            prop_assert!((back.height_m() - g.height_m()).abs() < 1e-6, "h {} vs {}", back.height_m(), g.height_m());
            prop_assert_eq!(back.lon_rad(), g.lon_rad());
        }

        /// Any numbers: a position is accepted exactly when finite and within the
        /// latitudes and heights documented, goes to spherical and back to itself, and a
        /// spherical point's geodetic position is one within those ranges or a typed
        /// refusal.
        #[test]
        fn any_f64_never_panics(
            lat in prop_oneof![any::<f64>(), -1.6f64..1.6],
            lon in prop_oneof![any::<f64>(), -10.0f64..10.0],
            h in prop_oneof![any::<f64>(), -2.0e6f64..2.0e8],
        ) {
            let finite = lat.is_finite() && lon.is_finite() && h.is_finite();
            let in_range = (-FRAC_PI_2..=FRAC_PI_2).contains(&lat) && (MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&h);
            match Geodetic::new(lat, lon, h) {
                Ok(g) => {
                    prop_assert!(finite && in_range);
                    let s = g.to_spherical();
                    prop_assert!(s.radius_m().is_finite() && s.radius_m() > 0.0);
                    let back = s.to_geodetic().unwrap();
                    prop_assert!((back.lat_rad() - g.lat_rad()).abs() < 1e-9);
                    prop_assert!((back.height_m() - g.height_m()).abs() < 1e-3 * (1.0 + g.height_m().abs() * 1e-9));
                }
                Err(_) => prop_assert!(!(finite && in_range)),
            }
            let deg_in_range = (-90.0..=90.0).contains(&lat) && (MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&h);
            prop_assert_eq!(Geodetic::from_degrees(lat, lon, h).is_ok(), finite && deg_in_range);
            if let Ok(s) = GeocentricSpherical::new(lat, lon, h) {
                match s.to_geodetic() {
                    Ok(g) => prop_assert!(
                        (-FRAC_PI_2..=FRAC_PI_2).contains(&g.lat_rad())
                            && (MIN_HEIGHT_M..=MAX_HEIGHT_M).contains(&g.height_m())
                    ),
                    Err(e) => prop_assert!(matches!(e, Error::OutOfRange { .. }), "{e}"),
                }
            }
        }
    }
}
