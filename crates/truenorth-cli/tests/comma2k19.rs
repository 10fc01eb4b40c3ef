//! `truenorth drive` on a real car: the comma2k19 example segment (a Toyota RAV4, 60 s and
//! 1 km driven north on an almost straight road; four CAN wheel speeds, a phone-class IMU
//! and magnetometer, and a reference pose from an INS/GNSS/vision optimiser).
//!
//! The recording's streams are merged into the command's DRIVE.csv (rows at the wheel-speed
//! rate, the yaw rate interpolated to each row, a magnetometer reading on the row after it
//! arrived and empty cells elsewhere), the command is run, and its track is compared with
//! the reference pose: heading drift, cross-track and along-track error against distance.
//!
//! What a straight minute can show: the plumbing of real wheel speeds (units, sides, the
//! speeds' integration), the odometer's scale against the reference, and how far the
//! heading drifts when the gyro's bias must be learned while driving — the car never stops,
//! so there is no rest to measure it at, and the wheels' heading is the only reference.
//! What it cannot show: anything that needs a turn — the compass calibration (so no north:
//! the heading stays relative to the start), the gyro's gains, the wheels' effective track
//! and speed coefficient — nor the odometer's mean scale, which no sensor on board sees.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::tables::{Table, integrate, interp};
use common::{ok, p, scratch};

const FOLDER: &str = "vehicle_comma2k19_example";

/// The rear track of the XA40 RAV4, m (Toyota's published figure, about 1.57 m).
const TRACK_M: f64 = 1.57;

/// The recording, the columns the comparison needs.
struct Recording {
    wheels: Table,
    imu: Table,
    mag: Table,
    pose: Table,
}

impl Recording {
    fn read(dir: &Path) -> Self {
        Self {
            wheels: Table::read(&dir.join("can_speed_wheels.csv")),
            imu: Table::read(&dir.join("imu.csv")),
            mag: Table::read(&dir.join("mag.csv")),
            pose: Table::read(&dir.join("pose_reference.csv")),
        }
    }

    /// Writes DRIVE.csv: the rear wheels' speeds (the rear axle is the one the command
    /// dead-reckons), the IMU's yaw-axis column `gyro` (if any) interpolated to each row
    /// (the IMU frame is forward-right-down, so its down axis is the command's z and
    /// positive is a right turn), and the raw magnetometer's forward and right axes (the
    /// command's x and y) on the first row at or after each reading.
    fn write_drive(&self, path: &Path, gyro: Option<&str>) {
        let t = self.wheels.col("t_boot_s");
        let (vl, vr) = (
            self.wheels.col("wheel_rl_mps"),
            self.wheels.col("wheel_rr_mps"),
        );
        let t_imu = self.imu.col("t_boot_s");
        let rate = gyro.map(|g| self.imu.col(g));
        let t_mag = self.mag.col("t_boot_s");
        let (mx, my) = (
            self.mag.col("mag_uncal_f_uT"),
            self.mag.col("mag_uncal_r_uT"),
        );
        let mut s = String::from("t_s,speed_l_mps,speed_r_mps,gyr_z,mag_x,mag_y\n");
        let mut next_mag = t_mag.partition_point(|&m| m < t[0]);
        for k in 0..t.len() {
            write!(s, "{},{},{},", t[k], vl[k], vr[k]).unwrap();
            if let Some(g) = &rate {
                write!(s, "{}", interp(&t_imu, g, t[k])).unwrap();
            }
            if next_mag < t_mag.len() && t_mag[next_mag] <= t[k] {
                writeln!(s, ",{},{}", mx[next_mag], my[next_mag]).unwrap();
                next_mag += 1;
            } else {
                s += ",,\n";
            }
        }
        std::fs::write(path, s).unwrap();
    }
}

/// The reference pose, moved to the start of the wheel rows: position from there, the
/// heading change since then (the camera is fixed to the body, so its yaw changes as the
/// vehicle's), the direction of travel and the distance travelled.
struct Reference {
    t: Vec<f64>,
    north: Vec<f64>,
    east: Vec<f64>,
    yaw_deg: Vec<f64>,
    course: Vec<f64>,
    distance: Vec<f64>,
    t0: f64,
    /// Direction of travel at the start, rad: the estimated track, relative to the start
    /// heading, is turned by it.
    start_course: f64,
}

