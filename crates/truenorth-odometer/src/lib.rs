//! # truenorth-odometer
//!
//! Wheel-odometer model, differential heading and the Ackermann effective track.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
