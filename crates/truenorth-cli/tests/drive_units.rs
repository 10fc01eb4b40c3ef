//! `truenorth drive` checks its yaw gyro against the wheels through the turns of the drive,
//! and `inspect` reports the same comparison: a gyro in deg/s read as rad/s, or one whose
//! sign is flipped, is named with the option that fixes it; declared right, it runs.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::{ok, p, run, scratch};
use serde_json::Value;
use truenorth_sim::{DriveSpec, SimulatedDrive};

/// Writes the drive's distances, its gyro times `gyro_factor`, and its compass.
fn write_drive(drive: &SimulatedDrive, path: &Path, gyro_factor: f64) {
    let mut s = String::from("t_s,dist_l_m,dist_r_m,gyr_z,mag_x,mag_y\n");
    for x in &drive.samples {
        let (w, m) = (x.wheels.unwrap(), x.mag.unwrap());
        let g = x.gyr_z_rps.unwrap() * gyro_factor;
        writeln!(
            s,
            "{},{},{},{g},{},{}",
            x.t_s, w.dist_l_m, w.dist_r_m, m.x, m.y
        )
        .unwrap();
    }
    std::fs::write(path, s).unwrap();
}

/// Runs `drive` on `input` with `extra`: (success, stderr).
fn drive(dir: &Path, input: &Path, extra: &[&str]) -> (bool, String) {
    let vehicle = common::rear_vehicle(dir, 1.55);
    common::outcome(&common::drive(&vehicle, input, &dir.join("out.csv"), extra))
}

#[test]
fn a_gyro_in_the_wrong_unit_or_sign_is_named_by_drive_and_inspect() {
    let dir = scratch("drive_units", "sim");
    let sim = SimulatedDrive::new(DriveSpec {
        length_m: 3000.0,
        ..DriveSpec::new(5)
    })
    .unwrap();
    let (good, degrees, flipped) = (
        dir.join("good.csv"),
        dir.join("degrees.csv"),
        dir.join("flipped.csv"),
    );
    write_drive(&sim, &good, 1.0);
    write_drive(&sim, &degrees, 1f64.to_degrees());
    write_drive(&sim, &flipped, -1.0);

    let (ran, err) = drive(&dir, &good, &[]);
    assert!(ran, "{err}");
    let (ran, err) = drive(&dir, &degrees, &[]);
    assert!(!ran && err.contains("--gyro-unit deg/s"), "{err}");
    let (ran, err) = drive(&dir, &degrees, &["--gyro-unit", "deg/s"]);
    assert!(ran, "{err}");
    let (ran, err) = drive(&dir, &flipped, &[]);
    assert!(!ran && err.contains("--column gyr_z=-gyr_z"), "{err}");
    assert!(err.contains("--accept-axes"), "{err}");
    let (ran, err) = drive(&dir, &flipped, &["--column", "gyr_z=-gyr_z"]);
    assert!(ran, "{err}");
    let (ran, err) = drive(&dir, &flipped, &["--accept-axes"]);
    assert!(ran && err.contains("warning"), "{err}");

    let yaw = |file: &Path| -> Value {
        let o = ok(&["inspect", p(file), "--json"]);
        let r: Value = serde_json::from_slice(&o.stdout).unwrap();
        println!("{}: {}", file.display(), r["yaw"]);
        r
    };
    let r = yaw(&good);
    let track = r["yaw"]["implied_track_m"].as_f64().unwrap();
    assert!((track / 1.55 - 1.0).abs() < 0.1, "implied track {track} m");
    assert_eq!(r["yaw"]["likely_unit"], "rad/s");
    let r = yaw(&degrees);
    assert_eq!(r["yaw"]["likely_unit"], "deg/s");
    assert!(
        r["options"]
            .as_array()
            .unwrap()
            .contains(&Value::from("--gyro-unit deg/s"))
    );
    let r = yaw(&flipped);
    assert_eq!(r["yaw"]["flipped"], true);
    assert!(
        r["options"]
            .as_array()
            .unwrap()
            .contains(&Value::from("--column gyr_z=-gyr_z"))
    );
    // The table names the same.
    let table = String::from_utf8(ok(&["inspect", p(&flipped)]).stdout).unwrap();
    assert!(
        table.contains("sign flipped") && table.contains("--column gyr_z=-gyr_z"),
        "{table}"
    );
}

/// The real car's straight minute does not turn enough to judge its gyro: it is accepted
/// as published, and `inspect` says so rather than guess.
#[test]
fn a_straight_real_drive_is_not_judged() {
    let Some(data) = truenorth_sim::shared_data::folder("vehicle_comma2k19_example").unwrap()
    else {
        return;
    };
    let dir = scratch("drive_units", "comma");
    let imu = data.join("imu.csv");
    let columns = "t_s=t_boot_s,gyr_x=gyr_f_rps,gyr_y=gyr_r_rps,gyr_z=gyr_d_rps,acc_x=acc_f_mps2,acc_y=acc_r_mps2,acc_z=acc_d_mps2";
    let o = ok(&["inspect", p(&imu), "--column", columns, "--json"]);
    let r: Value = serde_json::from_slice(&o.stdout).unwrap();
    println!("comma2k19 imu: gyro {} acc {}", r["gyro"], r["acc"]);
    assert_eq!(r["acc"]["likely_unit"], "m/s2");
    assert_eq!(r["acc"]["up_axis"], "-z");
    assert!(r["gyro"]["likely_unit"].is_null());
    assert!(
        r["options"]
            .as_array()
            .unwrap()
            .iter()
            .all(|o| !o.as_str().unwrap().contains("--column"))
    );
    // Orientation runs on it as published (nothing to refuse).
    let out = dir.join("o.csv");
    let o = run(
        &[
            "orientation",
            "--input",
            p(&imu),
            "--output",
            p(&out),
            "--column",
            columns,
        ],
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
