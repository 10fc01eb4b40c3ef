//! The Euler orientation detector of WO 00/36376 on BROAD's real recordings, with the
//! contribution of each of its pieces: every configuration below switches one piece on or
//! off against the default and is scored with BROAD's metric over the 20 trials.
//!
//! The suite runs the default configuration; the table of pieces is a release-mode command:
//! `cargo test --release -p truenorth-fusion --test euler_broad -- --ignored --nocapture`.

mod common;

use common::{Trial, mean, read_trial, score, trial_paths};
use truenorth_accel::static_tilt;
use truenorth_compass::MzReconstruction;
use truenorth_core::{Axes, ImuSample};
use truenorth_fusion::{
    CorrectionDefinerConfig, EulerDetector, EulerDetectorConfig, GyroConditioning, StartupField,
};
use truenorth_gyro::{
    HighPassConfig, HighPassCorrectionConfig, IirHighPassConfig, OscillationRemoverConfig,
};

/// Madgwick with BROAD's trial-agnostic best β: mean total RMSE over these 20 trials.
const MADGWICK_TOTAL_DEG: f64 = 4.59;

fn run_all(trials: &[Trial], config: EulerDetectorConfig) -> [f64; 3] {
    let r: Vec<_> = trials
        .iter()
        .map(|t| {
            let r = score(t, EulerDetector::new(config).unwrap());
            if std::env::var_os("EULER_VERBOSE").is_some() {
                println!("{:<45} {:6.2} {:6.2} {:6.2}", t.name, r[0], r[1], r[2]);
            }
            r
        })
        .collect();
    mean(&r)
}

/// `config` with the correction definer off: every static angle corrects.
fn always_correcting(config: EulerDetectorConfig) -> EulerDetectorConfig {
    EulerDetectorConfig {
        definer: CorrectionDefinerConfig {
            tilt_change_rad: None,
            yaw_change_rad: None,
            moving_average: None,
            gravity_tol_mps2: None,
            ..config.definer
        },
        ..config
    }
}

fn trials() -> Option<Vec<Trial>> {
    Some(trial_paths()?.iter().map(|p| read_trial(p)).collect())
}

/// The trial seen by a device with two accelerometers (x, y) and two magnetometers (x, y),
/// and the start-up field the seed measures for the M_z reconstruction (from the first
/// sample, with its static tilt).
fn two_axis(trial: &Trial) -> (Trial, StartupField) {
    let s0 = trial.samples[0];
    let m0 = s0.mag.as_xyz().unwrap();
    let tilt0 = static_tilt(&s0.acc_mps2.as_xyz().unwrap()).unwrap();
    let rec = MzReconstruction::from_startup_reading(&m0, &tilt0).unwrap();
    let samples = trial
        .samples
        .iter()
        .map(|s| ImuSample {
            acc_mps2: Axes::xy(s.acc_mps2.as_xyz().unwrap().xy()),
            mag: Axes::xy(s.mag.as_xyz().unwrap().xy()),
            ..*s
        })
        .collect();
    (
        Trial {
            name: trial.name.clone(),
            samples,
            truth: trial.truth.clone(),
            movement: trial.movement.clone(),
        },
        StartupField {
            total: rec.total_field(),
            inclination_rad: rec.inclination_rad(),
        },
    )
}

#[test]
fn euler_detector_on_broad() {
    let Some(trials) = trials() else {
        return;
    };
    // EULER_CONFIG (a JSON object) runs other parameters for experiments, unjudged.
    let experiment = std::env::var("EULER_CONFIG").ok();
    let config = experiment
        .as_deref()
        .map_or_else(EulerDetectorConfig::default, |j| {
            serde_json::from_str(j).unwrap()
        });
    let m = run_all(&trials, config);
    println!(
        "Euler detector on {} BROAD trials: total {:.2} heading {:.2} incl {:.2}",
        trials.len(),
        m[0],
        m[1],
        m[2]
    );
    if experiment.is_some() {
        return;
    }
    // What the seed's pieces are for: the corrections against gyro integration alone, and
    // the correction definer against correcting always.
    let gyro_only = run_all(
        &trials,
        EulerDetectorConfig {
            tau_s: [1e9; 3],
            ..config
        },
    );
    let always = run_all(&trials, always_correcting(config));
    println!(
        "gyro integration only: total {:.2}; always correcting: total {:.2}",
        gyro_only[0], always[0]
    );
    assert!(m[0] < 0.5 * gyro_only[0], "total {:.2}°", m[0]);
    assert!(m[0] < always[0], "total {:.2}° vs {:.2}°", m[0], always[0]);
    // Still far from a modern filter: Madgwick with BROAD's best gain scores 4.59°.
    assert!(m[0] > MADGWICK_TOTAL_DEG);
}

