//! `truenorth drive` on logs as they come: each sensor on its own rows at its own rate,
//! vehicles of every kind, no wheels at all, and a time base that is not in seconds.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::scratch;
use truenorth_sim::{Fitted, RangeDrive, RangeSpec, VehicleKind};

/// Writes `drive` as the command reads it, with an empty cell wherever a sensor did not
/// read on a row; `time_scale` multiplies the timestamps (1000: milliseconds).
fn write_log(drive: &RangeDrive, path: &Path, time_scale: f64) {
    let f = drive.spec.fitted;
    let mut s = String::from("t_s");
    if f.wheels {
        s += ",dist_l_m,dist_r_m";
    }
    if f.gyro {
        s += ",gyr_z";
    }
    if f.compass {
        s += ",mag_x,mag_y";
    }
    s.push('\n');
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    for x in &drive.samples {
        write!(s, "{}", x.t_s * time_scale).unwrap();
        if f.wheels {
            let w = x.wheels;
            write!(
                s,
                ",{},{}",
                cell(w.map(|w| w.dist_l_m)),
                cell(w.map(|w| w.dist_r_m))
            )
            .unwrap();
        }
        if f.gyro {
            write!(s, ",{}", cell(x.gyr_z_rps)).unwrap();
        }
        if f.compass {
            let m = x.mag;
            write!(s, ",{},{}", cell(m.map(|m| m.x)), cell(m.map(|m| m.y))).unwrap();
        }
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

fn write_vehicle(drive: &RangeDrive, path: &Path) {
    let json = match drive.vehicle.wheels {
        truenorth::odometer::OdometerWheels::Rear { track_m } => {
            format!(r#"{{"track_m": {track_m}, "odometer_wheels": "rear"}}"#)
        }
        truenorth::odometer::OdometerWheels::Front(a) => format!(
            r#"{{"track_m": {}, "wheelbase_m": {}, "odometer_wheels": "front", "pitman_ratio": {}}}"#,
            a.track_m,
            a.wheelbase_m,
            a.pitman_ratio()
        ),
        truenorth::odometer::OdometerWheels::SkidSteer { track_m } => {
            format!(r#"{{"track_m": {track_m}, "odometer_wheels": "skid_steer"}}"#)
        }
        truenorth::odometer::OdometerWheels::Differential { track_m } => {
            format!(r#"{{"track_m": {track_m}, "odometer_wheels": "differential"}}"#)
        }
    };
    let json = json.trim_end_matches('}').to_string()
        + &format!(
            r#", "wheel_resolution_m": {}}}"#,
            drive.wheel_resolution_m()
        );
    std::fs::write(path, json).unwrap();
}

/// The output's rows, empty cells read as NaN.
fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    common::table(path, true).1
}

fn run_drive(dir: &Path, drive: &RangeDrive, time_scale: f64) -> std::process::Output {
    let input = dir.join("drive.csv");
    let vehicle = dir.join("vehicle.json");
    write_log(drive, &input, time_scale);
    write_vehicle(drive, &vehicle);
    drive_files(dir, &vehicle, &input, &["--extra", "sigma,status,trust"])
}

/// `truenorth drive` on `vehicle` and `input`, writing `out.csv` in `dir`.
fn drive_files(dir: &Path, vehicle: &Path, input: &Path, extra: &[&str]) -> std::process::Output {
    common::drive(vehicle, input, &dir.join("out.csv"), extra)
}

/// Heading RMS error, degrees, over the rows referred to north.
fn heading_rms_deg(drive: &RangeDrive, rows: &[Vec<f64>]) -> f64 {
    let (mut sq, mut n) = (0.0, 0);
    for (r, t) in rows.iter().zip(&drive.truth) {
        if r[7] == 1.0 {
            let d = truenorth::core::angle_diff(r[3].to_radians(), t.heading_rad).to_degrees();
            sq += d * d;
            n += 1;
        }
    }
    (sq / f64::from(n.max(1))).sqrt()
}

/// Every kind of vehicle, its sensors on their own rows: one output row per input row, the
/// track ends within a few percent of the distance (the goals are held by
/// `truenorth-fusion`'s ensemble test; this holds the command's plumbing), and the trust
/// columns are there.
#[test]
fn every_kind_of_vehicle_from_rows_that_carry_any_subset() {
    for kind in VehicleKind::ALL {
        let dir = scratch("drive_logs", &format!("{kind:?}"));
        let drive = RangeDrive::new(RangeSpec {
            length_m: if kind.is_car() { 2500.0 } else { 400.0 },
            ..RangeSpec::new(2, kind)
        })
        .unwrap();
        assert!(drive.samples.iter().any(|s| s.wheels.is_none()));
        let o = run_drive(&dir, &drive, 1.0);
        assert!(
            o.status.success(),
            "{kind:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let rows = read_rows(&dir.join("out.csv"));
        assert_eq!(rows.len(), drive.samples.len(), "{kind:?}");
        assert_eq!(rows[0].len(), 4 + 3 + 4 + 9, "{kind:?}");
        let (last, t) = (rows.last().unwrap(), drive.truth.last().unwrap());
        // A track never referred to north is drawn as if the start heading were north.
        let (north, east) = if last[7] == 1.0 {
            (t.north_m, t.east_m)
        } else {
            let (s, c) = drive.truth[0].heading_rad.sin_cos();
            (c * t.north_m + s * t.east_m, -s * t.north_m + c * t.east_m)
        };
        let err = (last[1] - north).hypot(last[2] - east);
        assert!(
            err < 0.03 * drive.distance_m(),
            "{kind:?}: {err:.1} m off after {:.0} m",
            drive.distance_m()
        );
    }
}

/// A gyro and a compass without wheels are EP 0640207's own pair: the heading is
/// estimated, referred to north, and better than the calibrated compass read alone; the
/// position is absent (empty cells), not zero.
#[test]
fn gyro_and_compass_without_wheels_give_heading_and_no_position() {
    let dir = scratch("drive_logs", "no-wheels");
    let drive = RangeDrive::new(RangeSpec {
        fitted: Fitted {
            wheels: false,
            ..Fitted::ALL
        },
        disturbances: false,
        length_m: 3000.0,
        ..RangeSpec::new(4, VehicleKind::RearWheelCar)
    })
    .unwrap();
    let o = run_drive(&dir, &drive, 1.0);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = read_rows(&dir.join("out.csv"));
    assert!(rows.iter().all(|r| r[1].is_nan() && r[2].is_nan()));
    assert!(rows.iter().all(|r| r[3].is_finite()));
    let absolute = rows.iter().filter(|r| r[7] == 1.0).count();
    assert!(
        absolute > rows.len() / 2,
        "north for {absolute} of {} rows",
        rows.len()
    );
    // The compass read alone through its true calibration: its noise is the floor that a
    // fused heading must beat.
    let p = drive.params;
    let inverse = p.compass_soft_iron.try_inverse().unwrap();
    let (mut sq, mut n) = (0.0, 0);
    for (s, t) in drive.samples.iter().zip(&drive.truth) {
        if let Some(m) = s.mag {
            let u = inverse * (m - p.compass_hard_iron);
            let d = truenorth::core::angle_diff((-u.y).atan2(u.x), t.heading_rad).to_degrees();
            sq += d * d;
            n += 1;
        }
    }
    let compass_rms = (sq / f64::from(n)).sqrt();
    let fused_rms = heading_rms_deg(&drive, &rows);
    println!("gyro + compass: heading RMS {fused_rms:.2}°, the compass alone {compass_rms:.2}°");
    assert!(
        fused_rms < compass_rms,
        "fused {fused_rms:.2}° against the compass alone {compass_rms:.2}°"
    );
}

/// A time base in milliseconds makes every step of the log hundreds of "seconds" long:
/// the command refuses it with the row where that became clear, and says what it likely is.
#[test]
fn a_time_base_in_milliseconds_is_refused_as_such() {
    let dir = scratch("drive_logs", "milliseconds");
    let drive = RangeDrive::new(RangeSpec {
        length_m: 1000.0,
        ..RangeSpec::new(5, VehicleKind::RearWheelCar)
    })
    .unwrap();
    let o = run_drive(&dir, &drive, 1000.0);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("milliseconds") && err.contains("row ") && err.contains("drive.csv"),
        "{err}"
    );
    assert!(!dir.join("out.csv").exists());
}

/// VEHICLE.json names the kind of vehicle; a misspelled key is refused, not ignored.
#[test]
fn vehicle_files_name_their_kind_and_misspellings_are_refused() {
    let dir = scratch("drive_logs", "vehicle");
    let input = dir.join("drive.csv");
    std::fs::write(&input, "t_s,dist_l_m,dist_r_m\n0,0,0\n0.1,0.1,0.1\n").unwrap();
    for (json, good) in [
        (r#"{"track_m": 0.6, "odometer_wheels": "skid_steer"}"#, true),
        (
            r#"{"track_m": 0.4, "odometer_wheels": "differential"}"#,
            true,
        ),
        (
            r#"{"track_m": 1.5, "odometer_wheels": "rear", "trak_m": 2}"#,
            false,
        ),
        (r#"{"track_m": 1.5, "odometer_wheels": "tracked"}"#, false),
    ] {
        let vehicle = dir.join("vehicle.json");
        std::fs::write(&vehicle, json).unwrap();
        let o = drive_files(&dir, &vehicle, &input, &[]);
        assert_eq!(
            o.status.success(),
            good,
            "{json}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}
