//! `truenorth drive` with the sensor sets real vehicles have: a vehicle speed or distance
//! with a yaw rate, a speed beside wheels (not used, and said so), a speed alone (refused:
//! nothing measures the heading), a car's four wheel speeds (the odometer's axle read, the
//! other said unused; a skid-steered vehicle's sides as each side's mean).

mod common;

use common::{outcome, scratch};

/// A car at 10 m/s turning right at 0.05 rad/s for 20 s, at 10 Hz, as `header` and
/// `cells(t)` write it.
fn log(header: &str, cells: impl Fn(f64) -> String) -> String {
    let mut s = format!("{header}\n");
    for k in 0..=200 {
        let t = 0.1 * k as f64;
        s += &format!("{t},{}\n", cells(t));
    }
    s
}

#[test]
fn a_speed_or_a_distance_with_a_yaw_rate_draws_the_track() {
    let dir = scratch("drive_sets", "speed");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    for (name, text) in [
        ("speed", log("t_s,speed_mps,gyr_z", |_| "10,0.05".into())),
        (
            "dist",
            log("t_s,dist_m,gyr_z", |t| format!("{},0.05", 10.0 * t)),
        ),
    ] {
        let input = dir.join(format!("{name}.csv"));
        std::fs::write(&input, text).unwrap();
        let out = dir.join(format!("{name}-out.csv"));
        let o = common::succeeded(common::drive(&vehicle, &input, &out, &[]));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("sensors: speed + yaw rate"),
            "{name}: {stderr}"
        );
        let (_, rows) = common::table(&out, false);
        let last = rows.last().unwrap();
        // 200 m along an arc of 1 rad and radius 200 m.
        let (n, e) = (200.0 * 1f64.sin(), 200.0 * (1.0 - 1f64.cos()));
        assert!((last[1] - n).hypot(last[2] - e) < 1.0, "{name}: {last:?}");
        assert!(
            (last[3] - 1f64.to_degrees()).abs() < 0.1,
            "{name}: {last:?}"
        );
    }
}

/// A speed beside wheel columns is said unused; fixes without their accuracy are taken, and
/// the default accuracy they are judged by is said.
#[test]
fn a_speed_beside_wheels_is_said_unused_and_fixes_default_accuracy_said() {
    let dir = scratch("drive_sets", "unused");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    let input = dir.join("both.csv");
    let text = log(
        "t_s,dist_l_m,dist_r_m,speed_mps,gyr_z,lat_deg,lon_deg",
        |t| format!("{},{},10,0.0,52.5,13.4", 10.0 * t, 10.0 * t),
    );
    std::fs::write(&input, text).unwrap();
    let o = common::succeeded(common::drive(&vehicle, &input, &dir.join("o.csv"), &[]));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("`speed_mps` is not used"), "{stderr}");
    assert!(stderr.contains("carry no `gnss_sigma_m`"), "{stderr}");
    assert!(stderr.contains("sensors: wheels + gyro + GNSS"), "{stderr}");
}

#[test]
fn a_speed_alone_is_refused_with_what_to_add() {
    let dir = scratch("drive_sets", "alone");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    let input = dir.join("speed.csv");
    std::fs::write(&input, log("t_s,speed_mps", |_| "10".into())).unwrap();
    let (ok, stderr) = outcome(&common::drive(&vehicle, &input, &dir.join("o.csv"), &[]));
    assert!(!ok);
    assert!(
        stderr.contains("nothing that measures the heading"),
        "{stderr}"
    );
    assert!(stderr.contains("gyr_z"), "{stderr}");
}

/// The turn of [`log`] (right at 0.05 rad/s, 10 m/s) on wheels 1.6 m apart: the left runs
/// 0.04 m/s faster than the middle, the right 0.04 m/s slower.
const LEFT_RIGHT: &str = "10.04,9.96";

#[test]
fn a_cars_four_wheel_speeds_read_the_odometer_axle() {
    let dir = scratch("drive_sets", "four");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    // The front wheels carry nonsense: were they read, the track would be wrong.
    let input = dir.join("four.csv");
    let header = "t_s,speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps,gyr_z";
    let text = log(header, |_| format!("3,25,{LEFT_RIGHT},0.05"));
    std::fs::write(&input, text).unwrap();
    let out = dir.join("four-out.csv");
    let o = common::succeeded(common::drive(&vehicle, &input, &out, &[]));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("`speed_fl_mps,speed_fr_mps` is not used"),
        "{stderr}"
    );
    assert!(stderr.contains("sensors: wheels + gyro"), "{stderr}");
    let (_, rows) = common::table(&out, false);
    let last = rows.last().unwrap();
    let (n, e) = (200.0 * 1f64.sin(), 200.0 * (1.0 - 1f64.cos()));
    assert!((last[1] - n).hypot(last[2] - e) < 1.0, "{last:?}");

    // A skid-steered vehicle turns by its sides: each side's mean is its odometer wheel.
    // Its wheels slide in the turn, so its sides turn it as wheels twice as far apart would
    // (the middle of the effective track's prior, 1.5–2.5 times the physical one): ±0.08 m/s.
    let skid = common::vehicle_file(&dir, "skid.json", 1.6, "skid_steer");
    let sides = dir.join("sides.csv");
    let text = log(header, |_| "10.18,10.02,9.98,9.82,0.05".into());
    std::fs::write(&sides, text).unwrap();
    let out = dir.join("sides-out.csv");
    let o = common::succeeded(common::drive(&skid, &sides, &out, &[]));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("not used"), "{stderr}");
    let (_, rows) = common::table(&out, false);
    let last = rows.last().unwrap();
    // The distance is the sides' mean (the front axle alone would run 1 % further, the rear
    // 1 % shorter: 1.9 m on this chord); the heading is the estimator's weighing of the sides
    // against the gyro over the effective track's prior (2° over on this steady turn).
    let chord = 400.0 * 0.5f64.sin();
    assert!((last[1].hypot(last[2]) - chord).abs() < 1.0, "{last:?}");
}

