//! Saving and restoring the orientation estimators (`core::Persistent`): a filter saved at
//! any sample of a recording, written to JSON, read back and restored, continues exactly as
//! one that never stopped, bit for bit; a damaged state is refused.

use std::sync::OnceLock;

use nalgebra::{UnitQuaternion, Vector3};
use proptest::prelude::*;
use truenorth_core::{
    AttitudeEstimate, Error, ImuSample, OrientationEstimator, Persistent, Snapshot,
};
use truenorth_fusion::{
    EulerDetector, EulerDetectorConfig, EulerDetectorState, GyroConditioning, GyroTiming,
    QuaternionFilter, QuaternionFilterConfig, QuaternionFilterState,
};
use truenorth_gyro::{HighPassConfig, HighPassCorrectionConfig, OscillationRemoverConfig};
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

/// Half a minute of simulated hand-held motion with a gap of 2 s in the middle (the
/// estimators restart there), then 8 s still (rest detection and the bias at rest).
fn recording() -> &'static [ImuSample] {
    static SAMPLES: OnceLock<Vec<ImuSample>> = OnceLock::new();
    SAMPLES.get_or_init(|| {
        let truth = handheld_motion(&HandheldParams {
            duration_s: 30.0,
            seed: 7,
            ..HandheldParams::default()
        })
        .unwrap();
        let mut samples = imu_streams(&truth, &ImuSensorParams::typical(), 7).unwrap();
        let half = samples.len() / 2;
        for s in &mut samples[half..] {
            s.t_s += 2.0;
        }
        let last = *samples.last().unwrap();
        let still = ImuSample::new_9d(
            0.0,
            Vector3::new(0.004, -0.003, 0.002),
            Vector3::new(0.0, 0.0, -9.81),
            Vector3::new(20.0, 0.0, 45.0),
        );
        samples.extend((1..=800).map(|k| ImuSample {
            t_s: last.t_s + 0.01 * k as f64,
            ..still
        }));
        samples
    })
}

/// Every number of an estimate, as bits, and its flags.
fn bits(e: &AttitudeEstimate) -> (Vec<u64>, String) {
    let q = |q: &UnitQuaternion<f64>| q.coords.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let mut v = vec![e.t_s.to_bits()];
    v.extend(q(&e.attitude));
    v.extend(e.attitude_6d.iter().flat_map(q));
    v.extend(e.gyro_bias_rps.iter().map(|x| x.to_bits()));
    v.extend(
        e.sigma_rad
            .iter()
            .flat_map(|s| s.iter().map(|x| x.to_bits())),
    );
    (v, format!("{:?}", e.status))
}

/// Runs `make()` through the whole recording, and again with a stop at sample `cut`: the
/// snapshot written to JSON, read back, restored, and continued. Both runs must give the
/// same estimates bit for bit, and end in the same state.
fn restore_and_continue<E>(make: impl Fn() -> E, cut: usize) -> Result<(), TestCaseError>
where
    E: OrientationEstimator + Persistent,
    E::State: PartialEq + core::fmt::Debug,
{
    let samples = recording();
    let cut = cut % (samples.len() + 1);
    let mut never_stopped = make();
    let reference: Vec<_> = samples
        .iter()
        .map(|s| bits(&never_stopped.update(s).unwrap()))
        .collect();
    let mut first = make();
    for s in &samples[..cut] {
        first.update(s).unwrap();
    }
    let json = serde_json::to_string(&first.snapshot()).unwrap();
    let snapshot: Snapshot<E::State> = serde_json::from_str(&json).unwrap();
    let mut restored = E::restore(snapshot).unwrap();
    prop_assert_eq!(bits(&restored.estimate()), bits(&first.estimate()));
    for (k, s) in samples.iter().enumerate().skip(cut) {
        let e = bits(&restored.update(s).unwrap());
        prop_assert!(e == reference[k], "sample {k} after a stop at {cut}");
    }
    prop_assert_eq!(restored.state(), never_stopped.state());
    Ok(())
}

fn quaternion(config: QuaternionFilterConfig) -> impl Fn() -> QuaternionFilter {
    move || QuaternionFilter::new(config).unwrap()
}

fn euler(config: EulerDetectorConfig) -> impl Fn() -> EulerDetector {
    move || EulerDetector::new(config).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn quaternion_filter_continues_bit_identically(cut in 0usize..5000) {
        restore_and_continue(quaternion(QuaternionFilterConfig::default()), cut)?;
    }

    /// 6-D, with the trapezoid rule's previous rate carried over.
    #[test]
    fn quaternion_filter_6d_continues_bit_identically(cut in 0usize..5000) {
        let config = QuaternionFilterConfig {
            use_mag: false,
            gyro_timing: GyroTiming::Instantaneous,
            ..QuaternionFilterConfig::default()
        };
        restore_and_continue(quaternion(config), cut)?;
    }

    #[test]
    fn euler_detector_continues_bit_identically(cut in 0usize..5000) {
        restore_and_continue(euler(EulerDetectorConfig::default()), cut)?;
    }

    /// With every memory the detector can carry: high-pass, its correction, the
    /// oscillation remover.
    #[test]
    fn conditioned_euler_detector_continues_bit_identically(cut in 0usize..5000) {
        let config = EulerDetectorConfig {
            gyro: GyroConditioning::HighPass {
                filter: HighPassConfig::default(),
                correction: Some(HighPassCorrectionConfig::default()),
            },
            oscillation_remover: Some(OscillationRemoverConfig::default()),
            ..EulerDetectorConfig::default()
        };
        restore_and_continue(euler(config), cut)?;
    }
}

