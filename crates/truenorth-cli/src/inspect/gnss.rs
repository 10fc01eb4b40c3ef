//! A drive log's satellite fixes (`lat_deg,lon_deg` on rows of their own): how many, how
//! often, where they stop, and how accurate the receiver says they are — what `drive` will
//! be leaning on between its dead-reckoned stretches — and, where their course and a yaw gyro
//! are both given, how late the fixes are stamped by their course's turns.

use serde::Serialize;
use truenorth::checks::CourseLagCheck;

use super::Recording;
use super::column_stats::{ColumnStats, Gaps};

/// The fixes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GnssReport {
    /// Rows with a finite latitude and longitude.
    pub fixes: usize,
    /// Fixes per second (one over the median step between them), Hz.
    pub rate_hz: Option<f64>,
    /// Where the fixes stop (steps over five median steps).
    pub gaps: Gaps,
    /// The receiver's 1σ horizontal accuracy (`gnss_sigma_m`) over the fixes, m: smallest,
    /// median (over the judged rows) and largest; `None` without the column (`drive`
    /// assumes its `gnss.default_sigma_m`, 5 m).
    pub sigma_m: Option<[f64; 3]>,
    /// Whether speed and course over ground are given (`gnss_speed_mps,gnss_course_deg`).
    pub course: bool,
    /// How long after the epoch they describe the fixes are stamped, s, and its σ, as their
    /// course's turns (without a course, their track's: the chords between fixes) against the
    /// gyro's show it (`truenorth_checks::CourseLagCheck`; the gyro's unit, sign, bias and scale
    /// do not matter); `None` without a gyro, or where the turns do not tell.
    pub course_lag_s: Option<[f64; 2]>,
}

/// The fixes' delay by their course against `gyr_z`.
fn course_lag(rec: &Recording) -> Option<[f64; 2]> {
    let gyr = rec.col("gyr_z")?;
    let (lat, lon) = (rec.col("lat_deg")?, rec.col("lon_deg")?);
    let velocity = rec.col("gnss_speed_mps").zip(rec.col("gnss_course_deg"));
    let mut check = Box::new(CourseLagCheck::new());
    for (k, &t) in rec.t_s.iter().enumerate() {
        let v = velocity.map(|(speed, course)| (speed[k], course[k]));
        check.push_columns(t, gyr[k], lat[k], lon[k], v);
    }
    check.lag().map(|l| [l.lag_s, l.sigma_s])
}

/// The fixes' report, if the recording has `lat_deg` and `lon_deg`; `columns` are the
/// summaries over every row.
pub fn gnss(rec: &Recording, columns: &[ColumnStats]) -> Option<GnssReport> {
    let stats = |name: &str| columns.iter().find(|c| c.name == name);
    let (lat, lon) = (stats("lat_deg")?, stats("lon_deg")?);
    let sigma = stats("gnss_sigma_m").and_then(|s| {
        let mut judged: Vec<f64> = rec
            .col("gnss_sigma_m")?
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .collect();
        let median = truenorth::checks::median(&mut judged)?;
        Some([s.min?, median, s.max?])
    });
    Some(GnssReport {
        fixes: lat.readings.min(lon.readings),
        rate_hz: lat.rate_hz,
        gaps: lat.gaps.clone(),
        sigma_m: sigma,
        course: stats("gnss_speed_mps").is_some() && stats("gnss_course_deg").is_some(),
        course_lag_s: course_lag(rec),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inspect::Scan;

    /// Fixes at 5 Hz among 50 Hz rows, with one outage of 30 s: the rate and the gap are
    /// the fixes', not the rows'.
    #[test]
    fn fixes_among_faster_rows() {
        let n = 50 * 120;
        let t_s: Vec<f64> = (0..n).map(|k| k as f64 * 0.02).collect();
        let fix = |k: usize| k.is_multiple_of(10) && !(1500..3000).contains(&k);
        let cells = |v: f64| {
            (0..n)
                .map(|k| {
                    if fix(k) {
                        v + k as f64 * 1e-7
                    } else {
                        f64::NAN
                    }
                })
                .collect::<Vec<f64>>()
        };
        let sigma: Vec<f64> = (0..n)
            .map(|k| {
                if fix(k) {
                    1.0 + (k % 40) as f64 * 0.1
                } else {
                    f64::NAN
                }
            })
            .collect();
        let rec = Recording {
            t_s,
            columns: vec![
                ("lat_deg".into(), cells(52.5)),
                ("lon_deg".into(), cells(13.4)),
                ("gnss_sigma_m".into(), sigma),
            ],
        };
        let scan = Scan::of(&rec);
        let report = gnss(&scan.recording, &scan.columns).unwrap();
        assert_eq!(report.fixes, n / 10 - 150);
        assert!((report.rate_hz.unwrap() - 5.0).abs() < 1e-6);
        assert_eq!(report.gaps.count, 1);
        assert!((report.gaps.largest_s.unwrap() - 30.2).abs() < 1e-6);
        assert_eq!(report.sigma_m, Some([1.0, 2.0, 4.0]));
        assert!(!report.course);
        assert_eq!(report.course_lag_s, None);
    }
}
