//! `truenorth inspect`'s analysis: what a recording holds (each column's rate, gaps, range
//! and unreadable cells) and what its sensors' units and the gyro's axes are, judged from
//! the physics with the same checks `orientation` and `drive` refuse by, and the options
//! that read it right.
//!
//! * [`column_stats`]: one column's rate, gaps and range;
//! * [`sensors`]: each inertial sensor's likely unit, the gyro's axes;
//! * [`wheels`]: the odometer wheels, and a yaw gyro against them;
//! * [`gnss`]: a drive log's satellite fixes;
//! * [`report`]: the whole report, as a table or JSON, and the options to pass.

pub mod column_stats;
pub mod faults;
pub mod gnss;
pub mod report;
pub mod sensors;
pub mod wheels;

use nalgebra::Vector3;

use truenorth::checks::Inertial;

use crate::io::{CliError, CliResult, InputOptions, RowReader};
use column_stats::{ColumnScan, ColumnStats, TimeOrder};
use faults::FaultScan;
use report::Report;

/// The units, axes and wheels are judged on a recording's first this many rows (87
/// minutes at 100 Hz, nine at 1 kHz: many turns and rests), so that `inspect` holds at
/// most these rows whatever the length of the file; the columns' counts, ranges and gaps
/// are taken over every row.
pub const JUDGED_ROWS: usize = 1 << 19;

/// Every column `inspect` looks for (body axes, after `--axes` and `--column`): every
/// sensor column some command reads.
pub use crate::io::reading::columns::SENSOR_COLUMNS as COLUMNS;

/// A recording's columns as read: the time and the [`COLUMNS`] it has (NaN where a cell is
/// empty).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recording {
    /// `t_s`, s.
    pub t_s: Vec<f64>,
    /// The columns present, by name, each as long as `t_s`.
    pub columns: Vec<(String, Vec<f64>)>,
}

/// A recording as `inspect` reads it: every column summarised over every row, and the
/// first [`JUDGED_ROWS`] rows kept for the judgements of units, axes and wheels.
#[derive(Debug, Clone)]
pub struct Scan {
    /// The rows kept (all of them in a recording of up to [`JUDGED_ROWS`] rows).
    pub recording: Recording,
    /// Data rows in the whole recording.
    pub rows: usize,
    /// Rows whose `t_s` does not come after the previous row's.
    pub time_not_increasing: usize,
    /// `t_s` and every column of [`COLUMNS`] present, over every row.
    pub columns: Vec<ColumnStats>,
    /// Readings no live sensor gives, one line a sensor, over every row.
    pub sensor_faults: Vec<String>,
}

/// A [`Scan`] as the rows arrive.
struct Scanner {
    recording: Recording,
    rows: usize,
    order: TimeOrder,
    /// `t_s`'s summary, then each column's, in the recording's order.
    columns: Vec<ColumnScan>,
    faults: FaultScan,
}

impl Scanner {
    fn new(names: &[String]) -> Self {
        Self {
            recording: Recording {
                t_s: Vec::new(),
                columns: names.iter().map(|n| (n.clone(), Vec::new())).collect(),
            },
            rows: 0,
            order: TimeOrder::default(),
            columns: std::iter::once("t_s")
                .chain(names.iter().map(String::as_str))
                .map(ColumnScan::new)
                .collect(),
            faults: FaultScan::new(names),
        }
    }

    /// Takes input row `row`: its time and its cells in the order of the names given to
    /// `new`.
    fn push(&mut self, row: usize, t_s: f64, cells: impl Iterator<Item = f64> + Clone) {
        self.rows += 1;
        self.faults.push(row, t_s, cells.clone());
        self.order.push(t_s);
        self.columns[0].push(t_s, t_s);
        for (scan, v) in self.columns[1..].iter_mut().zip(cells.clone()) {
            scan.push(t_s, v);
        }
        if self.recording.t_s.len() < JUDGED_ROWS {
            self.recording.t_s.push(t_s);
            for ((_, kept), v) in self.recording.columns.iter_mut().zip(cells) {
                kept.push(v);
            }
        }
    }

    fn finish(self) -> Scan {
        Scan {
            recording: self.recording,
            rows: self.rows,
            time_not_increasing: self.order.not_increasing,
            columns: self.columns.into_iter().map(ColumnScan::finish).collect(),
            sensor_faults: self.faults.finish(),
        }
    }
}

