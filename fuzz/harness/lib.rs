//! The fuzz targets' harness: what each target does with its bytes (see [`harness`]).

#[path = "mod.rs"]
pub mod harness;
