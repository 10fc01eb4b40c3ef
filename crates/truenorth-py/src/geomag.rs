//! The World Magnetic Model 2025 at a place and date.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::geomag::{MagneticField as CoreField, field_at_deg};

use crate::convert::lib_err;

/// The WMM2025 field at one place and date (the columns of `truenorth field`).
#[pyclass(module = "truenorth", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct MagneticField {
    /// North component, nT.
    pub x_nt: f64,
    /// East component, nT.
    pub y_nt: f64,
    /// Down component, nT.
    pub z_nt: f64,
    /// Horizontal intensity, nT.
    pub h_nt: f64,
    /// Total intensity, nT.
    pub f_nt: f64,
    /// Inclination (dip), degrees, positive down.
    pub incl_deg: f64,
    /// Declination, degrees, positive east: true heading = magnetic heading + declination.
    pub decl_deg: f64,
    /// Decimal year of the evaluation.
    pub year: f64,
}

impl From<&CoreField> for MagneticField {
    fn from(f: &CoreField) -> Self {
        Self {
            x_nt: f.x_nt,
            y_nt: f.y_nt,
            z_nt: f.z_nt,
            h_nt: f.h_nt,
            f_nt: f.f_nt,
            incl_deg: f.inclination_deg(),
            decl_deg: f.declination_deg(),
            year: f.year,
        }
    }
}

#[pymethods]
impl MagneticField {
    /// The field as a dictionary.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in [
            ("x_nt", self.x_nt),
            ("y_nt", self.y_nt),
            ("z_nt", self.z_nt),
            ("h_nt", self.h_nt),
            ("f_nt", self.f_nt),
            ("incl_deg", self.incl_deg),
            ("decl_deg", self.decl_deg),
            ("year", self.year),
        ] {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "MagneticField(f_nt={:.1}, h_nt={:.1}, incl_deg={:.3}, decl_deg={:.3}, year={})",
            self.f_nt, self.h_nt, self.incl_deg, self.decl_deg, self.year
        )
    }
}

/// The World Magnetic Model 2025 field at geodetic latitude and longitude (degrees),
/// height above the WGS84 ellipsoid (km) and decimal year (2025.0–2030.0). A place or date
/// the model does not cover raises `TruenorthError`.
#[pyfunction]
#[pyo3(signature = (lat_deg, lon_deg, year, alt_km=0.0))]
pub fn field(lat_deg: f64, lon_deg: f64, year: f64, alt_km: f64) -> PyResult<MagneticField> {
    field_at_deg(lat_deg, lon_deg, alt_km, year)
        .map(|f| MagneticField::from(&f))
        .map_err(lib_err)
}
