//! The joint fit through readings cut into runs gives the fit of the samples in one slice,
//! bit for bit; a replay that fails fails the fit with its own error.

use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;
use truenorth_core::Calibrator;

use crate::fits::mag_accel::calibrator::fit_mag_accel_within;
use crate::fits::mag_accel::model::Limits;
use crate::fits::mag_accel::{
    MagAccelCalibrator, MagAccelConfig, MagAccelReading, MagAccelSample, fit_mag_accel,
    fit_mag_accel_readings, mag_accel_reading,
};
use crate::numerics::readings_tests::{Cut, FAILED};

/// Pseudo-noise in [−0.5, 0.5) of reading `k`, channel `c` (deterministic).
fn wobble(k: usize, c: usize) -> f64 {
    ((k as f64 * 12.9898 + c as f64 * 78.233).sin() * 43_758.545).fract() - 0.5
}

/// `n` readings of an instrument turned through attitudes whose pitch spans ±`pitch_rad`,
/// then `still` readings held at one attitude and `rolled` shots aimed the same way and
/// rolled about the pointing axis, 45° apart (with enough roll, one run): an
/// accelerometer with bias, scale and cross-axis, a magnetometer with hard and soft iron
/// turned 2° from it, both with noise of relative size `noise`.
fn recording(
    n: usize,
    pitch_rad: f64,
    still: usize,
    rolled: usize,
    noise: f64,
) -> Vec<MagAccelSample> {
    let dip = 60f64.to_radians();
    let up = Vector3::new(0.0, 0.0, 9.81);
    let field = Vector3::new(dip.cos(), 0.0, -dip.sin()) * 50.0;
    let acc_matrix = Matrix3::new(1.02, 0.01, 0.0, 0.01, 0.98, 0.0, 0.0, 0.0, 1.01);
    let soft = Matrix3::new(1.1, 0.05, 0.0, 0.05, 0.93, 0.02, 0.0, 0.02, 1.04);
    let turned = Rotation3::from_euler_angles(0.0, 0.0, 0.035);
    let attitudes = (0..n)
        .map(|k| {
            let k = k as f64;
            (2.4 * k, pitch_rad * (0.7 * k).sin(), 1.3 * k)
        })
        .chain((0..still).map(|_| (0.5, 0.3, 0.0)))
        .chain((0..rolled).map(|j| (0.5, 0.3, 0.785 * j as f64)));
    attitudes
        .enumerate()
        .map(|(k, (yaw, pitch, roll))| {
            let to_body = Rotation3::from_euler_angles(roll, pitch, yaw).inverse();
            let n3 = |c: usize| Vector3::new(wobble(k, c), wobble(k, c + 1), wobble(k, c + 2));
            MagAccelSample {
                t_s: k as f64 * 0.1,
                acc: Vector3::new(0.2, -0.1, 0.3)
                    + acc_matrix * (to_body * up)
                    + n3(0) * (9.81 * noise),
                mag: Vector3::new(12.0, -7.0, 4.0)
                    + soft * (turned * (to_body * field))
                    + n3(3) * (50.0 * noise),
            }
        })
        .collect()
}

/// The samples as six-wide readings replayed in runs of `runs` blocks.
fn cut(samples: &[MagAccelSample], runs: Vec<usize>) -> Cut<6> {
    Cut {
        points: samples.iter().map(mag_accel_reading).collect(),
        runs,
        ..Cut::default()
    }
}

