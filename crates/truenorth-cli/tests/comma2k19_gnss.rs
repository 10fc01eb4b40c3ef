//! `truenorth drive` on a real car with its own receiver's fixes: the comma2k19 example
//! segment (a Toyota RAV4, 60 s and 1 km north on an almost straight road), its rear wheel
//! speeds and the phone-class IMU's raw yaw rate (a bias of about 3.9°/s), with the u-blox
//! receiver's fixes (10 Hz, speed and course, no accuracy) on rows of their own, against the
//! reference pose of an INS/GNSS/vision optimiser.
//!
//! With every fix the track follows the reference to the fixes' own error; with the fixes
//! withheld after the first 30 s, the last 30 s are dead reckoned from what the first 30 s
//! taught — the raw gyro's bias above all, which no rest on this drive could give — beside
//! plain dead reckoning with the same sensors from the fixes' track direction. Without its
//! wheels, the raw yaw rate and the fixes' course alone give the heading.
//! `cargo test -p truenorth-cli --test comma2k19_gnss -- --nocapture` prints the figures.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::scratch;
use common::tables::{Table, interp};
use truenorth::geomag::{Geodetic, LocalTangentPlane};

const FOLDER: &str = "vehicle_comma2k19_example";

/// The rear track of the XA40 RAV4, m (Toyota's published figure, about 1.57 m).
const TRACK_M: f64 = 1.57;

/// Seconds of fixes before they are withheld.
const FIXES_FOR_S: f64 = 30.0;

/// Writes DRIVE.csv: rows at the wheel speeds' rate with the rear wheels (`wheels`; else
/// without them) and the raw yaw rate (the IMU's down axis, positive turning right)
/// interpolated to them, and each u-blox fix on a row of its own; fixes after
/// `fixes_until_s` (log time) left out.
fn write_drive(dir: &Path, path: &Path, fixes_until_s: f64, wheels_on: bool) {
    let wheels = Table::read(&dir.join("can_speed_wheels.csv"));
    let imu = Table::read(&dir.join("imu.csv"));
    let fixes = Table::read(&dir.join("gnss_ublox_fix.csv"));
    let t = wheels.col("t_boot_s");
    let (vl, vr) = (wheels.col("wheel_rl_mps"), wheels.col("wheel_rr_mps"));
    let (t_imu, rate) = (imu.col("t_boot_s"), imu.col("gyr_uncal_d_rps"));
    let tf = fixes.col("t_boot_s");
    let (lat, lon) = (fixes.col("lat_deg"), fixes.col("lon_deg"));
    let (speed, course) = (fixes.col("speed_mps"), fixes.col("bearing_deg"));
    let mut s = String::from(if wheels_on {
        "t_s,speed_l_mps,speed_r_mps,gyr_z,lat_deg,lon_deg,gnss_speed_mps,gnss_course_deg\n"
    } else {
        "t_s,gyr_z,lat_deg,lon_deg,gnss_speed_mps,gnss_course_deg\n"
    });
    let blank_wheels = if wheels_on { ",," } else { "" };
    let mut f = tf.partition_point(|&x| x <= t[0]);
    for k in 0..t.len() {
        while f < tf.len() && tf[f] < t[k] {
            if tf[f] <= fixes_until_s {
                writeln!(
                    s,
                    "{}{blank_wheels},,{},{},{},{}",
                    tf[f], lat[f], lon[f], speed[f], course[f]
                )
                .unwrap();
            }
            f += 1;
        }
        if f < tf.len() && tf[f] == t[k] {
            f += 1;
        }
        let rate_k = interp(&t_imu, &rate, t[k]);
        if wheels_on {
            writeln!(s, "{},{},{},{rate_k},,,,", t[k], vl[k], vr[k]).unwrap();
        } else {
            writeln!(s, "{},{rate_k},,,,", t[k]).unwrap();
        }
    }
    std::fs::write(path, s).unwrap();
}

