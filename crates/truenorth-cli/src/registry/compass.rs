//! Compass calibration methods by name.

use truenorth::calib::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, EllipseCalibrator, EllipseConfig,
    EllipsoidCalibrator, EllipsoidConfig, MagAccelCalibration, MagAccelCalibrator, MagAccelConfig,
    MagAccelQuality, MagAccelSample, MeritCircleCalibrator, MeritCircleConfig,
    OnlineEllipseCalibrator, OnlineEllipseConfig, OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
    TurnCalibration, TurnCalibrator, TurnCompassCalibrator, TurnConfig, TurnQuality, TurnSample,
};
use truenorth::compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth::core::{Calibrator, CompassQuality, Mag2Sample, Mag3Sample, Result};

use crate::io::spill::ReadingSpill;

/// A calibrator of two-axis magnetometer readings.
pub type Planar =
    dyn Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>;

/// A calibrator of three-axis magnetometer readings.
pub type Spatial =
    dyn Calibrator<Sample = Mag3Sample, Params = CompassCalibration3d, Quality = CompassQuality>;

/// A calibrator of the magnetometer and the accelerometer together.
pub type MagAccel = dyn Calibrator<Sample = MagAccelSample, Params = MagAccelCalibration, Quality = MagAccelQuality>;

/// A calibrator of one turn's compass and yaw gyro together.
pub type TurnWithGyro =
    dyn Calibrator<Sample = TurnSample, Params = TurnCalibration, Quality = TurnQuality>;

/// Calibration methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CalibrationMethod {
    /// Least-squares ellipse (2-D): direct fit refined geometrically; hard + symmetric soft iron.
    Ellipse,
    /// Least-squares ellipsoid (3-D, needs mag_z): hard iron + full symmetric soft iron.
    Ellipsoid,
    /// Magnetometer and accelerometer together (needs mag_x,mag_y,mag_z,acc_x,acc_y,acc_z,
    /// static or slow readings): accelerometer bias, scale and cross-axis, magnetometer hard
    /// and soft iron, the rotation between the two (from the constant dip), and the pointing
    /// axis from runs of shots aimed at one target while rolling (found automatically).
    EllipsoidAccel,
    /// Online least-squares ellipse (2-D): the same direct fit from running sums, in
    /// constant memory, as a vehicle would run it while driving.
    OnlineEllipse,
    /// Online least-squares ellipsoid (3-D, needs mag_z), in constant memory.
    OnlineEllipsoid,
    /// Binned ellipse (EP 0634001): heading bins, origin iteration, ellipse phasors.
    BinnedEllipse,
    /// Merit circle (US 5,297,063): merit-weighted circumcentres; hard iron only.
    MeritCircle,
    /// One full turn (EP 0640207): compass centre and radii from the extrema; with `gyr_z`,
    /// also the gyro's zero (from a standstill at the start) and scale.
    Turn,
}

/// A compass calibrator built by [`CalibrationMethod::calibrator`], by the samples it
/// learns from.
pub enum CompassCalibrator {
    /// Two-axis readings.
    Planar(Box<Planar>),
    /// Three-axis readings.
    Spatial(Box<Spatial>),
    /// Magnetometer and accelerometer readings.
    MagAccel(Box<MagAccel>),
    /// One turn: the compass alone, or with a yaw rate the gyro beside it (which one runs
    /// is known once the input's columns are).
    Turn {
        /// The compass from the turn's extrema.
        compass: Box<Planar>,
        /// The compass and the gyro's zero and scale.
        with_gyro: Box<TurnWithGyro>,
    },
}

impl CompassCalibrator {
    /// The calibrator of two-axis readings, for a method that has one.
    pub fn into_planar(self) -> Option<Box<Planar>> {
        match self {
            Self::Planar(c) | Self::Turn { compass: c, .. } => Some(c),
            Self::Spatial(_) | Self::MagAccel(_) => None,
        }
    }
}

