//! `heading --lat/--lon/--date`: true heading is magnetic heading plus the declination that
//! `truenorth field` reports for the same place and date, added exactly once.

mod common;

use std::path::{Path, PathBuf};

use common::{ScratchDir, TURN_HEADER, calibrate, heading, ok, succeeded};

fn headings(path: &Path) -> Vec<f64> {
    common::headings(&std::fs::read_to_string(path).expect("output written"))
}

/// A fresh folder holding `turn.csv`: a level compass turning through 360° one degree per
/// row, reading `field·(cos h, −sin h) + hard_iron`. Returns (folder, csv path).
fn level_turn(tag: &str, field: f64, hard_iron: [f64; 2]) -> (ScratchDir, PathBuf) {
    let dir = common::scratch("cli_true_heading", tag);
    let input = dir.join("turn.csv");
    let csv = TURN_HEADER.to_string() + &common::turn_rows(360, 0.1, field, hard_iron, 0.0);
    std::fs::write(&input, csv).unwrap();
    (dir, input)
}

#[test]
fn true_heading_adds_the_wmm_declination_once() {
    // A level compass turning through a full circle with hard iron (3, -2) on a 20 µT field.
    let (dir, input) = level_turn("true-heading", 20.0, [3.0, -2.0]);
    let cal = dir.join("cal.json");
    succeeded(calibrate("ellipse", &input, &cal, &[]));

    let magnetic = dir.join("magnetic.csv");
    succeeded(heading(&cal, &input, &magnetic, &[]));
    let truth = dir.join("true.csv");
    let place = ["--lat", "51.5", "--lon", "-0.13", "--date", "2026.5"];
    succeeded(heading(&cal, &input, &truth, &place));

    let field = ok(&[&["field"][..], &place[..]].concat()).stdout;
    let field = String::from_utf8_lossy(&field);
    let decl: f64 = field
        .lines()
        .nth(1)
        .and_then(|r| r.split(',').nth(6))
        .and_then(|d| d.parse().ok())
        .unwrap();
    assert!(decl.abs() > 0.1, "London's declination is not ~0: {decl}");
    let (m, t) = (headings(&magnetic), headings(&truth));
    assert_eq!(m.len(), 360);
    for (k, (m, t)) in m.iter().zip(&t).enumerate() {
        assert!((0.0..360.0).contains(t));
        let d = (t - m - decl + 540.0).rem_euclid(360.0) - 180.0;
        assert!(
            d.abs() < 1e-4,
            "row {k}: true {t} magnetic {m} declination {decl}"
        );
        // And the magnetic heading is the simulated one.
        let e = (m - k as f64 + 540.0).rem_euclid(360.0) - 180.0;
        assert!(e.abs() < 1e-6, "row {k}: magnetic {m}");
    }

    // A date without a place is refused with one line.
    let out = heading(&cal, &input, &dir.join("x.csv"), &["--date", "2026.5"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--lat"), "{err}");
}

#[test]
fn calibrate_compares_the_fit_with_the_wmm_field() {
    // 19.6 µT: London's horizontal field in 2026 (WMM2025 gives 19.56 µT).
    let (dir, input) = level_turn("expected-field", 19.6, [0.0, 0.0]);
    let cal = dir.join("cal.json");
    let place = ["--lat", "51.5", "--lon", "-0.13", "--date", "2026.5"];
    let with_unit = |unit: &str| {
        calibrate(
            "ellipse",
            &input,
            &cal,
            &[&place[..], &["--mag-unit", unit]].concat(),
        )
    };
    let ok = with_unit("uT");
    assert!(ok.status.success());
    // One summary line, no warning.
    let summary = String::from_utf8_lossy(&ok.stderr);
    assert_eq!(summary.lines().count(), 1, "{summary}");
    assert!(
        summary.starts_with("truenorth: calibrate:") && !summary.contains("warning"),
        "{summary}"
    );
    let json = std::fs::read_to_string(&cal).unwrap();
    let ratio: f64 = json
        .split("\"field_ratio_to_expected\":")
        .nth(1)
        .and_then(|r| r.split([',', '}']).next())
        .and_then(|r| r.trim().parse().ok())
        .unwrap();
    assert!((ratio - 1.0).abs() < 0.01, "{ratio}");

    // Readings in µT declared as mG: ten times too small a field, which no site makes. The
    // calibration is refused, naming the unit the data are in; nothing is written.
    std::fs::remove_file(&cal).unwrap();
    let wrong = with_unit("mG");
    assert_eq!(wrong.status.code(), Some(1));
    let err = String::from_utf8_lossy(&wrong.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("probably in uT") && err.contains("--accept-field-mismatch"),
        "{err}"
    );
    assert!(!cal.exists());
    // Accepted on request, with the warning and the summary.
    let forced = calibrate(
        "ellipse",
        &input,
        &cal,
        &[&place[..], &["--mag-unit", "mG", "--accept-field-mismatch"]].concat(),
    );
    assert!(forced.status.success());
    let err = String::from_utf8_lossy(&forced.stderr);
    assert_eq!(err.lines().count(), 2, "{err}");
    assert!(
        err.contains("warning") && err.contains("probably in uT"),
        "{err}"
    );
    // --mag-unit alone checks the field against the Earth's range.
    let alone = calibrate("ellipse", &input, &cal, &["--mag-unit", "nT"]);
    assert_eq!(alone.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&alone.stderr).contains("probably in uT"));
}