/// The distance of each output row's position (`lat_deg,lon_deg`, the last two columns) from
/// the reference pose at its time, m, on the rows that have one; and the last row's.
fn errors(rows: &[Vec<f64>], pose: &Table) -> (f64, f64) {
    let (t, lat, lon) = (
        pose.col("t_boot_s"),
        pose.col("lat_deg"),
        pose.col("lon_deg"),
    );
    let plane = LocalTangentPlane::new(lat[0], lon[0], 0.0).unwrap();
    let at = |la: f64, lo: f64| {
        let [n, e, _] = plane.from_geodetic(&Geodetic::from_degrees(la, lo, 0.0).unwrap());
        (n, e)
    };
    let (mut sq, mut n, mut last) = (0.0, 0usize, f64::NAN);
    for r in rows {
        let (la, lo) = (r[r.len() - 2], r[r.len() - 1]);
        if la.is_nan() || r[0] > *t.last().unwrap() {
            continue;
        }
        let (pn, pe) = at(la, lo);
        let (rn, re) = at(interp(&t, &lat, r[0]), interp(&t, &lon, r[0]));
        last = (pn - rn).hypot(pe - re);
        sq += last * last;
        n += 1;
    }
    ((sq / n.max(1) as f64).sqrt(), last)
}

/// Plain dead reckoning over the last 30 s: from the reference position where the fixes
/// stop, along the fixes' track over the last 20 m before it, the IMU's yaw-rate column
/// `gyro` integrated, times the rear wheels' mean distance. Its final error, m.
fn plain_end_error(dir: &Path, pose: &Table, from_s: f64, gyro: &str) -> f64 {
    let fixes = Table::read(&dir.join("gnss_ublox_fix.csv"));
    let (tf, lat, lon) = (
        fixes.col("t_boot_s"),
        fixes.col("lat_deg"),
        fixes.col("lon_deg"),
    );
    let (t, plat, plon) = (
        pose.col("t_boot_s"),
        pose.col("lat_deg"),
        pose.col("lon_deg"),
    );
    let plane = LocalTangentPlane::new(plat[0], plon[0], 0.0).unwrap();
    let at = |la: f64, lo: f64| {
        let [n, e, _] = plane.from_geodetic(&Geodetic::from_degrees(la, lo, 0.0).unwrap());
        (n, e)
    };
    let k1 = tf.partition_point(|&x| x <= from_s) - 1;
    let (n1, e1) = at(lat[k1], lon[k1]);
    let k0 = (0..k1)
        .rev()
        .find(|&k| {
            let (n0, e0) = at(lat[k], lon[k]);
            (n1 - n0).hypot(e1 - e0) >= 20.0
        })
        .unwrap();
    let (n0, e0) = at(lat[k0], lon[k0]);
    let mut psi = (e1 - e0).atan2(n1 - n0);
    let wheels = Table::read(&dir.join("can_speed_wheels.csv"));
    let imu = Table::read(&dir.join("imu.csv"));
    let tw = wheels.col("t_boot_s");
    let (vl, vr) = (wheels.col("wheel_rl_mps"), wheels.col("wheel_rr_mps"));
    let (t_imu, rate) = (imu.col("t_boot_s"), imu.col(gyro));
    let (mut n, mut e) = at(interp(&t, &plat, from_s), interp(&t, &plon, from_s));
    let end = *t.last().unwrap();
    let mut last = from_s;
    for k in tw.partition_point(|&x| x <= from_s)..tw.len() {
        if tw[k] > end {
            break;
        }
        let dt = tw[k] - last;
        psi += interp(&t_imu, &rate, tw[k] - 0.5 * dt) * dt;
        let ds = 0.5 * (vl[k] + vr[k]) * dt;
        n += ds * psi.cos();
        e += ds * psi.sin();
        last = tw[k];
    }
    let (rn, re) = at(interp(&t, &plat, last), interp(&t, &plon, last));
    (n - rn).hypot(e - re)
}

