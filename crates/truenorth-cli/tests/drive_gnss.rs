//! `truenorth drive` with satellite fixes on their own rows (`lat_deg,lon_deg,gnss_sigma_m,
//! gnss_speed_mps,gnss_course_deg`), on a simulated car whose receiver has a real one's
//! habits: the track in the tangent plane at the first fix, the heading from true north,
//! `--extra geodetic` giving each row's latitude and longitude, and the summary saying what
//! the fixes did.

mod common;

use common::scratch;
use truenorth::core::angle_diff;
use truenorth::geomag::Geodetic;
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

#[test]
fn fixes_put_the_track_on_the_earth_and_the_heading_on_true_north() {
    let dir = scratch("drive_gnss", "car");
    let d = LogDrive::new(
        LogDriveConfig::new(1, VehicleKind::RearWheelCar, SensorSet::WHEELS_GYRO).with_gnss(),
    )
    .unwrap();
    let input = dir.join("drive.csv");
    std::fs::write(&input, d.to_csv()).unwrap();
    let track_m = d.vehicle.wheels.track_m();
    let vehicle = common::rear_vehicle(&dir, track_m);
    let out = dir.join("out.csv");
    let o = common::succeeded(common::drive(
        &vehicle,
        &input,
        &out,
        &["--extra", "status", "--extra", "geodetic"],
    ));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("heading true north, from the satellite fixes"),
        "{stderr}"
    );
    assert!(
        stderr.contains("satellite fixes: ") && stderr.contains("(the first fix)"),
        "{stderr}"
    );
    assert!(!stderr.contains("no north"), "{stderr}");
    let (header, rows) = common::table(&out, true);
    assert_eq!(&header[..4], ["t_s", "north_m", "east_m", "heading_deg"]);
    assert_eq!(&header[header.len() - 2..], ["lat_deg", "lon_deg"]);
    let plane = d.plane.unwrap();
    let (mut sq, mut hsq, mut n) = (0.0, 0.0, 0usize);
    for (row, t) in rows.iter().zip(&d.truth) {
        let (lat, lon) = (row[row.len() - 2], row[row.len() - 1]);
        if lat.is_nan() {
            continue;
        }
        let [pn, pe, _] = plane.from_geodetic(&Geodetic::from_degrees(lat, lon, 0.0).unwrap());
        sq += (pn - t.north_m).powi(2) + (pe - t.east_m).powi(2);
        hsq += angle_diff(row[3].to_radians(), t.heading_rad).powi(2);
        n += 1;
    }
    let (rms, heading_rms) = ((sq / n as f64).sqrt(), (hsq / n as f64).sqrt().to_degrees());
    println!("{n} rows on the fixes: position RMS {rms:.2} m, true heading RMS {heading_rms:.2}°");
    assert!(
        n > rows.len() / 2,
        "only {n} of {} rows on the fixes",
        rows.len()
    );
    // The fixes' own error (σ 0.7-3 m, correlated over 20-200 s), the antenna 0.5-2.5 m
    // off the axle, outages of up to 90 s and canyons: a few metres.
    assert!(rms < 6.0, "position RMS {rms:.2} m");
    assert!(heading_rms < 3.0, "heading RMS {heading_rms:.2}°");
}

/// The antenna's place in VEHICLE.json (`gnss_lever_arm_m`, forward and right of the axle's
/// centre) is read, and one no vehicle has is refused with the key; given for a log without
/// fixes, it is said unused.
#[test]
fn the_antenna_s_lever_arm_is_read_and_checked() {
    let dir = scratch("drive_gnss", "lever");
    let d = LogDrive::new(
        LogDriveConfig::new(2, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW).with_gnss(),
    )
    .unwrap();
    let input = dir.join("drive.csv");
    std::fs::write(&input, d.to_csv()).unwrap();
    let [forward, right] = d.gnss.as_ref().unwrap().lever_arm_m;
    let vehicle = |name: &str, lever: [f64; 2]| {
        let path = dir.join(name);
        let json = format!(
            r#"{{"track_m": {}, "odometer_wheels": "rear", "gnss_lever_arm_m": [{}, {}]}}"#,
            d.vehicle.wheels.track_m(),
            lever[0],
            lever[1]
        );
        std::fs::write(&path, json).unwrap();
        path
    };
    let out = dir.join("out.csv");
    let o = common::drive(&vehicle("ok.json", [forward, right]), &input, &out, &[]);
    common::succeeded(o);
    let o = common::drive(&vehicle("far.json", [120.0, 0.0]), &input, &out, &[]);
    let (ok, stderr) = common::outcome(&o);
    assert!(!ok && stderr.contains("gnss_lever_arm_m"), "{stderr}");
    let no_fixes = LogDrive::new(LogDriveConfig::new(
        2,
        VehicleKind::RearWheelCar,
        SensorSet::SPEED_YAW,
    ))
    .unwrap();
    let input = dir.join("no_fixes.csv");
    std::fs::write(&input, no_fixes.to_csv()).unwrap();
    let o = common::drive(&vehicle("ok.json", [forward, right]), &input, &out, &[]);
    let (ok, stderr) = common::outcome(&o);
    assert!(
        ok && stderr.contains("`gnss_lever_arm_m` in the vehicle file is not used"),
        "{stderr}"
    );
}

