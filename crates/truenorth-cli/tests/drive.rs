//! `truenorth drive` on simulated drives written as the command's input: the contract's
//! columns, what the options add, and the refusals.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::{p, scratch};
use truenorth_sim::{DriveSpec, DriveWheels, SimulatedDrive, vehicle_streams_disturbed};

/// Writes `drive` as DRIVE.csv (distances or speeds; with or without the gyro).
fn write_drive(drive: &SimulatedDrive, path: &Path, speeds: bool, gyro: bool) {
    let mut s = String::new();
    s += if speeds {
        "t_s,speed_l_mps,speed_r_mps"
    } else {
        "t_s,dist_l_m,dist_r_m"
    };
    s += if gyro { ",gyr_z" } else { "" };
    s += ",mag_x,mag_y\n";
    let mut last: Option<&truenorth::core::VehicleSample> = None;
    for x in &drive.samples {
        let w = x.wheels.unwrap();
        if speeds {
            // The speed that, integrated by the trapezoid rule, gives the distances back.
            let (vl, vr) = match last {
                Some(prev) => {
                    let dt = x.t_s - prev.t_s;
                    let p = prev.wheels.unwrap();
                    (
                        (w.dist_l_m - p.dist_l_m) / dt,
                        (w.dist_r_m - p.dist_r_m) / dt,
                    )
                }
                None => (0.0, 0.0),
            };
            write!(s, "{},{vl},{vr}", x.t_s).unwrap();
        } else {
            write!(s, "{},{},{}", x.t_s, w.dist_l_m, w.dist_r_m).unwrap();
        }
        if gyro {
            write!(s, ",{}", x.gyr_z_rps.unwrap()).unwrap();
        }
        let m = x.mag.unwrap();
        writeln!(s, ",{},{}", m.x, m.y).unwrap();
        last = Some(x);
    }
    std::fs::write(path, s).unwrap();
}

fn read_rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    common::table(path, false)
}

/// The vehicle file of a simulated car. The simulator's roads are flat and its compass
/// level, so the compass's systematic error is the installation's 0.3°, not the default's
/// 3° for roads that tilt it.
fn vehicle(dir: &Path, wheels: DriveWheels) -> std::path::PathBuf {
    let path = dir.join("vehicle.json");
    let json = match wheels {
        DriveWheels::Rear => {
            r#"{"track_m": 1.55, "odometer_wheels": "rear", "compass_systematic_deg": 0.3}"#
                .to_string()
        }
        DriveWheels::Front => {
            r#"{"track_m": 1.55, "wheelbase_m": 2.7, "odometer_wheels": "front", "pitman_ratio": 0.129, "compass_systematic_deg": 0.3}"#.to_string()
        }
    };
    std::fs::write(&path, json).unwrap();
    path
}

/// Final position error over distance and heading RMS (from the first absolute row) of
/// the command's output against the drive's truth.
fn errors(drive: &SimulatedDrive, rows: &[Vec<f64>]) -> (f64, f64) {
    assert_eq!(rows.len(), drive.truth.len());
    let mut sq = 0.0;
    for (r, t) in rows.iter().zip(&drive.truth) {
        let d = truenorth::core::angle_diff(r[3].to_radians(), t.heading_rad).to_degrees();
        sq += d * d;
    }
    let (last, t) = (rows.last().unwrap(), drive.truth.last().unwrap());
    let err = (last[1] - t.north_m).hypot(last[2] - t.east_m);
    (
        100.0 * err / drive.distance_m(),
        (sq / rows.len() as f64).sqrt(),
    )
}

#[test]
fn a_drive_from_distances_with_a_gyro_and_front_wheels_from_speeds() {
    for (wheels, speeds, gyro, limit_pct) in [
        (DriveWheels::Rear, false, true, 0.3),
        (DriveWheels::Front, true, false, 1.0),
    ] {
        let dir = scratch("drive", &format!("{wheels:?}-{speeds}-{gyro}"));
        let drive = SimulatedDrive::new(DriveSpec {
            wheels,
            length_m: 4000.0,
            ..DriveSpec::new(11)
        })
        .unwrap();
        let input = dir.join("drive.csv");
        write_drive(&drive, &input, speeds, gyro);
        let out = dir.join("out.csv");
        let veh = vehicle(&dir, wheels);
        let o = common::succeeded(common::drive(&veh, &input, &out, &[]));
        let (header, rows) = read_rows(&out);
        assert_eq!(header, ["t_s", "north_m", "east_m", "heading_deg"]);
        let (final_pct, heading_rms) = errors(&drive, &rows);
        assert!(
            final_pct < limit_pct,
            "{wheels:?}: final error {final_pct:.3} % of the distance"
        );
        assert!(
            heading_rms < if gyro { 0.5 } else { 1.0 },
            "{wheels:?}: heading RMS {heading_rms:.2}°"
        );
        assert!(rows.iter().all(|r| (0.0..360.0).contains(&r[3])));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(stderr.contains("magnetic north"), "{stderr}");
    }
}

