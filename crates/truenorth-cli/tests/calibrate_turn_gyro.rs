//! `truenorth calibrate --method turn` with a `gyr_z` column: the gyro's zero and scale
//! beside the compass calibration, on the simulated opening turns of real-sized cars (a
//! standstill, then 1.25 turns of radius 12 m at 5 m/s; gyro bias 0.2–0.6 °/s with a
//! random walk, ±3 % scale error, noise; compass with hard and soft iron and 1 % noise;
//! 10 Hz), and the one-line refusals of records that cannot calibrate the gyro.

mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use common::{ScratchDir, p};
use truenorth_sim::{DriveSpec, SimulatedDrive};

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_calibrate_turn_gyro", name)
}

/// A recording's rows (t_s, mag_x, mag_y, gyr_z).
type Rows = Vec<[f64; 4]>;

/// The opening standstill and turn of a simulated drive (until the vehicle has stopped
/// again after the circle), the drive, and the index of the first row with the vehicle
/// turning.
fn opening_turn(seed: u64) -> (Rows, SimulatedDrive, usize) {
    let drive = SimulatedDrive::new(DriveSpec {
        length_m: 200.0,
        disturbances: false,
        ..DriveSpec::new(seed)
    })
    .unwrap();
    let mut rows = Vec::new();
    let mut moved = false;
    for (s, t) in drive.samples.iter().zip(&drive.truth) {
        moved |= t.speed_mps > 0.0;
        if moved && t.speed_mps == 0.0 {
            break;
        }
        let mag = s.mag.unwrap();
        rows.push([s.t_s, mag.x, mag.y, s.gyr_z_rps.unwrap()]);
    }
    let turning = drive
        .truth
        .iter()
        .position(|t| t.yaw_rate_rps != 0.0)
        .unwrap();
    (rows, drive, turning)
}

/// CSV text of `rows`, with the columns `header` names (a subset of t_s, mag_x, mag_y,
/// gyr_z, in that order) and an unrelated column that must be ignored.
fn csv(rows: &[[f64; 4]], header: &[&str]) -> String {
    let all = ["t_s", "mag_x", "mag_y", "gyr_z"];
    let keep: Vec<usize> = header
        .iter()
        .map(|h| all.iter().position(|a| a == h).unwrap())
        .collect();
    let mut text = header.join(",") + ",speed_note\n";
    for r in rows {
        for &i in &keep {
            write!(text, "{},", r[i]).unwrap();
        }
        text += "x\n";
    }
    text
}

const ALL: [&str; 4] = ["t_s", "mag_x", "mag_y", "gyr_z"];

/// Writes `text` as `name`.csv and runs `calibrate --method turn` on it; returns the run,
/// the input and the output path, and the folder that holds them (removed when dropped). The turn method's compass half cannot remove the soft
/// iron's rotation, so its verdict may be `poor`: `--accept-poor` writes it anyway, as the
/// gyro is what is checked here.
fn run_turn(name: &str, text: &str) -> (std::process::Output, PathBuf, PathBuf, ScratchDir) {
    let dir = scratch(name);
    let input = dir.join(format!("{name}.csv"));
    std::fs::write(&input, text).unwrap();
    let cal = dir.join("cal.json");
    let out = common::calibrate("turn", &input, &cal, &["--accept-poor"]);
    (out, input, cal, dir)
}

/// [`run_turn`] on a record it must accept: the JSON, the input, stderr and the folder.
fn calibrate(name: &str, text: &str) -> (serde_json::Value, PathBuf, String, ScratchDir) {
    let (out, input, cal, dir) = run_turn(name, text);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{name}: {stderr}");
    let json = common::read_json(&cal);
    (json, input, stderr, dir)
}

