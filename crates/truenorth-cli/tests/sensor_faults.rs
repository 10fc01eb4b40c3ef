//! Readings no live sensor gives, refused where they enter: a gyro clipped at its range or
//! frozen, a magnetometer reading exactly zero, a magnetometer axis pinned at full scale
//! while the field turns. Each was taken as motion before (85° RMS of error from a gyro
//! clipped at ±0.5 rad/s; a saturated compass fitted as `usable`).

mod common;

use std::path::{Path, PathBuf};

use common::{ScratchDir, TURN_HEADER, turn_rows};

fn dir(tag: &str) -> ScratchDir {
    common::scratch("cli_sensor_faults", tag)
}

/// A minute of simulated hand-held motion, each row's cells changed by `fault(k, cells)`.
fn recording(dir: &Path, fault: impl Fn(usize, &mut [f64; 10])) -> PathBuf {
    common::handheld_csv(dir, 60.0, 5, |k, cells, _| fault(k, cells))
}

/// `orientation` on `input`: refused with no output, naming `says`; then with
/// `--accept-sensor-faults` it runs and warns; `inspect` names the same fault.
fn orientation_refuses(dir: &Path, input: &Path, says: &str) {
    let report = common::ok(&["inspect", common::p(input)]);
    let report = String::from_utf8_lossy(&report.stdout);
    assert!(
        report
            .lines()
            .any(|l| l.starts_with("fault: ") && l.contains(says)),
        "{report}"
    );
    let output = dir.join("attitude.csv");
    let run = common::orientation(input, &output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(says), "{stderr}");
    assert!(stderr.contains("--accept-sensor-faults"), "{stderr}");
    assert!(!output.exists());
    let run = common::orientation(input, &output, &["--accept-sensor-faults"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning") && stderr.contains(says),
        "{stderr}"
    );
}

#[test]
fn a_clean_recording_runs() {
    let dir = dir("clean");
    let input = recording(&dir, |_, _| {});
    common::succeeded(common::orientation(&input, &dir.join("a.csv"), &[]));
    let report = common::ok(&["inspect", common::p(&input)]);
    assert!(!String::from_utf8_lossy(&report.stdout).contains("fault: "));
}

#[test]
fn a_gyro_clipped_at_half_a_radian_a_second_is_refused() {
    let dir = dir("clipped");
    let input = recording(&dir, |_, c| {
        for g in &mut c[1..4] {
            *g = g.clamp(-0.5, 0.5);
        }
    });
    orientation_refuses(&dir, &input, "clipped at its range");
}

#[test]
fn a_gyro_frozen_for_five_seconds_is_refused() {
    let dir = dir("frozen");
    let held = std::cell::Cell::new([0.0; 3]);
    let input = recording(&dir, |k, c| {
        // 100 Hz: rows 2000–2499 repeat the gyro of row 1999.
        if k == 1999 {
            held.set([c[1], c[2], c[3]]);
        }
        if (2000..2500).contains(&k) {
            c[1..4].copy_from_slice(&held.get());
        }
    });
    orientation_refuses(&dir, &input, "stopped updating");
    let stderr =
        String::from_utf8_lossy(&common::orientation(&input, &dir.join("b.csv"), &[]).stderr)
            .into_owned();
    // The run starts with the last live reading, data row 1999: file row 2001 (the header
    // is row 1).
    assert!(
        stderr.contains("row 2001") && stderr.contains("on 501 readings"),
        "{stderr}"
    );
}

#[test]
fn a_magnetometer_reading_zero_is_refused() {
    let dir = dir("zero");
    let input = recording(&dir, |k, c| {
        if (3000..3200).contains(&k) {
            c[7..10].fill(0.0);
        }
    });
    orientation_refuses(&dir, &input, "no place on Earth has no magnetic field");
}

/// A level compass turning twice, its x axis pinned at full scale on 28 % of the readings
/// (the field's x reaches past the clip level `h + A cos(0.28 π)` for 28 % of each turn).
#[test]
fn a_saturated_magnetometer_is_refused_by_calibrate_and_heading() {
    let dir = dir("saturated");
    let (field, hard) = (30.0, [12.0, -7.0]);
    let clip = hard[0] + field * (0.28 * std::f64::consts::PI).cos();
    let clean = format!("{TURN_HEADER}{}", turn_rows(2000, 0.01, field, hard, 3.0));
    let saturated: String = clean
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 0 {
                return format!("{l}\n");
            }
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            format!("{},{},{}\n", v[0], v[1].min(clip), v[2])
        })
        .collect();
    let input = dir.join("saturated.csv");
    std::fs::write(&input, &saturated).unwrap();
    let cal = dir.join("cal.json");
    let run = common::calibrate("ellipse", &input, &cal, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("magnetometer: x read") && stderr.contains("clipped"),
        "{stderr}"
    );
    assert!(!cal.exists());
    // A calibration from the clean turn, applied to the saturated one.
    let (_, good) = common::ellipse_calibration(&dir, &clean, &[]);
    let run = common::heading(&good, &input, &dir.join("h.csv"), &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("clipped at its range"), "{stderr}");
    let run = common::heading(
        &good,
        &input,
        &dir.join("h.csv"),
        &["--accept-sensor-faults"],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// `log` written to `out` with column `column` holding, on the lines `lines` (0 the header),
/// the value it has on the first of them.
fn hold(log: &Path, out: &Path, column: usize, lines: std::ops::Range<usize>) {
    let text = std::fs::read_to_string(log).unwrap();
    let mut all: Vec<String> = text.lines().map(String::from).collect();
    let held = all[lines.start].split(',').nth(column).unwrap().to_string();
    for line in &mut all[lines] {
        let mut cells: Vec<&str> = line.split(',').collect();
        cells[column] = &held;
        *line = cells.join(",");
    }
    std::fs::write(out, all.join("\n") + "\n").unwrap();
}

/// A drive's yaw gyro frozen on one reading for 400 rows: refused with the row; the
/// clean log runs.
#[test]
fn a_frozen_yaw_gyro_is_refused_by_drive() {
    let dir = dir("drive");
    let log = common::compass_drive_log(&dir);
    let vehicle = common::rear_vehicle(&dir, 1.5);
    common::succeeded(common::drive(&vehicle, &log, &dir.join("clean.csv"), &[]));
    let frozen = dir.join("frozen.csv");
    hold(&log, &frozen, 3, 1001..1401);
    let output = dir.join("out.csv");
    let run = common::drive(&vehicle, &frozen, &output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("gyr_z") && stderr.contains("stopped updating"),
        "{stderr}"
    );
    assert!(!output.exists());
}

/// A drive's right odometer stalled from row 1502 on (its distance repeated while the left
/// one goes on): named as a stalled odometer with its row, not blamed on a unit or the
/// track as it was; with `--accept-sensor-faults` it is a warning, and where the estimator
/// then refuses the spoiled wheels its message names the stall as the cause.
#[test]
fn a_stalled_wheel_is_named_not_blamed_on_units() {
    let dir = dir("stalled_wheel");
    let log = common::compass_drive_log(&dir);
    let vehicle = common::rear_vehicle(&dir, 1.5);
    let stalled = dir.join("stalled.csv");
    let rows = std::fs::read_to_string(&log).unwrap().lines().count();
    hold(&log, &stalled, 2, 1501..rows);
    let output = dir.join("out.csv");
    let run = common::drive(&vehicle, &stalled, &output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("the right odometer stalled"), "{stderr}");
    assert!(stderr.contains("row 1503"), "{stderr}");
    assert!(!stderr.contains("declared units"), "{stderr}");
    assert!(!output.exists());
    let run = common::drive(&vehicle, &stalled, &output, &["--accept-sensor-faults"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("warning") && stderr.contains("stalled"),
        "{stderr}"
    );
    if !run.status.success() {
        assert!(
            stderr.contains("stalled at row 1503 explains this"),
            "{stderr}"
        );
    }
}
