//! PX4 ULog and ROS 2 MCAP files as every command's `--input`: the three real PX4 logs in
//! `../shared/data/px4_ulog_samples/` (absent: skipped visibly; under CI: a failure) and the
//! MCAP bag the logs crate's tests keep in `crates/truenorth-logs/tests/data/`.
//!
//! A log is read into the CSV the command takes, every number as the shortest text that
//! parses back to the same `f64`: the same samples written out as CSV give byte-identical
//! outputs, which the tests here check.

mod common;

use std::path::{Path, PathBuf};

use common::{ok, p, scratch, truenorth};
use truenorth::core::{ImuSample, angle_diff, rad_to_deg};
use truenorth::fusion::AttitudeError;
use truenorth::nalgebra::{Quaternion, UnitQuaternion};
use truenorth_logs::{LogConfig, LogReader, Recording};

fn px4(name: &str) -> Option<PathBuf> {
    Some(
        truenorth_sim::shared_data::folder("px4_ulog_samples")
            .unwrap()?
            .join(name),
    )
}

fn mcap() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../truenorth-logs/tests/data/ros2_small.mcap")
}

fn read(path: &Path) -> Recording {
    LogReader::new(LogConfig::default())
        .unwrap()
        .read_path(path)
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The numeric rows of a CSV the command wrote (header skipped, empty cells NaN).
fn rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|c| c.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

/// Runs the command expecting a refusal: non-zero exit and exactly one line on stderr,
/// containing `expected`.
fn refused(args: &[&str], expected: &str) {
    let out = truenorth(args);
    let err = text(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(expected), "{args:?}: {err}");
}

/// Writes IMU rows as the orientation command's CSV (empty magnetometer cells where a row
/// has no reading), each number in Rust's shortest round-trip text.
fn write_imu_csv(path: &Path, samples: &[ImuSample]) {
    let mut s = String::from("t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n");
    for r in samples {
        let (g, a) = (r.gyr_rps.as_xyz().unwrap(), r.acc_mps2.as_xyz().unwrap());
        s += &format!("{},{},{},{},{},{},{}", r.t_s, g.x, g.y, g.z, a.x, a.y, a.z);
        match r.mag.as_xyz() {
            Some(m) => s += &format!(",{},{},{}\n", m.x, m.y, m.z),
            None => s += ",,,\n",
        }
    }
    std::fs::write(path, s).unwrap();
}

/// Inclination and heading of the command's attitudes against PX4's `vehicle_attitude`
/// after `settle_s`, as the logs crate's test compares the library's filter: the RMS of
/// the inclination difference, the RMS of the filter's own inclination σ over the same
/// instants, the mean heading offset and the number compared.
fn against_px4(out: &[Vec<f64>], r: &Recording, settle_s: f64) -> (f64, f64, f64, usize) {
    let start = out[0][0] + settle_s;
    let (mut incl2, mut sigma2, mut heads) = (0.0, 0.0, Vec::new());
    for a in r.attitude.iter().filter(|a| a.t_s >= start) {
        let k = out.partition_point(|row| row[0] <= a.t_s);
        if k == 0 {
            continue;
        }
        let row = &out[k - 1];
        let q = UnitQuaternion::from_quaternion(Quaternion::new(row[1], row[2], row[3], row[4]));
        let e = AttitudeError::between(&q, &a.attitude);
        incl2 += e.inclination_rad.powi(2);
        // --status: sigma_x_deg, sigma_y_deg (north, east) are columns 16 and 17.
        sigma2 += row[16].hypot(row[17]).to_radians().powi(2);
        let d = (q * a.attitude.inverse()).into_inner();
        heads.push(angle_diff(2.0 * (d.k / d.w).atan(), 0.0));
    }
    let n = heads.len() as f64;
    (
        rad_to_deg((incl2 / n).sqrt()),
        rad_to_deg((sigma2 / n).sqrt()),
        rad_to_deg(heads.iter().sum::<f64>() / n),
        heads.len(),
    )
}

#[test]
fn orientation_on_sample_ulg_agrees_with_px4_as_the_library_does() {
    let Some(log) = px4("sample.ulg") else { return };
    let dir = scratch("log_inputs", "orientation_px4");
    let out = dir.join("attitude.csv");
    ok(&[
        "orientation",
        "--input",
        p(&log),
        "--output",
        p(&out),
        "--status",
    ]);
    let r = read(&log);
    let got = rows(&out);
    assert_eq!(got.len(), r.imu.len(), "one row per IMU sample");
    let (incl_rms, sigma_rms, offset, n) = against_px4(&got, &r, 10.0);
    eprintln!(
        "truenorth orientation --input sample.ulg vs PX4 vehicle_attitude ({n} instants after \
         10 s): inclination RMS {incl_rms:.3}°, the filter's own σ RMS {sigma_rms:.3}°, \
         heading offset {offset:+.3}°"
    );
    assert!(n > 5000);
    // The logs crate's bound: PX4's estimate is another from the same sensors; twice the
    // filter's own σ bounds the difference.
    assert!(
        incl_rms <= 2.0 * sigma_rms,
        "{incl_rms:.3}° vs σ {sigma_rms:.3}°"
    );
}

#[test]
fn a_log_and_its_samples_as_csv_give_byte_identical_outputs() {
    let Some(log) = px4("sample.ulg") else { return };
    let dir = scratch("log_inputs", "same_as_csv");
    let r = read(&log);
    let csv = dir.join("imu.csv");
    write_imu_csv(&csv, &r.imu_with_mag());
    let (from_log, from_csv) = (dir.join("log.csv"), dir.join("csv.csv"));
    for (input, output) in [(&log, &from_log), (&csv, &from_csv)] {
        ok(&[
            "orientation",
            "--input",
            p(input),
            "--output",
            p(output),
            "--status",
        ]);
    }
    assert_eq!(
        std::fs::read(&from_log).unwrap(),
        std::fs::read(&from_csv).unwrap()
    );
    // The magnetometer at its own rate, as calibrate's 2-D and 3-D methods read it.
    let mag = dir.join("mag.csv");
    let mut s = String::from("t_s,mag_x,mag_y,mag_z\n");
    for m in &r.mag {
        s += &format!("{},{},{},{}\n", m.t_s, m.mag.x, m.mag.y, m.mag.z);
    }
    std::fs::write(&mag, s).unwrap();
    let calibration = |input: &Path| {
        let out = ok(&[
            "calibrate",
            "--method",
            "merit-circle",
            "--accept-poor",
            "--input",
            p(input),
            "--output",
            "-",
        ]);
        let mut json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        json.as_object_mut().unwrap().remove("input");
        json
    };
    assert_eq!(calibration(&log), calibration(&mag));
}

#[test]
fn calibrate_on_sample_ulg_gives_a_verdict() {
    let Some(log) = px4("sample.ulg") else { return };
    // A flight covers too little of the heading circle for a trustworthy fit: the verdict
    // is `poor`, refused in one line, written with --accept-poor.
    refused(
        &[
            "calibrate",
            "--method",
            "merit-circle",
            "--input",
            p(&log),
            "--output",
            "-",
        ],
        "is poor",
    );
    let out = ok(&[
        "calibrate",
        "--method",
        "merit-circle",
        "--accept-poor",
        "--input",
        p(&log),
        "--output",
        "-",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["quality"]["verdict"], "poor", "{json}");
    // Its heading: one row per magnetometer reading (a 2-D calibration reads no tilt).
    let dir = scratch("log_inputs", "calibrate_verdict");
    let (cal, heading) = (dir.join("cal.json"), dir.join("heading.csv"));
    std::fs::write(&cal, &out.stdout).unwrap();
    ok(&[
        "heading",
        "--calibration",
        p(&cal),
        "--input",
        p(&log),
        "--output",
        p(&heading),
    ]);
    assert_eq!(rows(&heading).len(), 6759);
    // The few-shot magnetometer + accelerometer method reads both, and says why it cannot
    // fit in one line.
    refused(
        &[
            "calibrate",
            "--method",
            "ellipsoid-accel",
            "--input",
            p(&log),
            "--output",
            "-",
        ],
        "cannot calibrate",
    );
}

#[test]
fn inspect_lists_the_topics_and_the_streams_read() {
    let out = ok(&["inspect", p(&mcap())]);
    let s = text(&out.stdout);
    for expected in [
        "(MCAP), complete",
        "/imu/data (sensor_msgs/msg/Imu, 200 messages",
        "/odom (nav_msgs/msg/Odometry, 20 messages",
        "imu: /imu/data, 200 samples, 200.00 Hz",
        "mag: /imu/mag, 50 samples, 50.00 Hz",
        "--odometry-topic",
    ] {
        assert!(s.contains(expected), "{expected}: {s}");
    }
    assert!(!s.contains("options: "), "no CSV option reads a log: {s}");
    let json = ok(&["inspect", "--json", p(&mcap())]);
    let json: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(json["log"]["format"], "MCAP");
    assert_eq!(json["log"]["topics"].as_array().unwrap().len(), 4);
    assert_eq!(json["options"].as_array().unwrap().len(), 0);
    let Some(log) = px4("sample_log_small.ulg") else {
        return;
    };
    let s = text(&ok(&["inspect", p(&log)]).stdout);
    for expected in [
        "(PX4 ULog), complete",
        "sensor_mag (instance 1, 6 messages",
        "mag: vehicle_magnetometer:0, 319 samples",
        "gnss: vehicle_gps_position:0, 32 samples",
        "gnss: 32 fixes at 5.0001 Hz, no gaps; sigma 2.51-3.26 m (median 2.83 m); speed and course given",
    ] {
        assert!(s.contains(expected), "{expected}: {s}");
    }
    let s = text(&ok(&["inspect", p(&log), "--mag-topic", "sensor_mag:1"]).stdout);
    assert!(s.contains("mag: sensor_mag:1, 6 samples"), "{s}");
}

#[test]
fn every_log_is_read_with_its_counts() {
    for (name, imu, mag) in [
        ("sample.ulg", 17070u64, 6759u64),
        ("sample_log_small.ulg", 1298, 319),
        ("sample_appended_multiple.ulg", 2373, 444),
    ] {
        let Some(log) = px4(name) else { return };
        let dir = scratch("log_inputs", &format!("counts_{name}"));
        let out = dir.join("o.csv");
        ok(&["orientation", "--input", p(&log), "--output", p(&out)]);
        assert_eq!(rows(&out).len() as u64, imu, "{name}");
        // inspect reads every stream at its own times: each column its own readings.
        let json = ok(&["inspect", "--json", p(&log)]);
        let json: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
        let readings = |name: &str| {
            json["columns"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c["name"] == name)
                .map(|c| c["readings"].as_u64().unwrap())
        };
        assert_eq!(readings("gyr_x"), Some(imu), "{name}");
        assert_eq!(readings("mag_z"), Some(mag), "{name}");
    }
}

#[test]
fn the_mcap_bag_drives_orients_and_heads() {
    let dir = scratch("log_inputs", "mcap");
    let bag = mcap();
    // The robot turns left at 0.5 rad/s for 0.995 s: its heading falls by 28.5°.
    let vehicle = common::vehicle_file(&dir, "robot.json", 0.5, "differential");
    let track = dir.join("track.csv");
    ok(&[
        "drive",
        "--vehicle",
        p(&vehicle),
        "--input",
        p(&bag),
        "--output",
        p(&track),
    ]);
    let last = rows(&track).pop().unwrap();
    let expected = 360.0 - rad_to_deg(0.5 * 0.995);
    assert!((last[3] - expected).abs() < 0.1, "{last:?}");
    let plain = dir.join("o.csv");
    ok(&["orientation", "--input", p(&bag), "--output", p(&plain)]);
    assert_eq!(rows(&plain).len(), 200);
    let without = dir.join("no_mag.csv");
    ok(&[
        "orientation",
        "--input",
        p(&bag),
        "--output",
        p(&without),
        "--mag-topic",
        "none",
    ]);
    assert_ne!(
        std::fs::read(&plain).unwrap(),
        std::fs::read(&without).unwrap()
    );
    // Standard input and gzip are looked into as for a CSV.
    let gz = dir.join("bag.mcap.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut enc, &std::fs::read(&bag).unwrap()).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    ok(&["orientation", "--input", p(&gz), "--output", p(&a)]);
    common::ok_with(
        &["orientation", "--input", "-", "--output", p(&b)],
        Some(&std::fs::read(&bag).unwrap()),
    );
    let plain = std::fs::read(&plain).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), plain);
    assert_eq!(std::fs::read(&b).unwrap(), plain);
}

#[test]
fn every_refusal_is_one_line() {
    let dir = scratch("log_inputs", "refusals");
    let bag = mcap();
    let bag = p(&bag);
    let o = dir.join("o.csv");
    let o = p(&o);
    let orientation = |extra: &[&str], expected: &str| {
        let mut args = vec!["orientation", "--input", bag, "--output", o];
        args.extend(extra);
        refused(&args, expected);
    };
    orientation(&["--axes", "flu"], "--axes applies to CSV input");
    orientation(
        &["--gyro-unit", "deg/s"],
        "--gyro-unit applies to CSV input",
    );
    orientation(&["--acc-unit", "g"], "--acc-unit applies to CSV input");
    orientation(&["--mag-unit", "G"], "--mag-unit applies to CSV input");
    orientation(&["--column", "t_s=time"], "--column applies to CSV input");
    orientation(&["--delimiter", ";"], "--delimiter applies to CSV input");
    orientation(&["--no-header"], "--no-header applies to CSV input");
    orientation(&["--imu-topic", "/nope"], "topics present: /chatter");
    orientation(&["--imu-topic", "/imu/mag"], "cannot serve as imu");
    orientation(&["--imu-topic", "none"], "--imu-topic cannot be `none`");
    // `eval broad` reads CSV trials only: a log option is refused before any folder is read.
    refused(
        &["eval", "broad", p(&dir), "--imu-topic", "/imu"],
        "eval broad reads CSV files only, and --imu-topic applies to a PX4 ULog or MCAP log",
    );
    refused(
        &[
            "calibrate",
            "--method",
            "ellipse",
            "--input",
            bag,
            "--output",
            o,
            "--mag-topic",
            "none",
        ],
        "needs the magnetometer",
    );
    let skid = dir.join("skid.json");
    std::fs::write(
        &skid,
        r#"{"track_m": 0.5, "odometer_wheels": "skid_steer"}"#,
    )
    .unwrap();
    refused(
        &[
            "drive",
            "--vehicle",
            p(&skid),
            "--input",
            bag,
            "--output",
            o,
        ],
        "rigid axle",
    );
    // Truncated and corrupt bytes.
    let bytes = std::fs::read(mcap()).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(
        &["orientation", "--input", p(&cut), "--output", o],
        "--accept-incomplete",
    );
    let kept = truenorth(&[
        "orientation",
        "--input",
        p(&cut),
        "--output",
        o,
        "--accept-incomplete",
    ]);
    assert!(kept.status.success(), "{}", text(&kept.stderr));
    assert!(text(&kept.stderr).contains("warning"));
    let mut corrupt = bytes.clone();
    for b in corrupt.iter_mut().skip(200).step_by(13) {
        *b ^= 0x5a;
    }
    let bad = dir.join("corrupt.mcap");
    std::fs::write(&bad, &corrupt).unwrap();
    refused(
        &["orientation", "--input", p(&bad), "--output", o],
        "corrupt",
    );
    // Topic options with a CSV.
    let csv = dir.join("x.csv");
    std::fs::write(&csv, "t_s,mag_x,mag_y\n0,1,2\n").unwrap();
    refused(
        &[
            "calibrate",
            "--method",
            "ellipse",
            "--input",
            p(&csv),
            "--output",
            o,
            "--mag-topic",
            "/imu/mag",
        ],
        "read as CSV",
    );
    let Some(log) = px4("sample.ulg") else { return };
    let log = p(&log);
    refused(
        &[
            "orientation",
            "--input",
            log,
            "--output",
            o,
            "--mag-topic",
            "foo",
        ],
        "no mag topic `foo:0` in the log; topics present: actuator_controls_0",
    );
    let bytes = std::fs::read(log).unwrap();
    let cut = dir.join("cut.ulg");
    std::fs::write(&cut, &bytes[..bytes.len() / 2 + 7]).unwrap();
    refused(
        &["orientation", "--input", p(&cut), "--output", o],
        "incomplete after",
    );
    let mut corrupt = bytes;
    for b in corrupt.iter_mut().skip(3000).take(3000).step_by(7) {
        *b ^= 0x5a;
    }
    let bad = dir.join("corrupt.ulg");
    std::fs::write(&bad, &corrupt).unwrap();
    refused(
        &["orientation", "--input", p(&bad), "--output", o],
        "corrupt",
    );
}

/// A PX4 ULog has no odometry: `drive` reads it as a vehicle with a gyro, a compass and
/// fixes and no wheels (its `vel_m_s` and `cog_rad` as the fixes' speed and course): the
/// heading on every row, no position, and the fixes said to give none. `sample_log_small`
/// stands still (0.02–0.28 m/s), so no course is used.
#[test]
fn drive_reads_a_ulog_as_gyro_compass_and_fixes_without_wheels() {
    let Some(log) = px4("sample_log_small.ulg") else {
        return;
    };
    let dir = scratch("log_inputs", "ulog_drive");
    let vehicle = common::vehicle_file(&dir, "robot.json", 0.57, "skid_steer");
    let out = dir.join("out.csv");
    let o = common::drive(&vehicle, &log, &out, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stderr = text(&o.stderr);
    for expected in [
        "`lat_deg,lon_deg` give no position",
        "0 courses used (no odometry: no position)",
        "sensors: gyro + compass, no wheels + GNSS",
    ] {
        assert!(stderr.contains(expected), "{expected}: {stderr}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 1649);
    for r in &rows {
        let cells: Vec<&str> = r.split(',').collect();
        assert!(cells[1].is_empty() && cells[2].is_empty(), "{r}");
        assert!(cells[3].parse::<f64>().is_ok(), "{r}");
    }
}
