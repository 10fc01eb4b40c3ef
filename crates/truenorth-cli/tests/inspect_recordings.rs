//! `truenorth inspect` on the real recordings: it finds each one's units and gyro axes as
//! published; with a unit or the gyro's axes made wrong (a rewritten copy, or the
//! `--column` negation and swap) it names the wrong one and the options that fix it, and
//! `orientation` refuses the wrong reading and runs the corrected one.

mod common;

use std::io::Read as _;
use std::path::{Path, PathBuf};

use common::{broad_trials, p, run, scratch};
use serde_json::Value;

/// x-io's recording: its column names, read with x forward, y left, z up.
const XIO_COLUMNS: &str = "t_s=Time (s),gyr_x=Gyroscope X (deg/s),gyr_y=Gyroscope Y (deg/s),gyr_z=Gyroscope Z (deg/s),acc_x=Accelerometer X (g),acc_y=Accelerometer Y (g),acc_z=Accelerometer Z (g),mag_x=Magnetometer X (uT),mag_y=Magnetometer Y (uT),mag_z=Magnetometer Z (uT)";

/// `inspect --json` of `file` with `extra` options.
fn inspect(file: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["inspect", p(file), "--json"];
    args.extend_from_slice(extra);
    let o = common::ok(&args);
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Runs `orientation` on `file` with `extra`: (success, stderr).
fn orientation(file: &Path, out: &Path, extra: &[&str]) -> (bool, String) {
    let mut args = vec!["orientation", "--input", p(file), "--output", p(out)];
    args.extend_from_slice(extra);
    let o = run(&args, None);
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The margins a report gives, on one line.
fn margins(name: &str, r: &Value) -> String {
    let (g, a) = (&r["gyro"], &r["gyro"]["axes"]);
    format!(
        "{name:<42} gyro {} (other unit {:.1}x), axes as read {:.2}° {} (best {} {:.2}°, runner-up {:.1}x, typical {:.1}x, spans {}+{}), acc {}, mag {}",
        g["likely_unit"],
        g["unit_margin"].as_f64().unwrap_or(f64::NAN),
        a["as_read_deg"].as_f64().unwrap_or(f64::NAN),
        a["verdict"],
        a["best"],
        a["best_deg"].as_f64().unwrap_or(f64::NAN),
        a["margin"].as_f64().unwrap_or(f64::NAN),
        a["typical_margin"].as_f64().unwrap_or(f64::NAN),
        a["spans_gravity"],
        a["spans_magnetic"],
        r["acc"]["likely_unit"],
        r["mag"]["likely_unit"],
    )
}

/// Every real IMU recording as published: the units it is in, and the gyro read along the
/// other sensors' axes (the best of the 48 mappings is the identity).
#[test]
fn every_real_recording_is_found_in_its_units_and_axes() {
    let Some(trials) = broad_trials() else { return };
    let mut cases: Vec<(PathBuf, Vec<&str>, &str, &str)> = trials
        .into_iter()
        .map(|t| (t, vec![], "rad/s", "m/s2"))
        .collect();
    if let Some(xio) = truenorth_sim::shared_data::folder("xio_fusion").unwrap() {
        let args = vec!["--column", XIO_COLUMNS, "--axes", "flu"];
        cases.push((xio.join("sensor_data.csv"), args, "deg/s", "g"));
    }
    for (file, args, gyro, acc) in &cases {
        let r = inspect(file, args);
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        println!("{}", margins(&name, &r));
        assert_eq!(r["gyro"]["likely_unit"], *gyro, "{name}");
        assert_eq!(r["acc"]["likely_unit"], *acc, "{name}");
        assert_eq!(r["mag"]["likely_unit"], "uT", "{name}");
        assert_eq!(r["gyro"]["axes"]["verdict"], "ok", "{name}");
        assert_eq!(r["gyro"]["axes"]["best"], "x=x,y=y,z=z", "{name}");
        let options = r["options"].as_array().unwrap();
        assert!(options.contains(&Value::from(format!("--gyro-unit {gyro}"))));
        assert!(
            options
                .iter()
                .all(|o| !o.as_str().unwrap().contains("--column"))
        );
    }
}

/// The gyro read wrong in four ways through `--column` (one flipped axis, x and y swapped
/// — both mirror images —, x and y turned by 90°, a rotation, and every axis reversed, the
/// left-handed mapping that turns every rotation backwards): `inspect` names the mapping
/// that undoes it and the `--column` to pass; `orientation` refuses the wrong reading
/// naming that option, and runs with it.
#[test]
fn wrong_gyro_axes_are_named_refused_and_fixed() {
    let Some(trials) = broad_trials() else { return };
    let dir = scratch("inspect", "axes");
    let out = dir.join("out.csv");
    let wrongs = [
        ("gyr_y=-gyr_y", "x=x,y=-y,z=z", false),
        ("gyr_x=gyr_y,gyr_y=gyr_x", "x=y,y=x,z=z", false),
        ("gyr_x=-gyr_y,gyr_y=gyr_x", "x=y,y=-x,z=z", true),
        (
            "gyr_x=-gyr_x,gyr_y=-gyr_y,gyr_z=-gyr_z",
            "x=-x,y=-y,z=-z",
            false,
        ),
    ];
    // Slow and fast rotation, slow translation (the fewest gravity turns), tapping.
    for trial in [0, 4, 6, 11].map(|k| &trials[k]) {
        for (k, (mapping, undo, rotation)) in wrongs.iter().enumerate() {
            let r = inspect(trial, &["--column", mapping]);
            let axes = &r["gyro"]["axes"];
            let name = format!("{} {mapping}", trial.file_name().unwrap().to_string_lossy());
            println!("{}", margins(&name, &r));
            assert_eq!(axes["verdict"], "wrong", "{name}");
            assert_eq!(axes["best"], *undo, "{name}");
            assert_eq!(axes["best_is_rotation"], *rotation, "{name}");
            let fix = axes["fix"].as_str().unwrap();
            assert_eq!(fix, "gyr_x=gyr_x,gyr_y=gyr_y,gyr_z=gyr_z", "{name}");
            assert!(
                r["options"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|o| o == &Value::from(format!("--column {fix}")))
            );
            // Refused (quickly: before anything is estimated) on every trial; run with the
            // fix on one, and with --accept-axes on another.
            let (ok, err) = orientation(trial, &out, &["--column", mapping]);
            assert!(!ok && err.contains(&format!("--column {fix}")), "{err}");
            assert!(err.contains("--accept-axes"), "{err}");
            if trial == &trials[0] {
                let (ok, err) = orientation(trial, &out, &["--column", mapping, "--column", fix]);
                assert!(ok, "{name} with the fix: {err}");
            }
            if trial == &trials[4] && k == 0 {
                let (ok, err) = orientation(trial, &out, &["--column", mapping, "--accept-axes"]);
                assert!(ok && err.contains("warning"), "{err}");
            }
        }
    }
}

/// x-io's recording with its gyro's x and y columns swapped: named, with the fix quoted for
/// a shell (its headers have blanks) and composed with the mapping and `--axes flu` given.
#[test]
fn a_swap_in_a_recording_with_its_own_headers_is_fixed_in_those_headers() {
    let Some(xio) = truenorth_sim::shared_data::folder("xio_fusion").unwrap() else {
        return;
    };
    let file = xio.join("sensor_data.csv");
    let swap = "gyr_x=Gyroscope Y (deg/s),gyr_y=Gyroscope X (deg/s)";
    let base = ["--column", XIO_COLUMNS, "--axes", "flu", "--column", swap];
    let r = inspect(&file, &base);
    println!("{}", margins("xio swapped x/y", &r));
    let axes = &r["gyro"]["axes"];
    assert_eq!(axes["verdict"], "wrong");
    let fix = axes["fix"].as_str().unwrap();
    assert_eq!(
        fix,
        "gyr_x=Gyroscope X (deg/s),gyr_y=Gyroscope Y (deg/s),gyr_z=Gyroscope Z (deg/s)"
    );
    let options = r["options"].as_array().unwrap();
    assert!(
        options.contains(&Value::from(format!("--column '{fix}'"))),
        "{options:?}"
    );
    let dir = scratch("inspect", "xio");
    let out = dir.join("out.csv");
    let units = ["--gyro-unit", "deg/s", "--acc-unit", "g"];
    let (ok, err) = orientation(&file, &out, &[&base[..], &units[..]].concat());
    assert!(!ok && err.contains("--column 'gyr_x=Gyroscope X"), "{err}");
    let fixed = [&base[..], &units[..], &["--column", fix][..]].concat();
    let (ok, err) = orientation(&file, &out, &fixed);
    assert!(ok, "{err}");
}

/// A gzip CSV rewritten with `f` applied to each cell of the columns whose header starts
/// with `prefix`.
fn rewritten(trial: &Path, prefix: &str, f: fn(f64) -> f64, to: &Path) {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(trial).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let hit: Vec<bool> = header.split(',').map(|h| h.starts_with(prefix)).collect();
    let mut out = format!("{header}\n");
    for line in lines {
        let cells: Vec<String> = line
            .split(',')
            .zip(&hit)
            .map(|(c, &h)| match c.parse::<f64>() {
                Ok(v) if h => f(v).to_string(),
                _ => c.to_string(),
            })
            .collect();
        out += &cells.join(",");
        out.push('\n');
    }
    std::fs::write(to, out).unwrap();
}

/// A BROAD trial rewritten with its gyro in deg/s, and another with its accelerometer in
/// g: `inspect` names the unit each is in; `orientation` refuses them read as rad/s and
/// m/s² naming the option, and runs with it.
#[test]
fn wrong_units_are_named_refused_and_fixed() {
    let Some(trials) = broad_trials() else { return };
    let dir = scratch("inspect", "units");
    let out = dir.join("out.csv");
    let degrees = dir.join("degrees.csv");
    rewritten(&trials[0], "gyr_", f64::to_degrees, &degrees);
    let gs = dir.join("gs.csv");
    rewritten(&trials[0], "acc_", |v| v / 9.80665, &gs);
    for (file, unit, option) in [(&degrees, "deg/s", "--gyro-unit"), (&gs, "g", "--acc-unit")] {
        let r = inspect(file, &[]);
        println!("{}", margins(&format!("01 in {unit}"), &r));
        let options = r["options"].as_array().unwrap();
        assert!(
            options.contains(&Value::from(format!("{option} {unit}"))),
            "{options:?}"
        );
        assert_eq!(r["gyro"]["axes"]["verdict"], "ok");
        let (ok, err) = orientation(file, &out, &[]);
        assert!(!ok && err.contains(&format!("{option} {unit}")), "{err}");
        let (ok, err) = orientation(file, &out, &[option, unit]);
        assert!(ok, "{err}");
    }
    let ratio = inspect(&degrees, &[])["gyro"]["rad_per_unit"]
        .as_f64()
        .unwrap();
    assert!((ratio * 57.2958 - 1.0).abs() < 0.1, "{ratio}");
}

/// The MPU6050 recordings of sunsided/sensor-fusion as published (deg/s, g; the
/// accelerometer gives the gravity vector, which turns as the specific force does): their
/// README says the gyro's x axis is reversed; against the accelerometer its x and y both
/// are (a rotation by 180° about z: full-sphere tumbling finds it with the runner-up 1.8
/// times worse; turns about x alone and about y alone find that axis reversed, the others'
/// signs left open). `inspect` names the mapping, `orientation` refuses the recordings as
/// published naming a `--column` fix, and runs with the full-sphere one.
#[test]
fn a_published_recording_with_reversed_gyro_axes_is_found() {
    let Some(dir) = truenorth_sim::shared_data::folder("magcal_sunsided_mpu6050_hmc5883l").unwrap()
    else {
        return;
    };
    let columns =
        "acc_x=acc_x_g,acc_y=acc_y_g,acc_z=acc_z_g,gyr_x=gyr_x_dps,gyr_y=gyr_y_dps,gyr_z=gyr_z_dps";
    let fix = "gyr_x=-gyr_x_dps,gyr_y=-gyr_y_dps,gyr_z=gyr_z_dps";
    let scratch_dir = scratch("inspect", "sunsided");
    let out = scratch_dir.join("out.csv");
    for (name, reversed) in [
        ("full-sphere", "x=-x,y=-y,z=z"),
        ("rotate-ccw-around-x-pointing-forward", "x=-x"),
        ("rotate-ccw-around-y-pointing-left", "y=-y"),
    ] {
        let file = dir.join(name).join("imu.csv.gz");
        let r = inspect(&file, &["--column", columns]);
        println!("{}", margins(name, &r));
        assert_eq!(r["gyro"]["likely_unit"], "deg/s", "{name}");
        assert_eq!(r["acc"]["likely_unit"], "g", "{name}");
        let axes = &r["gyro"]["axes"];
        assert_eq!(axes["verdict"], "wrong", "{name}");
        let best = axes["best"].as_str().unwrap();
        assert!(best.contains(reversed), "{name}: {best}");
        let units = ["--gyro-unit", "deg/s", "--acc-unit", "g"];
        let (ok, err) = orientation(
            &file,
            &out,
            &[&["--column", columns][..], &units[..]].concat(),
        );
        assert!(!ok && err.contains("--column gyr_x=-gyr_x_dps"), "{err}");
        let fixed = [&["--column", columns, "--column", fix][..], &units[..]].concat();
        let (ok, err) = orientation(&file, &out, &fixed);
        assert!(ok, "{name}: {err}");
    }
}
