//! `drive` on a ROS 2 bag with satellite fixes (`sensor_msgs/msg/NavSatFix`): the fixes are
//! read as the CSV's `lat_deg,lon_deg,gnss_sigma_m` (σ from the fix's covariance; "no fix"
//! messages left out), so the track is on the fixes' tangent plane and true north, and
//! `inspect` lists the stream; the receiver's velocity (`geometry_msgs/msg/
//! TwistWithCovarianceStamped` in the fixes' frame) as their `gnss_speed_mps,gnss_course_deg`.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

use common::{ok, p, scratch, truenorth};
use truenorth_logs::ros_msgs::{
    self, Header, Imu, NavSatFix, NavSatStatus, Odometry, Time, Twist, TwistStamped,
    TwistWithCovariance, TwistWithCovarianceStamped, Vec3,
};

const START_SEC: i32 = 1_750_000_000;
const SPEED_MPS: f64 = 5.0;
/// Berlin, where the drive starts (WGS84 degrees), and the Earth's radius for the small
/// steps between fixes, m.
const LAT0: f64 = 52.5;
const LON0: f64 = 13.4;
const EARTH_M: f64 = 6_378_137.0;

fn header(t_s: f64, frame: &str) -> Header {
    let ns = (t_s * 1e9).round() as u64;
    Header {
        stamp: Time {
            sec: START_SEC + (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        },
        frame_id: frame.into(),
    }
}

/// The yaw rate (NED, positive turning right) at `t_s`: straight east for 20 s, a right
/// turn at 0.1 rad/s for 15 s, straight again, and from 40 s a weave (a lane change each
/// way every 6 s).
fn yaw_rate(t_s: f64) -> f64 {
    if (20.0..35.0).contains(&t_s) {
        0.1
    } else if t_s >= 40.0 {
        0.2 * (std::f64::consts::TAU * (t_s - 40.0) / 6.0).sin()
    } else {
        0.0
    }
}

/// The true track at 100 Hz: (t, north, east, heading).
fn truth() -> Vec<(f64, f64, f64, f64)> {
    let (mut n, mut e, mut psi) = (0.0, 0.0, std::f64::consts::FRAC_PI_2);
    (0..6000)
        .map(|k| {
            let t = k as f64 * 0.01;
            let row = (t, n, e, psi);
            n += SPEED_MPS * psi.cos() * 0.01;
            e += SPEED_MPS * psi.sin() * 0.01;
            psi += yaw_rate(t) * 0.01;
            row
        })
        .collect()
}

fn vec3(x: f64, y: f64) -> Vec3 {
    Vec3 { x, y, z: 0.0 }
}

/// A rear-wheel car's vehicle file in `dir`.
fn car(dir: &Path) -> PathBuf {
    let vehicle = dir.join("car.json");
    std::fs::write(&vehicle, r#"{"track_m": 1.5, "odometer_wheels": "rear"}"#).unwrap();
    vehicle
}

/// `drive` of `bag` as `vehicle`, with `extra` arguments, into `track.csv` beside the bag:
/// the run and the track's path.
fn drive(vehicle: &Path, bag: &Path, extra: &[&str]) -> (Output, PathBuf) {
    let track = bag.with_file_name("track.csv");
    let mut args = vec![
        "drive",
        "--vehicle",
        p(vehicle),
        "--input",
        p(bag),
        "--output",
        p(&track),
    ];
    args.extend_from_slice(extra);
    (truenorth(&args), track)
}

/// A minute of a car in a bag: IMU at 50 Hz, odometry at 20 Hz, fixes at 5 Hz (σ 2 m; the
/// first second "no fix"); with `velocity`, the receiver's velocity on each fix's stamp
/// (`/fix_velocity`, ENU, the fixes' frame) and a body's `cmd_vel` (`TwistStamped` in
/// `base_link`, pointing the wrong way if it were read as ENU). Fixes and velocity are
/// stamped and logged `fix_delay_s` after their epoch.
fn write_bag(path: &Path, velocity: bool, fix_delay_s: f64) -> (f64, f64) {
    let truth = truth();
    let ns = |t_s: f64| (START_SEC as u64) * 1_000_000_000 + (t_s * 1e9).round() as u64;
    let mut messages: Vec<(&str, u64, Vec<u8>)> = Vec::new();
    for (k, &(t, n, e, psi)) in truth.iter().enumerate() {
        // ROS bodies are FLU: a right turn is a negative rate about z (up).
        let flu_rate = -yaw_rate(t);
        if k % 2 == 0 {
            let m = Imu {
                header: header(t, "imu"),
                angular_velocity: Vec3 {
                    x: 0.0,
                    y: 0.0,
                    z: flu_rate,
                },
                linear_acceleration: Vec3 {
                    x: 0.0,
                    y: 0.0,
                    z: 9.81,
                },
                orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                ..Imu::default()
            };
            messages.push(("/imu", ns(t), ros_msgs::encode(&m).unwrap()));
        }
        if k % 5 == 0 {
            let m = Odometry {
                header: header(t, "odom"),
                child_frame_id: "base_link".into(),
                twist: TwistWithCovariance {
                    twist: Twist {
                        linear: Vec3 {
                            x: SPEED_MPS,
                            y: 0.0,
                            z: 0.0,
                        },
                        angular: Vec3 {
                            x: 0.0,
                            y: 0.0,
                            z: flu_rate,
                        },
                    },
                    ..TwistWithCovariance::default()
                },
                ..Odometry::default()
            };
            messages.push(("/odom", ns(t), ros_msgs::encode(&m).unwrap()));
        }
        // A fix's epoch and when it is stamped and logged.
        let late = t + fix_delay_s;
        if k % 20 == 10 {
            let mut covariance = [0.0; 9];
            (covariance[0], covariance[4], covariance[8]) = (4.0, 4.0, 16.0);
            let m = NavSatFix {
                header: header(late, "gps"),
                status: NavSatStatus {
                    status: if t < 1.0 { -1 } else { 0 },
                    service: 1,
                },
                latitude: LAT0 + (n / EARTH_M).to_degrees(),
                longitude: LON0 + (e / (EARTH_M * LAT0.to_radians().cos())).to_degrees(),
                altitude: 40.0,
                position_covariance: covariance,
                position_covariance_type: 2,
            };
            messages.push(("/fix", ns(late), ros_msgs::encode(&m).unwrap()));
            if velocity {
                let (east, north) = (SPEED_MPS * psi.sin(), SPEED_MPS * psi.cos());
                let m = TwistWithCovarianceStamped {
                    header: header(late, "gps"),
                    twist: TwistWithCovariance {
                        twist: Twist {
                            linear: vec3(east, north),
                            ..Twist::default()
                        },
                        ..TwistWithCovariance::default()
                    },
                };
                messages.push(("/fix_velocity", ns(late), ros_msgs::encode(&m).unwrap()));
            }
        }
        if velocity && k % 5 == 0 {
            let m = TwistStamped {
                header: header(t, "base_link"),
                twist: Twist {
                    linear: vec3(0.0, SPEED_MPS),
                    ..Twist::default()
                },
            };
            messages.push(("/cmd_vel", ns(t), ros_msgs::encode(&m).unwrap()));
        }
    }
    messages.sort_by_key(|m| m.1);
    let mut bytes = Vec::new();
    {
        let mut w = mcap::WriteOptions::new()
            .create(std::io::Cursor::new(&mut bytes))
            .unwrap();
        let mut channels = BTreeMap::new();
        for (topic, schema) in [
            ("/imu", "sensor_msgs/msg/Imu"),
            ("/odom", "nav_msgs/msg/Odometry"),
            ("/fix", "sensor_msgs/msg/NavSatFix"),
            (
                "/fix_velocity",
                "geometry_msgs/msg/TwistWithCovarianceStamped",
            ),
            ("/cmd_vel", "geometry_msgs/msg/TwistStamped"),
        ] {
            let id = w.add_schema(schema, "ros2msg", b"").unwrap();
            let channel = w.add_channel(id, topic, "cdr", &BTreeMap::new()).unwrap();
            channels.insert(topic, channel);
        }
        for (seq, (topic, log_time, data)) in messages.into_iter().enumerate() {
            let header = mcap::records::MessageHeader {
                channel_id: channels[topic],
                sequence: seq as u32,
                log_time,
                publish_time: log_time,
            };
            w.write_to_known_channel(&header, &data).unwrap();
        }
        w.finish().unwrap();
    }
    std::fs::write(path, bytes).unwrap();
    let &(_, n, e, _) = truth.last().unwrap();
    (n, e)
}

#[test]
fn a_bag_with_fixes_drives_on_them() {
    let dir = scratch("mcap_gnss", "drive");
    let bag = dir.join("car.mcap");
    let (north_m, east_m) = write_bag(&bag, false, 0.0);
    let (run, track) = drive(&car(&dir), &bag, &["--extra", "geodetic"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("satellite fixes: "), "{stderr}");
    assert!(stderr.contains("from the satellite fixes"), "{stderr}");
    let (header, rows) = common::table(&track, true);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let last = rows.last().unwrap();
    // The tangent plane is at the first fix, 1 s (5 m east) after the start.
    let (n, e) = (last[col("north_m")], last[col("east_m")]);
    let error = (n - north_m).hypot(e - (east_m - SPEED_MPS));
    assert!(
        error < 3.0,
        "end {n:.2} N {e:.2} E, truth {north_m:.2} N {:.2} E",
        east_m - 5.0
    );
    // Rows before the fixes referred the heading to true north (the first 5 s here) are
    // put in the same plane when the head is run again: the track has no jump (it had one
    // of 4.2 m, the start frame against the plane) and every row has its latitude.
    let largest_step = rows
        .windows(2)
        .map(|w| {
            (w[1][col("north_m")] - w[0][col("north_m")])
                .hypot(w[1][col("east_m")] - w[0][col("east_m")])
        })
        .fold(0.0, f64::max);
    assert!(largest_step < 1.0, "a step of {largest_step:.2} m");
    assert!(rows.iter().all(|r| r[col("lat_deg")].is_finite()));
    assert!(
        (rows[0][col("east_m")] + SPEED_MPS).abs() < 3.0,
        "{:?}",
        rows[0]
    );
    let lat = last[col("lat_deg")];
    assert!(
        (lat - (LAT0 + (north_m / EARTH_M).to_degrees())).abs() < 3e-5,
        "{lat}"
    );
    let report = ok(&["inspect", p(&bag)]);
    let report = String::from_utf8_lossy(&report.stdout);
    assert!(
        report.contains("/fix (sensor_msgs/msg/NavSatFix, 300 messages"),
        "{report}"
    );
}

/// The receiver's velocity in the fixes' frame is found by default and gives the fixes their
/// course: without odometry (`--odometry-topic none`) it alone refers the gyro's heading to true
/// north. The body's `cmd_vel` is never taken for it unless named, and a topic of another type
/// named for it is refused.
#[test]
fn the_receivers_velocity_gives_the_fixes_their_course() {
    let dir = scratch("mcap_gnss", "velocity");
    let bag = dir.join("car.mcap");
    write_bag(&bag, true, 0.0);
    let report = ok(&["inspect", p(&bag)]);
    let report = String::from_utf8_lossy(&report.stdout);
    // The five velocities of the first second have no fix to ride on.
    assert!(
        report.contains(
            "gnss_velocity: /fix_velocity, 300 samples, 5.00 Hz (median step), 5 left out"
        ),
        "{report}"
    );
    let vehicle = car(&dir);
    let without_odometry = |extra: &[&str]| {
        let mut args = vec!["--odometry-topic", "none"];
        args.extend_from_slice(extra);
        drive(&vehicle, &bag, &args)
    };
    let (run, track) = without_odometry(&[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let used: usize = stderr
        .split("satellite fixes: ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{stderr}"));
    // One course a second is used (the fixes' errors are correlated over longer).
    assert!(used >= 55, "{used} courses used: {stderr}");
    assert!(
        stderr.contains("courses used (no odometry: no position)"),
        "{stderr}"
    );
    let (header, rows) = common::table(&track, true);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let truth = truth();
    let &(_, _, _, psi) = truth.last().unwrap();
    let last = rows.last().unwrap();
    let error_deg = (last[col("heading_deg")] - psi.to_degrees() + 180.0).rem_euclid(360.0) - 180.0;
    assert!(error_deg.abs() < 2.0, "end heading off by {error_deg:.2}°");
    assert!(last[col("north_m")].is_nan(), "no odometry, no position");

    // Named away, the fixes have no course: unused, and said so.
    let (run, _) = without_odometry(&["--gnss-velocity-topic", "none"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("`lat_deg,lon_deg` are not used"),
        "{stderr}"
    );
    let (run, _) = without_odometry(&["--gnss-velocity-topic", "/imu"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && stderr.contains("/imu"), "{stderr}");
}

/// Fixes stamped 2 s after their epoch (a logger's queue, another clock) pass the gate on a
/// gentle drive, and would teach the estimator a gyro bias; their course's turns, 2 s behind
/// the gyro's, are found and said. Fixes stamped on their epoch are not. Without the
/// receiver's velocity the chords between fixes find the delay too (`inspect`), but 40 s of
/// weaving do not refute 0.1 s through a chord's assumed error (0.5 m over 3 m), and nothing
/// is said.
#[test]
fn fixes_stamped_late_are_said() {
    let dir = scratch("mcap_gnss", "late");
    let vehicle = car(&dir);
    let said = |delay_s: f64, vehicle: &Path, velocity: bool| {
        let bag = dir.join(format!("car{delay_s}{velocity}.mcap"));
        write_bag(&bag, velocity, delay_s);
        let (run, _) = drive(vehicle, &bag, &[]);
        let stderr = String::from_utf8_lossy(&run.stderr).to_string();
        assert!(run.status.success(), "{stderr}");
        let lag: Option<f64> = stderr
            .split("satellite fixes are stamped ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|n| n.parse().ok());
        (lag, stderr)
    };
    let (lag, stderr) = said(2.0, &vehicle, true);
    let found = lag.unwrap_or_else(|| panic!("{stderr}"));
    assert!((found - 2.0).abs() < 0.2, "{stderr}");
    // `inspect` shows the same before anything is driven.
    let report = ok(&["inspect", p(&dir.join("car2true.mcap"))]);
    let report = String::from_utf8_lossy(&report.stdout);
    assert!(report.contains("the course turning 2.0"), "{report}");
    let (lag, stderr) = said(0.0, &vehicle, true);
    assert!(lag.is_none(), "{stderr}");
    let (lag, stderr) = said(2.0, &vehicle, false);
    assert!(lag.is_none(), "{stderr}");
    let report = ok(&["inspect", p(&dir.join("car2false.mcap"))]);
    let report = String::from_utf8_lossy(&report.stdout);
    assert!(report.contains("the track turning 2.0"), "{report}");
    let told = dir.join("told.json");
    std::fs::write(
        &told,
        format!(r#"{{"track_m": 1.5, "odometer_wheels": "rear", "gnss_latency_s": {found}}}"#),
    )
    .unwrap();
    let (lag, stderr) = said(2.0, &told, true);
    assert!(lag.is_none(), "{stderr}");
}