#[test]
#[ignore = "release-mode measurement: the contribution of each piece"]
fn euler_detector_pieces() {
    let Some(trials) = trials() else {
        return;
    };
    let base = EulerDetectorConfig::default();
    let d = base.definer;
    let hp = HighPassConfig::default();
    let pieces: Vec<(&str, EulerDetectorConfig)> = vec![
        ("default (all definer modes, table, no conditioning)", base),
        (
            "no correction at all (gyro integration only)",
            EulerDetectorConfig {
                tau_s: [1e9; 3],
                ..base
            },
        ),
        ("definer off (always correct)", always_correcting(base)),
        (
            "without modes (1)(2) (tilt change)",
            EulerDetectorConfig {
                definer: CorrectionDefinerConfig {
                    tilt_change_rad: None,
                    ..d
                },
                ..base
            },
        ),
        (
            "modes (1)(2) against constants B, D",
            EulerDetectorConfig {
                definer: CorrectionDefinerConfig {
                    tilt_change_against_motion: false,
                    ..d
                },
                ..base
            },
        ),
        (
            "without mode (3) (yaw change)",
            EulerDetectorConfig {
                definer: CorrectionDefinerConfig {
                    yaw_change_rad: None,
                    ..d
                },
                ..base
            },
        ),
        (
            "without modes (4)-(6) (single samples)",
            EulerDetectorConfig {
                definer: CorrectionDefinerConfig {
                    moving_average: None,
                    ..d
                },
                ..base
            },
        ),
        (
            "without mode (7) (|a| = g)",
            EulerDetectorConfig {
                definer: CorrectionDefinerConfig {
                    gravity_tol_mps2: None,
                    ..d
                },
                ..base
            },
        ),
        (
            "without the coefficient table",
            EulerDetectorConfig {
                coefficient_table: false,
                ..base
            },
        ),
        (
            "+ high-pass 0.1 Hz (variable cutoff)",
            EulerDetectorConfig {
                gyro: GyroConditioning::HighPass {
                    filter: hp,
                    correction: None,
                },
                ..base
            },
        ),
        (
            "+ high-pass and its correction, no compensator",
            EulerDetectorConfig {
                gyro: GyroConditioning::HighPass {
                    filter: hp,
                    correction: Some(HighPassCorrectionConfig {
                        compensate_offset: false,
                        ..Default::default()
                    }),
                },
                ..base
            },
        ),
        (
            "+ high-pass, correction and offset compensator",
            EulerDetectorConfig {
                gyro: GyroConditioning::HighPass {
                    filter: hp,
                    correction: Some(HighPassCorrectionConfig::default()),
                },
                ..base
            },
        ),
        (
            "+ IIR high-pass (buffer reset, offset correction)",
            EulerDetectorConfig {
                gyro: GyroConditioning::Iir(IirHighPassConfig::default()),
                ..base
            },
        ),
        (
            "+ oscillation remover (a = 3)",
            EulerDetectorConfig {
                oscillation_remover: Some(OscillationRemoverConfig::default()),
                ..base
            },
        ),
    ];
    println!(
        "{:<52} {:>6} {:>8} {:>6}",
        "configuration", "total", "heading", "incl"
    );
    for (name, cfg) in pieces {
        let m = run_all(&trials, cfg);
        println!("{name:<52} {:6.2} {:8.2} {:6.2}", m[0], m[1], m[2]);
    }
    // Two accelerometers (no quadrant, no mode (7)) and two magnetometers (M_z rebuilt from
    // the start-up field).
    let r: Vec<_> = trials
        .iter()
        .map(|t| {
            let (t2, field) = two_axis(t);
            let cfg = EulerDetectorConfig {
                startup_field: Some(field),
                ..base
            };
            score(&t2, EulerDetector::new(cfg).unwrap())
        })
        .collect();
    let m = mean(&r);
    println!(
        "{:<52} {:6.2} {:8.2} {:6.2}",
        "two accelerometers, two magnetometers + M_z", m[0], m[1], m[2]
    );
}