impl Scan {
    /// Reads every row of `rows` (opened for `t_s` and [`COLUMNS`]), one at a time.
    pub fn read(mut rows: RowReader) -> CliResult<Self> {
        let present: Vec<(String, usize)> = COLUMNS
            .iter()
            .filter_map(|n| Some((n.to_string(), rows.index(n)?)))
            .collect();
        let t_index = rows
            .index("t_s")
            .ok_or_else(|| CliError::file(rows.path(), "missing column `t_s`".to_string()))?;
        let names: Vec<String> = present.iter().map(|p| p.0.clone()).collect();
        let mut scanner = Scanner::new(&names);
        while let Some(row) = rows.next_row()? {
            let cells = present.iter().map(|(_, i)| row.values[*i]);
            scanner.push(row.number, row.values[t_index], cells);
        }
        if scanner.rows == 0 {
            return Err(CliError::row(
                rows.path(),
                2,
                "no data rows after the header",
            ));
        }
        Ok(scanner.finish())
    }

    /// The scan of a recording held in memory (its rows beyond [`JUDGED_ROWS`] are only
    /// counted and summarised, as from a file).
    pub fn of(rec: &Recording) -> Self {
        let names: Vec<String> = rec.columns.iter().map(|c| c.0.clone()).collect();
        let mut scanner = Scanner::new(&names);
        for (k, t) in rec.t_s.iter().enumerate() {
            scanner.push(k + 2, *t, rec.columns.iter().map(move |c| c.1[k]));
        }
        scanner.finish()
    }
}

impl Recording {
    /// Column `name`, if present.
    pub fn col(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The three columns `stem_x`, `stem_y`, `stem_z`, if all are present.
    pub fn vector(&self, stem: &str) -> Option<[&[f64]; 3]> {
        Some([
            self.col(&format!("{stem}_x"))?,
            self.col(&format!("{stem}_y"))?,
            self.col(&format!("{stem}_z"))?,
        ])
    }

    /// The rows with a finite time, gyro and accelerometer, as the checks take them (the
    /// magnetometer where its three cells are finite); empty without both sensors.
    pub fn inertial(&self) -> Vec<Inertial> {
        let (Some(g), Some(a)) = (self.vector("gyr"), self.vector("acc")) else {
            return Vec::new();
        };
        let m = self.vector("mag");
        let at = |c: [&[f64]; 3], k: usize| Vector3::new(c[0][k], c[1][k], c[2][k]);
        (0..self.t_s.len())
            .map(|k| Inertial {
                t_s: self.t_s[k],
                gyr: at(g, k),
                acc: at(a, k),
                mag: m
                    .map(|m| at(m, k))
                    .filter(|v| v.iter().all(|x| x.is_finite())),
            })
            .filter(Inertial::is_finite)
            .collect()
    }
}

/// Everything `inspect` says about `scan`, read under `opts` (which the suggested options
/// compose with); `file` names it.
pub fn analyse(file: &str, scan: &Scan, opts: &InputOptions) -> Report {
    let rec = &scan.recording;
    let rows = rec.inertial();
    Report {
        file: file.to_string(),
        rows: scan.rows,
        judged_rows: rec.t_s.len(),
        time_not_increasing: scan.time_not_increasing,
        columns: scan.columns.clone(),
        sensor_faults: scan.sensor_faults.clone(),
        acc: sensors::acc(rec, &rows),
        gyro: sensors::gyro(rec, &rows, opts),
        mag: sensors::mag(rec),
        wheels: wheels::wheels(rec),
        yaw: wheels::yaw(rec, opts),
        vehicle: wheels::vehicle_sensors(rec),
        gnss: gnss::gnss(rec, &scan.columns),
        findings: sensors::other_findings(&rows, opts),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A cell: mostly ordinary numbers, sometimes huge, zero, NaN or infinite.
    fn cell() -> impl Strategy<Value = f64> {
        prop_oneof![
            6 => -20.0f64..20.0,
            1 => Just(f64::NAN),
            1 => Just(f64::INFINITY),
            1 => Just(f64::NEG_INFINITY),
            1 => Just(0.0),
            1 => -1e300f64..1e300,
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any columns at all, finite or not, in or out of time order: a report, never a
        /// panic, and it serialises.
        #[test]
        fn inspect_never_panics(
            t in proptest::collection::vec(cell(), 0..300),
            present in proptest::collection::vec(any::<bool>(), COLUMNS.len()),
            seed in proptest::collection::vec(cell(), 300 * COLUMNS.len()),
            ramp in any::<bool>(),
        ) {
            let t_s: Vec<f64> = if ramp {
                (0..t.len()).map(|k| k as f64 * 0.01).collect()
            } else {
                t
            };
            let n = t_s.len();
            let columns = COLUMNS
                .iter()
                .enumerate()
                .filter(|(i, _)| present[*i])
                .map(|(i, name)| (name.to_string(), seed[i * 300..i * 300 + n].to_vec()))
                .collect();
            let rec = Recording { t_s, columns };
            let report = analyse("any", &Scan::of(&rec), &InputOptions::default());
            prop_assert_eq!(report.rows, n);
            prop_assert!(serde_json::to_string(&report).is_ok());
            prop_assert!(!report.to_table().is_empty());
        }
    }
}
