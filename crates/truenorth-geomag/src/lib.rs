//! # truenorth-geomag
//!
//! The World Magnetic Model 2025: declination, inclination and field strength at a place and date.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
