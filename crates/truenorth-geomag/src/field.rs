//! The result: the field vector in the local geodetic frame (north, east, down) and the
//! magnetic elements derived from it (WMM2025 Technical Report, §1.2, eqs. 16–20, and the
//! grid variation of §1.2 for the polar regions).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Declination, rad_to_deg, wrap_pi};

use crate::date::Extrapolated;
use crate::geodetic::Geodetic;
use crate::synthesis::Geocentric;

/// Geodetic latitude beyond which the grid variation is reported: 55° N or S, where polar
/// navigation switches to grid north (WMM2025 Technical Report, grid variation).
pub const GRID_VARIATION_MIN_LAT_RAD: f64 = 55.0 * (core::f64::consts::PI / 180.0);

/// The geomagnetic field at a place and date, as the WMM2025 gives it.
///
/// Frame: X north, Y east, Z down along the WGS84 ellipsoid normal (the NED frame the
/// workspace uses). Field strengths in nanotesla, angles in radians; `*_deg` methods convert
/// at the edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagneticField {
    /// North component X, nT.
    pub x_nt: f64,
    /// East component Y, nT.
    pub y_nt: f64,
    /// Down component Z, nT.
    pub z_nt: f64,
    /// Horizontal intensity H = √(X² + Y²), nT.
    pub h_nt: f64,
    /// Total intensity F = √(H² + Z²), nT: the field strength a calibrated magnetometer
    /// should measure (the expected radius of a calibration fit).
    pub f_nt: f64,
    /// Inclination (dip) I = atan2(Z, H), radians, positive down: the angle between the field
    /// and the horizontal.
    pub inclination_rad: f64,
    /// Declination D = atan2(Y, X), radians, positive east: the angle from true north to
    /// magnetic north.
    pub declination_rad: f64,
    /// Grid variation (grivation) for polar grid navigation, radians in (−π, π]: GV = D − λ
    /// north of 55° N, GV = D + λ south of 55° S, `None` in between.
    pub grid_variation_rad: Option<f64>,
    /// The yearly rate of change of each element.
    pub secular_variation: SecularVariation,
    /// The decimal year the field was computed for.
    pub year: f64,
    /// `Some` when the date was outside the model's validity and extrapolation had been
    /// allowed: the result is then a warning, not a model value.
    pub extrapolated: Option<Extrapolated>,
}

/// The secular variation (yearly rate of change) of the magnetic elements (WMM2025
/// Technical Report, eq. 20).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SecularVariation {
    /// dX/dt, nT per year.
    pub x_nt_per_yr: f64,
    /// dY/dt, nT per year.
    pub y_nt_per_yr: f64,
    /// dZ/dt, nT per year.
    pub z_nt_per_yr: f64,
    /// dH/dt = (X Ẋ + Y Ẏ) / H, nT per year (0 where H = 0).
    pub h_nt_per_yr: f64,
    /// dF/dt = (X Ẋ + Y Ẏ + Z Ż) / F, nT per year.
    pub f_nt_per_yr: f64,
    /// dI/dt = (H Ż − Z Ḣ) / F², radians per year.
    pub inclination_rad_per_yr: f64,
    /// dD/dt = (X Ẏ − Y Ẋ) / H², radians per year (0 where H = 0).
    pub declination_rad_per_yr: f64,
}

impl MagneticField {
    /// Rotates the geocentric field and its secular variation into the geodetic frame
    /// (eqs. 16–17, with ψ = φ′ − φ) and derives the elements (eqs. 19–20).
    pub(crate) fn from_geocentric(
        main: Geocentric,
        sv: Geocentric,
        (sin_psi, cos_psi): (f64, f64),
        at: &Geodetic,
        year: f64,
        extrapolated: Option<Extrapolated>,
    ) -> Self {
        // Eq. 16 (and 17 for the secular variation): X = X′ cos ψ − Z′ sin ψ, Y = Y′,
        // Z = X′ sin ψ + Z′ cos ψ.
        let rotate = |v: Geocentric| {
            (
                v.x * cos_psi - v.z * sin_psi,
                v.y,
                v.x * sin_psi + v.z * cos_psi,
            )
        };
        let (x, y, z) = rotate(main);
        let (xd, yd, zd) = rotate(sv);

        // Eq. 19.
        let h = (x * x + y * y).sqrt();
        let f = (h * h + z * z).sqrt();
        let inclination = z.atan2(h);
        let declination = y.atan2(x);

        // Eq. 20. H and F vanish only exactly at a magnetic pole (H) or nowhere on Earth (F);
        // the guards keep the rates finite there instead of dividing by zero.
        let h_dot = if h > 0.0 { (x * xd + y * yd) / h } else { 0.0 };
        let f_dot = if f > 0.0 {
            (x * xd + y * yd + z * zd) / f
        } else {
            0.0
        };
        let i_dot = if f > 0.0 {
            (h * zd - z * h_dot) / (f * f)
        } else {
            0.0
        };
        let d_dot = if h > 0.0 {
            (x * yd - y * xd) / (h * h)
        } else {
            0.0
        };

        // Grid variation: polar grids have grid north parallel to the Greenwich meridian, so
        // the angle from true to grid north (convergence of meridians) is +λ in the north and
        // −λ in the south, and GV = D − convergence.
        let lat = at.lat_rad();
        let lon = at.lon_rad();
        let grid_variation_rad = if lat > GRID_VARIATION_MIN_LAT_RAD {
            Some(wrap_pi(declination - lon))
        } else if lat < -GRID_VARIATION_MIN_LAT_RAD {
            Some(wrap_pi(declination + lon))
        } else {
            None
        };

        Self {
            x_nt: x,
            y_nt: y,
            z_nt: z,
            h_nt: h,
            f_nt: f,
            inclination_rad: inclination,
            declination_rad: declination,
            grid_variation_rad,
            secular_variation: SecularVariation {
                x_nt_per_yr: xd,
                y_nt_per_yr: yd,
                z_nt_per_yr: zd,
                h_nt_per_yr: h_dot,
                f_nt_per_yr: f_dot,
                inclination_rad_per_yr: i_dot,
                declination_rad_per_yr: d_dot,
            },
            year,
            extrapolated,
        }
    }

    /// The declination as core's type, ready for
    /// [`MagneticHeading::to_true`](truenorth_core::MagneticHeading::to_true).
    pub fn declination(&self) -> Declination {
        Declination(self.declination_rad)
    }

    /// The field vector (X, Y, Z) = (north, east, down), nT.
    pub fn ned_nt(&self) -> Vector3<f64> {
        Vector3::new(self.x_nt, self.y_nt, self.z_nt)
    }

    /// Edge helper: inclination in degrees.
    pub fn inclination_deg(&self) -> f64 {
        rad_to_deg(self.inclination_rad)
    }

    /// Edge helper: declination in degrees.
    pub fn declination_deg(&self) -> f64 {
        rad_to_deg(self.declination_rad)
    }

    /// Edge helper: grid variation in degrees, where it is defined (|latitude| > 55°).
    pub fn grid_variation_deg(&self) -> Option<f64> {
        self.grid_variation_rad.map(rad_to_deg)
    }
}
