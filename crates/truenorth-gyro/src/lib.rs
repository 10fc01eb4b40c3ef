//! # truenorth-gyro
//!
//! Rate-gyro model, zero and scale, high-pass conditioning and integration.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
