//! The report of `truenorth inspect`: the data ([`Report`], serialised as is for `--json`),
//! the options it implies ([`Report::options`]) and the table a person reads.

use std::fmt::Write as _;

use crate::io::checking::shell_word;
use truenorth::core::Fixed;

use serde::Serialize;

use super::column_stats::ColumnStats;
use super::gnss::GnssReport;
use super::sensors::{AccReport, AxesReport, GyroReport, MagReport};
use super::wheels::{VehicleSetReport, WheelReport, YawReport};

/// What `inspect` found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// The file (`<stdin>` for standard input).
    pub file: String,
    /// Data rows.
    pub rows: usize,
    /// The first rows, of `rows`, on which the units, axes and wheels were judged (all of
    /// them up to `truenorth inspect`'s bound of 524,288).
    pub judged_rows: usize,
    /// Rows whose `t_s` does not come after the previous row's.
    pub time_not_increasing: usize,
    /// `t_s` and every sensor column present.
    pub columns: Vec<ColumnStats>,
    /// The accelerometer, if present.
    pub acc: Option<AccReport>,
    /// The gyro, if present.
    pub gyro: Option<GyroReport>,
    /// The magnetometer, if present.
    pub mag: Option<MagReport>,
    /// The odometer wheels, if present.
    pub wheels: Option<WheelReport>,
    /// The yaw gyro against the wheels, if both are present.
    pub yaw: Option<YawReport>,
    /// A drive log's sensor set and what it cannot tell, if the file is one.
    pub vehicle: Option<VehicleSetReport>,
    /// The satellite fixes, if the file has them.
    pub gnss: Option<GnssReport>,
    /// What the physics contradicts beyond the units and the gyro's axes — no unit fits
    /// (the gyro's turns off by a factor no unit gives, an accelerometer that reads no
    /// gravity), or the magnetometer read through a wrong mapping — each with what to do:
    /// `orientation` refuses these.
    pub findings: Vec<String>,
    /// Readings no live sensor gives (clipped, frozen, a zero field), one line a sensor,
    /// over every row: `calibrate`, `heading`, `orientation` and `drive` refuse these.
    pub sensor_faults: Vec<String>,
}

/// The report with the options, as `--json` writes it.
#[derive(Debug, Serialize)]
pub struct JsonReport<'a> {
    /// The report.
    #[serde(flatten)]
    pub report: &'a Report,
    /// [`Report::options`], each as it is written on a shell's command line.
    pub options: Vec<String>,
}

impl Report {
    /// The options that read the recording right, added to those it was inspected with: the
    /// units the data are in (when decided) and the `--column` mapping that reads the gyro
    /// along the other sensors' axes (when it is wrong). Units are given even when they are
    /// the default, so that the line says what was found.
    pub fn options(&self) -> Vec<String> {
        let mut out = Vec::new();
        let gyro_unit = self.gyro.as_ref().and_then(|g| g.likely_unit);
        if let Some(u) = gyro_unit.or(self.yaw.as_ref().and_then(|y| y.likely_unit)) {
            out.push(format!("--gyro-unit {u}"));
        }
        if let Some(u) = self.acc.as_ref().and_then(|a| a.likely_unit) {
            out.push(format!("--acc-unit {u}"));
        }
        // A magnetometer read wrong makes the gyro look wrong against the field: its fix is
        // in `findings`, and the gyro's would make things worse.
        let magnetometer = self
            .findings
            .iter()
            .any(|f| f.contains("magnetometer is mirrored"));
        let gyro_fix = self.axes().filter(|a| a.wrong && !magnetometer);
        if let Some(fix) = gyro_fix.and_then(|a| a.fix.as_ref()) {
            out.push(format!("--column {}", shell_word(fix)));
        } else if let Some(fix) = self.yaw.as_ref().and_then(|y| y.fix.as_ref()) {
            out.push(format!("--column {}", shell_word(fix)));
        }
        out
    }

    fn axes(&self) -> Option<&AxesReport> {
        self.gyro.as_ref()?.axes.as_ref()
    }