impl Reference {
    fn new(pose: &Table, t0: f64) -> Self {
        let t = pose.col("t_boot_s");
        let (north, east) = (pose.col("north_m"), pose.col("east_m"));
        let (vn, ve) = (pose.col("vel_n_mps"), pose.col("vel_e_mps"));
        let course: Vec<f64> = vn.iter().zip(&ve).map(|(n, e)| e.atan2(*n)).collect();
        let mut distance = vec![0.0; t.len()];
        for k in 1..t.len() {
            distance[k] = distance[k - 1] + (north[k] - north[k - 1]).hypot(east[k] - east[k - 1]);
        }
        // The mean velocity over the first second: the course of one pose is noisier.
        let first: Vec<usize> = (0..t.len())
            .filter(|&k| t[k] >= t0 && t[k] < t0 + 1.0)
            .collect();
        let (sn, se) = first
            .iter()
            .fold((0.0, 0.0), |(a, b), &k| (a + vn[k], b + ve[k]));
        Self {
            yaw_deg: pose.col("cam_yaw_deg"),
            t,
            north,
            east,
            course,
            distance,
            t0,
            start_course: se.atan2(sn),
        }
    }

    fn at(&self, y: &[f64], t: f64) -> f64 {
        interp(&self.t, y, t)
    }
}

/// One output row against the reference.
#[derive(Debug, Clone, Copy)]
struct Errors {
    distance_m: f64,
    heading_deg: f64,
    cross_m: f64,
    along_m: f64,
}

