//! What each column of a recording holds: how often it has a reading (the median step of
//! `t_s` between its readings), where it stops for a while, its range and its cells that
//! are not finite numbers — gathered row by row, so that a recording of any length is
//! summarised in the same few kilobytes per column.

use serde::Serialize;

/// A step longer than this many times the column's median step is a gap: a logger that
/// jitters by tens of percent stays below it, a dropped burst of readings does not.
const GAP_FACTOR: f64 = 5.0;

/// The rate is one over the median of a column's first this many steps (a logger's rate
/// is its own from the start; 2¹⁶ steps are over ten minutes at 100 Hz), which bounds the
/// memory a column takes whatever the length of the recording. Gaps are counted over every
/// step against that median.
pub const MEDIAN_STEPS: usize = 1 << 16;

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
    /// Readings per second: one over the median step of `t_s` between readings (over the
    /// first [`MEDIAN_STEPS`]), Hz.
    pub rate_hz: Option<f64>,
    /// Steps longer than `GAP_FACTOR` median steps.
    pub gaps: Gaps,
}

impl ColumnStats {
    /// The summary of column `values` named `name`, read at times `t_s` (same length; rows
    /// whose time is not finite or does not increase give no step).
    pub fn new(name: &str, t_s: &[f64], values: &[f64]) -> Self {
        let mut column = ColumnScan::new(name);
        for (t, v) in t_s.iter().zip(values) {
            column.push(*t, *v);
        }
        column.finish()
    }
}

/// One column's summary as the rows arrive ([`ColumnScan::push`]), in bounded memory.
#[derive(Debug, Clone)]
pub struct ColumnScan {
    name: String,
    readings: usize,
    non_finite: usize,
    min: Option<f64>,
    max: Option<f64>,
    /// The time of the last finite reading.
    last_t_s: Option<f64>,
    /// The first [`MEDIAN_STEPS`] steps, until their median is known.
    first_steps: Vec<f64>,
    median_dt: Option<f64>,
    gaps: usize,
    /// The longest step and the time at its end.
    largest: Option<(f64, f64)>,
}

impl ColumnScan {
    /// An empty summary of the column named `name`.
    pub fn new(name: &str) -> Self {
        Self {
            name: name.to_string(),
            readings: 0,
            non_finite: 0,
            min: None,
            max: None,
            last_t_s: None,
            first_steps: Vec::new(),
            median_dt: None,
            gaps: 0,
            largest: None,
        }
    }

    /// Takes the next row: its time `t_s` and the column's cell `value` (NaN when empty).
    pub fn push(&mut self, t_s: f64, value: f64) {
        if !value.is_finite() {
            self.non_finite += 1;
            return;
        }
        self.readings += 1;
        self.min = Some(self.min.map_or(value, |m| m.min(value)));
        self.max = Some(self.max.map_or(value, |m| m.max(value)));
        let step = self.last_t_s.map(|last| t_s - last);
        self.last_t_s = Some(t_s);
        let Some(dt) = step.filter(|dt| dt.is_finite() && *dt > 0.0) else {
            return;
        };
        if self.largest.is_none_or(|(largest, _)| dt > largest) {
            self.largest = Some((dt, t_s));
        }
        match self.median_dt {
            Some(median) => self.gaps += usize::from(dt > GAP_FACTOR * median),
            None => {
                self.first_steps.push(dt);
                if self.first_steps.len() == MEDIAN_STEPS {
                    self.settle_median();
                }
            }
        }
    }

    /// Fixes the median step from the steps held, counts their gaps and lets them go.
    fn settle_median(&mut self) {
        let mut steps = std::mem::take(&mut self.first_steps);
        self.median_dt = truenorth::checks::median(&mut steps);
        if let Some(median) = self.median_dt {
            self.gaps += steps.iter().filter(|dt| **dt > GAP_FACTOR * median).count();
        }
    }

    /// The summary of every row pushed.
    pub fn finish(mut self) -> ColumnStats {
        if self.median_dt.is_none() {
            self.settle_median();
        }
        ColumnStats {
            name: self.name,
            readings: self.readings,
            non_finite: self.non_finite,
            min: self.min,
            max: self.max,
            rate_hz: self.median_dt.map(f64::recip),
            gaps: Gaps {
                count: self.gaps,
                largest_s: self.largest.map(|l| l.0),
                largest_at_t_s: self.largest.map(|l| l.1),
            },
        }
    }
}

/// Counts the rows whose `t_s` does not come after the previous row's (the commands
/// refuse them), row by row.
#[derive(Debug, Clone, Default)]
pub struct TimeOrder {
    last_t_s: Option<f64>,
    /// Rows so far whose time does not come after the previous row's.
    pub not_increasing: usize,
}

impl TimeOrder {
    /// Takes the next row's time.
    pub fn push(&mut self, t_s: f64) {
        if let Some(last) = self.last_t_s {
            let later = t_s.partial_cmp(&last) == Some(std::cmp::Ordering::Greater);
            self.not_increasing += usize::from(!later);
        }
        self.last_t_s = Some(t_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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
        let mut order = TimeOrder::default();
        for t in [0.0, 1.0, 1.0, 0.5, 2.0] {
            order.push(t);
        }
        assert_eq!(order.not_increasing, 2);
    }

    /// A column longer than the steps its median is taken over: the rate of its start,
    /// every gap counted, the largest one found wherever it is.
    #[test]
    fn a_long_column_counts_every_gap() {
        let n = MEDIAN_STEPS * 3;
        let mut t = 0.0;
        let mut scan = ColumnScan::new("gyr_z");
        for k in 0..n {
            t += if k % 10_000 == 9_999 { 0.5 } else { 0.01 };
            if k == n - 5 {
                t += 7.0;
            }
            scan.push(t, 1.0);
        }
        let s = scan.finish();
        assert!((s.rate_hz.unwrap() - 100.0).abs() < 1e-6);
        assert_eq!(s.gaps.count, n / 10_000 + 1);
        assert!((s.gaps.largest_s.unwrap() - 7.01).abs() < 1e-9);
    }

    proptest! {
        /// Below [`MEDIAN_STEPS`] the streamed summary is the whole column's: counts add
        /// up, the range holds every finite reading, the rate is one over the median step.
        #[test]
        fn the_streamed_summary_is_the_whole_columns(
            steps in proptest::collection::vec(0.001f64..1.0, 1..400),
            values in proptest::collection::vec(
                prop_oneof![4 => -50.0f64..50.0, 1 => Just(f64::NAN)], 400),
        ) {
            let t: Vec<f64> = steps.iter().scan(0.0, |t, dt| { *t += dt; Some(*t) }).collect();
            let v = &values[..t.len()];
            let s = ColumnStats::new("x", &t, v);
            let finite: Vec<(f64, f64)> =
                t.iter().zip(v).filter(|p| p.1.is_finite()).map(|(a, b)| (*a, *b)).collect();
            prop_assert_eq!(s.readings + s.non_finite, t.len());
            prop_assert_eq!(s.readings, finite.len());
            for (_, x) in &finite {
                prop_assert!(s.min.unwrap() <= *x && *x <= s.max.unwrap());
            }
            let mut dts: Vec<f64> = finite.windows(2).map(|w| w[1].0 - w[0].0).collect();
            let median = truenorth::checks::median(&mut dts);
            prop_assert_eq!(s.rate_hz, median.map(f64::recip));
        }
    }
}
