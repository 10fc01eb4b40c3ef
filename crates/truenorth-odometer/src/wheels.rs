//! Which wheels carry the odometer, and the step-level quantities that pass between the
//! vehicle, the odometer model and the heading computation.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_finite, check_positive};

use crate::{AckermannGeometry, AckermannParams, RigidMotion};

/// Which pair of wheels the odometer senses (the parameters; see [`WheelGeometry`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OdometerWheels {
    /// Rear wheels on a rigid (unsteered) axle with this track, m.
    Rear {
        /// Distance between the two wheels' contact points, m.
        track_m: f64,
    },
    /// Ackermann-steered front wheels.
    Front(AckermannParams),
}

impl Validate for OdometerWheels {
    /// A rear track positive and finite, or valid front-axle dimensions
    /// ([`AckermannParams`]).
    fn validate(&self) -> Result<()> {
        match self {
            Self::Rear { track_m } => check_positive("rear track_m", *track_m).map(drop),
            Self::Front(p) => p.validate(),
        }
    }
}

/// The built geometry of [`OdometerWheels`]: how far each wheel rolls for a given motion of
/// the rear-axle centre, and back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WheelGeometry {
    /// Rear wheels: exact `D = ds·(1 ± κT/2)` (US 4,788,645 eqs. 4-5).
    Rear {
        /// Track, m.
        track_m: f64,
    },
    /// Front wheels with exact Ackermann geometry.
    Front(AckermannGeometry),
}

impl WheelGeometry {
    /// Validates the parameters and builds the geometry.
    pub fn new(wheels: OdometerWheels) -> Result<Self> {
        Ok(match wheels {
            OdometerWheels::Rear { track_m } => Self::Rear {
                track_m: check_positive("rear track_m", track_m)?,
            },
            OdometerWheels::Front(p) => Self::Front(AckermannGeometry::new(p)?),
        })
    }

    /// The straight-ahead track of the odometer wheels, m.
    pub fn nominal_track_m(&self) -> f64 {
        match self {
            Self::Rear { track_m } => *track_m,
            Self::Front(g) => g.params().track_m,
        }
    }

    /// True path lengths of the left and right odometer wheels while the rear-axle centre
    /// travels `ds_m` on curvature `curvature_per_m` (positive = right turn).
    pub fn wheel_paths_m(&self, ds_m: f64, curvature_per_m: f64) -> Result<WheelDistances> {
        match self {
            Self::Rear { track_m } => {
                let ds = check_finite("ds_m", ds_m)?;
                let k = check_finite("curvature_per_m", curvature_per_m)?;
                let half = 0.5 * k * track_m;
                Ok(WheelDistances {
                    left_m: check_finite("left wheel path (inputs too large)", ds * (1.0 + half))?,
                    right_m: check_finite(
                        "right wheel path (inputs too large)",
                        ds * (1.0 - half),
                    )?,
                })
            }
            Self::Front(g) => g.wheel_paths_m(ds_m, curvature_per_m),
        }
    }

    /// Rear-axle-centre distance and heading change from the wheels' true path lengths.
    pub fn motion_from_paths(&self, left_m: f64, right_m: f64) -> Result<RigidMotion> {
        match self {
            Self::Rear { track_m } => {
                let l = check_finite("left wheel distance", left_m)?;
                let r = check_finite("right wheel distance", right_m)?;
                Ok(RigidMotion {
                    ds_m: check_finite("distance (inputs too large)", 0.5 * (l + r))?,
                    heading_change_rad: check_finite(
                        "heading change (inputs too large)",
                        (l - r) / track_m,
                    )?,
                })
            }
            Self::Front(g) => g.motion_from_paths(left_m, right_m),
        }
    }
}

/// Distances of the left and right odometer wheels over one step (or cumulative), m.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelDistances {
    /// Left wheel, m.
    pub left_m: f64,
    /// Right wheel, m.
    pub right_m: f64,
}

/// The true motion of the vehicle over one step, as a rear-axle kinematic model has it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelMotion {
    /// Distance travelled by the rear-axle centre during the step, m (negative reversing).
    pub ds_m: f64,
    /// Path curvature of the rear-axle centre, 1/m, positive for a right turn.
    pub curvature_per_m: f64,
    /// Speed of the rear-axle centre, m/s (its magnitude sets the `(1 + aV²)` error).
    pub speed_mps: f64,
}

impl WheelMotion {
    /// Checks that the distance, curvature and speed are finite.
    pub fn check_finite(&self) -> Result<()> {
        check_finite("ds_m", self.ds_m)?;
        check_finite("curvature_per_m", self.curvature_per_m)?;
        check_finite("speed_mps", self.speed_mps).map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn rear_paths_give_plain_heading_exactly(
            t in 1.0f64..2.0, ds in -10.0f64..10.0, k in -0.5f64..0.5,
        ) {
            let g = WheelGeometry::new(OdometerWheels::Rear { track_m: t }).unwrap();
            let w = g.wheel_paths_m(ds, k).unwrap();
            prop_assert!(((w.left_m - w.right_m) / t - k * ds).abs() < 1e-12);
            let m = g.motion_from_paths(w.left_m, w.right_m).unwrap();
            prop_assert!((m.ds_m - ds).abs() < 1e-12 && (m.heading_change_rad - k * ds).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_track_is_rejected() {
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(WheelGeometry::new(OdometerWheels::Rear { track_m: t }).is_err());
        }
    }
}
