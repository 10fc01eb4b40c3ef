//! BROAD's trial files and metric, shared by the filter and detector tests (Laidig, Caruso,
//! Cereatti & Seel, *Data* 6(7):72, 2021): per trial, the RMSE over the movement phase of the
//! total, heading and inclination error angles of `e = q_est ⊗ q_ref⁻¹` in the reference
//! (ENU, magnetic north) frame.

#![allow(dead_code)]

pub mod consistency;
pub mod persistence;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use truenorth_core::{ImuSample, OrientationEstimator};
use truenorth_fusion::orientation::broad_rmse;

pub struct Trial {
    pub name: String,
    pub samples: Vec<ImuSample>,
    pub truth: Vec<Option<UnitQuaternion<f64>>>,
    pub movement: Vec<bool>,
}

pub fn read_trial(path: &Path) -> Trial {
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

/// Body → NED into body → ENU (the library's frame change).
pub fn ned_to_enu() -> UnitQuaternion<f64> {
    truenorth_core::ned_to_enu()
}

/// (total, heading, inclination) RMSE in degrees, BROAD's definition (the library's
/// [`broad_rmse`]; NaN when no sample is scored).
pub fn rmse(est: &[UnitQuaternion<f64>], trial: &Trial) -> [f64; 3] {
    broad_rmse(est, &trial.truth, &trial.movement).map_or([f64::NAN; 3], |r| {
        [r.total_deg, r.heading_deg, r.inclination_deg]
    })
}

/// The trial files of `../shared/data/broad/trials/`, sorted; `None` when the folder is
/// absent outside CI (the shared-data helper prints SKIPPED).
pub fn trial_paths() -> Option<Vec<PathBuf>> {
    let dir = truenorth_sim::shared_data::folder("broad").unwrap()?;
    let mut paths: Vec<_> = std::fs::read_dir(dir.join("trials"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    Some(paths)
}

/// Runs an estimator over a trial and scores its attitude (body → NED, turned to ENU).
pub fn score<E: OrientationEstimator>(trial: &Trial, mut est: E) -> [f64; 3] {
    let to_enu = ned_to_enu();
    let q: Vec<_> = trial
        .samples
        .iter()
        .map(|s| to_enu * est.update(s).unwrap().attitude)
        .collect();
    rmse(&q, trial)
}

/// Mean of (total, heading, inclination) over trials.
pub fn mean(v: &[[f64; 3]]) -> [f64; 3] {
    let n = v.len() as f64;
    [0, 1, 2].map(|i| v.iter().map(|r| r[i]).sum::<f64>() / n)
}
