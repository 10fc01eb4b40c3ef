//! A compass calibration's quality report, its uncertainty and its verdict as Python
//! objects (read-only attributes and `to_dict()`), computed by the library with the solve.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::core::{CompassQuality, CompassUncertainty, Verdict as CoreVerdict};

use crate::convert::to_py;

/// What the readings determine: the dilution of the orientations seen and the predicted
/// 1-σ of the hard and soft iron.
#[pyclass(module = "truenorth", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Uncertainty {
    /// Worst-direction heading (3-D: field-direction) error per unit of relative
    /// per-reading error, for K directions times √K: 2 for an even circle, 3.67 for an even
    /// sphere, infinite when nothing is determined.
    pub dilution: f64,
    /// Predicted 1-σ of each hard-iron component, input unit (2-D: the third is 0).
    pub hard_iron_sigma: (f64, f64, f64),
    /// Predicted 1-σ of the least determined soft-iron entry, relative.
    pub soft_iron_sigma_rel: f64,
    /// The largest heading error, degrees, that a per-reading error of 0.5 % of the field
    /// could cause on the orientations seen.
    pub geometry_error_deg: f64,
}

impl From<&CompassUncertainty> for Uncertainty {
    fn from(u: &CompassUncertainty) -> Self {
        let s = u.hard_iron_sigma;
        Self {
            dilution: u.dilution,
            hard_iron_sigma: (s[0], s[1], s[2]),
            soft_iron_sigma_rel: u.soft_iron_sigma_rel,
            geometry_error_deg: u.geometry_error_deg(),
        }
    }
}

#[pymethods]
impl Uncertainty {
    fn __repr__(&self) -> String {
        format!(
            "Uncertainty(dilution={:.3}, hard_iron_sigma={:?}, soft_iron_sigma_rel={:.3e})",
            self.dilution, self.hard_iron_sigma, self.soft_iron_sigma_rel
        )
    }
}

/// The verdict on a calibration: `good`, `usable` or `poor`, the two numbers behind it and
/// which of them decided it.
#[pyclass(module = "truenorth", frozen, get_all)]
#[derive(Debug, Clone)]
pub struct Verdict {
    /// `"good"` (bound ≤ 1°, noise ≤ 2°), `"usable"` (both ≤ 5°) or `"poor"`.
    pub grade: String,
    /// `"none"`, `"calibration"` (its own bound) or `"noise"` (each reading's scatter).
    pub cause: String,
    /// The heading error bound of the calibration, degrees.
    pub bound_deg: f64,
    /// The per-reading heading noise, degrees RMS.
    pub noise_deg: f64,
    /// One line: which number decided the grade and what would help.
    pub reason: String,
}

impl From<&CoreVerdict> for Verdict {
    fn from(v: &CoreVerdict) -> Self {
        Self {
            grade: v.grade.to_string(),
            cause: v.cause.to_string(),
            bound_deg: v.bound_deg,
            noise_deg: v.noise_deg,
            reason: v.to_string(),
        }
    }
}

#[pymethods]
impl Verdict {
    /// The verdict as a dictionary.
    pub fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("grade", &self.grade)?;
        d.set_item("cause", &self.cause)?;
        d.set_item("bound_deg", self.bound_deg)?;
        d.set_item("noise_deg", self.noise_deg)?;
        d.set_item("reason", &self.reason)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("Verdict({}: {})", self.grade, self.reason)
    }
}

/// How good a compass calibration is: fit figures, the three parts of the heading error,
/// what the readings determine, and the verdict.
#[pyclass(module = "truenorth", frozen)]
#[derive(Debug, Clone)]
pub struct Quality {
    pub(crate) inner: CompassQuality,
}

#[pymethods]
impl Quality {
    /// Readings used by the fit.
    #[getter]
    fn points(&self) -> usize {
        self.inner.fit.points
    }
    /// Fraction of the circle (sphere) of directions covered, 0–1.
    #[getter]
    fn coverage(&self) -> f64 {
        self.inner.fit.coverage
    }
    /// RMS residual relative to the field.
    #[getter]
    fn residual_rms_rel(&self) -> f64 {
        self.inner.fit.residual_rms_rel
    }
    /// Condition number of the fit.
    #[getter]
    fn condition(&self) -> f64 {
        self.inner.fit.condition
    }
    /// Bound on the heading error the calibration itself adds, degrees (3σ + systematic).
    #[getter]
    fn heading_error_bound_deg(&self) -> f64 {
        self.inner.heading_error_bound_deg()
    }
    /// 3σ of the heading error from the parameters' uncertainty, degrees.
    #[getter]
    fn heading_error_3sigma_deg(&self) -> f64 {
        self.inner.heading_error_3sigma_deg
    }
    /// Heading error the method's model leaves even with perfect data, degrees.
    #[getter]
    fn heading_error_systematic_deg(&self) -> f64 {
        self.inner.heading_error_systematic_deg
    }
    /// RMS heading noise of one calibrated reading, degrees.
    #[getter]
    fn heading_noise_rms_deg(&self) -> f64 {
        self.inner.heading_noise_rms_deg
    }
    /// Fitted field magnitude (2-D horizontal, 3-D total), input unit.
    #[getter]
    fn field_magnitude(&self) -> f64 {
        self.inner.field_magnitude
    }
    /// Fitted field over the expected one, when one was configured.
    #[getter]
    fn field_ratio_to_expected(&self) -> Option<f64> {
        self.inner.field_ratio_to_expected
    }
    /// What the readings determine.
    #[getter]
    fn uncertainty(&self) -> Uncertainty {
        Uncertainty::from(&self.inner.uncertainty)
    }
    /// The verdict, a function of the bound and the noise.
    #[getter]
    fn verdict(&self) -> Verdict {
        Verdict::from(&self.inner.verdict())
    }

    /// The report as a dictionary (the library's field names, plus `heading_error_bound_deg`
    /// and `verdict`); infinite figures stay `inf`.
    pub fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = to_py(py, &self.inner)?;
        d.set_item(
            "heading_error_bound_deg",
            self.inner.heading_error_bound_deg(),
        )?;
        d.set_item("verdict", self.verdict().to_dict(py)?)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Quality(points={}, coverage={:.3}, bound={:.3} deg, noise={:.3} deg, verdict={})",
            self.inner.fit.points,
            self.inner.fit.coverage,
            self.inner.heading_error_bound_deg(),
            self.inner.heading_noise_rms_deg,
            self.inner.verdict().grade
        )
    }
}
