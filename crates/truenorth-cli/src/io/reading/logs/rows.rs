//! The rows a log becomes for a command: which rows and which columns (see
//! [`super`]), as numbers, so that the command reads them as it would read the same samples
//! written out as CSV, without writing and parsing that text.

use std::path::Path;

use truenorth_logs::Recording;

use crate::io::{CliError, CliResult};

/// How the odometry of a log becomes the wheels `drive` reads: the speeds of a rigid axle
/// with this track, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxleTrack {
    /// The odometer wheels' track, m.
    pub track_m: f64,
}

/// The columns a log can give, by stream.
const IMU: [&str; 6] = ["gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z"];
const MAG: [&str; 3] = ["mag_x", "mag_y", "mag_z"];
const WHEELS: [&str; 2] = ["speed_l_mps", "speed_r_mps"];
const GNSS: [&str; 3] = ["lat_deg", "lon_deg", "gnss_sigma_m"];
const GNSS_VELOCITY: [&str; 2] = ["gnss_speed_mps", "gnss_course_deg"];

/// A log as a table of numbers: the header a CSV of it would have (`t_s` first) and its
/// rows, one after the other; NaN is an empty cell (no reading of that stream on the row).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LogTable {
    /// The columns, `t_s` first.
    pub header: Vec<&'static str>,
    /// The values, row after row, `header.len()` a row.
    pub values: Vec<f64>,
}

