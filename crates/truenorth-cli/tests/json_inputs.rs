//! Every JSON file the tools read — a compass calibration (`heading`), a vehicle and a
//! drive's learned state (`drive`) — is versioned, refuses unknown keys naming the closest
//! known one, skips a byte-order mark, and is checked against physics with the same rules
//! wherever it is read; `field` bounds the height and says why a far date is refused.

mod common;

use std::path::{Path, PathBuf};

use common::{TURN_HEADER, p, run, scratch};
use serde_json::Value;

/// Runs the binary: (success, stderr).
fn outcome(args: &[&str]) -> (bool, String) {
    checked(run(args, None))
}

/// (success, stderr) of a run, which must not have panicked.
fn checked(o: std::process::Output) -> (bool, String) {
    let (ran, err) = common::outcome(&o);
    println!("-> {}", err.trim());
    assert!(!err.contains("panicked"), "{err}");
    (ran, err)
}

/// Asserts a refusal of one line that names `file` and holds every `want`.
fn refused(result: (bool, String), file: &Path, want: &[&str]) {
    let (ran, err) = result;
    assert!(!ran, "accepted: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains(p(file)), "{err}");
    for w in want {
        assert!(err.contains(w), "`{w}` missing from {err}");
    }
}

/// A level compass turning a full circle, as `t_s,mag_x,mag_y`.
fn turn_csv(dir: &Path) -> PathBuf {
    let path = dir.join("turn.csv");
    let rows = common::turn_rows(72, 1.0, 20.0, [3.0, -1.0], 0.0);
    std::fs::write(&path, TURN_HEADER.to_string() + &rows).unwrap();
    path
}

fn heading(dir: &Path, cal: &Path, input: &Path) -> (bool, String) {
    checked(common::heading(cal, input, &dir.join("h.csv"), &[]))
}

const GOOD_CAL: &str = r#"{"format":"truenorth-compass-calibration","version":2,"method":"hand","dimensions":2,"hard_iron":[3,-1],"soft_iron":[[1,0],[0,1]],"field":20}"#;

#[test]
fn calibration_files_are_versioned_strict_and_physical() {
    let dir = scratch("json_inputs", "calibration");
    let input = turn_csv(&dir);
    let cal = dir.join("cal.json");
    let with = |text: &str| {
        std::fs::write(&cal, text).unwrap();
        heading(&dir, &cal, &input)
    };
    assert!(with(GOOD_CAL).0);
    // A byte-order mark, as in a CSV, is skipped.
    assert!(with(&format!("\u{feff}{GOOD_CAL}")).0);
    // A version-1 file, with the quality block it carried then, still loads.
    let v1 = GOOD_CAL.replace(
        r#""version":2"#,
        r#""version":1,"quality":{"points":72,"coverage":1,"residual_rms_rel":0.01,"condition":2,"heading_error_bound_deg":1,"field_ratio_to_expected":null,"field_magnitude":20}"#,
    );
    let (ran, err) = with(&v1);
    assert!(ran, "{err}");
    refused(
        with(&GOOD_CAL.replace("[3,-1]", "[1e308,0]")),
        &cal,
        &["`hard_iron` is 1e308 from the origin", "recalibrate"],
    );
    refused(
        with(&GOOD_CAL.replace("hard_iron", "hard_irn")),
        &cal,
        &["unknown key `hard_irn` (did you mean `hard_iron`?)"],
    );
    refused(
        with(&GOOD_CAL.replace(r#""version":2,"#, "")),
        &cal,
        &["has no `version`"],
    );
    refused(
        with(&GOOD_CAL.replace(r#""version":2"#, r#""version":99"#)),
        &cal,
        &["layout version 99 is newer than this build reads"],
    );
    refused(
        with(&GOOD_CAL.replace("[[1,0],[0,1]]", "[[0,1],[1,0]]")),
        &cal,
        &["`soft_iron` has determinant", "mirrors"],
    );
    refused(
        with(&GOOD_CAL.replace("[[1,0],[0,1]]", "[[1,0],[0,0.001]]")),
        &cal,
        &["condition number"],
    );
    refused(
        with(&GOOD_CAL.replace(r#""field":20"#, r#""field":NaN"#)),
        &cal,
        &["not a truenorth calibration file"],
    );
    // Cut short, as by a full disk or a copy interrupted.
    refused(
        with(&GOOD_CAL[..GOOD_CAL.len() / 2]),
        &cal,
        &["not a truenorth calibration file", "EOF while parsing"],
    );
}

/// A drive log with a compass, and the vehicle file for it.
fn drive_files(dir: &Path) -> (PathBuf, PathBuf) {
    (common::compass_drive_log(dir), dir.join("vehicle.json"))
}

fn drive(dir: &Path, log: &Path, vehicle: &Path, extra: &[&str]) -> (bool, String) {
    checked(common::drive(vehicle, log, &dir.join("track.csv"), extra))
}

#[test]
fn vehicle_files_are_versioned_strict_and_physical() {
    let dir = scratch("json_inputs", "vehicle");
    let (log, vehicle) = drive_files(&dir);
    let with = |text: &str| {
        std::fs::write(&vehicle, text).unwrap();
        drive(&dir, &log, &vehicle, &[])
    };
    let good = r#"{"track_m": 1.55, "odometer_wheels": "rear"}"#;
    assert!(with(good).0);
    assert!(with(&format!("\u{feff}{good}")).0);
    assert!(with(r#"{"version": 1, "track_m": 1.55, "odometer_wheels": "rear"}"#).0);
    refused(
        with(r#"{"trak_m": 1.55, "odometer_wheels": "rear"}"#),
        &vehicle,
        &["unknown key `trak_m` (did you mean `track_m`?)"],
    );
    refused(
        with(r#"{"track_m": 1.55, "odometer_wheel": "rear"}"#),
        &vehicle,
        &["(did you mean `odometer_wheels`?)"],
    );
    refused(
        with(r#"{"version": 2, "track_m": 1.55, "odometer_wheels": "rear"}"#),
        &vehicle,
        &["layout version 2 is newer"],
    );
    refused(
        with(r#"{"track_m": -1.55, "odometer_wheels": "rear"}"#),
        &vehicle,
        &["`track_m` is -1.55 m, outside 0.05–10 m"],
    );
    refused(
        with(
            r#"{"track_m": 1.55, "odometer_wheels": "front", "wheelbase_m": 2.7, "pitman_ratio": 3}"#,
        ),
        &vehicle,
        &["`pitman_ratio` is 3"],
    );
    refused(
        with(r#"{"track_m": 1.55, "odometer_wheels": "re"#),
        &vehicle,
        &["not a vehicle file", "EOF while parsing"],
    );
    refused(
        with(r#"{"track_m": NaN, "odometer_wheels": "rear"}"#),
        &vehicle,
        &["not a vehicle file"],
    );
    std::fs::write(&vehicle, [0u8, 0xff, 0xfe, 7, 0x80]).unwrap();
    refused(
        drive(&dir, &log, &vehicle, &[]),
        &vehicle,
        &["did not contain valid UTF-8"],
    );
}

#[test]
fn learned_state_files_are_versioned_strict_and_physical() {
    let dir = scratch("json_inputs", "learned");
    let (log, vehicle) = drive_files(&dir);
    std::fs::write(&vehicle, r#"{"track_m": 1.55, "odometer_wheels": "rear"}"#).unwrap();
    let learned = dir.join("learned.json");
    let (ran, err) = drive(&dir, &log, &vehicle, &["--calibration-out", p(&learned)]);
    assert!(ran, "{err}");
    let written: Value = common::read_json(&learned);
    assert_eq!(written["format"], "truenorth-drive-calibration");
    assert_eq!(written["version"], 2);
    assert!(written["compass"].is_object(), "{written}");
    let input = dir.join("in.json");
    let with = |v: &Value| {
        std::fs::write(&input, v.to_string()).unwrap();
        drive(&dir, &log, &vehicle, &["--calibration-in", p(&input)])
    };
    let edited = |f: &dyn Fn(&mut serde_json::Map<String, Value>)| {
        let mut v = written.clone();
        f(v.as_object_mut().unwrap());
        v
    };
    assert!(with(&written).0);
    // Written before files were versioned: the state alone.
    let legacy = edited(&|m| {
        m.remove("format");
        m.remove("version");
    });
    assert!(with(&legacy).0);
    std::fs::write(&input, format!("\u{feff}{written}")).unwrap();
    assert!(drive(&dir, &log, &vehicle, &["--calibration-in", p(&input)]).0);
    refused(
        with(&edited(&|m| {
            m.remove("version");
        })),
        &input,
        &["has no `version`"],
    );
    refused(
        with(&edited(&|m| {
            m.insert("version".into(), 99.into());
        })),
        &input,
        &["layout version 99 is newer"],
    );
    refused(
        with(&edited(&|m| {
            let v = m.remove("wheel_diff").unwrap();
            m.insert("wheel_dif".into(), v);
        })),
        &input,
        &["unknown key `wheel_dif` (did you mean `wheel_diff`?)"],
    );
    // A reflecting soft iron: refused as `heading` refuses it.
    let reflect = edited(&|m| {
        let s = &mut m["compass"]["calibration"]["soft_iron"];
        let flat: Vec<f64> = serde_json::from_value(s.clone()).unwrap();
        *s = serde_json::json!([flat[2], flat[3], flat[0], flat[1]]);
    });
    refused(with(&reflect), &input, &["soft-iron", "reflecting"]);
    let far = edited(&|m| {
        m["compass"]["calibration"]["hard_iron"] = serde_json::json!([1e308, 0.0]);
    });
    refused(
        with(&far),
        &input,
        &["the learned compass: `hard_iron` is 1e308"],
    );
    let flat = edited(&|m| {
        let s = &mut m["compass"]["calibration"]["soft_iron"];
        let f: Vec<f64> = serde_json::from_value(s.clone()).unwrap();
        *s = serde_json::json!([f[0], f[1], f[2] * 0.01, f[3] * 0.01]);
    });
    refused(with(&flat), &input, &["condition number"]);
    let text = written.to_string();
    std::fs::write(&input, &text[..text.len() / 2]).unwrap();
    refused(
        drive(&dir, &log, &vehicle, &["--calibration-in", p(&input)]),
        &input,
        &["EOF while parsing"],
    );
    std::fs::write(
        &input,
        text.replacen("\"hard_iron\":[", "\"hard_iron\":[NaN,", 1),
    )
    .unwrap();
    refused(
        drive(&dir, &log, &vehicle, &["--calibration-in", p(&input)]),
        &input,
        &["not a drive calibration", "expected value"],
    );
}

#[test]
fn field_bounds_the_height_and_names_the_extrapolation_limit() {
    let (ran, err) = outcome(&["field", "--lat", "10", "--lon", "0", "--alt-km", "-1000"]);
    assert!(
        !ran && err.contains("--alt-km: -1000 is outside -1 to 850 km"),
        "{err}"
    );
    let (ran, err) = outcome(&[
        "field",
        "--lat",
        "10",
        "--lon",
        "0",
        "--date",
        "1900",
        "--allow-extrapolation",
    ]);
    assert!(
        !ran && err.contains("beyond what --allow-extrapolation extends to")
            && !err.contains("opt in"),
        "{err}"
    );
}
