//! Which wheels carry the odometer, and the step-level quantities that pass between the
//! vehicle, the odometer model and the heading computation.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Validate, check_finite};

use crate::wheel_distances::{WheelDistances, check_track};
use crate::{AckermannGeometry, AckermannParams, RigidMotion};

/// Which pair of wheels the odometer senses, on what kind of vehicle (the parameters; see
/// [`WheelGeometry`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OdometerWheels {
    /// A car's rear wheels on a rigid (unsteered) axle with this track, m.
    Rear {
        /// Distance between the two wheels' contact points, m.
        track_m: f64,
    },
    /// A car's Ackermann-steered front wheels.
    Front(AckermannParams),
    /// A skid-steered vehicle (four or more wheels, or tracks, and no steering: it turns by
    /// driving its sides at different speeds). The wheels slide sideways in every turn, so
    /// the track they turn with is not the physical one: 1.5–2.5 times it on most ground
    /// (Mandow et al., "Experimental kinematics for wheeled skid-steer mobile robots",
    /// IROS 2007, measured 1.5–2.0), and it changes with the ground and the turn.
    SkidSteer {
        /// Distance between the centre lines of the left and right wheels, m.
        track_m: f64,
    },
    /// A differential-drive robot: two driven wheels on one axle, casters elsewhere. The
    /// wheels roll without sliding, so their track is the physical one to within the width
    /// of their contact patches.
    Differential {
        /// Distance between the two wheels' contact points, m.
        track_m: f64,
    },
}

impl OdometerWheels {
    /// The physical track of the odometer wheels, m (the straight-ahead track for steered
    /// front wheels).
    pub fn track_m(&self) -> f64 {
        match self {
            Self::Rear { track_m }
            | Self::SkidSteer { track_m }
            | Self::Differential { track_m } => *track_m,
            Self::Front(p) => p.track_m,
        }
    }

    /// Whether the vehicle can turn in place (its odometer wheels on an unsteered axle of a
    /// robot that drives its sides independently).
    pub fn can_pivot(&self) -> bool {
        matches!(self, Self::SkidSteer { .. } | Self::Differential { .. })
    }
}

impl Validate for OdometerWheels {
    /// A track within [`TRACK_RANGE_M`](crate::TRACK_RANGE_M), or valid front-axle dimensions
    /// ([`AckermannParams`]).
    fn validate(&self) -> Result<()> {
        match self {
            Self::Rear { track_m }
            | Self::SkidSteer { track_m }
            | Self::Differential { track_m } => check_track("track_m", *track_m).map(drop),
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
            // A skid-steered or differential-drive robot's wheels sit on a rigid axle like a
            // car's rear wheels: the geometry is the same, the vehicle's turn is not (the
            // forward model is told the turn the wheels see).
            OdometerWheels::Rear { track_m }
            | OdometerWheels::SkidSteer { track_m }
            | OdometerWheels::Differential { track_m } => Self::Rear {
                track_m: check_track("track_m", track_m)?,
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

    /// Path lengths of the two wheels while the vehicle turns in place by `pivot_rad`
    /// (positive right): `±T/2` per radian. A steered axle cannot turn in place: a pivot
    /// on one is an error.
    pub fn pivot_paths_m(&self, pivot_rad: f64) -> Result<WheelDistances> {
        let a = check_finite("pivot_rad", pivot_rad)?;
        match self {
            Self::Rear { track_m } => {
                let half = check_finite("pivot wheel path (pivot too large)", 0.5 * a * track_m)?;
                Ok(WheelDistances {
                    left_m: half,
                    right_m: -half,
                })
            }
            Self::Front(_) if a == 0.0 => Ok(WheelDistances::default()),
            Self::Front(_) => Err(Error::OutOfRange {
                what: "turn in place (pivot_rad) of a steered front axle, which cannot pivot",
                value: a,
                min: 0.0,
                max: 0.0,
            }),
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

/// The true motion of the vehicle over one step, as a rear-axle kinematic model has it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WheelMotion {
    /// Distance travelled by the rear-axle centre during the step, m (negative reversing).
    pub ds_m: f64,
    /// Path curvature of the rear-axle centre, 1/m, positive for a right turn.
    pub curvature_per_m: f64,
    /// Speed of the rear-axle centre, m/s (its magnitude sets the `(1 + aV²)` error).
    pub speed_mps: f64,
    /// Turn in place during the step, rad, positive right: the wheels roll `±T/2` per
    /// radian in opposite directions. Only an unsteered axle can make it.
    #[serde(default)]
    pub pivot_rad: f64,
}

impl WheelMotion {
    /// Checks that the distance, curvature, speed and pivot are finite.
    pub fn check_finite(&self) -> Result<()> {
        check_finite("ds_m", self.ds_m)?;
        check_finite("curvature_per_m", self.curvature_per_m)?;
        check_finite("pivot_rad", self.pivot_rad)?;
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

    proptest! {
        #[test]
        fn a_pivot_rolls_the_wheels_apart_by_the_turn_on_every_rigid_axle(
            t in 0.2f64..2.0, a in -7.0f64..7.0, kind in 0usize..3,
        ) {
            let wheels = [
                OdometerWheels::Rear { track_m: t },
                OdometerWheels::SkidSteer { track_m: t },
                OdometerWheels::Differential { track_m: t },
            ][kind];
            let g = WheelGeometry::new(wheels).unwrap();
            let w = g.pivot_paths_m(a).unwrap();
            prop_assert!((w.left_m + w.right_m).abs() < 1e-12);
            let m = g.motion_from_paths(w.left_m, w.right_m).unwrap();
            prop_assert!(m.ds_m.abs() < 1e-12 && (m.heading_change_rad - a).abs() < 1e-12);
            prop_assert_eq!(wheels.track_m(), t);
        }
    }

    #[test]
    fn a_steered_axle_cannot_pivot() {
        let g = WheelGeometry::new(OdometerWheels::Front(AckermannParams {
            wheelbase_m: 2.7,
            track_m: 1.55,
            kingpin_offset_m: 0.1,
        }))
        .unwrap();
        assert!(g.pivot_paths_m(0.1).is_err());
        assert_eq!(g.pivot_paths_m(0.0).unwrap(), WheelDistances::default());
        assert!(!OdometerWheels::Rear { track_m: 1.5 }.can_pivot());
        assert!(OdometerWheels::SkidSteer { track_m: 0.5 }.can_pivot());
    }

    #[test]
    fn bad_track_is_rejected() {
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(WheelGeometry::new(OdometerWheels::Rear { track_m: t }).is_err());
            assert!(WheelGeometry::new(OdometerWheels::SkidSteer { track_m: t }).is_err());
            assert!(WheelGeometry::new(OdometerWheels::Differential { track_m: t }).is_err());
        }
    }
}
