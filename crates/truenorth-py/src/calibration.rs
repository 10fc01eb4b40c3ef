//! A solved compass calibration: its parameters, quality and verdict, and the heading of
//! raw readings under it (as `truenorth heading` computes it).

use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use truenorth::CompassCalibration;
use truenorth::calib::{MagAccelCalibration, MagAccelQuality};
use truenorth::compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth::core::{CompassQuality, rad_to_deg};
use truenorth::nalgebra::{Matrix3, Vector3};

use crate::convert::{array1, array2, row_err, rows, same_rows, to_py};
use crate::quality::{Quality, Verdict};

/// The parameters of each kind of calibration.
#[derive(Debug, Clone)]
pub enum Params {
    /// Two-axis magnetometer.
    TwoD(CompassCalibration2d),
    /// Three-axis magnetometer.
    ThreeD(CompassCalibration3d),
    /// Magnetometer and accelerometer together, with the joint report.
    Joint(Box<(MagAccelCalibration, MagAccelQuality)>),
}

/// A compass calibration: `corrected = soft_iron · (raw − hard_iron)` maps the raw
/// readings onto a circle (sphere) of radius `field`, input unit.
#[pyclass(module = "truenorth", frozen)]
#[derive(Debug, Clone)]
pub struct Calibration {
    pub(crate) method: String,
    pub(crate) params: Params,
    pub(crate) quality: CompassQuality,
}

/// A 3×3 matrix row by row.
fn rows_of(m: &Matrix3<f64>) -> Vec<f64> {
    (0..3)
        .flat_map(|r| (0..3).map(move |c| m[(r, c)]))
        .collect()
}

impl Calibration {
    /// The magnetometer's hard iron and soft iron (row by row), and the dimension.
    fn iron(&self) -> (Vec<f64>, Vec<f64>, usize) {
        match &self.params {
            Params::TwoD(c) => (
                c.hard_iron.iter().copied().collect(),
                vec![
                    c.soft_iron[(0, 0)],
                    c.soft_iron[(0, 1)],
                    c.soft_iron[(1, 0)],
                    c.soft_iron[(1, 1)],
                ],
                2,
            ),
            Params::ThreeD(c) => (
                c.hard_iron.iter().copied().collect(),
                rows_of(&c.soft_iron),
                3,
            ),
            Params::Joint(j) => (
                j.0.mag.hard_iron.iter().copied().collect(),
                rows_of(&j.0.mag.soft_iron),
                3,
            ),
        }
    }

    /// The calibration as the library's [`CompassCalibration`], whose heading the
    /// `truenorth heading` command gives.
    fn compass(&self) -> CompassCalibration {
        match &self.params {
            Params::TwoD(c) => CompassCalibration::TwoD(*c),
            Params::ThreeD(c) => CompassCalibration::ThreeD(*c),
            Params::Joint(j) => CompassCalibration::Joint(j.0),
        }
    }
}

#[pymethods]
impl Calibration {
    /// The method that produced it (the CLI's name, e.g. `"ellipsoid"`).
    #[getter]
    fn method(&self) -> &str {
        &self.method
    }
    /// 2 or 3.
    #[getter]
    fn dimensions(&self) -> usize {
        self.iron().2
    }
    /// Offset subtracted from raw readings, input unit, shape (D,).
    #[getter]
    fn hard_iron<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.iron().0)
    }
    /// Matrix turning the centred ellipse (ellipsoid) into a circle (sphere), shape (D, D).
    #[getter]
    fn soft_iron<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (_, soft, d) = self.iron();
        array2(py, soft, d)
    }
    /// Radius of the corrected circle (sphere): the field, input unit.
    #[getter]
    fn field(&self) -> f64 {
        self.quality.field_magnitude
    }
    /// The quality report.
    #[getter]
    fn quality(&self) -> Quality {
        Quality {
            inner: self.quality,
        }
    }
    /// The verdict (`quality.verdict`).
    #[getter]
    fn verdict(&self) -> Verdict {
        Verdict::from(&self.quality.verdict())
    }

    /// Magnetic heading of raw readings, degrees clockwise from magnetic north, [0, 360),
    /// one per row of `mag` (N×2 or N×3, input unit). With a 3-D calibration and `acc`
    /// (N×3, specific force, any unit), tilt-compensated (`ellipsoid-accel`: with the
    /// calibrated accelerometer); without it, a level sensor is assumed. The same numbers as
    /// `truenorth heading`.
    #[pyo3(signature = (mag, acc=None))]
    fn heading<'py>(
        &self,
        py: Python<'py>,
        mag: PyReadonlyArray2<'py, f64>,
        acc: Option<PyReadonlyArray2<'py, f64>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.iron().2;
        let m = rows(&mag, "mag", if d == 2 { &[2, 3] } else { &[3] })?;
        let a = match &acc {
            Some(a) => {
                let a = rows(a, "acc", &[3])?;
                same_rows("acc", a.nrows(), m.nrows())?;
                Some(a)
            }
            None => None,
        };
        let compass = self.compass();
        let mut out = Vec::with_capacity(m.nrows());
        for (k, row) in m.rows().into_iter().enumerate() {
            let mag3 = Vector3::new(row[0], row[1], row.get(2).copied().unwrap_or(f64::NAN));
            let acc3 = a
                .as_ref()
                .map(|a| Vector3::new(a[(k, 0)], a[(k, 1)], a[(k, 2)]));
            let (h, _) = compass
                .heading(&mag3, acc3.as_ref())
                .map_err(|e| row_err(k, e))?;
            out.push(rad_to_deg(h.rad()));
        }
        Ok(array1(py, out))
    }

    /// The calibration as a dictionary, in the layout of the CLI's calibration file:
    /// `method`, `dimensions`, `hard_iron`, `soft_iron` (row by row), `field`, for
    /// `ellipsoid-accel` `mag_to_body`, `accelerometer` and `dip_deg`, and `quality`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (hard, soft, dim) = self.iron();
        let d = PyDict::new(py);
        d.set_item("method", &self.method)?;
        d.set_item("dimensions", dim)?;
        d.set_item("hard_iron", hard)?;
        let soft_rows: Vec<Vec<f64>> = soft.chunks(dim).map(<[f64]>::to_vec).collect();
        d.set_item("soft_iron", soft_rows)?;
        d.set_item("field", self.quality.field_magnitude)?;
        let q = self.quality().to_dict(py)?;
        if let Params::Joint(j) = &self.params {
            let (c, jq) = (&j.0, &j.1);
            let m: Vec<Vec<f64>> = rows_of(&c.mag_to_body)
                .chunks(3)
                .map(<[f64]>::to_vec)
                .collect();
            d.set_item("mag_to_body", m)?;
            let acc = PyDict::new(py);
            acc.set_item("bias", c.accel.bias.iter().copied().collect::<Vec<_>>())?;
            let am: Vec<Vec<f64>> = rows_of(&c.accel.matrix)
                .chunks(3)
                .map(<[f64]>::to_vec)
                .collect();
            acc.set_item("matrix", am)?;
            acc.set_item("gravity", c.gravity)?;
            d.set_item("accelerometer", acc)?;
            d.set_item("dip_deg", jq.dip_deg)?;
            let joint = to_py(py, jq)?;
            joint.del_item("mag")?;
            q.set_item("joint", joint)?;
        }
        d.set_item("quality", q)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let (hard, _, dim) = self.iron();
        format!(
            "Calibration(method={:?}, dimensions={dim}, hard_iron={hard:?}, field={}, verdict={})",
            self.method,
            self.quality.field_magnitude,
            self.quality.verdict().grade
        )
    }
}
