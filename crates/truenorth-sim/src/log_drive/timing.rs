//! When each sensor measures and when its readings reach the log: its own rate and phase, a
//! latency (the row is stamped later than the motion it measured), the logger's arrival
//! jitter, lost readings, and timestamps of a finite resolution.
//!
//! Real logs stamp a reading when it arrives, not when it was measured: a CAN wheel speed
//! has passed the ABS unit's filter and the bus, a motor controller's counts its loop and a
//! serial link, so wheels commonly arrive 50–150 ms after a yaw gyro that measured the same
//! instant. A CAN bus sends its signals at 5–50 Hz and loses or delays a frame now and then
//! (a real car log at 5 Hz has 0.3 s steps in one row of fifteen).

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SplitMix64, check_range};

use super::span::Span;

/// How one sensor's readings are timed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorTiming {
    /// Readings per second, Hz, drawn log-uniformly per drive (0.1–1000).
    pub rate_hz: Span,
    /// From the instant measured to the row's stamp, s, drawn uniformly per drive (0–10).
    pub latency_s: Span,
    /// Each reading arrives a further uniform `[0, jitter_s)` late, s (0–10).
    pub jitter_s: f64,
    /// Share of readings the log loses, drawn uniformly per drive (0–0.5).
    pub drop_probability: Span,
}

impl SensorTiming {
    /// A sensor at `rate_hz` Hz whose rows are stamped `latency_s` s after the instant it
    /// measured, with 5 ms of arrival jitter and up to 2 % of its readings lost.
    pub const fn at(rate_hz: Span, latency_s: Span) -> Self {
        Self {
            rate_hz,
            latency_s,
            jitter_s: 0.005,
            drop_probability: Span::new(0.0, 0.02),
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.rate_hz.check("sensor rate_hz", 0.1, 1000.0)?;
        self.latency_s.check("sensor latency_s", 0.0, 10.0)?;
        check_range("sensor jitter_s", self.jitter_s, 0.0, 10.0)?;
        self.drop_probability
            .check("sensor drop_probability", 0.0, 0.5)?;
        Ok(())
    }
}

/// How readings are laid out in rows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum RowLayout {
    /// Each reading on a row of its own, stamped when it arrived (readings that arrive at
    /// the same stamp share a row).
    Separate,
    /// A logger that writes a row at its own rate, Hz (0.1–1000), carrying each sensor's
    /// newest reading that arrived since its previous row; rows it has nothing for are
    /// not written.
    Logger {
        /// Rows per second, Hz.
        rate_hz: f64,
    },
}

/// The timing of every sensor and the layout of the log (defaults per vehicle kind in
/// [`TimingConfig::for_car`] and [`TimingConfig::for_robot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TimingConfig {
    /// The yaw-rate gyro.
    pub gyro: SensorTiming,
    /// The odometry (speeds, distances).
    pub odometry: SensorTiming,
    /// The compass.
    pub compass: SensorTiming,
    /// How the readings are laid out in rows ([`RowLayout::Separate`]).
    pub rows: RowLayout,
    /// Every sensor measures on the odometry's clock, at its rate and instants (false):
    /// with no latency either, each instant's readings share a row, as in a simulator that
    /// samples every sensor together.
    pub common_clock: bool,
    /// Resolution of the timestamps, s (0.001; 1e-6–1): stamps are whole multiples of it.
    pub stamp_resolution_s: f64,
    /// The log's clock at the instant the truth starts, s (0; 0–1e10: a log may count
    /// from its Unix time).
    pub start_s: f64,
}

impl Default for TimingConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl TimingConfig {
    /// A car: the ESP's yaw rate and the odometry on a CAN bus at 5–50 Hz, the odometry
    /// 70–150 ms behind the motion and the yaw rate 0–20 ms (so 50–150 ms between them), a
    /// compass at 5–20 Hz up to 50 ms late.
    pub const fn for_car() -> Self {
        Self {
            gyro: SensorTiming::at(Span::new(5.0, 50.0), Span::new(0.0, 0.02)),
            odometry: SensorTiming::at(Span::new(5.0, 50.0), Span::new(0.07, 0.15)),
            compass: SensorTiming::at(Span::new(5.0, 20.0), Span::new(0.0, 0.05)),
            rows: RowLayout::Separate,
            common_clock: false,
            stamp_resolution_s: 0.001,
            start_s: 0.0,
        }
    }