    /// The report as a person reads it: the columns' table, one line per sensor, the
    /// options.
    pub fn to_table(&self) -> String {
        let mut s = format!(
            "{}: {} rows{}\n",
            self.file,
            self.rows,
            match self.time_not_increasing {
                0 => String::new(),
                n => format!(", t_s not increasing on {n} rows"),
            }
        );
        self.columns_table(&mut s);
        if self.judged_rows < self.rows {
            let _ = writeln!(
                s,
                "units, axes and wheels judged on the first {} rows of {}",
                self.judged_rows, self.rows
            );
        }
        self.sensor_lines(&mut s);
        let options = self.options();
        if !options.is_empty() {
            let _ = writeln!(s, "options: {}", options.join(" "));
        }
        s
    }

    fn columns_table(&self, s: &mut String) {
        // Wide enough for the longest name (`gnss_course_deg`), so the columns line up.
        let w = self
            .columns
            .iter()
            .map(|c| c.name.len())
            .fold(12, usize::max);
        let _ = writeln!(
            s,
            "{:<w$} {:>8} {:>9} {:>5} {:>10} {:>11} {:>12} {:>12} {:>10}",
            "column",
            "readings",
            "rate_Hz",
            "gaps",
            "largest_s",
            "at_t_s",
            "min",
            "max",
            "non_finite"
        );
        let num = |v: Option<f64>, p: usize| v.map_or("-".to_string(), |x| figure(x, p));
        for c in &self.columns {
            let _ = writeln!(
                s,
                "{:<w$} {:>8} {:>9} {:>5} {:>10} {:>11} {:>12} {:>12} {:>10}",
                c.name,
                c.readings,
                num(c.rate_hz, 2),
                c.gaps.count,
                num(c.gaps.largest_s, 3),
                num(c.gaps.largest_at_t_s, 3),
                num(c.min, 4),
                num(c.max, 4),
                c.non_finite
            );
        }
    }

    fn sensor_lines(&self, s: &mut String) {
        if let Some(a) = &self.acc {
            acc_line(s, a);
        }
        if let Some(g) = &self.gyro {
            gyro_lines(s, g);
        }
        if let Some(m) = &self.mag {
            mag_line(s, m);
        }
        if let Some(w) = &self.wheels {
            wheels_line(s, w);
        }
        if let Some(y) = &self.yaw {
            yaw_line(s, y);
        }
        if let Some(v) = &self.vehicle {
            let _ = writeln!(s, "vehicle sensors: {}", v.set);
            for l in &v.cannot_tell {
                let _ = writeln!(s, "  cannot tell: {l}");
            }
        }
        if let Some(g) = &self.gnss {
            gnss_line(s, g);
        }
        for finding in &self.findings {
            let _ = writeln!(s, "found: {finding}");
        }
        for fault in &self.sensor_faults {
            let _ = writeln!(s, "fault: {fault}");
        }
    }
}

/// The fixes' line: how many, how often, the longest outage, their accuracy.
fn gnss_line(s: &mut String, g: &GnssReport) {
    let outage = match (g.gaps.count, g.gaps.largest_s, g.gaps.largest_at_t_s) {
        (0, _, _) => "no gaps".to_string(),
        (n, Some(l), Some(at)) => format!("{n} gaps (longest {l:.1} s, ending at t_s {at:.3})"),
        (n, _, _) => format!("{n} gaps"),
    };
    let sigma = match g.sigma_m {
        Some([lo, median, hi]) => {
            format!("sigma {lo:.2}-{hi:.2} m (median {median:.2} m)")
        }
        None => "no gnss_sigma_m: drive assumes 5 m".to_string(),
    };
    let course = match (g.course, g.course_lag_s) {
        (true, Some([lag, sigma])) => format!(
            "speed and course given, the course turning {lag:.2} ± {sigma:.2} s after the gyro by the stamps"
        ),
        (true, None) => "speed and course given".to_string(),
        (false, Some([lag, sigma])) => format!(
            "no speed or course, the track turning {lag:.2} ± {sigma:.2} s after the gyro by the stamps"
        ),
        (false, None) => "no speed or course".to_string(),
    };
    let _ = writeln!(
        s,
        "gnss: {} fixes at {} Hz, {outage}; {sigma}; {course}",
        g.fixes,
        num(g.rate_hz)
    );
}

/// A value with four decimals, `-` when absent.
fn num(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |x| figure(x, 4))
}

/// A value from the file with `decimals` decimals, in exponent form where those would run to
/// hundreds of digits; NaN and infinities as `{}` shows them, to keep the table's columns.
fn figure(x: f64, decimals: usize) -> String {
    if x.is_finite() {
        Fixed(x, decimals).to_string()
    } else {
        x.to_string()
    }
}

