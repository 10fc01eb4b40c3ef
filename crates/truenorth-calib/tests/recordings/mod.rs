//! Reading the shared real recordings (../shared/data, see its README), and the rule by
//! which the README's figures measured on them are asserted.

// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The shared recording folder `name`: `None` (after a printed skip reason) when it is
/// absent on a developer's machine; a failure when it is absent under CI.
pub fn recording(name: &str) -> Option<PathBuf> {
    truenorth_sim::shared_data::folder(name).unwrap_or_else(|e| panic!("{e}"))
}

/// The magnetometer readings of one sunsided recording (`rec`: `full-sphere`, `x-axis`, …):
/// `None` as [`recording`] says.
pub fn sunsided_mag(rec: &str) -> Option<Vec<nalgebra::Vector3<f64>>> {
    let p = recording("magcal_sunsided_mpu6050_hmc5883l")?
        .join(rec)
        .join("mag.csv.gz");
    Some(
        read_rows(&p)
            .iter()
            .map(|r| nalgebra::Vector3::new(r[1], r[2], r[3]))
            .collect(),
    )
}

/// Rows of a CSV file (optionally gzipped, read through the system's `gzip`), header
/// skipped. The folder is present (see [`recording`]), so a file in it that cannot be read
/// is a failure, not a skip.
pub fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = if path.extension().is_some_and(|e| e == "gz") {
        let o = Command::new("gzip")
            .arg("-dc")
            .arg(path)
            .output()
            .unwrap_or_else(|e| panic!("cannot run gzip on {}: {e}", path.display()));
        assert!(o.status.success(), "cannot decompress {}", path.display());
        String::from_utf8(o.stdout).expect("the recording is UTF-8 text")
    } else {
        std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
    };
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter_map(|l| {
            let cells: Option<Vec<f64>> = l
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|c| !c.is_empty())
                .map(|c| c.parse().ok())
                .collect();
            cells.filter(|c| !c.is_empty())
        })
        .collect();
    rows
}

/// Asserts a figure the README quotes: `measured` may not exceed the README's `quoted`
/// value by more than the half unit of its last printed digit (`half_unit`) plus the
/// spread of the statistic itself. Every figure asserted this way is a root mean square
/// (of an angle difference, or of |B| about its mean) over `n` readings; with independent
/// readings the sampling standard deviation of an RMS is RMS/√(2n) (the χ² of n degrees of
/// freedom has variance 2n, and √ halves the relative spread), so 3·RMS/√(2n) covers a
/// change of method that leaves the result statistically as good. The figures may improve
/// without limit (the README's rule is "unchanged or better").
pub fn readme_figure(what: &str, measured: f64, quoted: f64, half_unit: f64, n: usize) {
    let limit = quoted * (1.0 + 3.0 / (2.0 * n as f64).sqrt()) + half_unit;
    assert!(
        measured <= limit,
        "{what}: {measured} exceeds the README's {quoted} (limit {limit})"
    );
}

/// Standard deviation of the values divided by their mean.
pub fn rel_std(v: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = v.clone().count() as f64;
    let mean = v.clone().sum::<f64>() / n;
    let var = v.map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    var.sqrt() / mean
}
