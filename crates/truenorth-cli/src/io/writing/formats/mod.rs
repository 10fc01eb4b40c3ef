//! The JSON files the commands write and read back: `calibration` (`calibrate` →
//! `heading`), `vehicle` (`drive --vehicle`), `learned` (`drive --calibration-out` →
//! `--calibration-in`), each versioned and checked against physics where it is read, and
//! `json`, what they share: a byte-order mark skipped, unknown keys refused at any depth
//! naming the closest known one.

pub(crate) mod calibration;
pub(crate) mod json;
pub(crate) mod learned;
pub(crate) mod vehicle;

pub use calibration::{
    AccelPart, CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, GyroPart, QualityReport,
    finite, gyro_units, matrix_rows, units_block,
};
pub use learned::{read_learned, write_learned};
pub use vehicle::VehicleFile;
