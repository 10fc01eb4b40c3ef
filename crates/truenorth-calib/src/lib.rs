//! # truenorth-calib
//!
//! Calibrators: they learn sensor parameters from data and say how far to trust them.
//! Every calibrator implements [`truenorth_core::Calibrator`]: `push` samples, watch
//! `progress`, `solve` for parameters plus a [`truenorth_core::Quality`] report, or get a
//! typed refusal that says why the data cannot support a calibration.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

pub mod quality;
