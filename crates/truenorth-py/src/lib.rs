//! # truenorth-py
//!
//! The Python package `truenorth`: the library's calibrators, estimators, World Magnetic
//! Model and BROAD metric for numpy users, built with PyO3 and maturin
//! (`pip install ./crates/truenorth-py`). Arrays are rows of samples with timestamps in
//! seconds, in the units and body axes of the `truenorth` command's contract (x forward,
//! y right, z down; gyro rad/s, specific force m/s², magnetometer any unit); loops over
//! arrays run in Rust without the GIL; the library's errors are raised as
//! `truenorth.TruenorthError`, a `ValueError`, with the library's message. `read_log` reads
//! PX4 ULog and ROS 2 MCAP files into arrays of the same frames and units; `check_imu` checks
//! a recording's declared units and the gyro's axes against its physics, `check_gnss_delay`
//! how late a drive's satellite fixes are stamped.
//!
//! The bindings wrap the library's public types only (the registry's method names, the
//! traits' samples and estimates), so this crate holds conversions and no method of its own.
//!
//! ```
//! // The Rust side of an array call, without Python: the same loop `update_array` runs.
//! use truenorth::core::{ImuSample, OrientationEstimator};
//! use truenorth::fusion::QuaternionFilter;
//! use truenorth::nalgebra::Vector3;
//!
//! let mut f = QuaternionFilter::new(Default::default())?;
//! for k in 0..100 {
//!     let s = ImuSample::new_6d(0.01 * k as f64, Vector3::zeros(), Vector3::new(0.0, 0.0, -9.81));
//!     f.update(&s)?;
//! }
//! # Ok::<(), truenorth::Error>(())
//! ```

mod broad;
mod calibration;
mod calibrators;
mod checks;
mod convert;
mod geomag;
mod gnss_delay;
mod logs;
mod orientation;
mod quality;
mod vehicle;

use pyo3::prelude::*;

/// The native module, re-exported by the Python package `truenorth`.
#[pymodule]
fn _truenorth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("TruenorthError", py.get_type::<convert::TruenorthError>())?;
    m.add("METHODS", calibrators::METHODS.to_vec())?;
    m.add_class::<calibrators::Calibrator>()?;
    m.add_class::<calibration::Calibration>()?;
    m.add_class::<quality::Quality>()?;
    m.add_class::<quality::Uncertainty>()?;
    m.add_class::<quality::Verdict>()?;
    m.add_class::<orientation::Attitude>()?;
    m.add_class::<orientation::OrientationEstimator>()?;
    m.add_class::<orientation::QuaternionFilter>()?;
    m.add_class::<orientation::EulerDetector>()?;
    m.add_class::<vehicle::VehicleEstimator>()?;
    m.add_class::<geomag::MagneticField>()?;
    m.add_function(wrap_pyfunction!(calibrators::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(geomag::field, m)?)?;
    m.add_function(wrap_pyfunction!(broad::broad_rmse, m)?)?;
    m.add_function(wrap_pyfunction!(logs::read_log, m)?)?;
    m.add_function(wrap_pyfunction!(checks::check_imu, m)?)?;
    m.add_function(wrap_pyfunction!(gnss_delay::check_gnss_delay, m)?)?;
    Ok(())
}
