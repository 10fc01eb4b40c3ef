//! The quaternion filter in single precision (`QuaternionFilter<f32>`, for a
//! microcontroller's FPU) against the same filter in `f64`, on the BROAD benchmark's real
//! recordings scored with BROAD's metric (the reader and metric of `broad.rs`), and on the
//! simulator's hand-held motion.
//!
//! Bound: 0.05° of RMSE per trial. Single precision rounds each operation by up to
//! 6·10⁻⁸ relative; in the strapdown these errors add as a random walk of about 10⁻⁷ rad per
//! step, 3·10⁻⁵ rad (0.002°) over BROAD's longest trials of 10⁵ samples before the
//! corrections pull it back, so 0.05° leaves a factor of 25.
//!
//! Run with `cargo test --release -p truenorth-fusion --test broad_f32 -- --nocapture` for
//! the table.

mod common;

use common::{Trial, mean, ned_to_enu, read_trial, rmse, score, trial_paths};
use nalgebra::{UnitQuaternion, Vector3};
use truenorth_core::{ImuSample, OrientationEstimator};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

/// Largest difference of a trial's RMSE (total, heading, inclination) between the `f32`
/// and the `f64` filter, degrees (see the module documentation).
const MAX_DIFF_DEG: f64 = 0.05;

/// The attitudes of the `f32` filter over `samples`, body → NED, as `f64` quaternions; the
/// readings are rounded to `f32` as a sensor driver in single precision would hold them.
fn attitudes_f32(
    samples: &[ImuSample],
    config: QuaternionFilterConfig,
) -> Vec<UnitQuaternion<f64>> {
    let mut f = QuaternionFilter::<f32>::with_precision(config).unwrap();
    let single = |v: Vector3<f64>| v.cast::<f32>();
    samples
        .iter()
        .map(|s| {
            f.update_readings(
                s.t_s,
                single(s.gyr_rps.as_xyz().unwrap()),
                s.acc_mps2.as_xyz().map(single),
                s.mag.as_xyz().map(single),
            )
            .unwrap();
            f.attitude().cast::<f64>()
        })
        .collect()
}

/// (f64, f32) RMSE (total, heading, inclination) of one trial, degrees.
fn both(trial: &Trial, config: QuaternionFilterConfig) -> ([f64; 3], [f64; 3]) {
    let double = score(trial, QuaternionFilter::new(config).unwrap());
    let to_enu = ned_to_enu();
    let single: Vec<_> = attitudes_f32(&trial.samples, config)
        .into_iter()
        .map(|q| to_enu * q)
        .collect();
    (double, rmse(&single, trial))
}

#[test]
fn f32_filter_matches_f64_on_broad() {
    let Some(paths) = trial_paths() else {
        return;
    };
    let config = QuaternionFilterConfig::default();
    let (mut doubles, mut singles, mut diffs) = (Vec::new(), Vec::new(), Vec::new());
    println!(
        "{:<45} {:>8} {:>8} {:>9} {:>9} {:>9}",
        "trial", "f64 tot", "f32 tot", "Δ total", "Δ heading", "Δ incl"
    );
    for p in &paths {
        let trial = read_trial(p);
        let (d, s) = both(&trial, config);
        let diff = [0, 1, 2].map(|i| (s[i] - d[i]).abs());
        println!(
            "{:<45} {:8.4} {:8.4} {:9.5} {:9.5} {:9.5}",
            trial.name, d[0], s[0], diff[0], diff[1], diff[2]
        );
        doubles.push(d);
        singles.push(s);
        diffs.push(diff);
    }
    let (md, ms, mdiff) = (mean(&doubles), mean(&singles), mean(&diffs));
    println!(
        "mean ({} trials): f64 total {:.4} f32 total {:.4}; mean |Δ| total {:.5} heading {:.5} incl {:.5}; |Δ mean| total {:.5}",
        paths.len(),
        md[0],
        ms[0],
        mdiff[0],
        mdiff[1],
        mdiff[2],
        (ms[0] - md[0]).abs()
    );
    for (p, diff) in paths.iter().zip(&diffs) {
        assert!(
            diff.iter().all(|d| *d <= MAX_DIFF_DEG),
            "{}: f32 − f64 RMSE differences {diff:?}°",
            p.display()
        );
    }
}

/// Without the recordings too: the simulator's hand-held motion, against its truth.
#[test]
fn f32_filter_matches_f64_on_simulated_motion() {
    let truth = handheld_motion(&HandheldParams {
        duration_s: 120.0,
        ..HandheldParams::default()
    })
    .unwrap();
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), 7).unwrap();
    let config = QuaternionFilterConfig::default();
    let mut double = QuaternionFilter::new(config).unwrap();
    let single = attitudes_f32(&samples, config);
    let (mut sum_d, mut sum_s) = (0.0, 0.0);
    for ((s, t), q32) in samples.iter().zip(&truth).zip(&single) {
        let q64 = double.update(s).unwrap().attitude;
        sum_d += q64.angle_to(&t.attitude).powi(2);
        sum_s += q32.angle_to(&t.attitude).powi(2);
    }
    let n = samples.len() as f64;
    let (rmse_d, rmse_s) = (
        (sum_d / n).sqrt().to_degrees(),
        (sum_s / n).sqrt().to_degrees(),
    );
    assert!(
        (rmse_s - rmse_d).abs() <= MAX_DIFF_DEG,
        "f64 {rmse_d:.4}° f32 {rmse_s:.4}°"
    );
}
