//! The readings of the joint fit as [`Readings`]: one six-wide reading per sample, the
//! magnetometer's three values then the accelerometer's, so that a store of the batch fits
//! (memory, or memory and a file) can hold them and the fit pass over them in order, as
//! often as it needs, without a copy of its own.

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::{SVector, Vector3};
use truenorth_core::Result;

use crate::fits::mag_accel::calibration::MagAccelSample;
use crate::numerics::readings::{READINGS_RUN_MULTIPLE, ReadingStore, Readings};

/// One reading of both sensors, as the joint fit keeps it: `[mag_x, mag_y, mag_z, acc_x,
/// acc_y, acc_z]` in their raw units (the time is not kept: the fit does not use it).
pub type MagAccelReading = SVector<f64, 6>;

/// The six-wide reading of a sample.
pub fn mag_accel_reading(sample: &MagAccelSample) -> MagAccelReading {
    let (m, a) = (sample.mag, sample.acc);
    MagAccelReading::from([m.x, m.y, m.z, a.x, a.y, a.z])
}

/// Readings converted to another shape go through a buffer of this many on the stack
/// (3 kB of six-wide readings): a multiple of [`READINGS_RUN_MULTIPLE`], so that the runs
/// handed on keep the blocks' boundaries, and long enough that handing on a run costs
/// little beside the fit's work on its readings.
const CONVERTED_RUN: usize = 2 * READINGS_RUN_MULTIPLE;

/// Calls `run` with `convert` of every item of `items`, in runs of [`CONVERTED_RUN`] (the
/// last shorter).
fn replay_converted<T, const D: usize>(
    items: &[T],
    convert: impl Fn(&T) -> SVector<f64, D>,
    run: &mut dyn FnMut(&[SVector<f64, D>]),
) {
    let mut buf = [SVector::<f64, D>::zeros(); CONVERTED_RUN];
    for chunk in items.chunks(CONVERTED_RUN) {
        for (b, item) in buf.iter_mut().zip(chunk) {
            *b = convert(item);
        }
        run(&buf[..chunk.len()]);
    }
}

/// Samples in memory are readings of the joint fit, converted as they are replayed.
impl Readings<6> for [MagAccelSample] {
    fn len(&self) -> usize {
        <[MagAccelSample]>::len(self)
    }

    fn replay(&self, run: &mut dyn FnMut(&[MagAccelReading])) -> Result<()> {
        replay_converted(self, mag_accel_reading, run);
        Ok(())
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[MagAccelReading]),
    ) -> Result<()> {
        let end = end.min(<[MagAccelSample]>::len(self));
        if start < end {
            replay_converted(&self[start..end], mag_accel_reading, run);
        }
        Ok(())
    }
}

impl Readings<6> for Vec<MagAccelSample> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[MagAccelReading])) -> Result<()> {
        self.as_slice().replay(run)
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[MagAccelReading]),
    ) -> Result<()> {
        self.as_slice().replay_range(start, end, run)
    }

    fn shared(&self) -> Option<&(dyn Readings<6> + Sync)> {
        Some(self)
    }
}

/// Samples in one slice as readings that threads may replay ranges of at once (a slice
/// itself is unsized, so it cannot be handed on as [`Readings::shared`]).
pub(crate) struct SampleSlice<'a>(pub &'a [MagAccelSample]);

impl Readings<6> for SampleSlice<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[MagAccelReading])) -> Result<()> {
        self.0.replay(run)
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[MagAccelReading]),
    ) -> Result<()> {
        self.0.replay_range(start, end, run)
    }

    fn shared(&self) -> Option<&(dyn Readings<6> + Sync)> {
        Some(self)
    }
}

