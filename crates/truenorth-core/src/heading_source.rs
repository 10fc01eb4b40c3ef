//! Heading sources: absolute (a compass) and relative (a gyro or odometer, per step).

use crate::Result;

/// A source of absolute heading, e.g. a calibrated compass.
pub trait AbsoluteHeadingSource {
    /// The sample it reads.
    type Sample;

    /// Heading, radians clockwise from magnetic north, wrapped to (-π, π].
    fn heading_rad(&self, sample: &Self::Sample) -> Result<f64>;
}

/// A source of heading change per step, e.g. an integrated gyro or a differential odometer.
pub trait RelativeHeadingSource {
    /// The sample it reads.
    type Sample;

    /// Heading change since the previous sample, radians, positive for a right turn.
    /// The first sample returns 0.
    fn heading_change_rad(&mut self, sample: &Self::Sample) -> Result<f64>;

    /// Forgets the previous sample.
    fn reset(&mut self);
}