/// The head of a drive, run again once the sensors are known, comes out in the fixes'
/// plane like the rest: with fixes alone (they refer the heading to true north) and with a
/// compass that refers it to magnetic north first, every row with a position has its
/// latitude and the track
/// no jump larger than the vehicle's own steps and the fixes' corrections (it jumped by the
/// start's distance from the first fix where the rows before switched frames).
#[test]
fn the_whole_track_is_on_the_plane() {
    for (name, set) in [
        ("fixes", SensorSet::WHEELS_GYRO),
        ("compass", SensorSet::WHEELS_GYRO.with_compass()),
    ] {
        let dir = scratch("drive_gnss", name);
        let d = LogDrive::new(LogDriveConfig::new(2, VehicleKind::RearWheelCar, set).with_gnss())
            .unwrap();
        let input = dir.join("drive.csv");
        std::fs::write(&input, d.to_csv()).unwrap();
        let vehicle = common::rear_vehicle(&dir, d.vehicle.wheels.track_m());
        let out = dir.join("out.csv");
        common::succeeded(common::drive(
            &vehicle,
            &input,
            &out,
            &["--extra", "geodetic"],
        ));
        let (header, rows) = common::table(&out, true);
        let lat = header.iter().position(|h| h == "lat_deg").unwrap();
        // Rows before the wheels' first reading have no position at all.
        let without = rows
            .iter()
            .filter(|r| r[1].is_finite() && r[lat].is_nan())
            .count();
        let step = rows
            .windows(2)
            .map(|w| (w[1][1] - w[0][1]).hypot(w[1][2] - w[0][2]))
            .fold(0.0, f64::max);
        println!(
            "{name}: {without} of {} rows off the plane, largest step {step:.2} m",
            rows.len()
        );
        assert_eq!(without, 0, "{name}");
        assert!(step < 5.0, "{name}: a step of {step:.2} m");
    }
}

/// An odometer that reads 1 % long (a tyre's rolling radius taken from its nominal size):
/// the fixes' speeds teach the scale, the summary says it, `--calibration-out` keeps it,
/// and `--extra calibration,trust` carries it on every row.
#[test]
fn the_fixes_teach_the_odometer_scale() {
    let dir = scratch("drive_gnss", "scale");
    let d = LogDrive::new(
        LogDriveConfig::new(1, VehicleKind::RearWheelCar, SensorSet::WHEELS_GYRO).with_gnss(),
    )
    .unwrap();
    let long = 1.01;
    let csv = d.to_csv();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let wheels: Vec<usize> = ["dist_l_m", "dist_r_m"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    let mut scaled = header.join(",") + "\n";
    for line in lines {
        let cells: Vec<String> = line
            .split(',')
            .enumerate()
            .map(|(k, c)| match c.parse::<f64>() {
                Ok(v) if wheels.contains(&k) => format!("{:.4}", v * long),
                _ => c.to_string(),
            })
            .collect();
        scaled += &(cells.join(",") + "\n");
    }
    let input = dir.join("drive.csv");
    std::fs::write(&input, scaled).unwrap();
    let vehicle = common::rear_vehicle(&dir, d.vehicle.wheels.track_m());
    let (out, cal) = (dir.join("out.csv"), dir.join("learned.json"));
    let o = common::succeeded(common::drive(
        &vehicle,
        &input,
        &out,
        &[
            "--extra",
            "calibration,trust",
            "--calibration-out",
            cal.to_str().unwrap(),
        ],
    ));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("odometer scale "), "{stderr}");
    let learned: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&cal).unwrap()).unwrap();
    let k = learned["wheel_scale"]["value"].as_f64().unwrap();
    let sigma = learned["wheel_scale"]["sigma"].as_f64().unwrap();
    let truth = 1.0 / (long * d.mean_wheel_scale()) - 1.0;
    println!(
        "odometer scale error {:+.3} %, learned {:+.3} ± {:.3} %",
        100.0 * truth,
        100.0 * k,
        100.0 * sigma
    );
    assert!(
        (k - truth).abs() <= 3.0 * sigma,
        "{k} ± {sigma} against {truth}"
    );
    assert!(sigma < 0.0015, "σ {sigma}");
    let (header, rows) = common::table(&out, true);
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let last = rows.last().unwrap();
    assert!((last[column("wheel_scale")] - (1.0 + k)).abs() < 1e-4);
    assert_eq!(last[column("unobserved_wheel_scale")], 0.0);
}
