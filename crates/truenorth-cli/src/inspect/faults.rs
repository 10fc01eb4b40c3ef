//! Readings no live sensor gives, looked for as the rows stream past (the watch `calibrate`,
//! `heading`, `orientation` and `drive` refuse by: `truenorth::checks::stuck_readings`), so
//! that `inspect` names what those commands would refuse.

use truenorth::checks::{StuckReadings, StuckRun};

/// One sensor's readings under watch, whatever its number of axes.
#[derive(Debug, Clone)]
enum Watch {
    One(StuckReadings<1>),
    Two(StuckReadings<2>),
    Three(StuckReadings<3>),
}

impl Watch {
    fn push(&mut self, row: usize, t_s: f64, v: &[f64]) -> Option<StuckRun> {
        match (self, v) {
            (Self::One(w), [x]) => w.push(row, t_s, &[*x]),
            (Self::Two(w), [x, y]) => w.push(row, t_s, &[*x, *y]),
            (Self::Three(w), [x, y, z]) => w.push(row, t_s, &[*x, *y, *z]),
            _ => None,
        }
    }

    fn finish(&mut self) -> Option<StuckRun> {
        match self {
            Self::One(w) => w.finish(),
            Self::Two(w) => w.finish(),
            Self::Three(w) => w.finish(),
        }
    }

    fn found(&self) -> usize {
        match self {
            Self::One(w) => w.found(),
            Self::Two(w) => w.found(),
            Self::Three(w) => w.found(),
        }
    }
}

/// The gyro and the magnetometer watched over every row.
#[derive(Debug, Clone, Default)]
pub struct FaultScan {
    /// Each sensor: its name, the positions of its cells among the row's, the watch and the
    /// first run found.
    sensors: Vec<(&'static str, Vec<usize>, Watch, Option<StuckRun>)>,
    /// The row's cells and one sensor's, kept between rows.
    row: Vec<f64>,
    cells: Vec<f64>,
}

impl FaultScan {
    /// Watches the gyro (`gyr_x,gyr_y,gyr_z`, or `gyr_z` alone) and the magnetometer
    /// (`mag_x,mag_y[,mag_z]`) among the columns `names` (a row's cells in that order).
    pub fn new(names: &[String]) -> Self {
        let at = |n: &str| names.iter().position(|c| c == n);
        let mut sensors = Vec::new();
        match [at("gyr_x"), at("gyr_y"), at("gyr_z")] {
            [Some(x), Some(y), Some(z)] => sensors.push((
                "gyro",
                vec![x, y, z],
                Watch::Three(StuckReadings::new()),
                None,
            )),
            [_, _, Some(z)] => {
                sensors.push(("gyr_z", vec![z], Watch::One(StuckReadings::new()), None));
            }
            _ => {}
        }
        match [at("mag_x"), at("mag_y"), at("mag_z")] {
            [Some(x), Some(y), Some(z)] => sensors.push((
                "magnetometer",
                vec![x, y, z],
                Watch::Three(StuckReadings::magnetometer()),
                None,
            )),
            [Some(x), Some(y), None] => sensors.push((
                "magnetometer",
                vec![x, y],
                Watch::Two(StuckReadings::magnetometer()),
                None,
            )),
            _ => {}
        }
        Self {
            sensors,
            row: Vec::with_capacity(names.len()),
            cells: Vec::with_capacity(3),
        }
    }

    /// Takes input row `row` at `t_s`, its cells in the order of the names given to `new`.
    pub fn push(&mut self, row: usize, t_s: f64, cells: impl Iterator<Item = f64>) {
        if self.sensors.is_empty() {
            return;
        }
        self.row.clear();
        self.row.extend(cells);
        for (_, at, watch, first) in &mut self.sensors {
            self.cells.clear();
            self.cells.extend(at.iter().map(|i| self.row[*i]));
            if let Some(run) = watch.push(row, t_s, &self.cells) {
                first.get_or_insert(run);
            }
        }
    }

    /// What was found, one line a sensor: the first run, what it means, and how many.
    pub fn finish(mut self) -> Vec<String> {
        let mut out = Vec::new();
        for (name, _, watch, first) in &mut self.sensors {
            if let Some(run) = watch.finish() {
                first.get_or_insert(run);
            }
            if let Some(run) = first {
                out.push(format!(
                    "{name}: {run}: {} ({} such runs)",
                    run.advice(),
                    watch.found()
                ));
            }
        }
        out
    }
}
