//! The seed configurations' states as plain data: saved with [`Persistent::state`] /
//! [`Persistent::snapshot`], they rebuild an estimator that continues bit for bit where the
//! saved one stopped (see ARCHITECTURE.md, "Persistence").
//!
//! The seed configurations report no heading uncertainty (NaN once referred to north, ∞
//! before), so their last estimate is saved with its heading σ beside it, written by name
//! ([`truenorth_core::extended_float`]), and the σ field of the estimate itself as 0.

use serde::{Deserialize, Serialize};
use truenorth_calib::{
    BinnedEllipseCalibrator, BinnedEllipseCalibratorState, SpeedCoefficientCalibrator,
    SpeedCoefficientState, TurnCalibration, TurnCalibrator, TurnCalibratorState,
};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::extended_float::check_plain_numbers_finite;
use truenorth_core::{Error, NavEstimate, Persistent, Result, TimeStep, Validate};

use super::seed_blend::SeedBlend;
use super::seed_gyro_compass::{SeedGyroCompass, SeedGyroCompassConfig};
use super::seed_odometer_compass::{SeedOdometerCompass, SeedOdometerCompassConfig};
use super::wheel_odometry::{TrackModel, WheelOdometry, WheelOdometryState};

/// A [`NavEstimate`] whose heading σ may be non-finite, for `#[serde(with = ...)]`: the
/// estimate with σ set to 0, and σ beside it as an extended float.
mod estimate_with_sigma {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use truenorth_core::NavEstimate;

    #[derive(Serialize, Deserialize)]
    struct Saved {
        estimate: NavEstimate,
        #[serde(with = "truenorth_core::extended_float::scalar")]
        heading_sigma_rad: f64,
    }

    pub fn serialize<S: Serializer>(e: &NavEstimate, serializer: S) -> Result<S::Ok, S::Error> {
        Saved {
            estimate: NavEstimate {
                heading_sigma_rad: 0.0,
                ..*e
            },
            heading_sigma_rad: e.heading_sigma_rad,
        }
        .serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<NavEstimate, D::Error> {
        let s = Saved::deserialize(deserializer)?;
        Ok(NavEstimate {
            heading_sigma_rad: s.heading_sigma_rad,
            ..s.estimate
        })
    }
}

/// Everything a [`SeedGyroCompass`] needs to continue bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedGyroCompassState {
    /// The configuration (validated again when the state is read back).
    pub config: SeedGyroCompassConfig,
    /// The wheels' last reading.
    pub wheels: WheelOdometryState,
    /// The blended heading and the track (opaque beyond serde).
    pub blend: SeedBlend,
    /// The turn calibrator, until the first full turn has calibrated gyro and compass.
    pub turn: Option<TurnCalibratorState>,
    /// The turn's calibration and the field in the compass's unit, once found.
    pub calibration: Option<(TurnCalibration, f64)>,
    /// The gyro's zero reading in use, rad/s.
    pub zero_rps: f64,
    /// Sum of the raw rates over the standstill in progress, rad/s.
    pub rest_sum_rps: f64,
    /// Readings in that sum.
    pub rest_n: u32,
    /// The last gyro reading and its time.
    pub last_gyro: Option<(f64, f64)>,
    /// The wheels stand still.
    pub at_rest: bool,
    /// Compass readings offered to the turn calibrator since it was last solved.
    pub since_solve: u32,
    /// The last accepted timestamp.
    pub clock: TimeStep,
    /// The last estimate published.
    #[serde(with = "estimate_with_sigma")]
    pub estimate: NavEstimate,
}

/// Everything a [`SeedOdometerCompass`] needs to continue bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedOdometerCompassState {
    /// The configuration (validated again when the state is read back).
    pub config: SeedOdometerCompassConfig,
    /// The wheels' last reading and the steered wheels' averaged curvature.
    pub wheels: WheelOdometryState,
    /// The blended heading and the track (opaque beyond serde).
    pub blend: SeedBlend,
    /// The binned-ellipse compass calibrator.
    pub calibrator: BinnedEllipseCalibratorState,
    /// The compass calibration in use and the field in the compass's unit, if any.
    pub compass: Option<(CompassCalibration2d, f64)>,
    /// The speed-coefficient refiner.
    pub refiner: SpeedCoefficientState,
    /// The last accepted timestamp.
    pub clock: TimeStep,
    /// The wheels stand still.
    pub at_rest: bool,
    /// The last estimate published.
    #[serde(with = "estimate_with_sigma")]
    pub estimate: NavEstimate,
}

