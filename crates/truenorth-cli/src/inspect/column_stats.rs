//! What each column of a recording holds: how often it has a reading (the median step of
//! `t_s` between its readings), where it stops for a while, its range and its cells that
//! are not finite numbers.

use serde::Serialize;

/// A step longer than this many times the column's median step is a gap: a logger that
/// jitters by tens of percent stays below it, a dropped burst of readings does not.
const GAP_FACTOR: f64 = 5.0;

/// Where a column stops for longer than usual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gaps {
    /// How many steps are gaps.
    pub count: usize,
    /// The longest step, s.
    pub largest_s: Option<f64>,
    /// The `t_s` at which the longest step ends.
    pub largest_at_t_s: Option<f64>,
}

/// The summary of one column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ColumnStats {
    /// The name truenorth reads it as (`gyr_x`, ...; body axes).
    pub name: String,
    /// Rows with a finite reading.
    pub readings: usize,
    /// Rows whose cell is empty or not finite.
    pub non_finite: usize,
    /// Smallest finite reading.
    pub min: Option<f64>,
    /// Largest finite reading.
    pub max: Option<f64>,
    /// Readings per second: one over the median step of `t_s` between readings, Hz.
    pub rate_hz: Option<f64>,
    /// Steps longer than `GAP_FACTOR` median steps.
    pub gaps: Gaps,
}

impl ColumnStats {
    /// The summary of column `values` named `name`, read at times `t_s` (same length; rows
    /// whose time is not finite or does not increase give no step).
    pub fn new(name: &str, t_s: &[f64], values: &[f64]) -> Self {
        let finite: Vec<(f64, f64)> = t_s
            .iter()
            .zip(values)
            .filter(|(_, v)| v.is_finite())
            .map(|(t, v)| (*t, *v))
            .collect();
        let range = |pick: fn(f64, f64) -> f64| finite.iter().map(|p| p.1).reduce(pick);
        let steps: Vec<(f64, f64)> = finite
            .windows(2)
            .map(|w| (w[1].0 - w[0].0, w[1].0))
            .filter(|(dt, _)| dt.is_finite() && *dt > 0.0)
            .collect();
        let mut dts: Vec<f64> = steps.iter().map(|s| s.0).collect();
        let median_dt = truenorth::checks::median(&mut dts);
        Self {
            name: name.to_string(),
            readings: finite.len(),
            non_finite: values.len() - finite.len(),
            min: range(f64::min),
            max: range(f64::max),
            rate_hz: median_dt.map(f64::recip),
            gaps: gaps(&steps, median_dt),
        }
    }
}

/// The gaps among `steps` (step, time at its end) given the median step.
fn gaps(steps: &[(f64, f64)], median_dt: Option<f64>) -> Gaps {
    let largest = steps
        .iter()
        .copied()
        .reduce(|a, b| if b.0 > a.0 { b } else { a });
    Gaps {
        count: median_dt.map_or(0, |m| steps.iter().filter(|s| s.0 > GAP_FACTOR * m).count()),
        largest_s: largest.map(|s| s.0),
        largest_at_t_s: largest.map(|s| s.1),
    }
}

/// Rows whose `t_s` does not come after the previous row's (the commands refuse them).
pub fn time_not_increasing(t_s: &[f64]) -> usize {
    t_s.windows(2)
        .filter(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_gap_range_and_holes() {
        let t: Vec<f64> = (0..100)
            .map(|k| {
                if k < 50 {
                    k as f64 * 0.01
                } else {
                    1.0 + k as f64 * 0.01
                }
            })
            .collect();
        let mut v: Vec<f64> = (0..100).map(f64::from).collect();
        v[3] = f64::NAN;
        v[4] = f64::INFINITY;
        let s = ColumnStats::new("gyr_x", &t, &v);
        assert_eq!((s.readings, s.non_finite), (98, 2));
        assert_eq!((s.min, s.max), (Some(0.0), Some(99.0)));
        assert!((s.rate_hz.unwrap() - 100.0).abs() < 1e-6);
        assert_eq!(s.gaps.count, 1);
        assert!((s.gaps.largest_s.unwrap() - 1.01).abs() < 1e-9);
        assert!((s.gaps.largest_at_t_s.unwrap() - 1.5).abs() < 1e-9);
        assert_eq!(time_not_increasing(&[0.0, 1.0, 1.0, 0.5, 2.0]), 2);
    }
}
