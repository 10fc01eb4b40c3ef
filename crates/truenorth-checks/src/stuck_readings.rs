//! Readings a live sensor cannot give: an axis that repeats one value to the last bit for a
//! run of readings while it changes from each reading to the next everywhere else (clipped
//! at its full scale, or frozen: a stalled driver repeating its last value), and a
//! magnetometer that reads exactly zero on every axis (no place on Earth has no field: a
//! placeholder for a missing reading). Taken as motion, they turn an estimate by tens of
//! degrees without a word; found, they are the row to look at.
//!
//! The rule is statistical and needs no full-scale value or noise figure: where an axis's
//! readings differ from the previous one on at least [`LIVE_SHARE`] of the steps, the chance
//! that noise alone repeats a value on [`RUN_READINGS`] readings in a row is at most
//! `(1 − LIVE_SHARE)^(RUN_READINGS − 1)` = 0.2¹⁹ ≈ 5·10⁻¹⁴. A sensor whose readings repeat
//! often anyway (printed with few decimals, held between slower samples, quantized coarser
//! than its noise) is not judged: a run there is not evidence; nor is a run of exactly zero
//! (a dead band at rest; a sensor frozen at zero goes unseen).

use std::fmt;

/// Readings in a row, all the same to the last bit, that make a run suspect.
pub const RUN_READINGS: usize = 20;

/// The share of steps (outside the run) on which a live axis's reading changes: below it
/// the axis repeats values by nature and a run is no evidence.
pub const LIVE_SHARE: f64 = 0.8;

/// Steps an axis must have shown (outside the run) before its share of changes is trusted.
pub const MIN_STEPS: usize = 200;

/// What is wrong with the readings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StuckKind {
    /// One value repeated at the largest magnitude the axis has read: clipped at its range.
    Clipped,
    /// One value repeated inside the axis's range: the sensor stopped updating.
    Frozen,
    /// Every axis exactly zero (a magnetometer: no Earth field is zero).
    ZeroField,
}

/// A run of readings a live sensor cannot give.
#[derive(Debug, Clone, PartialEq)]
pub struct StuckRun {
    /// What it looks like.
    pub kind: StuckKind,
    /// The axis (0 = x, 1 = y, 2 = z); `None` for a zero field (every axis).
    pub axis: Option<usize>,
    /// The value repeated, in the file's unit.
    pub value: f64,
    /// Readings in the run.
    pub readings: usize,
    /// The input row (1-based, a header is row 1) of its first reading.
    pub from_row: usize,
    /// The time of its first and last readings, s (NaN where the input has none).
    pub t_s: (f64, f64),
    /// The share of the axis's other steps on which its reading changed.
    pub live_share: f64,
}

impl fmt::Display for StuckRun {
    /// The evidence, e.g. "gyro y read 0.5 on 312 readings in a row from row 1204 (t_s
    /// 12.03–15.14) where it changes on 99 % of its other steps".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let axis = self
            .axis
            .map_or("every axis", |a| ["x", "y", "z"][a.min(2)]);
        match self.kind {
            StuckKind::ZeroField => write!(
                f,
                "{axis} read exactly 0 on {} readings from row {} (t_s {}–{}): no place on Earth has no magnetic field",
                self.readings, self.from_row, self.t_s.0, self.t_s.1
            ),
            _ => write!(
                f,
                "{axis} read {} on {} readings in a row from row {} (t_s {}–{}) where it changes on {:.0} % of its other steps",
                self.value,
                self.readings,
                self.from_row,
                self.t_s.0,
                self.t_s.1,
                100.0 * self.live_share
            ),
        }
    }
}

impl StuckRun {
    /// What it means and what to do, in words.
    pub fn advice(&self) -> &'static str {
        match self.kind {
            StuckKind::Clipped => {
                "the sensor is clipped at its range: the motion went beyond it; record with a larger full-scale range, or leave those rows out"
            }
            StuckKind::Frozen => {
                "the sensor stopped updating (a stalled driver or bus repeating its last value): leave those rows' cells empty or cut them"
            }
            StuckKind::ZeroField => {
                "those are placeholders for missing readings: leave their cells empty"
            }
        }
    }
}

/// One axis's current run and its history.
#[derive(Debug, Clone, Copy, Default)]
struct Axis {
    last: Option<u64>,
    run: usize,
    run_row: usize,
    run_t_s: f64,
    last_t_s: f64,
    /// Steps outside runs of [`RUN_READINGS`] or more (the habit a run is judged against).
    steps: usize,
    /// Of those, the steps on which the reading changed.
    changes: usize,
    /// The largest magnitude read outside the current run.
    largest: f64,
}

