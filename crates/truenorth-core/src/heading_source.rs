//! Heading sources: absolute (a compass) and relative (a gyro or odometer, per step).

use serde::{Deserialize, Serialize};

use crate::{MagneticHeading, Result, Tilt};

/// One absolute heading reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AbsoluteHeading {
    /// Heading of the body x axis from magnetic north.
    pub heading: MagneticHeading,
    /// Magnitude of the calibrated field the heading was taken from (horizontal for a
    /// two-axis compass, total for three axes), in the calibration's unit. A disturbance
    /// detector compares it with the calibrated field.
    pub field_norm: f64,
    /// Angle of the field below the horizontal (inclination), radians, when the source can
    /// see it (a tilt-compensated three-axis compass).
    pub dip_rad: Option<f64>,
}

/// A source of absolute heading, e.g. a calibrated compass.
pub trait AbsoluteHeadingSource {
    /// The sample it reads.
    type Sample;

    /// Heading of the body x axis from magnetic north. `tilt` is the body's roll and pitch
    /// when known (`None`: assume level); a source that cannot compensate tilt refuses a
    /// tilt it cannot ignore with [`crate::Error::Unsupported`].
    fn heading(&self, sample: &Self::Sample, tilt: Option<&Tilt>) -> Result<AbsoluteHeading>;
}

/// The motion between two consecutive samples of a relative heading source.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RelativeStep {
    /// Time between the samples, seconds (> 0).
    pub dt_s: f64,
    /// Heading change, radians, positive for a right turn.
    pub heading_change_rad: f64,
    /// Distance travelled along the track, metres, when the source measures it (an
    /// odometer); `None` for a gyro.
    pub distance_m: Option<f64>,
}

/// A source of heading change per step, e.g. an integrated gyro or a differential odometer.
pub trait RelativeHeadingSource {
    /// The sample it reads.
    type Sample;

    /// The motion since the previous sample; `None` for the first sample after
    /// construction or [`RelativeHeadingSource::reset`]. A non-increasing timestamp is an
    /// error and changes nothing.
    fn step(&mut self, sample: &Self::Sample) -> Result<Option<RelativeStep>>;

    /// Forgets the previous sample.
    fn reset(&mut self);
}
