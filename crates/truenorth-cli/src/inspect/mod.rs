//! `truenorth inspect`'s analysis: what a recording holds (each column's rate, gaps, range
//! and unreadable cells) and what its sensors' units and the gyro's axes are, judged from
//! the physics with the same checks `orientation` and `drive` refuse by, and the options
//! that read it right.
//!
//! * [`column_stats`]: one column's rate, gaps and range;
//! * [`sensors`]: each inertial sensor's likely unit, the gyro's axes;
//! * [`wheels`]: the odometer wheels, and a yaw gyro against them;
//! * [`report`]: the whole report, as a table or JSON, and the options to pass.

pub mod column_stats;
pub mod report;
pub mod sensors;
pub mod wheels;

use nalgebra::Vector3;

use truenorth::checks::Inertial;

use crate::io::{CliResult, InputOptions, RowReader, Table};
use report::Report;

/// Every column `inspect` looks for (body axes, after `--axes` and `--column`).
pub const COLUMNS: [&str; 19] = [
    "gyr_x",
    "gyr_y",
    "gyr_z",
    "acc_x",
    "acc_y",
    "acc_z",
    "mag_x",
    "mag_y",
    "mag_z",
    "dist_l_m",
    "dist_r_m",
    "speed_l_mps",
    "speed_r_mps",
    "speed_fl_mps",
    "speed_fr_mps",
    "speed_rl_mps",
    "speed_rr_mps",
    "dist_m",
    "speed_mps",
];

/// A recording's columns as read: the time and the [`COLUMNS`] it has (NaN where a cell is
/// empty).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Recording {
    /// `t_s`, s.
    pub t_s: Vec<f64>,
    /// The columns present, by name, each as long as `t_s`.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl Recording {
    /// Reads every row of `rows` (opened for `t_s` and [`COLUMNS`]): `t_s` and whichever
    /// of [`COLUMNS`] it has.
    pub fn read(rows: RowReader) -> CliResult<Self> {
        let table = Table::read(rows)?;
        table.require_rows()?;
        Ok(Self {
            t_s: table.req("t_s")?.to_vec(),
            columns: COLUMNS
                .iter()
                .filter_map(|n| Some((n.to_string(), table.col(n)?.to_vec())))
                .collect(),
        })
    }

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

/// Everything `inspect` says about `rec`, read under `opts` (which the suggested options
/// compose with); `file` names it.
pub fn analyse(file: &str, rec: &Recording, opts: &InputOptions) -> Report {
    let rows = rec.inertial();
    Report {
        file: file.to_string(),
        rows: rec.t_s.len(),
        time_not_increasing: column_stats::time_not_increasing(&rec.t_s),
        columns: std::iter::once(("t_s", rec.t_s.as_slice()))
            .chain(rec.columns.iter().map(|(n, v)| (n.as_str(), v.as_slice())))
            .map(|(n, v)| column_stats::ColumnStats::new(n, &rec.t_s, v))
            .collect(),
        acc: sensors::acc(rec, &rows),
        gyro: sensors::gyro(rec, &rows, opts),
        mag: sensors::mag(rec),
        wheels: wheels::wheels(rec),
        yaw: wheels::yaw(rec, opts),
        vehicle: wheels::vehicle_sensors(rec),
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
            let report = analyse("any", &rec, &InputOptions::default());
            prop_assert_eq!(report.rows, n);
            prop_assert!(serde_json::to_string(&report).is_ok());
            prop_assert!(!report.to_table().is_empty());
        }
    }
}