/// Refuses what a part's own configuration says against the estimator's.
fn check_same<T: PartialEq>(part: &T, config: &T, what: &'static str) -> Result<()> {
    if part == config {
        Ok(())
    } else {
        Err(Error::InvalidSnapshot { reason: what })
    }
}

/// Refuses a compass calibration with a field that is not positive, or an estimate time
/// that is infinite.
fn check_field_and_time(field: Option<f64>, estimate: &NavEstimate) -> Result<()> {
    if field.is_some_and(|f| f <= 0.0) || estimate.t_s.is_infinite() {
        return Err(Error::InvalidSnapshot {
            reason: "a saved compass field is not positive, or the estimate's time is infinite",
        });
    }
    Ok(())
}

impl Persistent for SeedGyroCompass {
    type State = SeedGyroCompassState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> SeedGyroCompassState {
        SeedGyroCompassState {
            config: self.config,
            wheels: self.wheels.state(),
            blend: self.blend,
            turn: self.turn.as_ref().map(TurnCalibrator::state),
            calibration: self.calibration,
            zero_rps: self.zero_rps,
            rest_sum_rps: self.rest_sum,
            rest_n: self.rest_n,
            last_gyro: self.last_gyro,
            at_rest: self.at_rest,
            since_solve: self.since_solve,
            clock: self.clock,
            estimate: self.est,
        }
    }

    fn from_state(s: SeedGyroCompassState) -> Result<Self> {
        s.config.validate()?;
        check_plain_numbers_finite(&s)?;
        check_same(
            s.blend.config(),
            &s.config.blend,
            "the blend was saved with another configuration",
        )?;
        let turn = s.turn.map(TurnCalibrator::from_state).transpose()?;
        if let Some(t) = &turn {
            check_same(
                t.config(),
                &s.config.turn,
                "the turn calibrator was saved with another configuration",
            )?;
        }
        if let Some((c, _)) = &s.calibration {
            c.gyro.validate()?;
        }
        check_field_and_time(s.calibration.map(|(_, f)| f), &s.estimate)?;
        Ok(Self {
            config: s.config,
            wheels: WheelOdometry::with_state(s.config.wheels, TrackModel::Patent, s.wheels)?,
            blend: s.blend,
            turn,
            calibration: s.calibration,
            zero_rps: s.zero_rps,
            rest_sum: s.rest_sum_rps,
            rest_n: s.rest_n,
            last_gyro: s.last_gyro,
            at_rest: s.at_rest,
            since_solve: s.since_solve,
            clock: s.clock,
            est: s.estimate,
        })
    }
}

impl Persistent for SeedOdometerCompass {
    type State = SeedOdometerCompassState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> SeedOdometerCompassState {
        SeedOdometerCompassState {
            config: self.config,
            wheels: self.wheels.state(),
            blend: self.blend,
            calibrator: self.calibrator.state(),
            compass: self.compass,
            refiner: self.refiner.state(),
            clock: self.clock,
            at_rest: self.at_rest,
            estimate: self.est,
        }
    }

    fn from_state(s: SeedOdometerCompassState) -> Result<Self> {
        s.config.validate()?;
        check_plain_numbers_finite(&s)?;
        check_same(
            s.blend.config(),
            &s.config.blend,
            "the blend was saved with another configuration",
        )?;
        check_same(
            &s.calibrator.config,
            &s.config.compass,
            "the compass calibrator was saved with another configuration",
        )?;
        check_same(
            &s.refiner.config,
            &s.config.speed_coefficient,
            "the speed-coefficient refiner was saved with another configuration",
        )?;
        check_field_and_time(s.compass.map(|(_, f)| f), &s.estimate)?;
        Ok(Self {
            config: s.config,
            wheels: WheelOdometry::with_state(s.config.wheels, TrackModel::Patent, s.wheels)?,
            blend: s.blend,
            calibrator: BinnedEllipseCalibrator::from_state(s.calibrator)?,
            compass: s.compass,
            refiner: SpeedCoefficientCalibrator::from_state(s.refiner)?,
            clock: s.clock,
            at_rest: s.at_rest,
            est: s.estimate,
        })
    }
}
