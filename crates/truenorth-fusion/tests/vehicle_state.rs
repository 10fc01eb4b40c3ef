//! The vehicle estimator saved mid-drive, written to JSON and read back continues bit for bit
//! as if it had never stopped; a damaged or foreign snapshot is refused with an error.
//!
//! Drives of every kind of vehicle (rear- and front-wheel cars, skid-steer and differential
//! robots), with and without a gyro, are cut at a random row: the estimator is saved there
//! (`snapshot`), the snapshot goes through `serde_json` and back, is `restore`d, and takes
//! the rest of the drive. Every later estimate and the final state must equal, bit for bit,
//! those of the run that never stopped.

mod common;

use common::persistence::{check_continues, json};
use proptest::prelude::*;
use truenorth_core::{Error, HeadingEstimator, Persistent, Snapshot, VehicleSample};
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_sim::{RangeDrive, RangeSpec, VehicleKind};

/// A short drive of `kind` (the cars' route shortened so that a case runs in a second or
/// two), with or without its gyro's readings.
fn drive(seed: u64, kind: VehicleKind, gyro: bool) -> (VehicleConfig, Vec<VehicleSample>) {
    let spec = RangeSpec::new(seed, kind);
    let d = RangeDrive::new(RangeSpec {
        length_m: if kind.is_car() { 1500.0 } else { 300.0 },
        ..spec
    })
    .unwrap();
    let mut priors = SensorPriors::for_wheels(&d.vehicle.wheels);
    priors.wheel_resolution_m = d.wheel_resolution_m();
    let config = VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(priors),
        ..VehicleConfig::default()
    };
    let samples = d
        .samples
        .iter()
        .map(|s| VehicleSample {
            gyr_z_rps: if gyro { s.gyr_z_rps } else { None },
            ..*s
        })
        .collect();
    (config, samples)
}

fn kind() -> impl Strategy<Value = VehicleKind> {
    prop::sample::select(VehicleKind::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    #[test]
    fn a_restored_estimator_continues_bit_for_bit(
        seed in 0u64..1000,
        kind in kind(),
        gyro in any::<bool>(),
        cut_share in 0.0f64..1.0,
    ) {
        let (config, samples) = drive(seed, kind, gyro);
        let cut = (cut_share * samples.len() as f64) as usize;
        check_continues(|| VehicleEstimator::new(config).unwrap(), &samples, cut);
    }
}

/// An estimator part-way through a drive with a gyro (its compass learned).
fn running() -> VehicleEstimator {
    let (config, samples) = drive(3, VehicleKind::RearWheelCar, true);
    let mut nav = VehicleEstimator::new(config).unwrap();
    for s in &samples[..samples.len() / 2] {
        nav.update(s).unwrap();
    }
    nav
}

#[test]
fn a_fresh_estimator_saves_its_non_finite_start_by_name_and_reads_it_back() {
    let nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let text = json(&nav.snapshot());
    assert!(text.contains("\"NaN\"") && text.contains("\"inf\"") && text.contains("\"-inf\""));
    let back = VehicleEstimator::restore(serde_json::from_str(&text).unwrap()).unwrap();
    assert_eq!(json(&back.state()), json(&nav.state()));
}

#[test]
fn a_finite_estimate_keeps_nalgebras_layout() {
    let e = running().estimate();
    assert!(e.position_cov_m2.iter().all(|v| v.is_finite()));
    let v = serde_json::to_value(e).unwrap();
    assert_eq!(
        v["position_cov_m2"],
        serde_json::to_value(e.position_cov_m2).unwrap()
    );
    assert_eq!(v["t_s"], serde_json::to_value(e.t_s).unwrap());
}

#[test]
fn a_snapshot_of_another_version_is_refused() {
    let nav = running();
    let mut snapshot = nav.snapshot();
    snapshot.version += 1;
    let err = VehicleEstimator::restore(snapshot).unwrap_err();
    assert_eq!(
        err,
        Error::SnapshotVersion {
            found: VehicleEstimator::SNAPSHOT_VERSION + 1,
            expected: VehicleEstimator::SNAPSHOT_VERSION,
        }
    );
}

fn refused(snapshot: Snapshot<<VehicleEstimator as Persistent>::State>) -> Error {
    match VehicleEstimator::restore(snapshot) {
        Ok(_) => panic!("a damaged state was accepted"),
        Err(e) => e,
    }
}

#[test]
fn a_damaged_state_is_refused_with_an_error() {
    let good = running().snapshot();
    let mut nan_cov = good.clone();
    nan_cov.state.filter.p[1][2] = f64::NAN;
    assert!(matches!(refused(nan_cov), Error::InvalidSnapshot { .. }));

    let mut lopsided = good.clone();
    lopsided.state.filter.p[0][3] += 1.0;
    assert!(matches!(refused(lopsided), Error::InvalidSnapshot { .. }));

    let mut negative = good.clone();
    negative.state.initial_filter.p[4][4] = -1.0;
    assert!(matches!(refused(negative), Error::InvalidSnapshot { .. }));

    let mut nan_estimate = good.clone();
    nan_estimate.state.estimate.north_m = f64::NAN;
    assert!(matches!(
        refused(nan_estimate),
        Error::InvalidSnapshot { .. }
    ));

    let mut bad_config = good.clone();
    bad_config.state.config.max_gap_s = -1.0;
    assert!(matches!(
        refused(bad_config),
        Error::OutOfRange { .. } | Error::NonFinite { .. }
    ));

    let mut bad_gates = good.clone();
    bad_gates.state.config.compass.field_tolerance = f64::NAN;
    let e = refused(bad_gates);
    assert!(!matches!(e, Error::InvalidSnapshot { .. }), "{e:?}");

    // The undamaged state is accepted.
    assert!(VehicleEstimator::restore(good).is_ok());
}
