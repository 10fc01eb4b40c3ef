//! The CSV text a log becomes for a command (see [`super::log_input`]): which rows, which
//! columns, each number as the shortest text that parses back to the same `f64`.

use std::fmt::Write as _;
use std::path::Path;

use truenorth_logs::Recording;

use super::reader::ReadSpec;
use super::{CliError, CliResult};

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

/// The CSV made of `recording` for the columns of `spec` (see the module documentation).
pub(super) fn render(
    name: &Path,
    recording: &Recording,
    spec: &ReadSpec<'_>,
    axle: Option<Result<AxleTrack, String>>,
) -> CliResult<String> {
    let wanted = |names: &[&str]| {
        spec.required
            .iter()
            .chain(spec.optional)
            .any(|c| names.contains(c))
    };
    let required = |names: &[&str]| spec.required.iter().any(|c| names.contains(c));
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
        let axle = axle.map_err(|why| CliError::file(name, why))?;
        if recording.odometry.is_empty() {
            return Err(CliError::file(
                name,
                format!(
                    "drive needs the wheels' speeds and this {} file has no odometry: give a ROS 2 MCAP log with a nav_msgs/msg/Odometry topic (--odometry-topic), or a CSV",
                    recording.format
                ),
            ));
        }
        return Ok(merged(recording, Some(axle)));
    }
    if wanted(&WHEELS) {
        return Ok(merged(recording, None));
    }
    if wanted(&IMU) {
        return Ok(imu_rows(recording, required(&MAG)));
    }
    Ok(mag_rows(recording))
}

/// Appends `,v` for each value (an empty cell for NaN, a reading the row does not have).
fn cells(text: &mut String, values: impl IntoIterator<Item = f64>) {
    for v in values {
        text.push(',');
        if !v.is_nan() {
            // Display writes the shortest text that parses back to the same f64.
            let _ = write!(text, "{v}");
        }
    }
}

fn header(text: &mut String, columns: &[&[&str]]) {
    text.push_str("t_s");
    for c in columns.iter().flat_map(|c| c.iter()) {
        text.push(',');
        text.push_str(c);
    }
    text.push('\n');
}

/// The magnetometer's own readings.
fn mag_rows(r: &Recording) -> String {
    let mut text = String::with_capacity(64 * (r.mag.len() + 1));
    header(&mut text, &[&MAG]);
    for m in &r.mag {
        let _ = write!(text, "{}", m.t_s);
        cells(&mut text, m.mag.iter().copied());
        text.push('\n');
    }
    text
}

/// The IMU's rows with the magnetometer laid on them (only those carrying a reading when
/// `mag_only`).
fn imu_rows(r: &Recording, mag_only: bool) -> String {
    let rows = r.imu_with_mag();
    let has_mag = !r.mag.is_empty();
    let mut text = String::with_capacity(128 * (rows.len() + 1));
    if has_mag {
        header(&mut text, &[&IMU, &MAG]);
    } else {
        header(&mut text, &[&IMU]);
    }
    for s in &rows {
        let mag = s.mag.as_xyz();
        if mag_only && mag.is_none() {
            continue;
        }
        let (g, a) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz());
        let _ = write!(text, "{}", s.t_s);
        for v in [g, a] {
            cells(&mut text, v.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
        if has_mag {
            cells(&mut text, mag.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]));
        }
        text.push('\n');
    }
    text
}

/// Every stream at its own times: one row per distinct time, an empty cell where a stream
/// has no reading then; the odometry as wheel speeds when an axle is given.
fn merged(r: &Recording, axle: Option<AxleTrack>) -> String {
    // (time, stream, index), ordered by time and then by stream, so that readings at the
    // same instant share a row.
    let mut events: Vec<(f64, u8, usize)> = Vec::new();
    events.extend(r.imu.iter().enumerate().map(|(k, s)| (s.t_s, 0, k)));
    events.extend(r.mag.iter().enumerate().map(|(k, s)| (s.t_s, 1, k)));
    if axle.is_some() {
        events.extend(r.odometry.iter().enumerate().map(|(k, s)| (s.t_s, 2, k)));
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut columns: Vec<&[&str]> = vec![&IMU];
    if !r.mag.is_empty() {
        columns.push(&MAG);
    }
    if axle.is_some() {
        columns.push(&WHEELS);
    }
    let mut text = String::with_capacity(160 * (events.len() + 1));
    header(&mut text, &columns);
    let mut k = 0;
    while k < events.len() {
        let t = events[k].0;
        let (mut imu, mut mag, mut odo) = ([f64::NAN; 6], [f64::NAN; 3], [f64::NAN; 2]);
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
        let _ = write!(text, "{t}");
        cells(&mut text, imu);
        if !r.mag.is_empty() {
            cells(&mut text, mag);
        }
        if axle.is_some() {
            cells(&mut text, odo);
        }
        text.push('\n');
    }
    text
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
        let mag = render(name, &r, &ReadSpec::new(&MAG), None).unwrap();
        assert_eq!(mag, "t_s,mag_x,mag_y,mag_z\n0.15,20,-0.0000001,45.5\n");
        let joint = render(name, &r, &ReadSpec::new(&["mag_x", "acc_x"]), None).unwrap();
        assert_eq!(joint.lines().count(), 2, "{joint}");
        assert!(joint.starts_with("t_s,gyr_x"), "{joint}");
        let all = render(name, &r, &ReadSpec::new(&["gyr_x"]), None).unwrap();
        let lines: Vec<&str> = all.lines().collect();
        assert_eq!(lines.len(), 5);
        assert!(
            lines[1].ends_with(",,,"),
            "no magnetometer yet: {}",
            lines[1]
        );
        assert!(lines[2].contains("0.3333333333333333"), "{}", lines[2]);
        let drive = render(
            name,
            &r,
            &ReadSpec::new(&["t_s"]).optional(&WHEELS),
            Some(Ok(AxleTrack { track_m: 0.4 })),
        )
        .unwrap();
        let lines: Vec<&str> = drive.lines().collect();
        assert_eq!(
            lines.len(),
            6,
            "4 IMU rows, one magnetometer, one odometry at 0.2 s (shared)"
        );
        assert!(
            lines[4].starts_with("0.2,") && lines[4].ends_with(",1.1,0.9"),
            "{}",
            lines[4]
        );
    }

    #[test]
    fn missing_streams_are_one_line_errors() {
        let mut r = recording();
        r.odometry.clear();
        let name = Path::new("x.mcap");
        let spec = ReadSpec::new(&["t_s"]);
        let e = render(name, &r, &spec, Some(Ok(AxleTrack { track_m: 1.0 }))).unwrap_err();
        assert!(e.to_string().contains("no odometry"), "{e}");
        let e = render(name, &r, &spec, Some(Err("steering wheels".to_string()))).unwrap_err();
        assert!(e.to_string().contains("steering"), "{e}");
        r.mag.clear();
        let e = render(name, &r, &ReadSpec::new(&MAG), None).unwrap_err();
        assert!(e.to_string().contains("--mag-topic"), "{e}");
    }
}
