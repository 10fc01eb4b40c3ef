//! The edge between numpy and the library: arrays of rows in, arrays out, the library's
//! errors as the one Python exception, serde values as Python dictionaries.

use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;
use serde::de::DeserializeOwned;

pyo3::create_exception!(
    truenorth,
    TruenorthError,
    pyo3::exceptions::PyValueError,
    "An error of the truenorth library: the data or the configuration cannot be used. The \
     message is the library's, naming what was wrong and what to do (and, for an array, the \
     row)."
);

/// The library's error as the Python exception, its message kept.
pub fn lib_err(e: truenorth::Error) -> PyErr {
    TruenorthError::new_err(e.to_string())
}

/// The library's error at row `k` of an array.
pub fn row_err(k: usize, e: truenorth::Error) -> PyErr {
    TruenorthError::new_err(format!("row {k}: {e}"))
}

/// An error of the caller's arguments (shapes, names) as the Python exception.
pub fn arg_err(msg: impl Into<String>) -> PyErr {
    TruenorthError::new_err(msg.into())
}

/// A configuration from a Python dictionary (`None`: the type's defaults); mistyped
/// fields are refused with serde's message, and so are top-level names the configuration
/// does not have (several configurations ignore unknown fields when read from a file, but
/// a misspelt keyword in a script should not pass unnoticed).
pub fn config_from<T: DeserializeOwned + Serialize + Default>(
    config: Option<&Bound<'_, PyAny>>,
) -> PyResult<T> {
    let Some(c) = config.filter(|c| !c.is_none()) else {
        return Ok(T::default());
    };
    if let Ok(given) = c.cast::<PyDict>() {
        let known = to_py(c.py(), &T::default())?;
        for key in given.keys() {
            if !known.contains(&key)? {
                let names: Vec<String> = known
                    .try_iter()?
                    .filter_map(|k| k.ok().map(|k| k.to_string()))
                    .collect();
                return Err(arg_err(format!(
                    "invalid configuration: unknown field `{key}`; the fields are {}",
                    names.join(", ")
                )));
            }
        }
    }
    pythonize::depythonize(c).map_err(|e| arg_err(format!("invalid configuration: {e}")))
}

/// Any serde value as Python data (dictionaries, lists, floats, strings).
pub fn to_py<'py, T: Serialize + ?Sized>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    pythonize::pythonize(py, value).map_err(|e| arg_err(format!("cannot convert: {e}")))
}

/// A 2-D float array with `cols` columns (any of `allowed`), checked.
pub fn rows<'a>(
    a: &'a PyReadonlyArray2<'_, f64>,
    name: &str,
    allowed: &[usize],
) -> PyResult<ArrayView2<'a, f64>> {
    let v = a.as_array();
    if !allowed.contains(&v.ncols()) {
        let want: Vec<String> = allowed.iter().map(usize::to_string).collect();
        return Err(arg_err(format!(
            "`{name}` must have {} columns (one row per sample), got shape ({}, {})",
            want.join(" or "),
            v.nrows(),
            v.ncols()
        )));
    }
    Ok(v)
}

/// The timestamps of `n` rows: given (same length), or the row numbers (one second apart).
pub fn times(t_s: Option<&PyReadonlyArray1<'_, f64>>, n: usize) -> PyResult<Vec<f64>> {
    match t_s {
        Some(t) => {
            let t = t.as_array();
            if t.len() != n {
                return Err(arg_err(format!(
                    "`t_s` has {} values for {n} rows",
                    t.len()
                )));
            }
            Ok(t.to_vec())
        }
        None => Ok((0..n).map(|k| k as f64).collect()),
    }
}

/// Checks that an optional array has `n` rows.
pub fn same_rows(name: &str, rows: usize, n: usize) -> PyResult<()> {
    if rows == n {
        Ok(())
    } else {
        Err(arg_err(format!("`{name}` has {rows} rows for {n} samples")))
    }
}

/// A vector of floats as a 1-D numpy array.
pub fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// A vector of booleans as a 1-D numpy array.
pub fn bools<'py>(py: Python<'py>, v: Vec<bool>) -> Bound<'py, PyArray1<bool>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// Row-major values of `cols` columns as a 2-D numpy array.
pub fn array2<'py>(
    py: Python<'py>,
    v: Vec<f64>,
    cols: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = v.len() / cols.max(1);
    Array2::from_shape_vec((n, cols), v)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| arg_err(format!("internal shape error: {e}")))
}
