//! `truenorth calibrate --method ellipse|ellipsoid|ellipsoid-accel` on a recording longer
//! than the memory
//! the fit keeps its readings in: the rest goes to a temporary file in TMPDIR, the output
//! is the same to the byte, nothing is left in TMPDIR, and a TMPDIR that cannot take the
//! file is one clear error line.

mod common;

use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

use common::{binary, command_args};

/// The memory share the tests give the fit (bytes), so that a recording of a few ten
/// thousand rows spills (see `io/reading_spill.rs`).
const SMALL_SHARE: &str = "4096";

/// Rows of each recording: more than one chunk of the file (2^15 readings) past the share.
const ROWS: usize = 70_000;

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_calibrate_spill", name)
}

/// A level compass turning a few times round (2-D), a sensor tumbled (3-D) or a
/// magnetometer and an accelerometer tumbled together (6: the two sensors' columns), with
/// deterministic pseudo-noise.
fn recording(dims: usize) -> String {
    if dims == 6 {
        return joint_recording();
    }
    let mut csv = String::from(if dims == 2 {
        "mag_x,mag_y\n"
    } else {
        "mag_x,mag_y,mag_z\n"
    });
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    for k in 0..ROWS {
        let noise = 0.2 * (((k as f64) * 12.9898).sin() * 43_758.545).fract();
        if dims == 2 {
            let psi = (k as f64 * 0.37).to_radians();
            let (x, y) = (20.0 * psi.cos(), -20.0 * psi.sin());
            writeln!(csv, "{},{}", 12.0 + 1.2 * x + noise, -7.0 + 0.9 * y - noise).unwrap();
        } else {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / ROWS as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            let (x, y, z) = (40.0 * r * c, 40.0 * r * s, 40.0 * z);
            writeln!(
                csv,
                "{},{},{}",
                3.0 + 1.1 * x + 0.05 * y + noise,
                -5.0 + 0.05 * x + 0.95 * y,
                2.0 + 1.02 * z - noise
            )
            .unwrap();
        }
    }
    csv
}

/// An instrument tumbled through every attitude (pitch within ±75°): its accelerometer
/// (bias, scale, cross-axis) and its magnetometer (hard and soft iron, turned 2° from the
/// accelerometer), m/s² and µT, with deterministic pseudo-noise.
fn joint_recording() -> String {
    let mut csv = String::from("acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n");
    let (sd, cd) = 60f64.to_radians().sin_cos();
    for k in 0..ROWS {
        let t = k as f64 / ROWS as f64;
        let noise = ((k as f64 * 12.9898).sin() * 43_758.545).fract() - 0.5;
        let (sy, cy) = (std::f64::consts::TAU * 37.0 * t).sin_cos();
        let (sp, cp) = (1.3 * (std::f64::consts::TAU * 23.0 * t).sin()).sin_cos();
        let (sr, cr) = (std::f64::consts::TAU * 53.0 * t).sin_cos();
        // Specific force (up) and the field (north, dipping 60°) in the body axes of an
        // attitude (yaw, pitch, roll), z up.
        let f = [-9.81 * sp, 9.81 * cp * sr, 9.81 * cp * cr];
        let (hx, hz) = (50.0 * cd, -50.0 * sd);
        let (ax, ay) = (cy * hx, -sy * hx);
        let (bx, bz) = (cp * ax - sp * hz, sp * ax + cp * hz);
        let h = [bx, cr * ay + sr * bz, -sr * ay + cr * bz];
        let (s2, c2) = 0.035f64.sin_cos();
        let m = [c2 * h[0] - s2 * h[1], s2 * h[0] + c2 * h[1], h[2]];
        writeln!(
            csv,
            "{},{},{},{},{},{}",
            0.2 + 1.02 * f[0] + 0.01 * f[1] + 0.01 * noise,
            -0.1 + 0.98 * f[1] + 0.01 * f[0],
            0.3 + 1.01 * f[2] - 0.01 * noise,
            12.0 + 1.1 * m[0] + 0.05 * m[1] + 0.1 * noise,
            -7.0 + 0.05 * m[0] + 0.93 * m[1],
            4.0 + 1.04 * m[2] - 0.1 * noise,
        )
        .unwrap();
    }
    csv
}

/// Runs `calibrate` with TMPDIR at `tmp` and, when given, the memory share.
fn calibrate(method: &str, input: &Path, output: &Path, tmp: &Path, share: Option<&str>) -> Output {
    let mut cmd = binary();
    cmd.args(command_args(
        "calibrate",
        &["--method", method],
        input,
        output,
        &["--accept-poor"],
    ))
    .env("TMPDIR", tmp);
    if let Some(s) = share {
        cmd.env("TRUENORTH_TEST_SPILL_MEMORY_BYTES", s);
    }
    cmd.output().unwrap()
}

fn spilled_output_is_the_same(method: &str, dims: usize) {
    let dir = scratch(method);
    let input = dir.join("in.csv");
    std::fs::write(&input, recording(dims)).unwrap();
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let (kept, spilled) = (dir.join("kept.json"), dir.join("spilled.json"));
    for (out, share) in [(&kept, None), (&spilled, Some(SMALL_SHARE))] {
        let run = calibrate(method, &input, out, &tmp, share);
        assert!(
            run.status.success(),
            "{method} {share:?}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    assert_eq!(
        std::fs::read(&kept).unwrap(),
        std::fs::read(&spilled).unwrap(),
        "{method}: the output with the readings on disk differs"
    );
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().collect();
    assert!(left.is_empty(), "{method}: left in TMPDIR: {left:?}");
}

#[test]
fn an_ellipse_fit_that_spills_writes_the_same_bytes_and_leaves_nothing() {
    spilled_output_is_the_same("ellipse", 2);
}

#[test]
fn an_ellipsoid_fit_that_spills_writes_the_same_bytes_and_leaves_nothing() {
    spilled_output_is_the_same("ellipsoid", 3);
}

#[test]
fn an_ellipsoid_accel_fit_that_spills_writes_the_same_bytes_and_leaves_nothing() {
    spilled_output_is_the_same("ellipsoid-accel", 6);
}

#[test]
fn a_tmpdir_that_cannot_take_the_readings_is_one_clear_line() {
    let dir = scratch("unwritable");
    let input = dir.join("in.csv");
    std::fs::write(&input, recording(2)).unwrap();
    let tmp = dir.join("no-such-directory");
    let out = dir.join("cal.json");
    let run = calibrate("ellipse", &input, &out, &tmp, Some(SMALL_SHARE));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains(&tmp.display().to_string()), "{stderr}");
    assert!(stderr.contains("set TMPDIR"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!out.exists());
}

/// Readings beyond what the disk may take for one fit (an unending or decompressed-bomb
/// input) are one clear line, not a temporary file that grows until the disk is full.
#[test]
fn readings_beyond_the_disk_share_are_refused() {
    let dir = scratch("disk-share");
    let input = dir.join("in.csv");
    std::fs::write(&input, recording(2)).unwrap();
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let out = dir.join("cal.json");
    let mut cmd = binary();
    cmd.args(command_args(
        "calibrate",
        &["--method", "ellipse"],
        &input,
        &out,
        &[],
    ))
    .env("TMPDIR", &tmp)
    .env("TRUENORTH_TEST_SPILL_MEMORY_BYTES", SMALL_SHARE)
    // One of the file's chunks of 2-D readings (2^15 of 16 bytes): the recording's
    // 70,000 rows take two beyond the memory share.
    .env("TRUENORTH_TEST_SPILL_DISK_BYTES", (16 << 15).to_string());
    let run = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("a calibration needs minutes"), "{stderr}");
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
}
