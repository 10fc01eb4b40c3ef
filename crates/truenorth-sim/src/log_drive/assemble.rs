//! The readings of every sensor laid out in rows: each on a row of its own at its stamp, or
//! on the rows a logger writes at its own rate.

use truenorth_core::{NoiseSource, SplitMix64};

use super::gnss_truth::GnssTruth;
use super::row::{LogRow, Measured};
use super::streams::Slot;
use super::timing::{RowLayout, Timed, TimingConfig, log_clock, rounded};

/// The rows (their stamps in the truth's time, and as written on the log's clock) and when
/// each of their readings was measured. Rows stamped after `duration_s` (the truth's end)
/// are dropped. `streams` are each sensor's readings in time order.
pub(crate) fn assemble(
    streams: Vec<Vec<Timed<Slot>>>,
    timing: &TimingConfig,
    rng: &mut SplitMix64,
    duration_s: f64,
) -> (Vec<f64>, Vec<LogRow>, Vec<Measured>) {
    let (start, res) = (timing.start_s, timing.stamp_resolution_s);
    let mut all: Vec<Timed<Slot>> = match timing.rows {
        RowLayout::Separate => streams.into_iter().flatten().collect(),
        RowLayout::Logger { rate_hz } => {
            let phase = rng.uniform() / rate_hz;
            streams
                .into_iter()
                .flat_map(|s| on_logger_ticks(s, phase, rate_hz, start, res))
                .collect()
        }
    };
    // A stable sort keeps each sensor's readings in order and the sensors in a fixed order
    // at one stamp.
    all.sort_by(|a, b| a.stamp_s.total_cmp(&b.stamp_s));
    let (mut times, mut rows, mut measured) = (Vec::new(), Vec::<LogRow>::new(), Vec::new());
    for r in all.into_iter().filter(|r| r.stamp_s <= duration_s) {
        if times.last() != Some(&r.stamp_s) {
            times.push(r.stamp_s);
            rows.push(LogRow::at(start + r.stamp_s));
            measured.push(Measured::default());
        }
        let (Some(row), Some(m)) = (rows.last_mut(), measured.last_mut()) else {
            continue;
        };
        let at = Some(start + r.measured_s);
        match r.value {
            Slot::Odometry(o, factor) => {
                row.odometry = Some(o);
                m.odometry_s = at;
                m.turn_factor = Some(factor);
            }
            Slot::Gyro(g, bias) => {
                row.gyr_z_rps = Some(g);
                m.gyro_s = at;
                m.gyro_bias_rps = Some(bias);
            }
            Slot::Compass(c, tilt) => {
                row.mag = Some(c);
                m.compass_s = at;
                m.compass_tilt_rad = tilt;
            }
            Slot::Gnss(fix, truth) => {
                row.gnss = Some(fix);
                m.gnss = Some(GnssTruth {
                    epoch_s: start + truth.epoch_s,
                    ..truth
                });
            }
        }
    }
    for (row, t) in rows.iter_mut().zip(&times) {
        row.t_s = log_clock(*t, start, res);
    }
    (times, rows, measured)
}

/// One sensor's readings as a logger writes them: on the first of its ticks at or after
/// each reading's arrival, the newest reading of a tick winning.
fn on_logger_ticks(
    stream: Vec<Timed<Slot>>,
    phase: f64,
    rate_hz: f64,
    start: f64,
    res: f64,
) -> Vec<Timed<Slot>> {
    let mut out: Vec<Timed<Slot>> = Vec::with_capacity(stream.len());
    for r in stream {
        let tick = ((r.stamp_s - phase) * rate_hz).ceil().max(0.0);
        let stamp = rounded(phase + tick / rate_hz, start, res);
        match out.last_mut() {
            Some(last) if last.stamp_s == stamp => {
                *last = Timed {
                    stamp_s: stamp,
                    ..r
                }
            }
            _ => out.push(Timed {
                stamp_s: stamp,
                ..r
            }),
        }
    }
    out
}
