//! `truenorth orientation`: the CSV contract, the frames, and refusals.

mod common;

use std::path::{Path, PathBuf};

use common::{IMU_HEADER, ScratchDir, csv_line, imu_cells};
use nalgebra::{Quaternion, UnitQuaternion};
use truenorth_sim::{HandheldParams, ImuSensorParams, MotionTruth, handheld_motion, imu_streams};

fn dir(tag: &str) -> ScratchDir {
    common::scratch("cli_orientation", tag)
}

/// Two minutes of simulated hand-held motion with a typical consumer IMU, as the CLI's input.
fn recording(dir: &Path) -> (PathBuf, Vec<MotionTruth>) {
    recording_with_time(dir, "imu.csv", |t| t)
}

/// The recording with its time column mapped by `time` (a gap, another unit).
fn recording_with_time(
    dir: &Path,
    name: &str,
    time: impl Fn(f64) -> f64,
) -> (PathBuf, Vec<MotionTruth>) {
    let truth = handheld_motion(&HandheldParams {
        duration_s: 120.0,
        ..HandheldParams::default()
    })
    .unwrap();
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), 11).unwrap();
    let mut csv = format!("{IMU_HEADER}\n");
    for s in &samples {
        let mut cells = imu_cells(s);
        cells[0] = time(cells[0]);
        csv += &csv_line(&cells, ",");
    }
    let path = dir.join(name);
    std::fs::write(&path, csv).unwrap();
    (path, truth)
}

/// Runs the default method on `input`, which must be refused without creating `output`;
/// returns what it said on stderr.
fn refused(input: &Path, output: &Path) -> String {
    let o = common::orientation(input, output, &[]);
    assert!(!o.status.success());
    assert!(!output.exists());
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    common::table(path, false)
}

/// The quaternion filter's error on the recording (NED output rows) after 20 s stays within
/// its bound. The motion never rests, so the 0.3°/s-per-axis gyro bias is learned only by
/// the slow in-motion estimate; until then a complementary filter lags by bias × time
/// constant, at most |b| · τ_mag = 0.52°/s · 15 s = 7.8° about the vertical, plus the tilt
/// of the 0.07 m/s² accelerometer bias (0.4°) and the noise: 1° covers both.
fn assert_within_bound(rows: &[Vec<f64>], truth: &[MotionTruth]) {
    let bias_dps = 0.3f64 * 3f64.sqrt();
    let bound_deg = bias_dps * truenorth::fusion::QuaternionFilterConfig::default().tau_mag_s + 1.0;
    assert_eq!(rows.len(), truth.len());
    let worst_deg = rows
        .iter()
        .zip(truth)
        .filter(|(_, t)| t.t_s > 20.0)
        .map(|(r, t)| quaternion(r).angle_to(&t.attitude).to_degrees())
        .fold(0.0, f64::max);
    assert!(
        worst_deg < bound_deg,
        "worst attitude error {worst_deg:.2}° (bound {bound_deg:.1}°)"
    );
}

fn quaternion(r: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(r[1], r[2], r[3], r[4]))
}

#[test]
fn attitude_follows_the_simulated_motion_in_both_frames() {
    let d = dir("frames");
    let (input, truth) = recording(&d);
    let (ned, enu) = (d.join("ned.csv"), d.join("enu.csv"));
    for (out, frame) in [(&ned, "ned"), (&enu, "enu")] {
        // The simulator's gyro reads the instantaneous rate.
        let o = common::orientation(
            &input,
            out,
            &[
                "--frame",
                frame,
                "--status",
                "--gyro-timing",
                "instantaneous",
            ],
        );
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{stderr}");
        // The Euler and σ columns' frame is said when it differs from the quaternion's.
        assert_eq!(
            stderr.contains("stay relative to north-east-down"),
            frame == "enu",
            "{frame}: {stderr}"
        );
    }
    let (header, ned_rows) = rows(&ned);
    assert_eq!(
        header,
        [
            "t_s",
            "qw",
            "qx",
            "qy",
            "qz",
            "yaw_deg",
            "pitch_deg",
            "roll_deg",
            "bias_x_rps",
            "bias_y_rps",
            "bias_z_rps",
            "at_rest",
            "mag_used",
            "mag_disturbed",
            "mag_calibrating",
            "gap",
            "sigma_x_deg",
            "sigma_y_deg",
            "sigma_z_deg"
        ]
    );
    let (_, enu_rows) = rows(&enu);
    assert_eq!(ned_rows.len(), truth.len());
    // ENU = (north, east, down) → (east, north, up): 180° about (1, 1, 0)/√2.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let ned_to_enu = UnitQuaternion::from_quaternion(Quaternion::new(0.0, h, h, 0.0));
    for (n, e) in ned_rows.iter().zip(&enu_rows) {
        let (qn, qe) = (quaternion(n), quaternion(e));
        assert!((ned_to_enu * qn).angle_to(&qe) < 1e-6);
        // Yaw, pitch and roll describe the NED attitude in both files.
        assert_eq!(n[5..8], e[5..8]);
    }
    assert_within_bound(&ned_rows, &truth);
}