/// Streams a `D`-axis sensor's readings and gives the first run no live sensor gives
/// ([`StuckReadings::push`], then [`StuckReadings::finish`] for a run still going).
#[derive(Debug, Clone)]
pub struct StuckReadings<const D: usize> {
    axes: [Axis; D],
    /// Whether a reading of zero on every axis is impossible (a magnetometer).
    never_zero: bool,
    zero: Option<(usize, f64, f64, usize)>,
    found: usize,
}

impl<const D: usize> StuckReadings<D> {
    /// A check of a sensor whose readings may be zero (a gyro, an accelerometer).
    pub fn new() -> Self {
        Self {
            axes: [Axis::default(); D],
            never_zero: false,
            zero: None,
            found: 0,
        }
    }

    /// A check of a magnetometer: a reading of exactly zero on every axis is a fault too.
    pub fn magnetometer() -> Self {
        Self {
            never_zero: true,
            ..Self::new()
        }
    }

    /// Runs found so far.
    pub fn found(&self) -> usize {
        self.found
    }

    /// Takes the reading `v` of input row `row` at `t_s`; a reading with a non-finite axis
    /// is skipped. Returns a run that has just ended, when it is one no live sensor gives.
    pub fn push(&mut self, row: usize, t_s: f64, v: &[f64; D]) -> Option<StuckRun> {
        if v.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut out = self.zero_field(row, t_s, v);
        for (i, x) in v.iter().enumerate() {
            let axis = &mut self.axes[i];
            let bits = x.to_bits();
            if axis.last == Some(bits) {
                axis.run += 1;
            } else {
                let ended = judge(axis, i, f64::from_bits(axis.last.unwrap_or(0)));
                if axis.last.is_some() {
                    axis.end_run();
                    axis.steps += 1;
                    axis.changes += 1;
                    axis.largest = axis
                        .largest
                        .max(f64::from_bits(axis.last.unwrap_or(0)).abs());
                }
                axis.last = Some(bits);
                axis.run = 1;
                axis.run_row = row;
                axis.run_t_s = t_s;
                if out.is_none() {
                    out = ended;
                }
            }
            axis.last_t_s = t_s;
        }
        self.found += usize::from(out.is_some());
        out
    }

    /// A run still going at the end of the readings, when it is one no live sensor gives.
    pub fn finish(&mut self) -> Option<StuckRun> {
        let mut out = self.zero.take().map(zero_run);
        for i in 0..D {
            let axis = &mut self.axes[i];
            let value = f64::from_bits(axis.last.unwrap_or(0));
            let ended = judge(axis, i, value);
            axis.run = 0;
            if out.is_none() {
                out = ended;
            }
        }
        self.found += usize::from(out.is_some());
        out
    }

    /// Follows a run of zero fields; gives it when it ends.
    fn zero_field(&mut self, row: usize, t_s: f64, v: &[f64; D]) -> Option<StuckRun> {
        if !self.never_zero {
            return None;
        }
        if v.iter().all(|x| *x == 0.0) {
            let z = self.zero.get_or_insert((row, t_s, t_s, 0));
            z.2 = t_s;
            z.3 += 1;
            None
        } else {
            self.zero.take().map(zero_run)
        }
    }
}

impl<const D: usize> Default for StuckReadings<D> {
    fn default() -> Self {
        Self::new()
    }
}

/// A run of zero fields as a finding (one zero reading is enough: no field is zero).
fn zero_run((row, from, to, readings): (usize, f64, f64, usize)) -> StuckRun {
    StuckRun {
        kind: StuckKind::ZeroField,
        axis: None,
        value: 0.0,
        readings,
        from_row: row,
        t_s: (from, to),
        live_share: f64::NAN,
    }
}

impl Axis {
    /// Counts the repeats of a run that has ended among the axis's habit, unless the run is
    /// long enough to be judged: those are not the habit.
    fn end_run(&mut self) {
        if self.run < RUN_READINGS {
            self.steps += self.run.saturating_sub(1);
        }
    }
}

