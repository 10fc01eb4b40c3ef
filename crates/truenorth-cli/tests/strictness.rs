//! Strict at every level: a key that a drive's learned-state file does not define is
//! refused wherever it stands (the top level, the compass, its calibration and quality
//! report, a learned value), with the closest known key; and the help and version text,
//! like every other output, fail the run when they cannot be written.

mod common;

use common::{outcome, p};
use serde_json::Value;

/// A misspelt key beside each real one, at every level of the file: (where, the key, the
/// key it is a misspelling of).
const MISSPELT: [(&[&str], &str, &str); 7] = [
    (&[], "wheel_dif", "wheel_diff"),
    (&["compass"], "calibraton", "calibration"),
    (&["compass", "calibration"], "hard_irn", "hard_iron"),
    (&["compass", "quality"], "field_magnitud", "field_magnitude"),
    (&["compass", "quality", "fit"], "pointz", "points"),
    (
        &["compass", "quality", "uncertainty"],
        "dilutio",
        "dilution",
    ),
    (&["gyro_bias_rps"], "sigm", "sigma"),
];

#[test]
fn an_unknown_key_at_any_depth_of_a_learned_state_is_refused_with_the_closest_one() {
    let dir = common::scratch("cli_strictness", "learned");
    let log = common::compass_drive_log(&dir);
    let vehicle = common::rear_vehicle(&dir, 1.55);
    let learned = dir.join("learned.json");
    let track = dir.join("track.csv");
    common::succeeded(common::drive(
        &vehicle,
        &log,
        &track,
        &["--calibration-out", p(&learned)],
    ));
    let written = common::read_json(&learned);
    let input = dir.join("in.json");
    let with = |v: &Value| {
        std::fs::write(&input, v.to_string()).unwrap();
        outcome(&common::drive(
            &vehicle,
            &log,
            &track,
            &["--calibration-in", p(&input)],
        ))
    };
    let (ran, err) = with(&written);
    assert!(ran, "the file as written is read: {err}");
    for (path, key, meant) in MISSPELT {
        let mut v = written.clone();
        let object = path
            .iter()
            .fold(&mut v, |v, k| &mut v[*k])
            .as_object_mut()
            .unwrap_or_else(|| panic!("{path:?} is an object in {written}"));
        assert!(object.contains_key(meant), "{path:?} has `{meant}`");
        object.insert(key.into(), 1.into());
        let (ran, err) = with(&v);
        assert!(!ran, "{path:?}: `{key}` accepted");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(p(&input)), "names the file: {err}");
        assert!(
            err.contains(&format!("unknown key `{key}` (did you mean `{meant}`?)")),
            "{path:?}: {err}"
        );
        if !path.is_empty() {
            assert!(
                err.contains(&format!("in `{}`", path.join("."))),
                "names where: {err}"
            );
        }
    }
}

/// `--help` and `--version` into a full disk: one line on stderr and a failure, as for any
/// other output that cannot be written.
#[test]
fn help_and_version_into_a_full_disk_fail_with_one_line() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("SKIPPED: no /dev/full here");
        return;
    };
    for arg in ["--help", "--version", "help"] {
        let out = common::binary()
            .arg(arg)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{arg}: {err}");
        assert_eq!(err.lines().count(), 1, "{arg}: {err}");
        assert!(err.contains("standard output"), "{arg}: {err}");
    }
    // Written where it can be, the help is still the help, and a success.
    let out = common::succeeded(common::truenorth(&["--help"]));
    assert!(String::from_utf8_lossy(&out.stdout).contains("Usage: truenorth"));
}
