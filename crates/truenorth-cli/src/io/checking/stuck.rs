//! A sensor's readings watched, as they stream, for runs no live sensor gives (the physics
//! is `truenorth::checks::stuck_readings`): the first is refused with its row and what to
//! do, or with `--accept-sensor-faults` said on stderr, and the count said at the end.

use std::path::{Path, PathBuf};

use truenorth::checks::{StuckReadings, StuckRun};

use crate::io::{CliError, CliResult, errln};

/// One sensor's readings under watch.
#[derive(Debug)]
pub struct StuckWatch<const D: usize> {
    /// The sensor and the unit its readings are in, as the message names them.
    sensor: &'static str,
    check: StuckReadings<D>,
    input: PathBuf,
    accept: bool,
    warned: bool,
    readings: usize,
}

impl<const D: usize> StuckWatch<D> {
    /// A sensor whose readings may be zero on every axis (a gyro), named `sensor`.
    pub fn new(sensor: &'static str, input: &Path, accept: bool) -> Self {
        Self::with(sensor, StuckReadings::new(), input, accept)
    }

    /// A magnetometer (no reading of zero on every axis), named `sensor`.
    pub fn magnetometer(sensor: &'static str, input: &Path, accept: bool) -> Self {
        Self::with(sensor, StuckReadings::magnetometer(), input, accept)
    }

    fn with(sensor: &'static str, check: StuckReadings<D>, input: &Path, accept: bool) -> Self {
        Self {
            sensor,
            check,
            input: input.to_path_buf(),
            accept,
            warned: false,
            readings: 0,
        }
    }

    /// Readings taken so far (finite on every axis or not).
    pub fn readings(&self) -> usize {
        self.readings
    }

    /// Takes the reading `v` of input row `row` at `t_s`.
    pub fn push(&mut self, row: usize, t_s: f64, v: &[f64; D]) -> CliResult {
        self.readings += 1;
        match self.check.push(row, t_s, v) {
            Some(run) => self.found(&run),
            None => Ok(()),
        }
    }

    /// The end of the readings: a run still going is judged, and the count said.
    pub fn finish(&mut self) -> CliResult {
        if let Some(run) = self.check.finish() {
            self.found(&run)?;
        }
        if self.warned && self.check.found() > 1 {
            errln!(
                "warning: {}: {}: {} runs of readings no live sensor gives (the first said above)",
                self.input.display(),
                self.sensor,
                self.check.found()
            );
        }
        Ok(())
    }

    fn found(&mut self, run: &StuckRun) -> CliResult {
        let message = format!("{}: {run}: {}", self.sensor, run.advice());
        if !self.accept {
            return Err(CliError::row(
                &self.input,
                run.from_row,
                format!("{message} (or --accept-sensor-faults to go on)"),
            ));
        }
        if !self.warned {
            errln!(
                "warning: {}: row {}: {message}",
                self.input.display(),
                run.from_row
            );
            self.warned = true;
        }
        Ok(())
    }
}

/// A reading with a magnetometer: its time and the magnetometer's axes.
pub trait MagCells {
    /// The time, s.
    fn t_s(&self) -> f64;
    /// The magnetometer's axes, x first (two or three).
    fn mag_cells(&self) -> &[f64];
}

macro_rules! mag_cells {
    ($($t:ty),*) => {$(
        impl MagCells for $t {
            fn t_s(&self) -> f64 {
                self.t_s
            }
            fn mag_cells(&self) -> &[f64] {
                self.mag.as_slice()
            }
        }
    )*};
}

mag_cells!(
    truenorth::core::Mag2Sample,
    truenorth::core::Mag3Sample,
    truenorth::calib::MagAccelSample,
    truenorth::calib::TurnSample
);

/// A two- or three-axis magnetometer under watch, whichever its readings are.
#[derive(Debug)]
pub struct MagWatch {
    two: StuckWatch<2>,
    three: StuckWatch<3>,
}

impl MagWatch {
    /// A magnetometer read from `input`, refused (or with `accept` warned) by.
    pub fn new(input: &Path, accept: bool) -> Self {
        Self {
            two: StuckWatch::magnetometer("magnetometer", input, accept),
            three: StuckWatch::magnetometer("magnetometer", input, accept),
        }
    }

    /// Takes the reading of input row `row`.
    pub fn push(&mut self, row: usize, reading: &impl MagCells) -> CliResult {
        self.push_cells(row, reading.t_s(), reading.mag_cells())
    }

    /// Takes the magnetometer's axes `cells` (two or three) of input row `row` at `t_s`.
    pub fn push_cells(&mut self, row: usize, t_s: f64, cells: &[f64]) -> CliResult {
        match *cells {
            [x, y] => self.two.push(row, t_s, &[x, y]),
            [x, y, z] => self.three.push(row, t_s, &[x, y, z]),
            _ => Ok(()),
        }
    }

    /// The end of the readings (see [`StuckWatch::finish`]).
    pub fn finish(&mut self) -> CliResult {
        self.two.finish()?;
        self.three.finish()
    }
}
