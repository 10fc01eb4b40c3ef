//! Numeric CSV tables of real recordings, and the interpolation and integration their
//! comparisons need.

use std::path::Path;

/// A CSV file of numbers with a header row.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| {
                l.split(',')
                    .map(|v| v.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        Self { header, rows }
    }

    pub fn col(&self, name: &str) -> Vec<f64> {
        let i = self
            .header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[i]).collect()
    }
}

/// Linear interpolation of `y(x)` at `t` (`x` increasing), held at the ends.
pub fn interp(x: &[f64], y: &[f64], t: f64) -> f64 {
    let k = x.partition_point(|&v| v < t);
    if k == 0 {
        return y[0];
    }
    if k == x.len() {
        return y[k - 1];
    }
    let f = (t - x[k - 1]) / (x[k] - x[k - 1]);
    y[k - 1] + f * (y[k] - y[k - 1])
}

/// Cumulative trapezoid integral of `v(t)`.
pub fn integrate(t: &[f64], v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; t.len()];
    for k in 1..t.len() {
        out[k] = out[k - 1] + 0.5 * (v[k] + v[k - 1]) * (t[k] - t[k - 1]);
    }
    out
}