#[test]
fn extra_columns_true_north_and_the_learned_calibration_carried_over() {
    let dir = scratch("drive", "extras");
    let drive = SimulatedDrive::new(DriveSpec {
        length_m: 2000.0,
        ..DriveSpec::new(5)
    })
    .unwrap();
    let input = dir.join("drive.csv");
    write_drive(&drive, &input, false, true);
    let veh = vehicle(&dir, DriveWheels::Rear);
    let (out, cal) = (dir.join("out.csv"), dir.join("learned.json"));
    common::succeeded(common::drive(
        &veh,
        &input,
        &out,
        &[
            "--extra",
            "sigma,status,calibration",
            "--calibration-out",
            p(&cal),
        ],
    ));
    let (header, rows) = read_rows(&out);
    assert_eq!(header.len(), 4 + 3 + 4 + 8);
    assert_eq!(
        &header[4..7],
        ["heading_sigma_deg", "north_sigma_m", "east_sigma_m"]
    );
    let last = rows.last().unwrap();
    assert!(last[4] > 0.0 && last[4] < 1.0, "heading sigma {}", last[4]);
    assert_eq!(last[7], 1.0, "heading absolute at the end");
    // The gyro bias learned in the opening standstill is the simulated one to a few
    // hundredths of a degree per second (it wanders afterwards).
    let bias = drive.params.gyro.bias_rps.to_degrees();
    let at_rest = rows.iter().find(|r| r[0] >= 6.0).unwrap();
    assert!(
        (at_rest[11] - bias).abs() < 0.03,
        "{} vs {bias}",
        at_rest[11]
    );
    // True north: the track and the heading turn by the declination.
    let true_out = dir.join("true.csv");
    common::succeeded(common::drive(
        &veh,
        &input,
        &true_out,
        &["--lat", "52.5", "--lon", "13.4", "--date", "2026.5"],
    ));
    let (_, t_rows) = read_rows(&true_out);
    let (m, t) = (rows.last().unwrap(), t_rows.last().unwrap());
    let decl = truenorth::core::angle_diff(t[3].to_radians(), m[3].to_radians()).to_degrees();
    assert!(
        decl > 3.0 && decl < 7.0,
        "Berlin's declination in 2026 is about 5°: {decl}"
    );
    assert!((m[1].hypot(m[2]) - t[1].hypot(t[2])).abs() < 1e-6);
    // A second drive of the same vehicle (another route, the same sensors), started from
    // the first one's calibration, needs no turn to know north.
    let mut second = SimulatedDrive::new(DriveSpec {
        opening_turn: false,
        length_m: 2000.0,
        ..DriveSpec::new(6)
    })
    .unwrap();
    second.samples = vehicle_streams_disturbed(&second.truth, &drive.params, &[], 7).unwrap();
    let input2 = dir.join("drive2.csv");
    write_drive(&second, &input2, false, true);
    let out2 = dir.join("out2.csv");
    common::succeeded(common::drive(
        &veh,
        &input2,
        &out2,
        &[
            "--calibration-in",
            p(&cal),
            "--single-pass",
            "--extra",
            "status",
        ],
    ));
    let (_, rows2) = read_rows(&out2);
    let first_absolute = rows2
        .iter()
        .position(|r| r[4] == 1.0)
        .expect("referred to north");
    assert!(
        rows2[first_absolute][0] - rows2[0][0] < 5.0,
        "north known after {} s",
        rows2[first_absolute][0]
    );
}

#[test]
fn refusals_name_the_file_and_the_problem() {
    let dir = scratch("drive", "refusals");
    let veh = vehicle(&dir, DriveWheels::Rear);
    let input = dir.join("drive.csv");
    let out = dir.join("out.csv");
    let cases: [(&str, &str); 4] = [
        ("t_s,mag_x,mag_y\n0,1,2\n", "needs a heading sensor"),
        (
            "t_s,dist_l_m,dist_r_m\n0,0,0\n0,1,1\n",
            "does not come after",
        ),
        ("t_s,dist_l_m,dist_r_m,mag_x\n0,0,0,1\n", "mag_x, mag_y"),
        ("t_s,dist_l_m,dist_r_m\n0,0,0\n1,,1\n", "one wheel's value"),
    ];
    for (text, expect) in cases {
        std::fs::write(&input, text).unwrap();
        let o = common::drive(&veh, &input, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{text}");
        assert!(
            err.contains(expect) && err.contains("drive.csv"),
            "{text}: {err}"
        );
        assert!(!out.exists(), "no output left behind");
    }
    // The output may not be an input; a front-wheel vehicle needs its geometry.
    std::fs::write(&input, "t_s,dist_l_m,dist_r_m\n0,0,0\n1,1,1\n").unwrap();
    let o = common::drive(&veh, &input, &input, &[]);
    assert!(!o.status.success());
    let front = dir.join("front.json");
    std::fs::write(&front, r#"{"track_m": 1.5, "odometer_wheels": "front"}"#).unwrap();
    let o = common::drive(&front, &input, &out, &[]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("pitman_ratio"));
}