    /// A robot: a MEMS gyro at 20–100 Hz, a motor controller's wheel data at 8–20 Hz
    /// 70–150 ms behind the motion (10 Hz is common), a compass at 5–50 Hz.
    pub const fn for_robot() -> Self {
        Self {
            gyro: SensorTiming::at(Span::new(20.0, 100.0), Span::new(0.0, 0.02)),
            odometry: SensorTiming::at(Span::new(8.0, 20.0), Span::new(0.07, 0.15)),
            compass: SensorTiming::at(Span::new(5.0, 50.0), Span::new(0.0, 0.05)),
            rows: RowLayout::Separate,
            common_clock: false,
            stamp_resolution_s: 0.001,
            start_s: 0.0,
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.gyro.check()?;
        self.odometry.check()?;
        self.compass.check()?;
        if let RowLayout::Logger { rate_hz } = self.rows {
            check_range("logger rate_hz", rate_hz, 0.1, 1000.0)?;
        }
        check_range("stamp_resolution_s", self.stamp_resolution_s, 1e-6, 1.0)?;
        check_range("start_s", self.start_s, 0.0, 1e10)?;
        Ok(())
    }
}

/// One sensor's clock as drawn for a drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    /// Readings per second, Hz.
    pub rate_hz: f64,
    /// The first instant measured, s after the truth starts (within one period).
    pub phase_s: f64,
    /// From the instant measured to the stamp, s.
    pub latency_s: f64,
    /// Arrival jitter, s (each reading a uniform `[0, jitter_s)` later still).
    pub jitter_s: f64,
    /// Share of readings lost.
    pub drop_probability: f64,
}

impl Clock {
    /// A clock drawn from `timing`.
    pub fn draw(timing: &SensorTiming, rng: &mut SplitMix64) -> Self {
        let rate_hz = timing.rate_hz.draw_log(rng);
        Self {
            rate_hz,
            phase_s: rng.uniform() / rate_hz,
            latency_s: timing.latency_s.draw(rng),
            jitter_s: timing.jitter_s,
            drop_probability: timing.drop_probability.draw(rng),
        }
    }

    /// The instants the sensor measures (the odometry: sends) at whose readings can arrive by `end_s` (the truth's
    /// end), s after the truth starts.
    pub fn instants(&self, end_s: f64) -> Vec<f64> {
        let last = end_s - self.latency_s - self.jitter_s;
        let period = 1.0 / self.rate_hz;
        (0..)
            .map(|k| self.phase_s + k as f64 * period)
            .take_while(|&t| t <= last)
            .collect()
    }

    /// When a reading sent at `t_s` arrives, and whether the log keeps it.
    pub(crate) fn arrival(&self, t_s: f64, rng: &mut SplitMix64) -> (f64, bool) {
        let at = t_s + self.latency_s + self.jitter_s * rng.uniform();
        (at, rng.uniform() >= self.drop_probability)
    }
}

/// A reading with the instant it measured and the stamp it arrived with, s after the
/// truth starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Timed<T> {
    pub measured_s: f64,
    pub stamp_s: f64,
    pub value: T,
}

/// The stamp on the log's clock (`start` at the truth's start) nearest to `t` (the truth's
/// time) that is a whole multiple of `resolution`, written as a logger writes it: a count of
/// milliseconds divided by 1000 reads back as `0.026`, not `0.026000000000000002`.
pub(crate) fn log_clock(t: f64, start: f64, resolution: f64) -> f64 {
    let n = ((start + t) / resolution).round();
    let per_s = (1.0 / resolution).round();
    if (per_s * resolution - 1.0).abs() < 1e-12 {
        n / per_s
    } else {
        n * resolution
    }
}

/// [`log_clock`] as the truth's time.
pub(crate) fn rounded(t: f64, start: f64, resolution: f64) -> f64 {
    log_clock(t, start, resolution) - start
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clock_reads_at_its_rate_and_its_readings_arrive_late_by_its_latency() {
        let mut rng = SplitMix64::new(3);
        let timing = SensorTiming::at(Span::fixed(30.0), Span::fixed(0.1));
        let c = Clock::draw(&timing, &mut rng);
        let t = c.instants(10.0);
        assert!(t[0] >= 0.0 && t[0] < 1.0 / 30.0);
        assert!(
            t.windows(2)
                .all(|w| ((w[1] - w[0]) * 30.0 - 1.0).abs() < 1e-9)
        );
        assert!(*t.last().unwrap() <= 10.0 - 0.1 - 0.005);
        for &m in &t {
            let (at, _) = c.arrival(m, &mut rng);
            assert!(at - m >= 0.1 && at - m < 0.105);
        }
    }

    #[test]
    fn stamps_are_written_as_loggers_write_them() {
        assert_eq!(log_clock(0.0261, 0.0, 0.001), 0.026);
        assert_eq!(log_clock(0.2079, 0.0, 0.001).to_string(), "0.208");
        assert_eq!(log_clock(0.3, 1.7e9, 0.01), 1_700_000_000.3);
        assert_eq!(log_clock(0.26, 0.0, 0.25), 0.25);
    }

    #[test]
    fn defaults_are_valid_and_bad_timings_are_refused() {
        assert!(TimingConfig::for_car().check().is_ok());
        assert!(TimingConfig::for_robot().check().is_ok());
        let mut bad = TimingConfig::for_car();
        bad.gyro.rate_hz = Span::fixed(0.0);
        assert!(bad.check().is_err());
        let mut bad = TimingConfig::for_car();
        bad.rows = RowLayout::Logger { rate_hz: f64::NAN };
        assert!(bad.check().is_err());
        let mut bad = TimingConfig::for_car();
        bad.stamp_resolution_s = 0.0;
        assert!(bad.check().is_err());
    }
}