/// The command's rows (`t_s,north_m,east_m,heading_deg,…`) against the reference: the
/// track is turned by the reference's start course (the command knows no north here), the
/// heading compared as a change from the start.
fn compare(rows: &[Vec<f64>], r: &Reference) -> Vec<Errors> {
    let (s, c) = r.start_course.sin_cos();
    let (n0, e0) = (r.at(&r.north, r.t0), r.at(&r.east, r.t0));
    let (yaw0, d0) = (r.at(&r.yaw_deg, r.t0), r.at(&r.distance, r.t0));
    rows.iter()
        .map(|row| {
            let t = row[0];
            let (n, e) = (c * row[1] - s * row[2], s * row[1] + c * row[2]);
            let (dn, de) = (n - (r.at(&r.north, t) - n0), e - (r.at(&r.east, t) - e0));
            let (sc, cc) = r.at(&r.course, t).sin_cos();
            let turned = r.at(&r.yaw_deg, t) - yaw0;
            Errors {
                distance_m: r.at(&r.distance, t) - d0,
                heading_deg: wrap_deg(row[3] - turned),
                cross_m: -sc * dn + cc * de,
                along_m: cc * dn + sc * de,
            }
        })
        .collect()
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// A run of the command on the merged drive.
struct Run {
    name: &'static str,
    rows: Vec<Vec<f64>>,
    errors: Vec<Errors>,
    stderr: String,
    /// What the drive learned (`--calibration-out`).
    learned: serde_json::Value,
}

impl Run {
    /// A learned value and its standard deviation.
    fn learned(&self, what: &str) -> (f64, f64) {
        let v = &self.learned[what];
        (v["value"].as_f64().unwrap(), v["sigma"].as_f64().unwrap())
    }
}

/// The vehicle file: the rear wheels only. The distance resolution is left to the
/// command's default for speed columns, which should be that of the CAN speeds integrated
/// over one comparison of the wheels with the gyro (0.01 km/h × 1 s = 2.8 mm), not the
/// 2 cm of ABS pulses.
fn write_vehicle(dir: &Path) -> std::path::PathBuf {
    common::rear_vehicle(dir, TRACK_M)
}

/// Runs the command on `input` with `extra` arguments and compares its rows with `r`.
fn drive(dir: &Path, name: &'static str, input: &Path, extra: &[&str], r: &Reference) -> Run {
    let vehicle = write_vehicle(dir);
    let out = dir.join(format!("{name}.csv"));
    let learned = dir.join(format!("{name}.json"));
    let mut args = vec![
        "drive",
        "--vehicle",
        p(&vehicle),
        "--input",
        p(input),
        "--output",
        p(&out),
        "--extra",
        "sigma,status,calibration",
        "--calibration-out",
        p(&learned),
    ];
    args.extend_from_slice(extra);
    let o = ok(&args);
    let rows = Table::read(&out).rows;
    let errors = compare(&rows, r);
    Run {
        name,
        rows,
        errors,
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        learned: common::read_json(&learned),
    }
}

/// What the sensors do alone, integrated here without the command, over the wheel rows'
/// span and against the reference.
struct Alone {
    /// The rear wheels' differential heading minus the reference's turn at the end, °.
    wheels_drift_deg: f64,
    /// The same under the estimator's prior speed coefficient, °.
    wheels_prior_drift_deg: f64,
    /// The same as a mean rate, °/s: what the gyro bias learned from the wheels would be
    /// off by if the estimator blamed all of the wheels' drift on the gyro.
    wheels_rate_dps: f64,
    /// The raw gyro's bias that the reference implies (its mean rate minus the reference's
    /// mean turn rate), °/s.
    raw_bias_dps: f64,
    /// Largest and final drift of the Android-zeroed gyro's integrated heading, °.
    zeroed_max_drift_deg: f64,
    zeroed_final_drift_deg: f64,
    /// The rear wheels' mean distance over the reference's distance, minus one.
    odometer_scale_error: f64,
    /// The rear wheels' differential scale that the reference implies: the left wheel's
    /// excess distance, less what the reference's turn explains, over the distance.
    wheel_diff: f64,
}

impl Alone {
    fn new(rec: &Recording, r: &Reference) -> Self {
        let t = rec.wheels.col("t_boot_s");
        let (t0, t1) = (t[0], t[t.len() - 1]);
        let span = t1 - t0;
        let turn = |t: f64| r.at(&r.yaw_deg, t) - r.at(&r.yaw_deg, t0);
        let dl = integrate(&t, &rec.wheels.col("wheel_rl_mps"));
        let dr = integrate(&t, &rec.wheels.col("wheel_rr_mps"));
        let n = t.len() - 1;
        // A right turn takes the left wheel further.
        let wheels_drift_deg = ((dl[n] - dr[n]) / TRACK_M).to_degrees() - turn(t1);
        // The same with the car's prior speed coefficient (US 4,788,645 eq. 8: the wheels'
        // difference divided by 1 + aV²), which is what an estimator that learns nothing
        // about the wheels uses.
        let a = truenorth::fusion::SensorPriors::default().speed_coeff_s2_per_m2;
        let mut prior_turn = 0.0;
        for k in 1..=n {
            let (l, r) = (dl[k] - dl[k - 1], dr[k] - dr[k - 1]);
            let v = 0.5 * (l + r) / (t[k] - t[k - 1]);
            prior_turn += (l - r) / (TRACK_M * (1.0 + a * v * v));
        }
        let wheels_prior_drift_deg = prior_turn.to_degrees() - turn(t1);
        let t_imu = rec.imu.col("t_boot_s");
        let gyro = |c: &str| {
            let deg: Vec<f64> = integrate(&t_imu, &rec.imu.col(c))
                .iter()
                .map(|a| a.to_degrees())
                .collect();
            let at0 = interp(&t_imu, &deg, t0);
            t_imu
                .iter()
                .zip(&deg)
                .filter(|(ti, _)| (t0..=t1).contains(*ti))
                .map(|(ti, d)| (*ti, d - at0 - turn(*ti)))
                .collect::<Vec<_>>()
        };
        let raw = gyro("gyr_uncal_d_rps");
        let zeroed = gyro("gyr_d_rps");
        let (t_last, raw_last) = raw[raw.len() - 1];
        Self {
            wheels_drift_deg,
            wheels_prior_drift_deg,
            wheels_rate_dps: wheels_drift_deg / span,
            raw_bias_dps: raw_last / (t_last - t0),
            zeroed_max_drift_deg: zeroed.iter().map(|(_, d)| d.abs()).fold(0.0, f64::max),
            zeroed_final_drift_deg: zeroed[zeroed.len() - 1].1,
            wheel_diff: (dl[n] - dr[n] - turn(t1).to_radians() * TRACK_M) / (0.5 * (dl[n] + dr[n])),
            odometer_scale_error: 0.5 * (dl[n] + dr[n])
                / (r.at(&r.distance, t1) - r.at(&r.distance, t0))
                - 1.0,
        }
    }
}

fn max_abs(errors: &[Errors], f: impl Fn(&Errors) -> f64) -> f64 {
    errors.iter().map(|e| f(e).abs()).fold(0.0, f64::max)
}

/// Column indices of the output with `--extra sigma,status,calibration`.
const HEADING_SIGMA: usize = 4;
const HEADING_ABSOLUTE: usize = 7;
const COMPASS_USED: usize = 8;
const AT_REST: usize = 10;

#[test]
fn a_straight_real_kilometre_drifts_as_its_sensors_allow() {
    let Some(data) = truenorth_sim::shared_data::folder(FOLDER).unwrap() else {
        return;
    };
    let rec = Recording::read(&data);
    let dir = scratch("comma2k19", "drive");
    let t_wheels = rec.wheels.col("t_boot_s");
    let reference = Reference::new(&rec.pose, t_wheels[0]);
    let (raw, zeroed, no_gyro) = (
        dir.join("raw_gyro.csv"),
        dir.join("zeroed_gyro.csv"),
        dir.join("no_gyro.csv"),
    );
    rec.write_drive(&raw, Some("gyr_uncal_d_rps"));
    rec.write_drive(&zeroed, Some("gyr_d_rps"));
    rec.write_drive(&no_gyro, None);
    let runs = [
        drive(&dir, "raw gyro", &raw, &[], &reference),
        drive(
            &dir,
            "raw gyro, causal",
            &raw,
            &["--single-pass"],
            &reference,
        ),
        drive(&dir, "Android-zeroed gyro", &zeroed, &[], &reference),
        drive(&dir, "no gyro", &no_gyro, &[], &reference),
    ];
    let alone = Alone::new(&rec, &reference);
    // Plain integration beside the command: each gyro's rate integrated (trapezoid) into a
    // heading, times the rear wheels' mean distance.
    let plain = |c: &str| {
        let t_imu = rec.imu.col("t_boot_s");
        let psi = integrate(&t_imu, &rec.imu.col(c));
        let dl = integrate(&t_wheels, &rec.wheels.col("wheel_rl_mps"));
        let dr = integrate(&t_wheels, &rec.wheels.col("wheel_rr_mps"));
        let psi0 = interp(&t_imu, &psi, t_wheels[0]);
        let (mut north, mut east) = (0.0, 0.0);
        let mut rows = vec![vec![t_wheels[0], 0.0, 0.0, 0.0]];
        for k in 1..t_wheels.len() {
            let mid = 0.5 * (t_wheels[k - 1] + t_wheels[k]);
            let h = interp(&t_imu, &psi, mid) - psi0;
            let ds = 0.5 * ((dl[k] - dl[k - 1]) + (dr[k] - dr[k - 1]));
            north += ds * h.cos();
            east += ds * h.sin();
            let h_end = interp(&t_imu, &psi, t_wheels[k]) - psi0;
            rows.push(vec![t_wheels[k], north, east, h_end.to_degrees()]);
        }
        compare(&rows, &reference)
    };
    let rms_cross =
        |e: &[Errors]| (e.iter().map(|e| e.cross_m.powi(2)).sum::<f64>() / e.len() as f64).sqrt();
    let (plain_raw, plain_zeroed) = (plain("gyr_uncal_d_rps"), plain("gyr_d_rps"));

    println!(
        "alone over the drive: rear wheels' heading drift {:+.2}° ({:+.3}°/s), raw gyro bias {:.3}°/s (reference-implied), Android-zeroed gyro drift {:+.2}° (largest {:.2}°), odometer scale error {:+.2} %",
        alone.wheels_drift_deg,
        alone.wheels_rate_dps,
        alone.raw_bias_dps,
        alone.zeroed_final_drift_deg,
        alone.zeroed_max_drift_deg,
        100.0 * alone.odometer_scale_error
    );
    println!(
        "{:<20} {:>7} {:>10} {:>9} {:>8} {:>8} {:>8}",
        "run", "dist m", "heading °", "cross m", "cross %", "along m", "along %"
    );
    for run in &runs {
        for mark in [100.0, 250.0, 500.0, 750.0, f64::INFINITY] {
            let k = run
                .errors
                .iter()
                .position(|e| e.distance_m >= mark)
                .unwrap_or(run.errors.len() - 1);
            let e = run.errors[k];
            println!(
                "{:<20} {:>7.0} {:>+10.2} {:>+9.2} {:>+8.2} {:>+8.2} {:>+8.2}",
                run.name,
                e.distance_m,
                e.heading_deg,
                e.cross_m,
                100.0 * e.cross_m / e.distance_m,
                e.along_m,
                100.0 * e.along_m / e.distance_m,
            );
        }
        println!(
            "{:<20} largest: heading {:.2}°, cross-track {:.2} m",
            run.name,
            max_abs(&run.errors, |e| e.heading_deg),
            max_abs(&run.errors, |e| e.cross_m),
        );
    }
    for (name, e) in [
        ("plain, raw gyro", &plain_raw),
        ("plain, zeroed gyro", &plain_zeroed),
        ("raw gyro", &runs[0].errors),
        ("raw gyro, causal", &runs[1].errors),
        ("Android-zeroed gyro", &runs[2].errors),
    ] {
        println!(
            "{name:<20} cross-track {:.2} m RMS, final {:+.2} m; final heading {:+.2}°",
            rms_cross(e),
            e[e.len() - 1].cross_m,
            e[e.len() - 1].heading_deg
        );
    }
    // Fused against plain: both take the same wheels' distance and face the same reference,
    // so only the heading differs, and no tolerance is given. The command's default runs are
    // held to the plain integration of the gyro Android had already zeroed (the best sensor
    // alone here); every run, the causal one too, to the raw gyro's.
    let final_cross = |e: &[Errors]| e[e.len() - 1].cross_m.abs();
    for run in [&runs[0], &runs[2]] {
        assert!(
            rms_cross(&run.errors) <= rms_cross(&plain_zeroed)
                && final_cross(&run.errors) <= final_cross(&plain_zeroed),
            "{}: cross-track worse than plain integration of the zeroed gyro",
            run.name
        );
    }
    for run in &runs[..3] {
        assert!(
            rms_cross(&run.errors) <= rms_cross(&plain_raw)
                && final_cross(&run.errors) <= final_cross(&plain_raw),
            "{}: cross-track worse than plain integration of the raw gyro",
            run.name
        );
    }
    // What each run learned, with the σ it reports. A straight drive does not observe the
    // gyro's gains, the effective track or the speed coefficient (they scale turns).
    for run in &runs {
        let mut line = format!("{:<20} learned:", run.name);
        for key in [
            "gyro_gain_error_right",
            "gyro_gain_error_left",
            "track_scale",
            "speed_coeff_s2_per_m2",
        ] {
            let (v, sigma) = run.learned(key);
            write!(line, " {key} {v:+.2e} ± {sigma:.1e},").unwrap();
        }
        println!("{}", line.trim_end_matches(','));
    }

    for run in &runs {
        let name = run.name;
        assert_eq!(
            run.rows.len(),
            t_wheels.len(),
            "{name}: one row per input row"
        );
        // No turn, so no compass calibration: the heading stays relative to the start,
        // the compass is never used, and the command says so.
        assert!(
            run.rows
                .iter()
                .all(|r| r[HEADING_ABSOLUTE] == 0.0 && r[COMPASS_USED] == 0.0),
            "{name}: the heading became absolute or the compass was used without a turn"
        );
        // The σ it reports is then that of the heading change since the start, and it
        // covers the error on every row (3σ, plus the reference's own start course, good
        // to 0.15° and allowed twice that).
        for (r, e) in run.rows.iter().zip(&run.errors) {
            assert!(
                e.heading_deg.abs() <= 3.0 * r[HEADING_SIGMA] + 0.3,
                "{name}: heading error {:.2}° at {:.0} m against σ {:.2}°",
                e.heading_deg,
                e.distance_m,
                r[HEADING_SIGMA]
            );
        }
        assert!(
            run.stderr.contains("relative to the start heading"),
            "{name}: {}",
            run.stderr
        );
        // The car never stops (8 to 20 m/s).
        assert!(
            run.rows.iter().all(|r| r[AT_REST] == 0.0),
            "{name}: at rest"
        );
        assert!(
            run.rows
                .iter()
                .all(|r| r[..4].iter().all(|v| v.is_finite()))
        );
        // The track follows the heading: a cross-track error at distance s needs a heading
        // error of at least its angle somewhere before, plus the start course taken from
        // the reference's first second (its yaw and course agree within about 0.15° on
        // this drive; allowed twice that) and the camera-to-axle lever arm (centimetres).
        let mut worst = 0.0_f64;
        for e in &run.errors {
            worst = worst.max(e.heading_deg.abs());
            let limit = e.distance_m * (worst + 0.3).to_radians() + 0.1;
            assert!(
                e.cross_m.abs() <= limit,
                "{name}: cross-track {:.2} m at {:.0} m with headings within {worst:.2}°",
                e.cross_m,
                e.distance_m
            );
        }
        // Along the track the odometer's mean scale rules, and nothing on board observes
        // it: the error is the wheels' own, plus the shortening of a track that wanders by
        // the heading error (1 − cos of a few degrees).
        let last = run.errors[run.errors.len() - 1];
        let along = last.along_m / last.distance_m;
        let wander = 1.0 - max_abs(&run.errors, |e| e.heading_deg).to_radians().cos();
        assert!(
            (along - alone.odometer_scale_error).abs() <= wander + 5e-4,
            "{name}: along-track {:.3} % against the odometer's {:.3} %",
            100.0 * along,
            100.0 * alone.odometer_scale_error
        );
    }
    // Tyre rolling radius: tread wear alone (8 mm to 1.6 mm on a 0.36 m radius) moves it
    // by 1.8 %; pressure and load by a few tenths more.
    assert!(alone.odometer_scale_error.abs() < 0.025);

    let [two_pass, causal, zeroed_run, wheels_only] = &runs;
    // Without a gyro or a calibrated compass nothing observes the wheels' differential
    // scale: the heading is the wheels' own under the prior speed coefficient, drift and
    // all.
    let final_drift = wheels_only.errors[wheels_only.errors.len() - 1].heading_deg;
    assert!(
        (final_drift - alone.wheels_prior_drift_deg).abs() < 0.05,
        "wheels only: {final_drift:.2}° against the wheels' own {:.2}°",
        alone.wheels_prior_drift_deg
    );
    // A raw gyro with a bias of ~3.9°/s and no standstill to measure it: the wheels are
    // the only reference for the bias, so the fused heading must stay closer to the truth
    // than the wheels' own heading does.
    for run in [two_pass, causal] {
        let worst = max_abs(&run.errors, |e| e.heading_deg);
        assert!(
            worst < alone.wheels_drift_deg.abs(),
            "{}: heading drifted {worst:.2}°, the wheels alone {:.2}°",
            run.name,
            alone.wheels_drift_deg
        );
    }
    // What the straight can teach, the gyro bias and the wheels' differential scale, is
    // learned within the uncertainty the command reports for it (3σ).
    // The phone's bias estimate is one value over the whole segment.
    let android_bias_dps = rec.imu.col("gyr_bias_d_rps")[0].to_degrees();
    for (run, zero) in [
        (two_pass, alone.raw_bias_dps),
        (causal, alone.raw_bias_dps),
        (zeroed_run, alone.raw_bias_dps - android_bias_dps),
    ] {
        let (bias, bias_sigma) = run.learned("gyro_bias_rps");
        let (diff, diff_sigma) = run.learned("wheel_diff");
        println!(
            "{:<20} learned gyro bias {:.3} ± {:.3}°/s (reference {zero:.3}), wheel diff {diff:.2e} ± {diff_sigma:.1e} (reference {:.2e})",
            run.name,
            bias.to_degrees(),
            bias_sigma.to_degrees(),
            alone.wheel_diff
        );
        assert!(
            (bias.to_degrees() - zero).abs() < 3.0 * bias_sigma.to_degrees(),
            "{}: gyro bias {:.3} ± {:.3}°/s against {zero:.3}°/s",
            run.name,
            bias.to_degrees(),
            bias_sigma.to_degrees()
        );
        assert!(
            (diff - alone.wheel_diff).abs() < 3.0 * diff_sigma,
            "{}: wheel diff {diff:.2e} ± {diff_sigma:.1e} against {:.2e}",
            run.name,
            alone.wheel_diff
        );
    }
    // A gyro already zeroed (by the phone, from its own standstills): the wheels must not
    // pull the heading further from the truth than the gyro alone drifts.
    let worst = max_abs(&zeroed_run.errors, |e| e.heading_deg);
    assert!(
        worst <= alone.zeroed_max_drift_deg,
        "zeroed gyro: heading drifted {worst:.2}°, the gyro alone {:.2}°",
        alone.zeroed_max_drift_deg
    );
}