#[test]
fn some_of_four_wheel_speeds_are_refused() {
    let dir = scratch("drive_sets", "three");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    let input = dir.join("three.csv");
    let text = log("t_s,speed_fl_mps,speed_rl_mps,speed_rr_mps,gyr_z", |_| {
        format!("10,{LEFT_RIGHT},0.05")
    });
    std::fs::write(&input, text).unwrap();
    let (ok, stderr) = outcome(&common::drive(&vehicle, &input, &dir.join("o.csv"), &[]));
    assert!(!ok);
    assert!(stderr.contains("speed_fr_mps"), "{stderr}");
}

#[test]
fn inspect_names_a_drive_logs_sensor_set_and_what_it_cannot_tell() {
    let dir = scratch("drive_sets", "inspect");
    for (name, header, cells, set) in [
        (
            "speed",
            "t_s,speed_mps,gyr_z",
            "10,0.05",
            "speed + yaw rate",
        ),
        (
            "four",
            "t_s,speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps,gyr_z",
            "10,10,10,10,0.05",
            "wheels + gyro",
        ),
    ] {
        let input = dir.join(format!("{name}.csv"));
        std::fs::write(&input, log(header, |_| cells.into())).unwrap();
        let o = common::ok(&["inspect", common::p(&input)]);
        let s = String::from_utf8_lossy(&o.stdout);
        assert!(
            s.contains(&format!("vehicle sensors: {set}")),
            "{name}: {s}"
        );
        assert!(s.contains("cannot tell: no north"), "{name}: {s}");
    }
}

/// VEHICLE.json for the odometer wheels `wheels`.
fn vehicle_json(wheels: &truenorth::odometer::OdometerWheels) -> String {
    use truenorth::odometer::OdometerWheels as W;
    match wheels {
        W::Rear { track_m } => format!(r#"{{"track_m": {track_m}, "odometer_wheels": "rear"}}"#),
        W::Front(a) => format!(
            r#"{{"track_m": {}, "wheelbase_m": {}, "odometer_wheels": "front", "pitman_ratio": {}}}"#,
            a.track_m,
            a.wheelbase_m,
            a.pitman_ratio()
        ),
        W::SkidSteer { track_m } => {
            format!(r#"{{"track_m": {track_m}, "odometer_wheels": "skid_steer"}}"#)
        }
        W::Differential { track_m } => {
            format!(r#"{{"track_m": {track_m}, "odometer_wheels": "differential"}}"#)
        }
    }
}

/// Every sensor set the simulator writes as a real log, on every kind of vehicle, with a
/// GNSS receiver's columns beside: read whole, its set named, the fixes used where odometry
/// carries the position between them and said unused where none does, and (on a car's four
/// wheels) the other axle said unused.
#[test]
fn every_real_sensor_set_is_read_and_what_is_unused_said() {
    use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};
    let dir = scratch("drive_sets", "every");
    let mut refused = Vec::new();
    for kind in truenorth_sim::VehicleKind::ALL {
        for (k, set) in SensorSet::every(kind).into_iter().enumerate() {
            let name = format!("{kind:?} {set:?}");
            let drive = LogDrive::new(LogDriveConfig::new(k as u64, kind, set).with_gnss())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let input = dir.join(format!("{kind:?}-{k}.csv"));
            std::fs::write(&input, drive.to_csv()).unwrap();
            let vehicle = dir.join(format!("{kind:?}-{k}.json"));
            std::fs::write(&vehicle, vehicle_json(&drive.vehicle.wheels)).unwrap();
            let out = dir.join(format!("{kind:?}-{k}-out.csv"));
            let o = common::drive(&vehicle, &input, &out, &[]);
            let (ok, stderr) = outcome(&o);
            if !ok {
                refused.push(format!("{name}: {}", stderr.lines().last().unwrap_or("")));
                continue;
            }
            assert!(stderr.contains("; sensors: "), "{name}: {stderr}");
            if matches!(set.odometry, truenorth_sim::log_drive::Odometry::None) {
                // The simulated receiver reports its course: it refers the heading, and the
                // fixes give no position.
                assert!(
                    stderr.contains("`lat_deg,lon_deg` give no position"),
                    "{name}: {stderr}"
                );
                if kind.is_car() {
                    assert!(stderr.contains("courses used"), "{name}: {stderr}");
                    assert!(!stderr.contains(": 0 courses used"), "{name}: {stderr}");
                }
            } else {
                assert!(stderr.contains("satellite fixes: "), "{name}: {stderr}");
                assert!(
                    !stderr.contains("satellite fixes: 0 used"),
                    "{name}: {stderr}"
                );
            }
            let header = drive.to_csv().lines().next().unwrap().to_string();
            if header.contains("speed_fl_mps")
                && !matches!(kind, truenorth_sim::VehicleKind::SkidSteer)
            {
                assert!(stderr.contains("_mps` is not used"), "{name}: {stderr}");
            }
            assert_eq!(
                common::table(&out, true).1.len(),
                drive.rows.len(),
                "{name}: one row per input row"
            );
        }
    }
    assert!(refused.is_empty(), "refused:\n{}", refused.join("\n"));
}
