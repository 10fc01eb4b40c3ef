//! # truenorth-checks
//!
//! A recording checked against the physics it must obey, before an estimator is trusted
//! with it: whatever a file's header says, an accelerometer at rest reads one gravity, a
//! magnetometer an Earth field, a gyro turns gravity's and the magnetic field's directions in
//! the body exactly as they are seen to turn, and a vehicle's yaw gyro turns as its wheels
//! do. A unit off by a constant factor, an axis swapped or flipped, a mirrored mapping
//! breaks one of these by far more than any sensor error, and each check says which
//! declaration the data contradict and what reads them right ([`Finding`], [`Fix`]).
//!
//! * [`units`]: the units a column may be in ([`GyroUnit`], [`AccUnit`], [`MagUnit`]);
//! * [`spans`]: the turns of gravity's and the field's directions between moments they are
//!   trusted, against the gyro's integrated rotation;
//! * [`axes`]: the gyro's axes, the best of the 48 signed permutations;
//! * [`mag_axes`]: the magnetometer's axes, where the gyro and gravity agree and the field
//!   does not;
//! * [`inertial`]: the accelerometer's and gyro's units, then the gyro's axes;
//! * [`yaw_rate`]: a vehicle's yaw gyro against its wheels, streaming;
//! * [`course_lag`]: the satellite fixes' clock against the gyro's, by the course's turns;
//! * [`field_unit`]: a fitted field against an Earth field in the declared unit;
//! * [`compass`]: a stored compass calibration that no real compass could have;
//! * [`stuck_readings`]: readings no live sensor gives (clipped, frozen, a zero field).
//!
//! The `truenorth` command refuses (or warns) by them, naming its own options; the Python
//! package returns them as dictionaries. Nothing here reads a file or prints.
//!
//! ```
//! use nalgebra::Vector3;
//! use truenorth_checks::{AccUnit, Fix, GyroUnit, check_inertial_units};
//! use truenorth_core::ImuSample;
//!
//! // A sensor lying still, its accelerometer in g, declared as m/s².
//! let still: Vec<ImuSample> = (0..200)
//!     .map(|k| ImuSample::new_6d(0.01 * k as f64, Vector3::zeros(), Vector3::new(0.0, 0.0, -1.0)))
//!     .collect();
//! let findings = check_inertial_units(&still, GyroUnit::RadPerS, AccUnit::MetrePerS2);
//! assert_eq!(findings[0].fix, Fix::AccUnit(AccUnit::G));
//! ```

pub mod axes;
pub mod calibration_fit;
pub mod compass;
pub mod course_lag;
pub mod field_unit;
pub mod finding;
pub mod inertial;
pub mod mag_axes;
pub mod spans;
pub mod stuck_readings;
pub mod units;
pub mod yaw_rate;

pub use axes::{AxisFit, SignedPermutation, axes_are_wrong, fit_gyro_axes};
pub use course_lag::{CourseLag, CourseLagCheck};
pub use field_unit::check_field;
pub use finding::{Finding, FindingKind, Fix};
pub use inertial::{
    check_inertial, check_inertial_units, check_rows, check_rows_units, likely_acc_unit,
};
pub use mag_axes::{MagAxes, magnetometer_reads_the_accelerometer, wrong_magnetometer_axes};
pub use spans::{Inertial, Reference, median, median_magnitude};
pub use stuck_readings::{StuckKind, StuckReadings, StuckRun};
pub use units::{AccUnit, GyroUnit, MagUnit};
pub use yaw_rate::{Turns, YawRateCheck};
