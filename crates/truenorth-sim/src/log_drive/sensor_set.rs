//! The sensor sets real vehicles have: what the odometry gives (a CAN vehicle speed, a
//! cumulative distance, two or four wheel speeds, two wheel distances, or nothing), whether a
//! yaw-rate gyro is fitted, and whether a compass is.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result};

use crate::VehicleKind;

/// What the odometry of a log gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Odometry {
    /// No odometry (a gyro and a compass only).
    None,
    /// One vehicle speed, as a car's CAN bus gives it (`speed_mps`).
    VehicleSpeed,
    /// One cumulative distance (`dist_m`), as a distance counter gives it.
    VehicleDistance,
    /// The cumulative distances of the two odometer wheels or sides (`dist_l_m,dist_r_m`),
    /// as a motor controller's encoder counts or a car's wheel pulses give them.
    WheelDistances,
    /// The speeds of the two odometer wheels or sides (`speed_l_mps,speed_r_mps`).
    WheelSpeeds,
    /// The speeds of all four wheels (`speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps`),
    /// as an ABS unit gives them.
    FourWheelSpeeds,
}

/// The sensors a log carries. The constants are the sets real vehicles have; `with_compass`
/// adds a compass to any of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SensorSet {
    /// What the odometry gives.
    pub odometry: Odometry,
    /// A yaw-rate gyro (`gyr_z`).
    pub gyro: bool,
    /// A two-axis compass (`mag_x,mag_y`).
    pub compass: bool,
}

impl SensorSet {
    /// A car's CAN bus: the vehicle speed and the ESP's yaw rate.
    pub const SPEED_YAW: Self = Self::of(Odometry::VehicleSpeed, true);
    /// A cumulative distance and a yaw rate.
    pub const DISTANCE_YAW: Self = Self::of(Odometry::VehicleDistance, true);
    /// Two wheel (or side) distances only.
    pub const WHEELS: Self = Self::of(Odometry::WheelDistances, false);
    /// Two wheel (or side) speeds only.
    pub const WHEEL_SPEEDS: Self = Self::of(Odometry::WheelSpeeds, false);
    /// Four wheel speeds only.
    pub const FOUR_WHEEL_SPEEDS: Self = Self::of(Odometry::FourWheelSpeeds, false);
    /// Two wheel (or side) distances and a yaw-rate gyro.
    pub const WHEELS_GYRO: Self = Self::of(Odometry::WheelDistances, true);
    /// Two wheel (or side) speeds and a yaw-rate gyro.
    pub const WHEEL_SPEEDS_GYRO: Self = Self::of(Odometry::WheelSpeeds, true);
    /// Four wheel speeds and a yaw-rate gyro.
    pub const FOUR_WHEEL_SPEEDS_GYRO: Self = Self::of(Odometry::FourWheelSpeeds, true);
    /// A gyro and a compass without odometry.
    pub const GYRO_COMPASS: Self = Self {
        odometry: Odometry::None,
        gyro: true,
        compass: true,
    };

    const fn of(odometry: Odometry, gyro: bool) -> Self {
        Self {
            odometry,
            gyro,
            compass: false,
        }
    }

    /// The same set with a compass.
    pub const fn with_compass(self) -> Self {
        Self {
            compass: true,
            ..self
        }
    }

    /// Every set a vehicle of `kind` can have, each without and with a compass (a
    /// differential-drive robot has no four wheel speeds).
    pub fn every(kind: VehicleKind) -> Vec<Self> {
        let mut base = vec![
            Self::SPEED_YAW,
            Self::DISTANCE_YAW,
            Self::WHEELS,
            Self::WHEEL_SPEEDS,
            Self::WHEELS_GYRO,
            Self::WHEEL_SPEEDS_GYRO,
        ];
        if kind != VehicleKind::Differential {
            base.extend([Self::FOUR_WHEEL_SPEEDS, Self::FOUR_WHEEL_SPEEDS_GYRO]);
        }
        let mut all: Vec<Self> = base.iter().flat_map(|s| [*s, s.with_compass()]).collect();
        all.push(Self::GYRO_COMPASS);
        all
    }

    /// Checks that the set can be fitted to `kind` and gives a dead reckoner something to
    /// turn with: odometry or a gyro, and four wheel speeds only on four wheels.
    pub fn check(&self, kind: VehicleKind) -> Result<()> {
        if self.odometry == Odometry::None && !self.gyro {
            return Err(Error::Unsupported {
                reason: "a sensor set needs odometry or a yaw-rate gyro (a compass alone does not dead-reckon)",
            });
        }
        if self.odometry == Odometry::FourWheelSpeeds && kind == VehicleKind::Differential {
            return Err(Error::Unsupported {
                reason: "a differential-drive robot has two wheels: use WheelSpeeds or WheelDistances",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_set_is_accepted_and_the_impossible_ones_are_not() {
        for kind in VehicleKind::ALL {
            let sets = SensorSet::every(kind);
            assert!(sets.iter().all(|s| s.check(kind).is_ok()));
            assert!(sets.contains(&SensorSet::GYRO_COMPASS));
            assert!(sets.contains(&SensorSet::SPEED_YAW.with_compass()));
        }
        let compass_only = SensorSet {
            odometry: Odometry::None,
            gyro: false,
            compass: true,
        };
        assert!(compass_only.check(VehicleKind::RearWheelCar).is_err());
        assert!(
            SensorSet::FOUR_WHEEL_SPEEDS
                .check(VehicleKind::Differential)
                .is_err()
        );
    }
}
