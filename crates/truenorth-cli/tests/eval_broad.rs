//! `truenorth eval broad`: reading BROAD's trial files, grouping, the JSON report, the
//! progress lines and refusals, on small trials made here from the simulator; and the
//! figures on the real benchmark when `../shared/data/broad/` is present.

mod common;

use std::path::Path;

use common::{IMU_HEADER, ScratchDir, csv_cells, gzip, imu_cells, p, truenorth};
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

fn dir(tag: &str) -> ScratchDir {
    common::scratch("cli_eval_broad", tag)
}

/// A BROAD-format trial (gzip CSV, ENU reference) of simulated hand-held motion; the first
/// 5 s are outside the movement phase and the reference is NaN on every 50th sample.
fn write_trial(path: &Path, seed: u64) {
    let truth = handheld_motion(&HandheldParams {
        duration_s: 30.0,
        seed,
        ..HandheldParams::default()
    })
    .unwrap();
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), seed).unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let to_enu =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(0.0, h, h, 0.0));
    let mut csv = format!("{IMU_HEADER},qw,qx,qy,qz,movement\n");
    for (k, (s, t)) in samples.iter().zip(&truth).enumerate() {
        let q = to_enu * t.attitude;
        let qs = if k % 50 == 0 {
            "NaN,NaN,NaN,NaN".to_string()
        } else {
            format!("{},{},{},{}", q.w, q.i, q.j, q.k)
        };
        csv += &format!(
            "{},{qs},{}\n",
            csv_cells(&imu_cells(s), ","),
            u8::from(s.t_s >= 5.0)
        );
    }
    std::fs::write(path, gzip(csv.as_bytes())).unwrap();
}

#[test]
fn scores_a_folder_of_trials_as_json() {
    let d = dir("json");
    let trials = d.join("trials");
    std::fs::create_dir_all(&trials).unwrap();
    write_trial(&trials.join("01_undisturbed_sim.csv.gz"), 1);
    write_trial(&trials.join("02_disturbed_sim.csv.gz"), 2);
    let o = truenorth(&["eval", "broad", p(&d), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let t = v["trials"].as_array().unwrap();
    assert_eq!(t.len(), 2);
    assert_eq!(t[0]["group"], "undisturbed");
    assert_eq!(t[1]["group"], "disturbed");
    let groups = v["groups"].as_array().unwrap();
    assert_eq!(groups.len(), 3);
    let all = &groups[2];
    assert_eq!(all["trials"], 2);
    let mean = (t[0]["total_deg"].as_f64().unwrap() + t[1]["total_deg"].as_f64().unwrap()) / 2.0;
    assert!((all["total_deg"].as_f64().unwrap() - mean).abs() < 1e-12);
    // The simulated sensor: the filter is within a few degrees (bias learned in motion).
    assert!(mean < 5.0, "{mean}");
    // Progress on stderr, one line per trial off a terminal.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("1/2") && err.contains("2/2"), "{err}");
    // The table form and the Euler detector.
    let o = truenorth(&["eval", "broad", p(&trials), "--method", "euler-detector"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("mean, all (2 trials)"));
}

#[test]
fn refuses_a_folder_without_trials_and_a_broken_file() {
    let d = dir("empty");
    let o = truenorth(&["eval", "broad", p(&d)]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no BROAD trial files"));
    let bad = d.join("01_undisturbed_bad.csv.gz");
    std::fs::write(&bad, gzip(b"t_s,gyr_x\n0,1\n")).unwrap();
    let o = truenorth(&["eval", "broad", p(&d)]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("missing column") && err.contains("01_undisturbed_bad"),
        "{err}"
    );
}

/// The real benchmark: the command reproduces the library test's figure
/// (`crates/truenorth-fusion/tests/broad.rs`), the goal of 2.2° mean total.
#[test]
fn real_broad_within_the_goal() {
    let Some(broad) = truenorth_sim::shared_data::folder("broad").unwrap() else {
        return;
    };
    let o = truenorth(&["eval", "broad", p(&broad), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["trials"].as_array().unwrap().len(), 20);
    let all = v["groups"][2]["total_deg"].as_f64().unwrap();
    assert!(all <= 2.2, "{all}");
}
