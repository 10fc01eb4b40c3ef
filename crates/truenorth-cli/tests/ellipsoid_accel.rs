//! `calibrate --method ellipsoid-accel` and tilt-compensated `heading`, run as a user runs
//! them on a simulated 24-shot protocol of a hand-held instrument with known truth.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::p;

use truenorth::core::{SplitMix64, angle_diff};
use truenorth_sim::{FewShotInstrument, Shot, protocol_shots, random_attitude};

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_ellipsoid_accel", name)
}

/// Shots as a CSV in the sensors' raw axes; `gravity` writes the accelerometer negated, as
/// a sensor reporting the gravity vector does.
fn csv(shots: &[Shot], gravity: bool) -> String {
    let sign = if gravity { -1.0 } else { 1.0 };
    let mut s = String::from("t_s,mag_x,mag_y,mag_z,gx,gy,gz\n");
    for (k, shot) in shots.iter().enumerate() {
        let (m, a) = (shot.mag, shot.acc * sign);
        writeln!(s, "{k},{},{},{},{},{},{}", m.x, m.y, m.z, a.x, a.y, a.z).unwrap();
    }
    s
}

/// Rows of a CSV output: header and numbers.
fn rows(text: &str) -> (String, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// The protocol calibrates both sensors; fresh shots at any tilt then read the heading of
/// the pointing axis to within the shot noise and the calibration's own bound, and their
/// pitch and roll. An accelerometer reporting gravity is read through a negating column
/// mapping and gives the same result.
#[test]
fn ellipsoid_accel_then_tilt_compensated_heading() {
    let dir = scratch("protocol");
    let ins = FewShotInstrument::typical(21);
    let shots = protocol_shots(&ins, 8, 2, 8, 21);
    let input = dir.join("shots.csv");
    std::fs::write(&input, csv(&shots, true)).unwrap();
    let cal = dir.join("cal.json");
    let out = common::succeeded(common::calibrate(
        "ellipsoid-accel",
        &input,
        &cal,
        &[
            "--column",
            "acc_x=-gx,acc_y=-gy,acc_z=-gz",
            "--mag-unit",
            "uT",
        ],
    ));
    let summary = String::from_utf8(out.stderr).unwrap();
    assert_eq!(summary.lines().count(), 1, "{summary}");
    assert!(
        summary.contains("ellipsoid-accel") && summary.contains("dip"),
        "{summary}"
    );
    let json = common::read_json(&cal);
    assert_eq!(json["version"], 2);
    assert_eq!(json["dimensions"], 3);
    assert!(
        (json["dip_deg"].as_f64().unwrap() - 65.0).abs() < 0.5,
        "{}",
        json["dip_deg"]
    );
    let q = &json["quality"];
    assert_eq!(q["runs"], 2);
    assert_eq!(q["run_shots"], 16);
    assert_ne!(q["verdict"], "poor");
    for key in [
        "dip_spread_deg",
        "alignment_deg",
        "accel_residual_rms_rel",
        "pointing_offset_deg",
    ] {
        assert!(q[key].as_f64().is_some_and(f64::is_finite), "{key}");
        assert!(json["units"][format!("quality.{key}")].is_string(), "{key}");
    }
    let gravity = json["accelerometer"]["gravity"].as_f64().unwrap();
    assert!((gravity / 9.80665 - 1.0).abs() < 0.05, "{gravity}");
    let bound = q["heading_error_bound_deg"].as_f64().unwrap();

    // Fresh shots within ±60° of level, any roll.
    let mut rng = SplitMix64::new(5);
    let fresh: Vec<Shot> = (0..100)
        .map(|_| ins.shot(random_attitude(&mut rng, 60f64.to_radians()), &mut rng))
        .collect();
    let test = dir.join("fresh.csv");
    std::fs::write(&test, csv(&fresh, true)).unwrap();
    let out = common::succeeded(common::heading(
        &cal,
        &test,
        Path::new("-"),
        &["--column", "acc_x=-gx,acc_y=-gy,acc_z=-gz"],
    ));
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("tilt-compensated with the calibrated accelerometer"),
        "{note}"
    );
    let (header, got) = rows(&String::from_utf8(out.stdout).unwrap());
    assert_eq!(header, "t_s,heading_deg,pitch_deg,roll_deg");
    // Shot noise (0.1 % of the field and of g: about 0.2° of heading RMS) at 4σ, plus the
    // calibration's own 3σ bound.
    let allowed = bound + 4.0 * 0.2;
    for (r, s) in got.iter().zip(&fresh) {
        let e = angle_diff(r[1].to_radians(), s.attitude.yaw_rad).to_degrees();
        assert!(
            e.abs() <= allowed,
            "heading off by {e}° (allowed {allowed})"
        );
        assert!(
            (r[2] - s.attitude.pitch_rad.to_degrees()).abs() < 1.0,
            "pitch {r:?}"
        );
        // Roll about the pointing axis is measured from the accelerometer's own axes: no
        // shot can tell how the instrument's "up" sits about that axis, so roll keeps the
        // accelerometer's mounting error (1° per axis in this simulation, at 3σ), doubled
        // at 60° of pitch where roll is measured from a gravity component half as large.
        let roll = angle_diff(r[3].to_radians(), s.attitude.roll_rad).to_degrees();
        assert!(roll.abs() < 6.0, "roll off by {roll}°");
    }

    // Without the accelerometer the same file reads as level, and says so.
    let level = dir.join("level.csv");
    let text: String = csv(&fresh, true)
        .lines()
        .map(|l| l.splitn(5, ',').take(4).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    std::fs::write(&level, text).unwrap();
    let out = common::succeeded(common::heading(&cal, &level, Path::new("-"), &[]));
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(note.contains("level sensor assumed"), "{note}");
    let (header, _) = rows(&String::from_utf8(out.stdout).unwrap());
    assert_eq!(header, "t_s,heading_deg");
}

/// A calibration file that would give constant, mirrored or NaN headings is refused on
/// load with the reason, and nothing is written.
#[test]
fn unusable_calibrations_are_refused_on_load() {
    let dir = scratch("bad_files");
    let input = dir.join("in.csv");
    std::fs::write(
        &input,
        "t_s,mag_x,mag_y,mag_z,acc_x,acc_y,acc_z\n0,1,2,3,0,0,-9.8\n",
    )
    .unwrap();
    let identity = "[[1,0,0],[0,1,0],[0,0,1]]";
    let base = |soft: &str, extra: &str| {
        format!(
            r#"{{"format":"truenorth-compass-calibration","version":2,"method":"x","dimensions":3,"hard_iron":[0,0,0],"soft_iron":{soft},"field":50{extra}}}"#
        )
    };
    let accel =
        r#","accelerometer":{"bias":[0,0,0],"matrix":[[1,0,0],[0,1,0],[0,0,1]],"gravity":9.8}"#;
    let cases = [
        ("zero", base("[[0,0,0],[0,0,0],[0,0,0]]", ""), "determinant"),
        (
            "rank1",
            base("[[1,1,1],[1,1,1],[1,1,1]]", ""),
            "determinant",
        ),
        (
            "mirror",
            base("[[1,0,0],[0,1,0],[0,0,-1]]", ""),
            "determinant",
        ),
        (
            "flat",
            base("[[1,0,0],[0,1,0],[0,0,0.001]]", ""),
            "condition number",
        ),
        (
            "version",
            base(identity, "").replace("\"version\":2", "\"version\":7"),
            "version 7",
        ),
        (
            "nan",
            base(identity, "").replace("\"field\":50", "\"field\":-1"),
            "field",
        ),
        (
            "not_a_rotation",
            base(
                identity,
                &format!(r#","mag_to_body":[[2,0,0],[0,1,0],[0,0,1]]{accel}"#),
            ),
            "not a rotation",
        ),
        ("half_joint", base(identity, accel), "both"),
    ];
    for (name, text, why) in cases {
        let cal = dir.join(format!("{name}.json"));
        std::fs::write(&cal, text).unwrap();
        let out_path = dir.join(format!("{name}.csv"));
        let out = common::heading(&cal, &input, &out_path, &[]);
        assert_eq!(out.status.code(), Some(1), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(p(&cal)) && err.contains(why), "{name}: {err}");
        assert!(!out_path.exists(), "{name}");
    }
}

/// With the place given, a joint fit whose dip has the wrong sign for it (an accelerometer
/// giving gravity read as specific force: the fit is as good, the dip −65° where Berlin's
/// field dips +68°) is refused naming the fix; read right, it is written.
#[test]
fn a_dip_of_the_wrong_sign_for_the_place_is_refused() {
    let dir = scratch("dip_sign");
    let ins = FewShotInstrument::typical(21);
    let shots = protocol_shots(&ins, 8, 2, 8, 21);
    let input = dir.join("shots.csv");
    std::fs::write(&input, csv(&shots, true)).unwrap();
    let cal = dir.join("cal.json");
    let place = [
        "--mag-unit",
        "uT",
        "--lat",
        "52.5",
        "--lon",
        "13.4",
        "--date",
        "2026.5",
    ];
    let wrong: Vec<&str> = ["--column", "acc_x=gx,acc_y=gy,acc_z=gz"]
        .into_iter()
        .chain(place)
        .collect();
    let (ok, err) = common::outcome(&common::calibrate("ellipsoid-accel", &input, &cal, &wrong));
    assert!(!ok, "{err}");
    assert!(
        err.contains("the fitted dip is -") && err.contains("acc_x=-"),
        "{err}"
    );
    assert!(!cal.exists(), "nothing written");
    let right: Vec<&str> = ["--column", "acc_x=-gx,acc_y=-gy,acc_z=-gz"]
        .into_iter()
        .chain(place)
        .collect();
    let (ok, err) = common::outcome(&common::calibrate("ellipsoid-accel", &input, &cal, &right));
    assert!(ok, "{err}");
    // The same check where the calibration is used: `heading` with the place refuses a
    // file whose dip has the other sign (here edited), and says it under
    // --accept-calibration.
    let mut json = common::read_json(&cal);
    let dip = json["dip_deg"].as_f64().unwrap();
    assert!(dip > 10.0, "{dip}");
    json["dip_deg"] = serde_json::json!(-dip);
    let flipped = dir.join("flipped.json");
    std::fs::write(&flipped, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    let extra = [
        "--lat",
        "52.5",
        "--lon",
        "13.4",
        "--date",
        "2026.5",
        "--column",
        "acc_x=-gx,acc_y=-gy,acc_z=-gz",
    ];
    let out = dir.join("h.csv");
    let (ok, err) = common::outcome(&common::heading(&flipped, &input, &out, &extra));
    assert!(!ok && err.contains("the calibration's dip is -"), "{err}");
    let (ok, err) = common::outcome(&common::heading(&cal, &input, &out, &extra));
    assert!(ok, "{err}");
    let accepted: Vec<&str> = extra.into_iter().chain(["--accept-calibration"]).collect();
    let (ok, err) = common::outcome(&common::heading(&flipped, &input, &out, &accepted));
    assert!(ok && err.contains("warning"), "{err}");
}