/// Where a [`crate::MagAccelCalibrator`] keeps the samples pushed to it.
///
/// `Vec<MagAccelSample>` keeps them whole, times included (the default, whose
/// [`crate::MagAccelCalibrator::samples`] gives them back); every [`ReadingStore`] of
/// six-wide readings keeps their [`MagAccelReading`]s, which is all the fit needs: one of
/// the caller's own can bound the memory a long recording takes.
pub trait MagAccelStore: Readings<6> {
    /// Adds a sample after the others.
    ///
    /// # Errors
    /// When it cannot be stored (memory or disk full); the store then holds the samples
    /// before it.
    fn push_sample(&mut self, sample: &MagAccelSample) -> Result<()>;

    /// Forgets every sample.
    fn clear_samples(&mut self);
}

impl MagAccelStore for Vec<MagAccelSample> {
    fn push_sample(&mut self, sample: &MagAccelSample) -> Result<()> {
        self.push(*sample);
        Ok(())
    }

    fn clear_samples(&mut self) {
        self.clear();
    }
}

impl<S: ReadingStore<6>> MagAccelStore for S {
    fn push_sample(&mut self, sample: &MagAccelSample) -> Result<()> {
        ReadingStore::push(self, mag_accel_reading(sample))
    }

    fn clear_samples(&mut self) {
        ReadingStore::clear(self);
    }
}

/// Which sensor of a [`MagAccelReading`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sensor {
    /// The first three values.
    Mag,
    /// The last three.
    Acc,
}

impl Sensor {
    /// This sensor's reading in `r`.
    #[inline]
    pub fn of(self, r: &MagAccelReading) -> Vector3<f64> {
        let k = match self {
            Self::Mag => 0,
            Self::Acc => 3,
        };
        Vector3::new(r[k], r[k + 1], r[k + 2])
    }
}

/// One sensor's readings among the joint ones, replayed as three-wide readings in the same
/// order (for the fits and reports of one sensor: its ellipsoid, its normaliser, its
/// coverage).
pub(crate) struct SensorReadings<'a, R: ?Sized> {
    view: SensorView<'a, R>,
    /// The same view of the joint readings as threads may replay them, when they may.
    shared: Option<SensorView<'a, dyn Readings<6> + Sync + 'a>>,
}

impl<'a, R: Readings<6> + ?Sized> SensorReadings<'a, R> {
    /// `sensor`'s readings among `readings`.
    pub fn new(readings: &'a R, sensor: Sensor) -> Self {
        Self {
            view: SensorView { readings, sensor },
            shared: readings
                .shared()
                .map(|readings| SensorView { readings, sensor }),
        }
    }
}

impl<R: Readings<6> + ?Sized> Readings<3> for SensorReadings<'_, R> {
    fn len(&self) -> usize {
        self.view.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[Vector3<f64>])) -> Result<()> {
        self.view.replay(run)
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[Vector3<f64>]),
    ) -> Result<()> {
        self.view.replay_range(start, end, run)
    }

    fn shared(&self) -> Option<&(dyn Readings<3> + Sync)> {
        self.shared.as_ref().map(|v| v as &(dyn Readings<3> + Sync))
    }
}

/// A sensor's three values of each joint reading. A run of the joint readings is a
/// multiple of READINGS_RUN_MULTIPLE but perhaps the last, and so is every piece of
/// CONVERTED_RUN it is cut into but its last: the runs handed on keep the rule.
struct SensorView<'a, R: ?Sized> {
    readings: &'a R,
    sensor: Sensor,
}

impl<R: Readings<6> + ?Sized> Readings<3> for SensorView<'_, R> {
    fn len(&self) -> usize {
        self.readings.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[Vector3<f64>])) -> Result<()> {
        let sensor = self.sensor;
        self.readings
            .replay(&mut |joint| replay_converted(joint, |r| sensor.of(r), run))
    }

    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[Vector3<f64>]),
    ) -> Result<()> {
        let sensor = self.sensor;
        self.readings.replay_range(start, end, &mut |joint| {
            replay_converted(joint, |r| sensor.of(r), run);
        })
    }
}