#[test]
fn a_real_car_with_its_own_fixes() {
    let Some(dir) = truenorth_sim::shared_data::folder(FOLDER).unwrap() else {
        return;
    };
    let scratch = scratch("comma2k19_gnss", "drive");
    let pose = Table::read(&dir.join("pose_reference.csv"));
    let vehicle = common::rear_vehicle(&scratch, TRACK_M);
    let t0 = Table::read(&dir.join("can_speed_wheels.csv")).col("t_boot_s")[0];
    let run = |name: &str, until_s: f64| {
        let input = scratch.join(format!("{name}.csv"));
        write_drive(&dir, &input, until_s, true);
        let out = scratch.join(format!("{name}-out.csv"));
        let o = common::succeeded(common::drive(
            &vehicle,
            &input,
            &out,
            &["--extra", "calibration", "--extra", "geodetic"],
        ));
        let stderr = String::from_utf8_lossy(&o.stderr).to_string();
        let (header, rows) = common::table(&out, true);
        let bias = header.iter().position(|h| h == "gyro_bias_dps").unwrap();
        (stderr, rows.last().unwrap()[bias], errors(&rows, &pose))
    };
    let (stderr, bias, (rms, _)) = run("all", f64::INFINITY);
    assert!(
        stderr.contains("true north, from the satellite fixes"),
        "{stderr}"
    );
    println!(
        "every fix: position RMS {rms:.2} m against the reference; gyro bias learned {bias:.3}°/s"
    );
    let from_s = t0 + FIXES_FOR_S;
    let (_, bias_30, (_, end)) = run("first30", from_s);
    // The raw gyro with no bias removed (the car never stops), and the phone's own
    // bias-corrected rate.
    let plain = plain_end_error(&dir, &pose, from_s, "gyr_uncal_d_rps");
    let zeroed = plain_end_error(&dir, &pose, from_s, "gyr_d_rps");
    println!(
        "fixes for the first {FIXES_FOR_S} s only: end error {end:.2} m after the last 30 s (gyro bias learned {bias_30:.3}°/s); plain dead reckoning from the fixes' track {plain:.2} m with the raw gyro, {zeroed:.2} m with the phone's zeroed one"
    );
    // The u-blox fixes against the reference: a few metres.
    assert!(rms < 5.0, "position RMS {rms:.2} m");
    // What 30 s of fixes taught must beat dead reckoning that did not learn the bias, and be
    // no worse than the phone's own bias correction: on a straight road both ends are off
    // by the start's error and the odometer's scale, so within a tenth of each other.
    assert!(end < plain / 3.0, "{end:.2} m against plain {plain:.2} m");
    assert!(
        end <= 1.1 * zeroed,
        "{end:.2} m against the zeroed gyro's {zeroed:.2} m"
    );
}

/// The same car without its wheels: the raw yaw rate (3.9°/s of bias, no rest) and the
/// u-blox fixes' course. The courses refer the heading to true north and teach the bias;
/// against the reference's course over ground the heading's error RMS on the rows referred,
/// with the position cells empty on every row.
#[test]
fn without_its_wheels_the_courses_refer_the_heading() {
    let Some(dir) = truenorth_sim::shared_data::folder(FOLDER).unwrap() else {
        return;
    };
    let scratch = scratch("comma2k19_gnss", "courses");
    let pose = Table::read(&dir.join("pose_reference.csv"));
    let (tp, cog) = (pose.col("t_boot_s"), pose.col("course_over_ground_deg"));
    let vehicle = common::rear_vehicle(&scratch, TRACK_M);
    let input = scratch.join("no_wheels.csv");
    write_drive(&dir, &input, f64::INFINITY, false);
    let out = scratch.join("no_wheels-out.csv");
    let o = common::succeeded(common::drive(
        &vehicle,
        &input,
        &out,
        &[
            "--extra",
            "sigma",
            "--extra",
            "status",
            "--extra",
            "calibration",
            "--single-pass",
        ],
    ));
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        stderr.contains("true north, from the satellite fixes"),
        "{stderr}"
    );
    let (header, rows) = common::table(&out, true);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{name} not in {header:?}"))
    };
    let (heading, sigma, bias) = (
        col("heading_deg"),
        col("heading_sigma_deg"),
        col("gyro_bias_dps"),
    );
    let absolute = col("heading_absolute");
    let (mut sq, mut n, mut beyond) = (0.0, 0usize, 0usize);
    for r in &rows {
        assert!(
            r[1].is_nan() && r[2].is_nan(),
            "a position without odometry: {r:?}"
        );
        if r[0] > *tp.last().unwrap() || r[absolute] != 1.0 {
            continue;
        }
        let err = (r[heading] - interp(&tp, &cog, r[0]) + 540.0).rem_euclid(360.0) - 180.0;
        sq += err * err;
        n += 1;
        beyond += usize::from(err.abs() > 3.0 * r[sigma]);
    }
    let rms = (sq / n.max(1) as f64).sqrt();
    let last_bias = rows.last().unwrap()[bias];
    println!(
        "no wheels, raw gyro + courses: heading against the reference's course {rms:.2}° RMS over {n} rows, {:.2} % beyond 3σ; gyro bias learned {last_bias:.3}°/s (the reference implies 3.884)",
        100.0 * beyond as f64 / n.max(1) as f64
    );
    assert!(n > rows.len() / 2, "{n} of {} rows referred", rows.len());
    assert!(rms < 3.0, "{rms:.2}°");
    assert!(beyond * 50 <= n, "{beyond} of {n} rows beyond 3σ");
}
