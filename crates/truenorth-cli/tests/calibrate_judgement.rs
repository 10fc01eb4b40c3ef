//! What `truenorth calibrate` judges, on recordings of the kinds users make that it was
//! once wrong about:
//!
//! * two full turns followed by 100 s of gentle swaying about one heading: accepted by
//!   every least-squares 2-D method (the batch ellipse once read the raw locus's turning
//!   in time order and refused it as covering a fraction of the circle);
//! * a hand tumble of a noisy three-axis magnetometer (6 % of the field per reading, 19,743
//!   readings in every direction): accepted, `usable` because of the noise, with the noise
//!   and the calibration's own bound in the reason (it was refused as "degenerate
//!   geometry").

mod common;

use std::fmt::Write as _;

use nalgebra::{Matrix3, Rotation3, Vector3};
use truenorth::core::{NoiseSource, SplitMix64};
use truenorth_sim::{HandheldParams, handheld_motion};

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_calibrate_judgement", name)
}

/// Runs `calibrate --method M` on `csv` and returns the JSON and the summary line.
fn calibrate(name: &str, method: &str, csv: &str) -> (serde_json::Value, String) {
    let dir = scratch(name);
    let input = dir.join(format!("{name}.csv"));
    std::fs::write(&input, csv).unwrap();
    let cal = dir.join(format!("{method}.json"));
    let out = common::succeeded(common::calibrate(method, &input, &cal, &[]));
    let json = common::read_json(&cal);
    (json, String::from_utf8(out.stderr).unwrap())
}

/// Two turns at 30°/s then 100 s of swaying ±35° with a period of 7 s, at 25 Hz: a level
/// compass with hard iron (6, −4), soft iron 1.25 : 1 at 30°, field 20 and 1 % noise
/// (draw `seed`).
fn turns_then_swaying(seed: u64) -> String {
    let (s, c) = 30f64.to_radians().sin_cos();
    let r = 1.25f64.sqrt();
    let w = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    let d = Matrix3::from_diagonal(&Vector3::new(r, 1.0 / r, 1.0));
    let soft = w * d * w.transpose();
    let mut rng = SplitMix64::new(seed);
    let mut csv = String::from("t_s,mag_x,mag_y\n");
    for k in 0..(124 * 25) {
        let t = k as f64 / 25.0;
        let psi = if t < 24.0 {
            30.0 * t
        } else {
            720.0 + 35.0 * (std::f64::consts::TAU * (t - 24.0) / 7.0).sin()
        }
        .to_radians();
        let h = soft * Vector3::new(20.0 * psi.cos(), -20.0 * psi.sin(), 0.0);
        let (x, y) = (6.0 + h.x + rng.normal(0.2), -4.0 + h.y + rng.normal(0.2));
        writeln!(csv, "{t},{x},{y}").unwrap();
    }
    csv
}

/// Twelve draws of the noise: every one calibrates, `good`, with the heading bins filled;
/// the old measure, the raw locus's turning in time order on chords of a quarter of the
/// field (which the back-and-forth of the swaying scrambles), read some of them as short
/// of 200°.
#[test]
fn two_turns_then_swaying_calibrate() {
    let mut short = 0;
    for seed in 1..=12 {
        let csv = turns_then_swaying(seed);
        let pts: Vec<nalgebra::Vector2<f64>> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                nalgebra::Vector2::new(v[1], v[2])
            })
            .collect();
        let old = truenorth::calib::quality::locus_turning_rad(&pts, 0.25 * 20.0).to_degrees();
        short += usize::from(old < 200.0);
        for method in ["ellipse", "online-ellipse", "binned-ellipse"] {
            let (json, stderr) = calibrate("sway", method, &csv);
            assert_eq!(json["quality"]["verdict"], "good", "{method}: {json}");
            // The online calibrator measures coverage on the one reading it keeps per 5°
            // slot, which may leave one 10° bin of 36 empty.
            let coverage = json["quality"]["coverage"].as_f64().unwrap();
            assert!(coverage >= 35.0 / 36.0, "{method}: {coverage}");
            assert!(stderr.contains("verdict good"), "{stderr}");
        }
    }
    println!("the raw locus's turning read under 200° for {short} of 12 draws");
    assert!(short > 0);
}

/// 197.42 s of hand tumbling at 100 Hz (19,743 readings), 6 % noise per axis: hard iron
/// (15, −10, 7.5), soft iron within ±10 %, field 50 at a dip of 64°.
fn noisy_tumble() -> String {
    let motion = handheld_motion(&HandheldParams {
        duration_s: 197.42,
        rate_hz: 100.0,
        rate_amplitude_rps: 3.0,
        accel_amplitude_mps2: 0.5,
        seed: 7,
    })
    .unwrap();
    let rot = Rotation3::from_euler_angles(0.4, -0.3, 1.1);
    let soft = rot.matrix()
        * Matrix3::from_diagonal(&Vector3::new(1.1, 0.93, 1.0 / (1.1 * 0.93)))
        * rot.matrix().transpose();
    let (sd, cd) = 64f64.to_radians().sin_cos();
    let field = Vector3::new(cd, 0.0, sd) * 50.0;
    let mut rng = SplitMix64::new(7);
    let mut csv = String::from("t_s,mag_x,mag_y,mag_z\n");
    for m in &motion {
        let b = soft * (m.attitude.inverse() * field);
        let sigma = 0.06 * 50.0;
        let raw = Vector3::new(15.0, -10.0, 7.5)
            + b
            + Vector3::new(rng.normal(sigma), rng.normal(sigma), rng.normal(sigma));
        writeln!(csv, "{},{},{},{}", m.t_s, raw.x, raw.y, raw.z).unwrap();
    }
    csv
}

#[test]
fn a_noisy_tumble_calibrates_and_is_judged_noisy() {
    let csv = noisy_tumble();
    for method in ["ellipsoid", "online-ellipsoid"] {
        let (json, stderr) = calibrate("noisy", method, &csv);
        let q = &json["quality"];
        assert_eq!(q["points"], 19_743, "{method}");
        assert_eq!(q["verdict"], "usable", "{method}: {q}");
        assert_eq!(q["verdict_cause"], "noise", "{method}: {q}");
        let reason = q["verdict_reason"].as_str().unwrap();
        let noise = q["heading_noise_rms_deg"].as_f64().unwrap();
        let bound = q["heading_error_bound_deg"].as_f64().unwrap();
        assert!(reason.contains("the sensor is noisy"), "{reason}");
        assert!(
            reason.contains(&format!("scatters {noise:.2} deg RMS")),
            "{reason}"
        );
        assert!(
            reason.contains(&format!("determined to {bound:.2} deg")),
            "{reason}"
        );
        // 6 % of the field is 3.44° of direction per reading; the bound falls with the
        // count (3σG/√N ≈ 0.3° for the batch fit, twice that with the online fit's bias).
        assert!((noise - 0.06f64.to_degrees()).abs() < 0.05 * 0.06f64.to_degrees());
        assert!(bound < 1.0, "{method}: {bound}");
        assert!(
            stderr.contains("verdict usable (decided by the noise)"),
            "{stderr}"
        );
    }
}
