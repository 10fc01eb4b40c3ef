//! A recording with a one-hour gap in the middle, through each command, and what each does
//! with it, from the physics of what it computes:
//!
//! - `calibrate`: hard and soft iron belong to the installation, not to the moment; a fit
//!   that does not follow the readings in time takes both halves alike, so the gap changes
//!   nothing: accepted, with the calibration of the same readings without the gap.
//! - `heading`: each row's heading is its own reading through the calibration; a gap between
//!   rows changes no row: every row out, continuous across it.
//! - `orientation`: the gyro's integrated attitude cannot bridge an hour (the body may have
//!   turned any way): the filter restarts from the accelerometer and magnetometer at the
//!   first row after the gap, flags it (`gap` with `--status`), resets σ to that of an
//!   attitude taken from one reading, and says at which row.
//! - `drive`: the cumulative wheel distances still say how far the vehicle went across the
//!   gap, the heading it went at is unknown: the position goes on, its σ widened rather
//!   than the path bridged, and the summary says so.

mod common;

use common::*;
use std::fmt::Write as _;
use std::path::Path;

const GAP_S: f64 = 3600.0;

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

/// Two turns of a tilted 2-D ellipse at 10 Hz, the second after `gap_s`.
fn compass(gap_s: f64) -> String {
    let mut s = String::from("t_s,mag_x,mag_y\n");
    let n = 1440;
    for k in 0..n {
        let t = k as f64 * 0.1 + if k >= n / 2 { gap_s } else { 0.0 };
        let a = std::f64::consts::TAU * 2.0 * k as f64 / n as f64;
        // A deterministic ripple for noise.
        let e = 0.2 * (37.0 * a).sin();
        let x = 20.0 + 31.0 * a.cos() + 2.0 * a.sin() + e;
        let y = -10.0 + 4.0 * a.cos() + 27.0 * a.sin() - e;
        writeln!(s, "{t:.2},{x:.4},{y:.4}").unwrap();
    }
    s
}

fn rows(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

fn number(v: &serde_json::Value, key: &str) -> Vec<f64> {
    fn walk(v: &serde_json::Value, key: &str, out: &mut Vec<f64>) {
        match v {
            serde_json::Value::Object(m) => {
                for (k, x) in m {
                    if k == key {
                        collect(x, out);
                    } else {
                        walk(x, key, out);
                    }
                }
            }
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, key, out)),
            _ => {}
        }
    }
    fn collect(v: &serde_json::Value, out: &mut Vec<f64>) {
        match v {
            serde_json::Value::Number(n) => out.push(n.as_f64().unwrap()),
            serde_json::Value::Array(a) => a.iter().for_each(|x| collect(x, out)),
            serde_json::Value::Object(m) => m.values().for_each(|x| collect(x, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, key, &mut out);
    out
}

#[test]
fn calibrate_takes_both_sides_of_an_hour_gap_alike() {
    let d = scratch("long_gaps", "calibrate");
    let (gap, none) = (d.join("gap.csv"), d.join("none.csv"));
    write(&gap, &compass(GAP_S));
    write(&none, &compass(0.0));
    for method in ["ellipse", "online-ellipse", "binned-ellipse"] {
        let out = |input: &Path, name: &str| {
            let path = d.join(format!("{method}-{name}.json"));
            ok(&[
                "calibrate",
                "--method",
                method,
                "--input",
                p(input),
                "--output",
                p(&path),
            ]);
            serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&path).unwrap())
                .unwrap()
        };
        let (a, b) = (out(&gap, "gap"), out(&none, "none"));
        let (ha, hb) = (number(&a, "hard_iron"), number(&b, "hard_iron"));
        assert!(!ha.is_empty() && ha.len() == hb.len(), "{method}: {a}");
        for (x, y) in ha.iter().zip(&hb) {
            assert!(
                (x - y).abs() < 1e-6,
                "{method}: hard iron {ha:?} with the gap, {hb:?} without"
            );
        }
    }
}

