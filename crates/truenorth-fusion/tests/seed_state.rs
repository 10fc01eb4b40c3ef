//! The seed configurations (EP 0640207's gyro and compass, US 4,788,645's wheels and
//! compass) saved mid-drive, written to JSON and read back, continue bit for bit as if they
//! had never stopped; their non-finite heading σ is written by name; a snapshot of another
//! version or a damaged state is refused.

mod common;

use common::persistence::{check_continues, json};
use proptest::prelude::*;
use truenorth_core::{Error, HeadingEstimator, Persistent, VehicleSample};
use truenorth_fusion::vehicle::{
    SeedGyroCompass, SeedGyroCompassConfig, SeedOdometerCompass, SeedOdometerCompassConfig,
};
use truenorth_odometer::OdometerWheels;
use truenorth_sim::{DriveSpec, DriveWheels, SimulatedDrive};

/// A short drive with an opening turn (which calibrates the compass and, for the gyro
/// configuration, the gyro).
fn drive(seed: u64, wheels: DriveWheels) -> (OdometerWheels, Vec<VehicleSample>) {
    let d = SimulatedDrive::new(DriveSpec {
        wheels,
        length_m: 2000.0,
        ..DriveSpec::new(seed)
    })
    .unwrap();
    (wheels.odometer_wheels(), d.samples)
}

fn gyro_compass(wheels: OdometerWheels) -> SeedGyroCompass {
    SeedGyroCompass::new(SeedGyroCompassConfig {
        wheels,
        ..Default::default()
    })
    .unwrap()
}

fn odometer_compass(wheels: OdometerWheels) -> SeedOdometerCompass {
    SeedOdometerCompass::new(SeedOdometerCompassConfig {
        wheels,
        ..Default::default()
    })
    .unwrap()
}

fn wheels() -> impl Strategy<Value = DriveWheels> {
    prop::sample::select(vec![DriveWheels::Rear, DriveWheels::Front])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn a_restored_seed_gyro_compass_continues_bit_for_bit(
        seed in 0u64..1000,
        kind in wheels(),
        cut_share in 0.0f64..1.0,
    ) {
        let (w, samples) = drive(seed, kind);
        let cut = (cut_share * samples.len() as f64) as usize;
        check_continues(|| gyro_compass(w), &samples, cut);
    }

    #[test]
    fn a_restored_seed_odometer_compass_continues_bit_for_bit(
        seed in 0u64..1000,
        kind in wheels(),
        cut_share in 0.0f64..1.0,
    ) {
        let (w, samples) = drive(seed, kind);
        let cut = (cut_share * samples.len() as f64) as usize;
        check_continues(|| odometer_compass(w), &samples, cut);
    }
}

/// Cut while the turn calibrator is still learning, and again once it has calibrated:
/// both continue bit for bit, and the heading σ (∞, then NaN) is written by name.
#[test]
fn the_gyro_compass_continues_before_and_after_its_turn_calibration() {
    let (w, samples) = drive(4, DriveWheels::Rear);
    let mut probe = gyro_compass(w);
    let text = json(&probe.snapshot());
    assert!(text.contains("\"inf\""), "{text}");
    let calibrated = samples
        .iter()
        .position(|s| {
            probe.update(s).unwrap();
            probe.calibration().is_some()
        })
        .expect("the opening turn calibrates gyro and compass");
    check_continues(|| gyro_compass(w), &samples, calibrated / 2);
    check_continues(|| gyro_compass(w), &samples, calibrated + 1);
}

#[test]
fn damaged_states_are_refused() {
    let (w, samples) = drive(9, DriveWheels::Rear);
    let mut gyro = gyro_compass(w);
    let mut odo = odometer_compass(w);
    for s in &samples[..samples.len() / 2] {
        gyro.update(s).unwrap();
        odo.update(s).unwrap();
    }
    let good = gyro.snapshot();
    assert!(SeedGyroCompass::restore(good.clone()).is_ok());
    let mut nan_zero = good.clone();
    nan_zero.state.zero_rps = f64::NAN;
    assert!(matches!(
        SeedGyroCompass::restore(nan_zero),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut other_blend = good.clone();
    other_blend.state.config.blend.tau_s *= 2.0;
    assert!(matches!(
        SeedGyroCompass::restore(other_blend),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut bad_config = good;
    bad_config.state.config.turn.max_gap_s = -1.0;
    assert!(SeedGyroCompass::restore(bad_config).is_err());

    let good = odo.snapshot();
    assert!(SeedOdometerCompass::restore(good.clone()).is_ok());
    let mut other_refiner = good.clone();
    other_refiner.state.config.speed_coefficient.filter_constant *= 2.0;
    assert!(matches!(
        SeedOdometerCompass::restore(other_refiner),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut infinite_time = good;
    infinite_time.state.estimate.t_s = f64::INFINITY;
    assert!(matches!(
        SeedOdometerCompass::restore(infinite_time),
        Err(Error::InvalidSnapshot { .. })
    ));
}
