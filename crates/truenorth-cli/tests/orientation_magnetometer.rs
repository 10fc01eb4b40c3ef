//! `orientation` with a magnetometer read wrong: mirrored (x and y swapped, y negated) it
//! was blamed on the gyro's axes, with a `--column` for the gyro that made things worse;
//! mapped onto the accelerometer's columns it ran (165° RMS). Now the magnetometer is named
//! with the `--column` that reads it right, and the gyro is still named when it is the one.

mod common;

use std::path::{Path, PathBuf};

use common::{ScratchDir, outcome};

fn dir(tag: &str) -> ScratchDir {
    common::scratch("cli_orientation_magnetometer", tag)
}

/// Two minutes of simulated hand-held motion in the contract's columns.
fn recording(dir: &Path) -> PathBuf {
    common::handheld_csv(dir, 120.0, 9, |_, _, _| {})
}

/// The `--column` value after `--column ` in `message` (the first one).
fn first_fix(message: &str) -> String {
    let at = message.find("pass --column ").expect("a --column fix") + "pass --column ".len();
    message[at..].split_whitespace().next().unwrap().to_string()
}

#[test]
fn a_mirrored_magnetometer_is_named_with_the_columns_that_undo_it() {
    let dir = dir("mirrored");
    let input = recording(&dir);
    let out = dir.join("a.csv");
    for wrong in ["mag_x=mag_y,mag_y=mag_x", "mag_y=-mag_y"] {
        let (ok, err) = outcome(&common::orientation(&input, &out, &["--column", wrong]));
        assert!(!ok, "{wrong}: {err}");
        assert!(
            err.contains("the magnetometer is mirrored"),
            "{wrong}: {err}"
        );
        assert!(!err.contains("gyr_"), "{wrong}: {err}");
        let report = common::ok(&["inspect", common::p(&input), "--column", wrong]);
        let report = String::from_utf8_lossy(&report.stdout);
        assert!(
            report.contains("found: the gyro turns gravity's"),
            "{report}"
        );
        assert!(!report.contains("options: --column gyr"), "{report}");
        let fix = first_fix(&err);
        let (ok, err) = outcome(&common::orientation(
            &input,
            &out,
            &["--column", wrong, "--column", &fix],
        ));
        assert!(ok, "{wrong} then {fix}: {err}");
    }
}

#[test]
fn the_accelerometer_read_as_the_magnetometer_is_refused() {
    let dir = dir("onto_acc");
    let input = recording(&dir);
    let (ok, err) = outcome(&common::orientation(
        &input,
        &dir.join("a.csv"),
        &["--column", "mag_x=acc_x,mag_y=acc_y,mag_z=acc_z"],
    ));
    assert!(!ok && err.contains("hold the accelerometer's"), "{err}");
}

#[test]
fn a_swapped_gyro_is_still_the_gyro() {
    let dir = dir("gyro");
    let input = recording(&dir);
    let (ok, err) = outcome(&common::orientation(
        &input,
        &dir.join("a.csv"),
        &["--column", "gyr_x=gyr_y,gyr_y=gyr_x"],
    ));
    assert!(!ok && err.contains("the gyro's axes do not turn"), "{err}");
    assert!(!err.contains("magnetometer is mirrored"), "{err}");
}