#[test]
fn heading_gives_every_row_continuous_across_an_hour_gap() {
    let d = scratch("long_gaps", "heading");
    let (input, cal, out) = (d.join("in.csv"), d.join("cal.json"), d.join("out.csv"));
    write(&input, &compass(GAP_S));
    ok(&[
        "calibrate",
        "--method",
        "ellipse",
        "--input",
        p(&input),
        "--output",
        p(&cal),
    ]);
    ok(&[
        "heading",
        "--calibration",
        p(&cal),
        "--input",
        p(&input),
        "--output",
        p(&out),
    ]);
    let r = rows(&out);
    assert_eq!(r.len(), 1441);
    let h = |i: usize| r[i][1].parse::<f64>().unwrap();
    // Rows 720 and 721 are the last before the gap and the first after it: a tenth of a
    // second of the turn apart (0.5°) in heading.
    let step = truenorth::core::angle_diff(h(721).to_radians(), h(720).to_radians()).to_degrees();
    assert!(step.abs() < 2.0, "{} → {}", h(720), h(721));
}

#[test]
fn orientation_restarts_at_the_row_after_an_hour_gap_and_says_so() {
    let d = scratch("long_gaps", "orientation");
    let (input, out) = (d.join("imu.csv"), d.join("out.csv"));
    let mut s = String::from("t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n");
    let mut yaw = 0.0f64;
    for k in 0..6000 {
        let t = k as f64 * 0.01 + if k >= 3000 { GAP_S } else { 0.0 };
        yaw += 0.2 * 0.01;
        let (mx, my) = (20.0 * yaw.cos(), -20.0 * yaw.sin());
        writeln!(s, "{t:.2},0,0,0.2,0,0,-9.81,{mx:.4},{my:.4},40").unwrap();
    }
    write(&input, &s);
    let o = ok(&[
        "orientation",
        "--method",
        "quaternion",
        "--input",
        p(&input),
        "--output",
        p(&out),
        "--status",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("row 3002") && err.contains("restarted"),
        "{err}"
    );
    let r = rows(&out);
    let col = |name: &str| r[0].iter().position(|c| c == name).unwrap();
    let (gap, sigma_z) = (col("gap"), col("sigma_z_deg"));
    let flagged: Vec<usize> = (1..r.len()).filter(|&i| r[i][gap] == "1").collect();
    assert_eq!(flagged, [3001], "rows flagged as gaps");
    let sz = |i: usize| r[i][sigma_z].parse::<f64>().unwrap();
    assert!(
        sz(3001) > 5.0 * sz(3000),
        "σ_z {} before the gap, {} after",
        sz(3000),
        sz(3001)
    );
}

#[test]
fn drive_widens_rather_than_bridges_an_hour_gap() {
    let d = scratch("long_gaps", "drive");
    let (input, car, out) = (d.join("drive.csv"), d.join("car.json"), d.join("out.csv"));
    write(&car, r#"{"track_m": 1.5, "odometer_wheels": "rear"}"#);
    let mut s = String::from("t_s,dist_l_m,dist_r_m,gyr_z,mag_x,mag_y\n");
    let (mut yaw, mut l, mut r) = (0.0f64, 0.0, 0.0);
    for k in 0..1200 {
        let t = k as f64 * 0.1 + if k >= 600 { GAP_S } else { 0.0 };
        yaw += 0.01;
        l += 1.0 + 0.0075;
        r += 1.0 - 0.0075;
        let (mx, my) = (5.0 + 20.0 * yaw.cos(), -3.0 - 18.0 * yaw.sin());
        writeln!(s, "{t:.2},{l:.4},{r:.4},0.1,{mx:.4},{my:.4}").unwrap();
    }
    write(&input, &s);
    let o = ok(&[
        "drive",
        "--vehicle",
        p(&car),
        "--input",
        p(&input),
        "--output",
        p(&out),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("1 gaps in the log, widened rather than bridged"),
        "{err}"
    );
    let rows = rows(&out);
    assert_eq!(rows.len(), 1201);
    // Position goes on across the gap by the wheels' metre, heading by the turn's 0.6°.
    let v = |i: usize, j: usize| rows[i][j].parse::<f64>().unwrap();
    let moved = ((v(601, 1) - v(600, 1)).powi(2) + (v(601, 2) - v(600, 2)).powi(2)).sqrt();
    assert!((moved - 1.0).abs() < 0.1, "moved {moved} m across the gap");
    assert!(
        rows.iter()
            .skip(1)
            .all(|r| r.iter().all(|c| c.parse::<f64>().unwrap().is_finite()))
    );
}
