//! The configuration of US 4,788,645: heading from two wheels with the
//! speed correction `ΔD/(T(1 + aV²))` and, on steered front wheels, the Ackermann effective
//! track from the patent's look-up table; `a` refined turn by turn against the compass
//! (eqs. 9-13); a compass calibrated by the binned ellipse of EP 0634001 pulling the heading
//! through a fixed-gain complementary filter ([`super::seed_blend`]). No gyro, and no wheel
//! scale is learned: the comparison with [`crate::VehicleEstimator`] shows what those add.

use serde::{Deserialize, Serialize};
use truenorth_calib::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, SpeedCoefficientCalibrator,
    SpeedCoefficientConfig, SpeedStep,
};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, HeadingEstimator, Mag2Sample, MagneticHeading, NavEstimate, OnlineCalibrator,
    Result, TimeStep, Validate, VehicleSample,
};
use truenorth_odometer::OdometerWheels;

use super::seed_blend::{SeedBlend, SeedBlendConfig};
use super::wheel_odometry::{TrackModel, WheelCalibration, WheelOdometry};

/// Configuration of [`SeedOdometerCompass`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SeedOdometerCompassConfig {
    /// The odometer wheels and the vehicle's dimensions.
    pub wheels: OdometerWheels,
    /// The compass blend (default time constant 2 s and outlier gate 45°: wheels whose
    /// scales differ by a few tenths of a percent turn the heading by a tenth of a degree
    /// per metre, which a slower blend cannot hold; on the simulated drives of
    /// `tests/vehicle_drives.rs` longer time constants or a tighter gate lost the heading
    /// more often).
    pub blend: SeedBlendConfig,
    /// The binned-ellipse compass calibrator.
    pub compass: BinnedEllipseConfig,
    /// The adaptive speed coefficient.
    pub speed_coefficient: SpeedCoefficientConfig,
}

impl Default for SeedOdometerCompassConfig {
    fn default() -> Self {
        Self {
            wheels: OdometerWheels::Rear { track_m: 1.55 },
            blend: SeedBlendConfig {
                tau_s: 2.0,
                outlier_deg: 45.0,
                ..SeedBlendConfig::default()
            },
            compass: BinnedEllipseConfig::default(),
            speed_coefficient: SpeedCoefficientConfig::default(),
        }
    }
}

impl Validate for SeedOdometerCompassConfig {
    fn validate(&self) -> Result<()> {
        self.wheels.validate()?;
        self.blend.validate()?;
        self.compass.validate()?;
        self.speed_coefficient.validate()
    }
}

/// The wheels-and-compass estimator of US 4,788,645. See the module documentation.
#[derive(Debug, Clone)]
pub struct SeedOdometerCompass {
    pub(super) config: SeedOdometerCompassConfig,
    pub(super) wheels: WheelOdometry,
    pub(super) blend: SeedBlend,
    pub(super) calibrator: BinnedEllipseCalibrator,
    pub(super) compass: Option<(CompassCalibration2d, f64)>,
    pub(super) refiner: SpeedCoefficientCalibrator,
    pub(super) clock: TimeStep,
    /// The wheels stand still.
    pub(super) at_rest: bool,
    pub(super) est: NavEstimate,
}

impl SeedOdometerCompass {
    /// An estimator that knows nothing yet.
    pub fn new(config: SeedOdometerCompassConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            wheels: WheelOdometry::new(config.wheels, TrackModel::Patent)?,
            blend: SeedBlend::new(config.blend)?,
            calibrator: BinnedEllipseCalibrator::new(config.compass)?,
            compass: None,
            refiner: SpeedCoefficientCalibrator::new(config.speed_coefficient)?,
            clock: TimeStep::new(),
            at_rest: false,
            est: NavEstimate::at_start(f64::NAN, MagneticHeading::new(0.0), f64::INFINITY),
        })
    }

    /// The speed coefficient refiner.
    pub fn speed_coefficient(&self) -> &SpeedCoefficientCalibrator {
        &self.refiner
    }
}

impl HeadingEstimator for SeedOdometerCompass {
    /// Takes one sample (the gyro, if any, is not used, but a non-finite one is refused like
    /// any other field, so that every estimator accepts the same input). A non-finite value
    /// or a timestamp that does not increase is a typed error and changes nothing.
    fn update(&mut self, sample: &VehicleSample) -> Result<NavEstimate> {
        sample.validate()?;
        if let Some(w) = &sample.wheels {
            self.wheels.check_speed(sample.t_s, w)?;
        }
        self.clock.dt_s(sample.t_s)?;
        let cal = WheelCalibration {
            speed_coeff: self.refiner.coefficient(),
            ..WheelCalibration::default()
        };
        let wheel = sample
            .wheels
            .and_then(|w| self.wheels.step(sample.t_s, w, &cal));
        if let Some(w) = wheel {
            self.blend.turn(w.heading_change_rad);
            self.at_rest = self.blend.travel(w.ds_m, w.dt_s, w.moved);
            self.est.speed_mps = w.speed_mps;
        }
        let mut used = None;
        if let Some(raw) = sample.mag {
            let reading = Mag2Sample {
                t_s: sample.t_s,
                mag: raw,
            };
            // The last calibration stays in use while the calibrator has none (it starts
            // its bins over when it judges the ellipse changed, which a long disturbance
            // also triggers): without it the heading runs on the wheels alone, which drift
            // a tenth of a degree per metre.
            if let Ok(truenorth_core::Pushed::NewEstimate) = self.calibrator.push(&reading)
                && let Some(s) = self.calibrator.estimate()
            {
                self.compass = Some((s.params, s.quality.field_magnitude));
            }
            if let Some((c, field)) = self.compass {
                used = self
                    .blend
                    .compass_vector(sample.t_s, c.correct(&raw), field);
            }
        }
        if let Some(w) = wheel {
            // Every sample here was accepted above, so the refiner accepts it too.
            self.refiner.push(&SpeedStep {
                t_s: sample.t_s,
                wheel_heading_change_rad: w.heading_change_rad,
                speed_mps: w.speed_mps,
                compass_heading_rad: used,
            })?;
        }
        self.blend.write_estimate(&mut self.est, sample.t_s);
        let e = &mut self.est;
        e.status.compass_calibrated = self.compass.is_some();
        e.status.compass_used = used.is_some();
        e.status.at_rest = self.at_rest;
        e.status.position_known = self.wheels.last_s().is_some();
        Ok(*e)
    }

    fn estimate(&self) -> NavEstimate {
        self.est
    }

    fn reset(&mut self) {
        if let Ok(fresh) = Self::new(self.config) {
            *self = fresh;
        }
    }
}
