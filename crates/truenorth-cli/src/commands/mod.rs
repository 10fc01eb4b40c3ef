//! The product commands, one file each: `batch` (any of the per-file ones over many files),
//! `calibrate`, `heading`, `field`, `orientation`,
//! `drive` and `inspect`; [`mag_unit`] is the magnetometer unit `calibrate` checks a fitted field
//! against, and [`field::Place`] the place and date every command that turns magnetic into
//! true north reads.

pub mod batch;
pub mod calibrate;
pub mod drive;
pub mod field;
pub mod heading;
pub mod inspect;
pub mod mag_unit;
pub mod orientation;