/// The axis's run that has ended, when no live sensor gives it.
fn judge(axis: &Axis, i: usize, value: f64) -> Option<StuckRun> {
    // Exactly zero is what a driver's dead band or a car's bus gives at rest, between
    // readings that change in motion: not evidence of a fault (a magnetometer's zero
    // field is, on every axis at once: `zero_field`).
    if axis.run < RUN_READINGS || axis.steps < MIN_STEPS || value == 0.0 {
        return None;
    }
    let live_share = axis.changes as f64 / axis.steps as f64;
    if live_share < LIVE_SHARE {
        return None;
    }
    Some(StuckRun {
        kind: if value.abs() >= axis.largest {
            StuckKind::Clipped
        } else {
            StuckKind::Frozen
        },
        axis: Some(i),
        value,
        readings: axis.run,
        from_row: axis.run_row,
        t_s: (axis.run_t_s, axis.last_t_s),
        live_share,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A noisy turning gyro axis: a different value on nearly every reading.
    fn rate(k: usize) -> f64 {
        0.8 * (k as f64 * 0.01).sin() + 1e-3 * ((k as f64 * 12.9898).sin() * 43_758.545).fract()
    }

    fn run_all<const D: usize>(check: &mut StuckReadings<D>, rows: &[[f64; D]]) -> Vec<StuckRun> {
        let mut found: Vec<StuckRun> = rows
            .iter()
            .enumerate()
            .filter_map(|(k, v)| check.push(k + 2, k as f64 * 0.01, v))
            .collect();
        found.extend(check.finish());
        found
    }

    #[test]
    fn a_clipped_axis_is_found_at_its_row() {
        let rows: Vec<[f64; 3]> = (0..2000)
            .map(|k| [rate(k + 7), rate(k).clamp(-0.5, 0.5), rate(k + 3)])
            .collect();
        let found = run_all(&mut StuckReadings::new(), &rows);
        assert!(!found.is_empty());
        let first = &found[0];
        // The first plateau (k = 68–246, where 0.8 sin(0.01 k) > 0.5) comes before the
        // axis has shown its habit; the second, at −0.5, is found where it starts
        // (sin(0.01 k) < −0.625 from k = 382: row k + 2).
        assert_eq!(
            (first.kind, first.axis, first.value),
            (StuckKind::Clipped, Some(1), -0.5)
        );
        assert_eq!(first.from_row, 384);
        assert!(first.to_string().contains("y read -0.5"), "{first}");
    }

    #[test]
    fn a_frozen_sensor_is_found() {
        let rows: Vec<[f64; 3]> = (0..2000)
            .map(|k| {
                let k = if (800..1300).contains(&k) { 800 } else { k };
                [rate(k), rate(k + 1), rate(k + 2)]
            })
            .collect();
        let found = run_all(&mut StuckReadings::new(), &rows);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].kind, StuckKind::Frozen);
        assert_eq!((found[0].readings, found[0].from_row), (500, 802));
    }

    #[test]
    fn zero_fields_are_found_and_a_zero_rate_is_not() {
        let rows: Vec<[f64; 2]> = (0..1000)
            .map(|k| {
                if (400..600).contains(&k) {
                    [0.0; 2]
                } else {
                    [20.0 + rate(k), rate(k + 5)]
                }
            })
            .collect();
        let found = run_all(&mut StuckReadings::magnetometer(), &rows);
        assert_eq!(found[0].kind, StuckKind::ZeroField);
        assert_eq!(found[0].readings, 200);
        // One zero reading on a gyro's axes is rest, not a fault.
        let rows = [[0.0, 0.0]; 5];
        assert!(run_all(&mut StuckReadings::new(), &rows).is_empty());
    }

    #[test]
    fn values_that_repeat_by_nature_are_no_evidence() {
        // Printed with two decimals: the value repeats on most steps.
        let rows: Vec<[f64; 1]> = (0..5000)
            .map(|k| [(rate(k) * 10.0).round() / 10.0])
            .collect();
        assert!(run_all(&mut StuckReadings::new(), &rows).is_empty());
        // A dead band: exactly zero at rest between live stretches.
        let rows: Vec<[f64; 1]> = (0..5000)
            .map(|k| {
                [if (1000..3000).contains(&k) {
                    0.0
                } else {
                    rate(k)
                }]
            })
            .collect();
        assert!(run_all(&mut StuckReadings::new(), &rows).is_empty());
        // Held between a slower sensor's samples: each value on five rows.
        let rows: Vec<[f64; 1]> = (0..5000).map(|k| [rate(k / 5)]).collect();
        assert!(run_all(&mut StuckReadings::new(), &rows).is_empty());
    }

    proptest! {
        /// Any readings at all: no panic, and a live axis (a new value on every reading) never
        /// gives a run.
        #[test]
        fn no_panic_and_no_false_run(
            cells in proptest::collection::vec(
                prop_oneof![6 => -5.0f64..5.0, 1 => Just(0.0), 1 => Just(f64::NAN), 1 => Just(f64::INFINITY)],
                0..900),
            offset in -1e3f64..1e3,
        ) {
            let rows: Vec<[f64; 3]> = cells.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let _ = run_all(&mut StuckReadings::magnetometer(), &rows);
            let live: Vec<[f64; 3]> =
                (0..cells.len()).map(|k| [offset + rate(k), rate(k + 1), rate(k + 2)]).collect();
            prop_assert!(run_all(&mut StuckReadings::new(), &live).is_empty());
        }
    }
}