impl LogTable {
    /// A table with these columns and no rows yet, room for `rows`.
    fn new(columns: &[&[&'static str]], rows: usize) -> Self {
        let mut header = vec!["t_s"];
        header.extend(columns.iter().flat_map(|c| c.iter().copied()));
        let values = Vec::with_capacity(header.len() * rows);
        Self { header, values }
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.values.len() / self.header.len().max(1)
    }

    /// Row `k`'s values, in header order.
    pub fn row(&self, k: usize) -> &[f64] {
        let w = self.header.len();
        &self.values[k * w..(k + 1) * w]
    }
}

/// The table made of `recording` for a command that needs the columns `required` and reads
/// `optional` ones where present (see the module documentation).
pub fn table(
    name: &Path,
    recording: &Recording,
    required: &[&str],
    optional: &[&str],
    axle: Option<Result<AxleTrack, String>>,
) -> CliResult<LogTable> {
    let wanted = |names: &[&str]| required.iter().chain(optional).any(|c| names.contains(c));
    let required = |names: &[&str]| required.iter().any(|c| names.contains(c));
    if required(&MAG) && recording.mag.is_empty() {
        return Err(CliError::file(
            name,
            format!(
                "this command needs the magnetometer and the log gives none ({}); name its topic with --mag-topic (`truenorth inspect` lists them)",
                match recording.stream("mag") {
                    Some(s) => format!("topic `{}` has no usable reading", s.topic),
                    None => "--mag-topic none".to_string(),
                }
            ),
        ));
    }
    if let Some(axle) = axle {
        // A log without odometry is a vehicle with a gyro (and a compass, and fixes) and no
        // wheels, which `drive` takes as such.
        if recording.odometry.is_empty() {
            return Ok(merged(recording, None, true));
        }
        let axle = axle.map_err(|why| CliError::file(name, why))?;
        return Ok(merged(recording, Some(axle), true));
    }
    if wanted(&WHEELS) {
        return Ok(merged(recording, None, wanted(&GNSS)));
    }
    if wanted(&IMU) {
        return Ok(imu_rows(recording, required(&MAG)));
    }
    Ok(mag_rows(recording))
}

/// The magnetometer's own readings.
fn mag_rows(r: &Recording) -> LogTable {
    let mut table = LogTable::new(&[&MAG], r.mag.len());
    for m in &r.mag {
        table.values.push(m.t_s);
        table.values.extend(m.mag.iter().copied());
    }
    table
}

/// The IMU's rows with the magnetometer laid on them (only those carrying a reading when
/// `mag_only`).
fn imu_rows(r: &Recording, mag_only: bool) -> LogTable {
    let rows = r.imu_with_mag();
    let has_mag = !r.mag.is_empty();
    let columns: &[&[&'static str]] = if has_mag { &[&IMU, &MAG] } else { &[&IMU] };
    let mut table = LogTable::new(columns, rows.len());
    for s in &rows {
        let mag = s.mag.as_xyz();
        if mag_only && mag.is_none() {
            continue;
        }
        let (g, a) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz());
        table.values.push(s.t_s);
        for v in [g, a] {
            table
                .values
                .extend(v.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
        if has_mag {
            table
                .values
                .extend(mag.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
    }
    table
}

/// Every stream at its own times: one row per distinct time, an empty cell where a stream
/// has no reading then; the odometry as wheel speeds when an axle is given (`drive`), the
/// satellite fixes when `with_gnss`.
fn merged(r: &Recording, axle: Option<AxleTrack>, with_gnss: bool) -> LogTable {
    // (time, stream, index), ordered by time and then by stream, so that readings at the
    // same instant share a row.
    let mut events: Vec<(f64, u8, usize)> = Vec::new();
    events.extend(r.imu.iter().enumerate().map(|(k, s)| (s.t_s, 0, k)));
    events.extend(r.mag.iter().enumerate().map(|(k, s)| (s.t_s, 1, k)));
    let gnss = with_gnss && !r.gnss.is_empty();
    if axle.is_some() {
        events.extend(r.odometry.iter().enumerate().map(|(k, s)| (s.t_s, 2, k)));
    }
    if gnss {
        events.extend(r.gnss.iter().enumerate().map(|(k, s)| (s.t_s, 3, k)));
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut columns: Vec<&[&'static str]> = vec![&IMU];
    if !r.mag.is_empty() {
        columns.push(&MAG);
    }
    if axle.is_some() {
        columns.push(&WHEELS);
    }
    if gnss {
        columns.push(&GNSS);
    }
    let velocity = gnss && r.gnss.iter().any(|f| f.velocity.is_some());
    if velocity {
        columns.push(&GNSS_VELOCITY);
    }
    let mut table = LogTable::new(&columns, events.len());
    let mut k = 0;
    while k < events.len() {
        let t = events[k].0;
        let (mut imu, mut mag, mut odo) = ([f64::NAN; 6], [f64::NAN; 3], [f64::NAN; 2]);
        let mut fix = [f64::NAN; 5];
        while k < events.len() && events[k].0 == t {
            let (_, stream, i) = events[k];
            match stream {
                0 => {
                    let s = &r.imu[i];
                    let (g, a) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz());
                    if let (Some(g), Some(a)) = (g, a) {
                        imu = [g.x, g.y, g.z, a.x, a.y, a.z];
                    }
                }
                1 => mag = [r.mag[i].mag.x, r.mag[i].mag.y, r.mag[i].mag.z],
                3 => {
                    let g = &r.gnss[i];
                    let (speed, course) = g.velocity.unwrap_or((f64::NAN, f64::NAN));
                    fix = [
                        g.lat_deg,
                        g.lon_deg,
                        g.sigma_m.unwrap_or(f64::NAN),
                        speed,
                        course,
                    ];
                }
                _ => {
                    if let Some(AxleTrack { track_m }) = axle {
                        // A right turn (positive yaw rate about z down) drives the left
                        // wheel, on the outside, faster.
                        let o = &r.odometry[i];
                        let half = o.yaw_rate_rps * track_m / 2.0;
                        odo = [o.velocity_mps.x + half, o.velocity_mps.x - half];
                    }
                }
            }
            k += 1;
        }
        table.values.push(t);
        table.values.extend(imu);
        if !r.mag.is_empty() {
            table.values.extend(mag);
        }
        if axle.is_some() {
            table.values.extend(odo);
        }
        if gnss {
            table.values.extend(&fix[..if velocity { 5 } else { 3 }]);
        }
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use truenorth::core::{ImuSample, Mag3Sample};
    use truenorth_logs::{LogFormat, OdometrySample};

    fn recording() -> Recording {
        Recording {
            format: LogFormat::Mcap,
            time_origin_s: 0.0,
            complete: true,
            topics: Vec::new(),
            streams: Vec::new(),
            imu: (0..4)
                .map(|k| {
                    ImuSample::new_6d(
                        f64::from(k) * 0.1,
                        Vector3::new(0.1, -0.2, 1.0 / 3.0),
                        Vector3::new(0.0, 0.0, -9.81),
                    )
                })
                .collect(),
            mag: vec![Mag3Sample::new(0.15, 20.0, -1e-7, 45.5)],
            attitude: Vec::new(),
            gnss: Vec::new(),
            odometry: vec![OdometrySample {
                t_s: 0.2,
                velocity_mps: Vector3::new(1.0, 0.0, 0.0),
                yaw_rate_rps: 0.5,
            }],
        }
    }

    #[test]
    fn rows_follow_the_columns_asked_for() {
        let r = recording();
        let name = Path::new("x.mcap");
        let mag = table(name, &r, &MAG, &[], None).unwrap();
        assert_eq!(mag.header, ["t_s", "mag_x", "mag_y", "mag_z"]);
        assert_eq!(mag.values, [0.15, 20.0, -1e-7, 45.5]);
        let joint = table(name, &r, &["mag_x", "acc_x"], &[], None).unwrap();
        assert_eq!(joint.rows(), 1, "{joint:?}");
        assert_eq!(joint.header[..2], ["t_s", "gyr_x"]);
        let all = table(name, &r, &["gyr_x"], &[], None).unwrap();
        assert_eq!(all.rows(), 4);
        assert!(
            all.row(0)[7..].iter().all(|v| v.is_nan()),
            "no magnetometer yet: {:?}",
            all.row(0)
        );
        assert_eq!(all.row(1)[3], 1.0 / 3.0);
        let drive = table(
            name,
            &r,
            &["t_s"],
            &WHEELS,
            Some(Ok(AxleTrack { track_m: 0.4 })),
        )
        .unwrap();
        assert_eq!(
            drive.rows(),
            5,
            "4 IMU rows, one magnetometer, one odometry at 0.2 s (shared)"
        );
        let row = drive.row(3);
        assert!(
            row[0] == 0.2 && row[row.len() - 2..] == [1.1, 0.9],
            "{row:?}"
        );
    }

    #[test]
    fn missing_streams_are_one_line_errors() {
        let mut r = recording();
        r.odometry.clear();
        let name = Path::new("x.mcap");
        let t = ["t_s"];
        // No odometry: the rows without wheels, whatever the axle.
        for axle in [Ok(AxleTrack { track_m: 1.0 }), Err("steering".to_string())] {
            let rows = table(name, &r, &t, &[], Some(axle)).unwrap();
            assert!(!rows.header.contains(&"speed_l_mps"), "{:?}", rows.header);
        }
        r.odometry = recording().odometry;
        let e = table(name, &r, &t, &[], Some(Err("steering wheels".to_string()))).unwrap_err();
        assert!(e.to_string().contains("steering"), "{e}");
        r.mag.clear();
        let e = table(name, &r, &MAG, &[], None).unwrap_err();
        assert!(e.to_string().contains("--mag-topic"), "{e}");
    }
}