/// Scale within 0.3 % of the simulated gain of the direction turned (the goal for the
/// turn calibrator), zero within four standard deviations of what a standstill of this
/// length can give: the mean of white noise over at least the standstill less the
/// calibrator's margin (`N²/T`), and the bias random walk's mean over at most the time to
/// the turn (`σ_w²·T/3`, the variance of a random walk's mean from its start value).
#[test]
fn gyro_zero_and_scale_from_simulated_turns() {
    for seed in 0..6 {
        let (rows, drive, turning) = opening_turn(seed);
        let (json, input, stderr, dir) = calibrate(&format!("seed{seed}"), &csv(&rows, &ALL));
        let g = &drive.params.gyro;
        let right = drive.truth[turning + 200].yaw_rate_rps > 0.0;
        let true_scale = 1.0
            + if right {
                g.scale_error_pos
            } else {
                g.scale_error_neg
            };
        let gyro = &json["gyro"];
        let scale = gyro["scale"].as_f64().unwrap();
        let zero = gyro["zero_rps"].as_f64().unwrap();
        assert!(
            (scale / true_scale - 1.0).abs() < 0.003,
            "seed {seed}: scale {scale} vs {true_scale}"
        );
        let stand_s = drive.truth.iter().find(|t| t.speed_mps > 0.0).unwrap().t_s;
        let turn_s = drive.truth[turning].t_s;
        let sigma = (g.bias_walk_rps_per_sqrt_s.powi(2) * turn_s / 3.0
            + g.noise_density_rps_per_sqrt_hz.powi(2) / (stand_s - 1.0))
            .sqrt();
        assert!(
            (zero - g.bias_rps).abs() < 4.0 * sigma,
            "seed {seed}: zero {zero} vs {} (σ {sigma})",
            g.bias_rps
        );
        let turned = gyro["turned_deg"].as_f64().unwrap();
        assert!(turned.abs() >= 360.0 && (turned > 0.0) == right, "{turned}");
        assert!(gyro["rest_s"].as_f64().unwrap() >= 1.0);
        assert!(json["units"]["gyro.scale"].is_string());
        assert!(stderr.contains("gyro zero"), "{stderr}");
        println!(
            "seed {seed}: scale error {:+.3} %, zero error {:+.4} °/s (tolerance {:.4})",
            100.0 * (scale / true_scale - 1.0),
            (zero - g.bias_rps).to_degrees(),
            4.0 * sigma.to_degrees()
        );

        // The compass part is as before, and `heading` reads the file.
        assert_eq!(json["method"], "turn");
        assert_eq!(json["version"], 2);
        assert_eq!(json["dimensions"], 2);
        let h = dir.join("h.csv");
        common::succeeded(common::heading(&dir.join("cal.json"), &input, &h, &[]));
        let lines = std::fs::read_to_string(&h).unwrap().lines().count();
        assert_eq!(lines, rows.len() + 1);
    }
}

/// Without `gyr_z` the turn method calibrates the compass alone, as it always has.
#[test]
fn without_gyr_z_only_the_compass() {
    let (rows, _, _) = opening_turn(2);
    let (json, ..) = calibrate("no_gyro", &csv(&rows, &["t_s", "mag_x", "mag_y"]));
    assert!(json.get("gyro").is_none(), "{json}");
    assert!(json["units"].get("gyro.scale").is_none());
    assert_eq!(json["hard_iron"].as_array().unwrap().len(), 2);
}

/// [`run_turn`] on a record it must refuse: exit 1, one line on stderr naming the file,
/// no output. Returns the line.
fn refused(name: &str, text: &str) -> String {
    let (out, input, cal, _dir) = run_turn(name, text);
    assert_eq!(out.status.code(), Some(1), "{name}");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1, "{stderr:?}");
    assert!(stderr.contains(p(&input)), "{stderr}");
    assert!(!cal.exists());
    stderr
}

#[test]
fn records_that_cannot_calibrate_the_gyro_are_refused_with_the_reason() {
    let (rows, drive, turning) = opening_turn(3);

    // Stopped after 300° of the turn.
    let h0 = drive.truth[0].heading_unwrapped_rad;
    let cut = drive
        .truth
        .iter()
        .position(|t| (t.heading_unwrapped_rad - h0).abs() >= 300f64.to_radians())
        .unwrap();
    let line = refused("incomplete", &csv(&rows[..cut], &ALL));
    assert!(
        line.contains("cannot calibrate with method `turn`") && line.contains("need at least 360°"),
        "{line}"
    );

    // No standstill: the record starts turning.
    let line = refused("no_rest", &csv(&rows[turning + 5..], &ALL));
    assert!(line.contains("at rest") && line.contains("zero"), "{line}");

    // A gyro mounted upside down turns the other way from the compass.
    let flipped: Rows = rows.iter().map(|r| [r[0], r[1], r[2], -r[3]]).collect();
    let line = refused("flipped", &csv(&flipped, &ALL));
    assert!(line.contains("sign of gyr_z"), "{line}");

    // A missing rate names its row.
    let mut text = csv(&rows, &ALL);
    text = text.replacen(&format!(",{},x\n", rows[40][3]), ",,x\n", 1);
    let line = refused("empty_cell", &text);
    assert!(line.contains("gyr_z") && line.contains("row 42"), "{line}");

    // The rate cannot be integrated without times.
    let no_time = csv(&rows, &["mag_x", "mag_y", "gyr_z"]);
    let line = refused("no_time", &no_time);
    assert!(line.contains("`gyr_z` needs a `t_s` column"), "{line}");

    // An hour missing in the middle of the turn: refused at the row after the gap, with the
    // gap and what to do, instead of a scale from extrema paired across it (88.9 for a gyro
    // of 1.02 once, with the verdict good).
    let mid = turning + (rows.len() - turning) / 2;
    let gapped: Rows = rows
        .iter()
        .enumerate()
        .map(|(k, r)| {
            [
                if k >= mid { r[0] + 3600.0 } else { r[0] },
                r[1],
                r[2],
                r[3],
            ]
        })
        .collect();
    let line = refused("gap", &csv(&gapped, &ALL));
    let gap = gapped[mid][0] - gapped[mid - 1][0];
    assert!(
        line.contains(&format!("row {}", mid + 2))
            && line.contains(&format!("a gap of {gap} s"))
            && line.contains("split the record at the gap"),
        "{line}"
    );
}