/// A unit, `undecided` when absent.
fn unit(u: Option<&str>) -> &str {
    u.unwrap_or("undecided")
}

/// The accelerometer's line: its unit and which axis points up.
fn acc_line(s: &mut String, a: &AccReport) {
    let up = a.up_axis.as_deref().map_or(String::new(), |u| {
        let meaning = if u == "-z" {
            " (frd: z down, as truenorth expects)"
        } else {
            " (that axis points up; truenorth's frd has -z up: see --axes)"
        };
        format!("; at rest gravity's reaction is along {u}{meaning}")
    });
    let _ = writeln!(
        s,
        "accelerometer: median |acc| {} -> {}{up}",
        num(a.median_magnitude),
        unit(a.likely_unit)
    );
}

/// The magnetometer's line: its unit and the field it makes.
fn mag_line(s: &mut String, m: &MagReport) {
    let also = if m.also_possible.is_empty() {
        String::new()
    } else {
        format!(" (also possible: {})", m.also_possible.join(", "))
    };
    let _ = writeln!(
        s,
        "magnetometer: median |mag| {} -> {} = {} uT{also}",
        num(m.median_magnitude),
        unit(m.likely_unit),
        num(m.field_ut)
    );
}

/// The wheels' line: their columns and whether their speed is plausible in m/s.
fn wheels_line(s: &mut String, w: &WheelReport) {
    let what = if w.columns == "speeds" {
        "fastest"
    } else {
        "mean speed"
    };
    let judged = match w.plausible_in_mps {
        Some(true) => "plausible in m/s",
        Some(false) => "too fast for m/s: km/h? (convert to m/s)",
        None => "undecided",
    };
    let _ = writeln!(
        s,
        "wheels: {}, {what} {} per s: {judged}",
        w.columns,
        num(w.speed)
    );
}

/// The yaw gyro against the wheels: the track it implies, its unit and sign.
fn yaw_line(s: &mut String, y: &YawReport) {
    let judged = match (y.likely_unit, y.flipped) {
        (Some(u), Some(true)) => format!("{u}, sign flipped (turns against the wheels)"),
        (Some(u), _) => u.to_string(),
        (None, Some(_)) => "neither rad/s nor deg/s (check the wheels' unit)".to_string(),
        (None, None) => "too few turns to judge".to_string(),
    };
    let _ = writeln!(
        s,
        "yaw gyro vs wheels: implied track {} m (r2 {}) over {} turning seconds: {judged}",
        num(y.implied_track_m),
        num(y.r2),
        y.windows
    );
}

/// The gyro's lines: its unit and, when judged, its axes.
fn gyro_lines(s: &mut String, g: &GyroReport) {
    let Some(u) = g.likely_unit else {
        let why = match g.unit_margin {
            Some(m) => format!("the units' best fits differ only {m:.1}x"),
            None => "too few turns near rest".to_string(),
        };
        let _ = writeln!(s, "gyro: unit and axes undecided ({why})");
        return;
    };
    let _ = writeln!(
        s,
        "gyro: {u} (the other unit agrees {:.1}x worse; turn seen per turn of the file's numbers {:.4})",
        g.unit_margin.unwrap_or(f64::NAN),
        g.rad_per_unit.unwrap_or(f64::NAN)
    );
    if let Some(a) = &g.axes {
        let _ = writeln!(
            s,
            "gyro axes: as read {:.2} deg ({}, {:.1}x the best); best {} ({}) {:.2} deg, runner-up {} {:.2} deg, margin {:.1}x, typical mapping {:.1}x, over {} gravity + {} magnetic spans",
            a.as_read_deg,
            a.verdict,
            a.as_read_margin,
            a.best,
            if a.best_is_rotation {
                "rotation"
            } else {
                "mirror image: left-handed"
            },
            a.best_deg,
            a.runner_up,
            a.runner_up_deg,
            a.margin,
            a.typical_margin,
            a.spans_gravity,
            a.spans_magnetic
        );
        if let (Some(fix), false) = (&a.fix, a.wrong) {
            let _ = writeln!(
                s,
                "gyro axes: not sure enough to refuse; if the other sensors are right, --column {fix}"
            );
        }
    }
}