#[test]
fn refusals_name_the_file_and_row() {
    let d = dir("refusals");
    let (input, _) = recording(&d);
    // The output may not overwrite the recording.
    let o = common::orientation(&input, &input, &[]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("overwrite"));
    // A non-finite gyro reading is refused with its row; the output is not created.
    let text = std::fs::read_to_string(&input).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    cells[2] = "inf".into();
    lines[5] = cells.join(",");
    let bad = d.join("bad.csv");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let out = d.join("out.csv");
    let err = refused(&bad, &out);
    assert!(err.contains("row 6"), "{err}");
    // A failed run leaves an existing output as it was.
    std::fs::write(&out, "kept\n").unwrap();
    let o = common::orientation(&bad, &out, &[]);
    assert!(!o.status.success());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept\n");
}

#[test]
fn euler_detector_and_plot() {
    let d = dir("euler");
    let (input, truth) = recording(&d);
    let (out, plot) = (d.join("euler.csv"), d.join("euler.svg"));
    let o = common::orientation(
        &input,
        &out,
        &[
            "--method",
            "euler-detector",
            "--plot",
            plot.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (header, rows) = rows(&out);
    assert_eq!(header.len(), 8);
    assert_eq!(rows.len(), truth.len());
    // The detector has no gyro-bias estimate: its yaw lags the 0.3°/s-per-axis bias by
    // about bias × τ_yaw (0.52°/s · 5 s = 2.6°), its tilt the accelerometer bias; the hand
    // motion's accelerations, which the definer only partly screens, add a few degrees.
    let mut sum = 0.0;
    let mut n = 0;
    for (r, t) in rows.iter().zip(&truth) {
        if t.t_s > 20.0 {
            sum += quaternion(r).angle_to(&t.attitude).to_degrees().powi(2);
            n += 1;
        }
    }
    let rms = (sum / n as f64).sqrt();
    assert!(rms < 10.0, "Euler detector RMS error {rms:.2}°");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("yaw") && svg.trim_end().ends_with("</svg>"));
    // The plot may not overwrite an input.
    let o = common::orientation(&input, &out, &["--plot", input.to_str().unwrap()]);
    assert!(!o.status.success());
}

/// A recording with an hour missing in the middle: the attitude after the gap is taken anew
/// from the sensors (not the gyro's last rate held for an hour), the rows say where, and a
/// line on stderr says how many gaps there were and where.
#[test]
fn a_gap_restarts_the_attitude_and_is_reported() {
    let d = dir("gap");
    let (input, truth) =
        recording_with_time(&d, "gap.csv", |t| if t >= 60.0 { t + 3600.0 } else { t });
    let out = d.join("out.csv");
    let o = common::orientation(
        &input,
        &out,
        &["--status", "--gyro-timing", "instantaneous"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (header, rows) = rows(&out);
    let gap = header.iter().position(|h| h == "gap").unwrap();
    let gap_rows: Vec<usize> = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r[gap] == 1.0)
        .map(|(k, _)| k)
        .collect();
    // Sample 6000 (t = 60 s) follows the gap: file row 6002 with the header.
    assert_eq!(gap_rows, [6000]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("1 gap") && err.contains("row 6002"), "{err}");
    // Restarted from one reading in motion, then held within the bound of the gap-free run:
    // the gyro's rate held over the hour instead turned the attitude 30–50° off.
    assert_within_bound(&rows, &truth);
}

/// A time column in milliseconds: every step is a gap, which is no gyro record; refused
/// with the row, and nothing written.
#[test]
fn a_millisecond_time_base_is_refused() {
    let d = dir("ms");
    let (input, _) = recording_with_time(&d, "ms.csv", |t| 1000.0 * t);
    let err = refused(&input, &d.join("out.csv"));
    assert!(
        err.contains("row 4") && err.contains("milliseconds"),
        "{err}"
    );
}
