//! The model: which coefficients, and the policy for dates outside their validity. These
//! are the only parameters; coefficients are static data and each evaluation's working
//! state lives on the stack.

use truenorth_core::{Declination, Result, check_finite};

use crate::coefficients::{Coefficients, WMM2025};
use crate::date::{Extrapolation, check_year};
use crate::field::MagneticField;
use crate::geodetic::Geodetic;
use crate::synthesis::PreparedPoint;

/// A World Magnetic Model: a coefficient set plus the extrapolation policy. Small and
/// `Copy`; [`WorldMagneticModel::WMM2025`] is the built-in one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldMagneticModel {
    coefficients: &'static Coefficients,
    extrapolation: Extrapolation,
}

impl Default for WorldMagneticModel {
    fn default() -> Self {
        Self::WMM2025
    }
}

impl WorldMagneticModel {
    /// WMM2025, refusing dates outside 2025.0–2030.0.
    pub const WMM2025: Self = Self::new(&WMM2025);

    /// A model over `coefficients`, refusing dates outside their validity.
    pub const fn new(coefficients: &'static Coefficients) -> Self {
        Self {
            coefficients,
            extrapolation: Extrapolation::Refuse,
        }
    }

    /// The same model with another extrapolation policy. Opting in to
    /// [`Extrapolation::Allow`] makes out-of-window dates return a result whose
    /// [`MagneticField::extrapolated`] is `Some`.
    pub const fn with_extrapolation(self, extrapolation: Extrapolation) -> Self {
        Self {
            extrapolation,
            ..self
        }
    }

    /// The coefficients.
    pub const fn coefficients(&self) -> &'static Coefficients {
        self.coefficients
    }

    /// The extrapolation policy.
    pub const fn extrapolation(&self) -> Extrapolation {
        self.extrapolation
    }

    /// The field at a geodetic position and decimal year.
    ///
    /// Errors: [`Error::NonFinite`](truenorth_core::Error::NonFinite) for a NaN or infinite
    /// year; [`Error::DateOutOfRange`](truenorth_core::Error::DateOutOfRange) outside the
    /// validity unless extrapolation is allowed. Allocates nothing.
    pub fn field(&self, at: &Geodetic, year: f64) -> Result<MagneticField> {
        // Check the date before the (comparatively costly) place-dependent terms.
        let extrapolated = check_year(self.coefficients, year, self.extrapolation)?;
        let point = PreparedPoint::new(at);
        Ok(self.evaluate(&point, year, extrapolated))
    }

    /// The field at a point prepared with [`PreparedPoint::new`], for a decimal year: the
    /// cheap path when one place is evaluated for several dates.
    pub fn field_prepared(&self, at: &PreparedPoint, year: f64) -> Result<MagneticField> {
        let extrapolated = check_year(self.coefficients, year, self.extrapolation)?;
        Ok(self.evaluate(at, year, extrapolated))
    }

    /// The field at geodetic latitude and longitude (radians), height above the WGS84
    /// ellipsoid (metres) and decimal year. See [`Geodetic::new`] for the position checks.
    pub fn field_at(
        &self,
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        year: f64,
    ) -> Result<MagneticField> {
        let at = Geodetic::new(lat_rad, lon_rad, height_m)?;
        self.field(&at, year)
    }

    /// Edge function: the field at latitude and longitude in degrees and height above the
    /// WGS84 ellipsoid in kilometres (the units of the WMM test values and of the CLI).
    pub fn field_at_deg(
        &self,
        lat_deg: f64,
        lon_deg: f64,
        alt_km: f64,
        year: f64,
    ) -> Result<MagneticField> {
        let alt_km = check_finite("height (km)", alt_km)?;
        let at = Geodetic::from_degrees(lat_deg, lon_deg, alt_km * 1000.0)?;
        self.field(&at, year)
    }

    /// The declination at a place (radians, metres) and date, as core's [`Declination`].
    pub fn declination(
        &self,
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        year: f64,
    ) -> Result<Declination> {
        Ok(self
            .field_at(lat_rad, lon_rad, height_m, year)?
            .declination())
    }

    /// The expected total intensity F at a place (radians, metres) and date, nT: what a
    /// calibrated magnetometer should measure there, for calibration quality reports and
    /// disturbance detection.
    pub fn total_intensity_nt(
        &self,
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        year: f64,
    ) -> Result<f64> {
        Ok(self.field_at(lat_rad, lon_rad, height_m, year)?.f_nt)
    }

    /// The expected inclination (dip) I at a place (radians, metres) and date, radians,
    /// positive down.
    pub fn inclination_rad(
        &self,
        lat_rad: f64,
        lon_rad: f64,
        height_m: f64,
        year: f64,
    ) -> Result<f64> {
        Ok(self
            .field_at(lat_rad, lon_rad, height_m, year)?
            .inclination_rad)
    }

    fn evaluate(
        &self,
        at: &PreparedPoint,
        year: f64,
        extrapolated: Option<crate::date::Extrapolated>,
    ) -> MagneticField {
        let dt_years = year - self.coefficients.epoch_year();
        let (main, sv) = at.synthesize(self.coefficients, dt_years);
        MagneticField::from_geocentric(main, sv, at.rotation(), at.geodetic(), year, extrapolated)
    }
}