/// The recording takes the estimators through a gap and a rest.
#[test]
fn the_recording_has_a_gap_and_a_rest() {
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    let e: Vec<_> = recording().iter().map(|s| f.update(s).unwrap()).collect();
    assert!(e.iter().any(|e| e.status.gap));
    assert!(e.iter().any(|e| e.status.at_rest));
}

/// A quaternion filter's state part way through the recording.
fn quaternion_state() -> QuaternionFilterState {
    let mut f = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    for s in &recording()[..1000] {
        f.update(s).unwrap();
    }
    f.state()
}

/// An Euler detector's state part way through the recording.
fn euler_state() -> EulerDetectorState {
    let mut d = EulerDetector::new(EulerDetectorConfig::default()).unwrap();
    for s in &recording()[..1000] {
        d.update(s).unwrap();
    }
    d.state()
}

#[test]
fn a_damaged_quaternion_filter_state_is_refused() {
    let good = quaternion_state();
    assert!(QuaternionFilter::from_state(good).is_ok());
    let damaged = [
        QuaternionFilterState {
            gyro_bias_rps: Vector3::new(f64::NAN, 0.0, 0.0),
            ..good
        },
        QuaternionFilterState {
            since_start_s: f64::INFINITY,
            ..good
        },
        QuaternionFilterState {
            attitude: UnitQuaternion::new_unchecked(good.attitude.into_inner() * 1.1),
            ..good
        },
        QuaternionFilterState {
            config: QuaternionFilterConfig {
                tau_acc_s: -1.0,
                ..good.config
            },
            ..good
        },
        // Parts built for other parameters than the filter's.
        QuaternionFilterState {
            config: QuaternionFilterConfig {
                max_gap_s: 2.0,
                ..good.config
            },
            ..good
        },
    ];
    for state in damaged {
        assert!(QuaternionFilter::from_state(state).is_err(), "{state:?}");
    }
    let version = QuaternionFilter::SNAPSHOT_VERSION + 1;
    let wrong = Snapshot {
        version,
        state: good,
    };
    assert!(matches!(
        QuaternionFilter::restore(wrong),
        Err(Error::SnapshotVersion { .. })
    ));
}

#[test]
fn a_damaged_euler_detector_state_is_refused() {
    let good = euler_state();
    assert!(EulerDetector::from_state(good).is_ok());
    let edited = |path: [&str; 2], value: serde_json::Value| {
        let mut v = serde_json::to_value(good).unwrap();
        v[path[0]][path[1]] = value;
        serde_json::from_value(v).unwrap()
    };
    let mut other_window = serde_json::to_value(good).unwrap();
    other_window["averages"][0]["n"] = serde_json::json!(3);
    let damaged = [
        edited(["angles", "pitch_rad"], serde_json::json!(2.0)),
        serde_json::from_value(other_window).unwrap(),
        EulerDetectorState {
            angles: truenorth_core::EulerZyx {
                yaw_rad: f64::NAN,
                ..good.angles
            },
            ..good
        },
        EulerDetectorState {
            previous_static: Some([0.0, f64::NEG_INFINITY, 0.0]),
            ..good
        },
        // Conditioning the parameters do not select.
        EulerDetectorState {
            config: EulerDetectorConfig {
                oscillation_remover: Some(OscillationRemoverConfig::default()),
                ..good.config
            },
            ..good
        },
    ];
    for state in damaged {
        assert!(EulerDetector::from_state(state).is_err(), "{state:?}");
    }
    let json = serde_json::to_string(&EulerDetector::from_state(good).unwrap().snapshot())
        .unwrap()
        .replacen(
            &format!("\"version\":{}", EulerDetector::SNAPSHOT_VERSION),
            "\"version\":99",
            1,
        );
    let wrong: Snapshot<EulerDetectorState> = serde_json::from_str(&json).unwrap();
    assert!(matches!(
        EulerDetector::restore(wrong),
        Err(Error::SnapshotVersion { found: 99, .. })
    ));
}

/// A configuration or a saved state that names the removed `acc_lowpass_s` (written before
/// the inclination low-pass became one second-order filter of `tau_acc_s`) is refused on
/// reading, with what replaced it, never read with its `tau_acc_s` meaning something else;
/// one without it reads, each absent field at its default.
#[test]
fn a_configuration_naming_the_removed_lowpass_is_refused_with_its_replacement() {
    let says_what_replaced_it = |e: &serde_json::Error| {
        let m = e.to_string();
        m.contains("acc_lowpass_s is no longer a parameter") && m.contains("set tau_acc_s anew")
    };
    let old = r#"{"tau_acc_s": 3.0, "acc_lowpass_s": 1.0}"#;
    let e = serde_json::from_str::<QuaternionFilterConfig>(old).unwrap_err();
    assert!(says_what_replaced_it(&e), "{e}");

    let mut snapshot = serde_json::to_value(
        QuaternionFilter::new(QuaternionFilterConfig::default())
            .unwrap()
            .snapshot(),
    )
    .unwrap();
    snapshot["version"] = serde_json::json!(1);
    snapshot["state"]["config"]["acc_lowpass_s"] = serde_json::json!(1.0);
    let e = serde_json::from_value::<Snapshot<QuaternionFilterState>>(snapshot).unwrap_err();
    assert!(says_what_replaced_it(&e), "{e}");

    let new: QuaternionFilterConfig = serde_json::from_str(r#"{"tau_acc_s": 3.0}"#).unwrap();
    assert_eq!(
        new,
        QuaternionFilterConfig {
            tau_acc_s: 3.0,
            ..QuaternionFilterConfig::default()
        }
    );
    let written = serde_json::to_string(&QuaternionFilterConfig::default()).unwrap();
    assert!(!written.contains("acc_lowpass_s"), "{written}");
    let read: QuaternionFilterConfig = serde_json::from_str(&written).unwrap();
    assert_eq!(read, QuaternionFilterConfig::default());
}
