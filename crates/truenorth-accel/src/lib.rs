//! # truenorth-accel
//!
//! Accelerometer model, static tilt and quasi-static detection.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