fn runs() -> impl Strategy<Value = Vec<usize>> {
    proptest::collection::vec(1usize..6, 1..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The joint fit (refusals included) through runs is the fit of the slice, bit for bit
    /// (compared through `Debug`, which writes every `f64` so that it reads back exactly);
    /// so is a calibrator with its own store, `progress` included.
    #[test]
    fn the_joint_fit_through_runs_is_the_slice_fit(
        n in 4usize..260, pitch in 0.0f64..1.4, still in 0usize..40,
        rolled in prop_oneof![Just(0usize), 3usize..9], noise in 0.0f64..0.02, runs in runs(), run_shots_kept in 1usize..6,
        frames_kept in 1usize..12,
    ) {
        let samples = recording(n, pitch, still, rolled, noise);
        let config = MagAccelConfig::default();
        let store = cut(&samples, runs);
        let want = format!("{:?}", fit_mag_accel(&samples, &config));
        prop_assert_eq!(format!("{:?}", fit_mag_accel_readings(&store, &config)), want.clone());
        let mut cal = MagAccelCalibrator::with_store(config, store.clone()).unwrap();
        let mut plain = MagAccelCalibrator::new(config).unwrap();
        for s in &samples {
            cal.push(s).unwrap();
            plain.push(s).unwrap();
        }
        prop_assert_eq!(format!("{:?}", cal.solve()), want.clone());
        prop_assert_eq!(format!("{:?}", cal.progress()), format!("{:?}", plain.progress()));
        // And keeping only a few frames and shots at once, passing over them again.
        let limits = Limits { run_shots: run_shots_kept, stretch_frames: frames_kept };
        prop_assert_eq!(format!("{:?}", fit_mag_accel_within(&store, &config, limits)), want);
    }

    /// A replay that fails, whichever pass it is, fails the fit with its error (the
    /// passes of long runs and stretches included).
    #[test]
    fn a_failed_replay_is_the_error(
        n in 40usize..200, pitch in 0.3f64..1.4, still in 0usize..40,
        rolled in prop_oneof![Just(0usize), 3usize..9], at in 0.0f64..1.0, runs in runs(), kept in 1usize..8,
    ) {
        let samples = recording(n, pitch, still, rolled, 0.005);
        let config = MagAccelConfig::default();
        let limits = Limits { run_shots: kept, stretch_frames: kept };
        let store = cut(&samples, runs);
        let _ = fit_mag_accel_within(&store, &config, limits);
        let passes = store.replays.load(core::sync::atomic::Ordering::Relaxed);
        let failing = Cut { fail_at: Some((at * passes as f64) as usize), ..cut(&samples, store.runs.clone()) };
        prop_assert_eq!(fit_mag_accel_within(&failing, &config, limits), Err(FAILED));
    }
}

/// The recordings above reach every step: a fit with runs, one without, and a refusal.
#[test]
fn the_recordings_reach_runs_fits_and_refusals() {
    let config = MagAccelConfig::default();
    let with_runs = fit_mag_accel(&recording(120, 1.2, 0, 8, 0.002), &config).unwrap();
    assert!(with_runs.quality.runs > 0, "{:?}", with_runs.quality);
    // A still stretch before the roll joins the run.
    let long_run = fit_mag_accel(&recording(120, 1.2, 30, 8, 0.002), &config).unwrap();
    assert!(long_run.quality.run_shots >= 38, "{:?}", long_run.quality);
    let without = fit_mag_accel(&recording(120, 1.2, 30, 0, 0.002), &config).unwrap();
    assert_eq!(without.quality.runs, 0);
    assert!(fit_mag_accel(&recording(120, 0.0, 0, 0, 0.002), &config).is_err());
}

/// The joint fit of readings three segments long, folded on every core (readings in one
/// slice, samples in one slice, the default calibrator's samples), is the fit of the same
/// readings replayed in runs, folded on one thread, to the bit (see
/// `fits_on_several_threads_are_the_fits_on_one` for the 2-D and 3-D fits).
#[test]
fn the_joint_fit_on_several_threads_is_the_fit_on_one() {
    let samples = recording(
        2 * crate::numerics::segments::SEGMENT + 2_000,
        1.2,
        0,
        8,
        0.002,
    );
    let config = MagAccelConfig::default();
    let on_one = format!(
        "{:?}",
        fit_mag_accel_readings(&cut(&samples, vec![3, 1]), &config)
    );
    assert!(on_one.starts_with("Ok"), "{on_one}");
    let readings: Vec<MagAccelReading> = samples.iter().map(mag_accel_reading).collect();
    assert_eq!(
        format!("{:?}", fit_mag_accel_readings(&readings, &config)),
        on_one
    );
    assert_eq!(format!("{:?}", fit_mag_accel(&samples, &config)), on_one);
    let mut cal = MagAccelCalibrator::new(config).unwrap();
    for s in &samples {
        cal.push(s).unwrap();
    }
    assert_eq!(format!("{:?}", cal.solve()), on_one);
}
