//! # truenorth-fusion
//!
//! Estimators: Euler orientation detector, quaternion filter, vehicle heading and dead reckoning.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
