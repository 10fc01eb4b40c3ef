//! `truenorth heading` with a calibration that does not describe the readings it is given:
//! made in another unit, for another device, or edited — each refused with the file, the row
//! where the evidence became enough and the fix (or, with `--accept-calibration`, run with a
//! warning the summary repeats); and what a file says of itself (a `poor` verdict, a method
//! no `calibrate` writes) said rather than passed over.

mod common;

use std::path::Path;

use common::{TURN_HEADER, ellipse_calibration, outcome, scratch, turn_rows};

/// A calibration of a compass with a field of 30 and hard iron (5, −3), and its turn.
fn calibrated(dir: &Path) -> std::path::PathBuf {
    let csv = format!(
        "{TURN_HEADER}{}",
        turn_rows(360, 0.1, 30.0, [5.0, -3.0], 0.0)
    );
    ellipse_calibration(dir, &csv, &[]).1
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_calibration_in_another_unit_is_refused_and_accepted_on_request() {
    let dir = scratch("heading_checks", "unit");
    let cal = calibrated(&dir);
    // The same sensor read in another unit: every number 100 times larger (gauss → µT).
    let input = write(
        &dir,
        "in_ut.csv",
        &format!(
            "{TURN_HEADER}{}",
            turn_rows(200, 0.1, 3000.0, [500.0, -300.0], 0.3)
        ),
    );
    let out = dir.join("h.csv");
    let (ok, err) = outcome(&common::heading(&cal, &input, &out, &[]));
    assert!(!ok, "{err}");
    assert!(
        err.contains("in_ut.csv: row 51") && err.contains("another unit"),
        "{err}"
    );
    assert!(err.contains("--accept-calibration"), "{err}");
    assert!(!out.exists(), "nothing is written by a refused run");
    let (ok, err) = outcome(&common::heading(
        &cal,
        &input,
        &out,
        &["--accept-calibration"],
    ));
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: ") && err.contains("accepted with --accept-calibration"),
        "{err}"
    );
}

#[test]
fn another_device_s_calibration_is_refused() {
    let dir = scratch("heading_checks", "device");
    let cal = calibrated(&dir);
    // Another compass: the same field, its hard iron elsewhere (−20, 25).
    let input = write(
        &dir,
        "other.csv",
        &format!(
            "{TURN_HEADER}{}",
            turn_rows(200, 0.1, 30.0, [-20.0, 25.0], 0.0)
        ),
    );
    let (ok, err) = outcome(&common::heading(&cal, &input, &dir.join("h.csv"), &[]));
    assert!(!ok && err.contains("another device"), "{err}");
    // The sensor's own readings pass.
    let own = write(
        &dir,
        "own.csv",
        &format!(
            "{TURN_HEADER}{}",
            turn_rows(200, 0.1, 30.0, [5.0, -3.0], 1.0)
        ),
    );
    let (ok, err) = outcome(&common::heading(&cal, &own, &dir.join("h2.csv"), &[]));
    assert!(ok && !err.contains("warning"), "{err}");
}

#[test]
fn an_edited_asymmetric_soft_iron_is_refused_and_a_hand_made_one_said() {
    let dir = scratch("heading_checks", "edited");
    let input = write(
        &dir,
        "turn.csv",
        &format!(
            "{TURN_HEADER}{}",
            turn_rows(100, 0.1, 30.0, [0.0, 0.0], 0.0)
        ),
    );
    let edited = write(
        &dir,
        "edited.json",
        r#"{"format":"truenorth-compass-calibration","version":2,"method":"ellipse","dimensions":2,
            "hard_iron":[0,0],"soft_iron":[[1,0.3],[0,1]],"field":30}"#,
    );
    let (ok, err) = outcome(&common::heading(&edited, &input, &dir.join("h.csv"), &[]));
    assert!(
        !ok && err.contains("edited.json") && err.contains("not symmetric"),
        "{err}"
    );
    let hand = write(
        &dir,
        "hand.json",
        r#"{"format":"truenorth-compass-calibration","version":2,"method":"hand","dimensions":2,
            "hard_iron":[0,0],"soft_iron":[[1,0],[0,1]],"field":30}"#,
    );
    let (ok, err) = outcome(&common::heading(&hand, &input, &dir.join("h.csv"), &[]));
    assert!(
        ok && err.contains("warning: the calibration's method `hand`"),
        "{err}"
    );
}