impl CalibrationMethod {
    /// The name used on the command line and in the output file.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ellipse => "ellipse",
            Self::Ellipsoid => "ellipsoid",
            Self::EllipsoidAccel => "ellipsoid-accel",
            Self::OnlineEllipse => "online-ellipse",
            Self::OnlineEllipsoid => "online-ellipsoid",
            Self::BinnedEllipse => "binned-ellipse",
            Self::MeritCircle => "merit-circle",
            Self::Turn => "turn",
        }
    }

    /// 2 or 3.
    pub fn dimensions(self) -> usize {
        match self {
            Self::Ellipsoid | Self::EllipsoidAccel | Self::OnlineEllipsoid => 3,
            _ => 2,
        }
    }

    /// The method's calibrator in its default configuration, with `expected_field` (input
    /// unit): every method reports the fitted field against it; `ellipsoid-accel` also
    /// uses it in the fit.
    pub fn calibrator(self, expected_field: Option<f64>) -> Result<CompassCalibrator> {
        self.build(expected_field, None)
    }

    /// [`Self::calibrator`], with the batch ellipse, ellipsoid and ellipsoid-accel fits
    /// keeping their readings in stores of `spill` (memory up to a share, the rest in a
    /// temporary file): the same results in bounded memory.
    pub fn calibrator_spilling(
        self,
        expected_field: Option<f64>,
        spill: &ReadingSpill,
    ) -> Result<CompassCalibrator> {
        self.build(expected_field, Some(spill))
    }

    fn build(
        self,
        expected_field: Option<f64>,
        spill: Option<&ReadingSpill>,
    ) -> Result<CompassCalibrator> {
        use CompassCalibrator as C;
        Ok(match self {
            Self::Ellipse => {
                let config = EllipseConfig {
                    expected_field,
                    ..EllipseConfig::default()
                };
                C::Planar(match spill {
                    Some(s) => Box::new(EllipseCalibrator::with_store(config, s.store::<2>())?),
                    None => Box::new(EllipseCalibrator::new(config)?),
                })
            }
            Self::OnlineEllipse => C::Planar(Box::new(OnlineEllipseCalibrator::new(
                OnlineEllipseConfig {
                    expected_field,
                    ..OnlineEllipseConfig::default()
                },
            )?)),
            Self::BinnedEllipse => C::Planar(Box::new(BinnedEllipseCalibrator::new(
                BinnedEllipseConfig {
                    expected_field,
                    ..BinnedEllipseConfig::default()
                },
            )?)),
            Self::MeritCircle => {
                C::Planar(Box::new(MeritCircleCalibrator::new(MeritCircleConfig {
                    expected_field,
                    ..MeritCircleConfig::default()
                })?))
            }
            Self::Ellipsoid => {
                let config = EllipsoidConfig {
                    expected_field,
                    ..EllipsoidConfig::default()
                };
                C::Spatial(match spill {
                    Some(s) => Box::new(EllipsoidCalibrator::with_store(config, s.store::<3>())?),
                    None => Box::new(EllipsoidCalibrator::new(config)?),
                })
            }
            Self::OnlineEllipsoid => C::Spatial(Box::new(OnlineEllipsoidCalibrator::new(
                OnlineEllipsoidConfig {
                    expected_field,
                    ..OnlineEllipsoidConfig::default()
                },
            )?)),
            Self::EllipsoidAccel => {
                let config = MagAccelConfig {
                    expected_field,
                    ..MagAccelConfig::default()
                };
                C::MagAccel(match spill {
                    Some(s) => Box::new(MagAccelCalibrator::with_store(config, s.store::<6>())?),
                    None => Box::new(MagAccelCalibrator::new(config)?),
                })
            }
            Self::Turn => {
                let config = TurnConfig {
                    expected_field,
                    ..TurnConfig::default()
                };
                C::Turn {
                    compass: Box::new(TurnCompassCalibrator::new(config)?),
                    with_gyro: Box::new(TurnCalibrator::new(config)?),
                }
            }
        })
    }
}
