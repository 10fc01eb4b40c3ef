//! Magnetic versus true heading as distinct types, so that declination is added exactly once.

use serde::{Deserialize, Serialize};

use crate::{rad_to_deg, wrap_two_pi};

/// Magnetic declination at a place and date: the angle from true north to magnetic north,
/// positive east, radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Declination(pub f64);

/// A heading measured from magnetic north, radians, clockwise, in [0, 2π).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagneticHeading(f64);

/// A heading measured from true (geographic) north, radians, clockwise, in [0, 2π).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrueHeading(f64);

impl MagneticHeading {
    /// Wraps `rad` into [0, 2π).
    pub fn new(rad: f64) -> Self {
        Self(wrap_two_pi(rad))
    }

    /// Radians in [0, 2π).
    pub fn rad(self) -> f64 {
        self.0
    }

    /// Degrees in [0, 360), for display and files (radians are the library's unit).
    pub fn deg(self) -> f64 {
        rad_to_deg(self.0)
    }

    /// True heading = magnetic heading + declination (declination positive east).
    pub fn to_true(self, declination: Declination) -> TrueHeading {
        TrueHeading::new(self.0 + declination.0)
    }
}

impl TrueHeading {
    /// Wraps `rad` into [0, 2π).
    pub fn new(rad: f64) -> Self {
        Self(wrap_two_pi(rad))
    }

    /// Radians in [0, 2π).
    pub fn rad(self) -> f64 {
        self.0
    }

    /// Degrees in [0, 360), for display and files (radians are the library's unit).
    pub fn deg(self) -> f64 {
        rad_to_deg(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle_diff;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn east_declination_adds(h in -10.0f64..10.0, d in -0.5f64..0.5) {
            let t = MagneticHeading::new(h).to_true(Declination(d));
            prop_assert!(angle_diff(t.rad(), h + d).abs() < 1e-9);
            prop_assert!((0.0..core::f64::consts::TAU).contains(&t.rad()));
            prop_assert!((0.0..=360.0).contains(&t.deg()));
            prop_assert!((t.deg() - t.rad().to_degrees()).abs() < 1e-9);
        }
    }
}
