//! The product commands, one file each: `batch` (any of the per-file ones over many files),
//! `calibrate`, `heading`, `field`, `orientation`,
//! `drive` and `inspect`; [`field::PlaceArgs`] is the place and date every command that turns
//! magnetic into true north reads.

pub mod batch;
pub mod calibrate;
pub mod drive;
pub mod field;
pub mod heading;
pub mod inspect;
pub mod orientation;
