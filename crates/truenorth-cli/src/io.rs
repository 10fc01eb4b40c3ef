//! Input and output shared by the subcommands, with errors that name the file, the row and
//! the problem.
//!
//! Reading (the same for every command, and for any that reads a CSV later):
//! * [`InputPath`]: a file or `-` (standard input), gzip-compressed or not (found by the
//!   magic bytes);
//! * [`InputOptions`] (flatten into a command's arguments): the delimiter, a file without a
//!   header, the column mapping `NAME=HEADER` (`-HEADER` negates) and the sensor's axis
//!   convention (`--axes flu`); headers match without regard to case, and a requested
//!   column named twice is an error;
//! * [`RowReader`]: the streaming read, one row at a time, the requested columns by name as
//!   `f64` with the row number for messages, time order checked on the way; memory does not
//!   grow with the file;
//! * [`Table`]: the whole-table read built on it.
//!
//! Writing: [`AtomicOutput`] / [`CsvOutput`] / [`write_csv`] / [`write_atomically`] write a
//! temporary file beside the target, sync it and rename it over the target (`-`: standard
//! output; `*.gz`: compressed); [`check_distinct`] refuses an output that is one of the
//! inputs before anything is read.

mod atomic_write;
mod calibration_file;
mod columns;
mod error;
mod reader;
mod source;
mod table;

#[allow(unused_imports)]
pub use atomic_write::{AtomicOutput, CsvOutput, check_distinct, write_atomically, write_csv};
pub use calibration_file::{
    AccelPart, CALIBRATION_FORMAT, CALIBRATION_VERSION, CalibrationFile, CompassCalibration,
    GyroPart, QualityReport, finite, gyro_units, matrix_rows, units_block,
};
#[allow(unused_imports)]
pub use columns::{AxisConvention, ColumnMapping, ColumnSource, Delimiter, Header, InputOptions};
pub use error::{CliError, CliResult};
#[allow(unused_imports)]
pub use reader::{ReadSpec, Row, RowReader};
#[allow(unused_imports)]
pub use source::{InputPath, STDIO};
pub use table::Table;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::path::PathBuf;

    fn temp_file(tag: &str, contents: &[u8]) -> PathBuf {
        let path = std::env::temp_dir().join(format!(
            "truenorth-io-{tag}-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        std::fs::write(&path, contents).expect("temp dir is writable");
        path
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// What write_csv writes, Table::read reads back exactly (Rust prints the shortest
        /// text that parses back to the same f64).
        #[test]
        fn write_then_read_round_trips(rows in proptest::collection::vec((-1e12f64..1e12, -1e6f64..1e6), 1..50)) {
            let path = temp_file("rt", b"");
            write_csv(&path, &["t_s", "mag_x"], rows.iter().map(|&(a, b)| vec![a, b])).unwrap();
            let t = Table::read(&path, &["t_s", "mag_x"], &["mag_z"]).unwrap();
            prop_assert_eq!(t.len(), rows.len());
            prop_assert!(t.col("mag_z").is_none());
            for (k, &(a, b)) in rows.iter().enumerate() {
                prop_assert_eq!(t.req("t_s").unwrap()[k], a);
                prop_assert_eq!(t.req("mag_x").unwrap()[k], b);
            }
            std::fs::remove_file(&path).ok();
        }

        /// Any bytes at all: a table or a one-line error naming the file, never a panic.
        #[test]
        fn any_file_reads_or_fails_with_one_line(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let path = temp_file("any", &bytes);
            match Table::read(&path, &["t_s"], &["mag_x"]) {
                Ok(t) => prop_assert!(t.req("t_s").unwrap().iter().all(|v| v.is_finite())),
                Err(e) => {
                    let line = e.to_string();
                    prop_assert!(!line.contains('\n'), "{}", line);
                    prop_assert!(line.contains("truenorth-io-any"), "{}", line);
                }
            }
            std::fs::remove_file(&path).ok();
        }
    }
}
