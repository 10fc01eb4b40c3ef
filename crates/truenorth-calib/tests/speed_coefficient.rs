//! The adaptive speed coefficient of US 4,788,645 on simulated mixed drives: rear wheels
//! whose difference grows as `1 + aV²` (a drawn from 2–8·10⁻⁵ s²/m²), 2 cm pulses, and a
//! calibrated compass with 1 % noise (0.57° per reading), at 10 Hz.

use proptest::prelude::*;
use truenorth_calib::{SpeedCoefficientCalibrator, SpeedCoefficientConfig, SpeedStep};
use truenorth_core::{Calibrator, NoiseSource, SplitMix64, wrap_pi};
use truenorth_sim::{DriveSpec, SimulatedDrive, vehicle_streams};

/// Runs `cal` over one drive of a vehicle whose wheels have no scale error (the patent
/// calibrates `a` alone) and whose `a` is `a_true`.
fn drive(cal: &mut SpeedCoefficientCalibrator, seed: u64, a_true: f64) {
    let drive = SimulatedDrive::new(DriveSpec {
        disturbances: false,
        ..DriveSpec::new(seed)
    })
    .unwrap();
    let mut params = drive.params;
    params.odometer.scale_error_l = 0.0;
    params.odometer.scale_error_r = 0.0;
    params.odometer.speed_coeff_s2_per_m2 = a_true;
    let samples = vehicle_streams(&drive.truth, &params, seed).unwrap();
    let track = 1.55;
    let mut noise = SplitMix64::new(seed ^ 0x5eed);
    // Timestamps continue from drive to drive, as a stored calibrator sees them.
    let t0 = 10_000.0 * seed as f64;
    for (w, t) in samples.windows(2).zip(drive.truth.iter().skip(1)) {
        let (Some(a), Some(b)) = (w[0].wheels, w[1].wheels) else {
            continue;
        };
        let (l, r) = (b.dist_l_m - a.dist_l_m, b.dist_r_m - a.dist_r_m);
        let dt = w[1].t_s - w[0].t_s;
        let v = 0.5 * (l + r) / dt;
        let a = cal.coefficient();
        let compass = wrap_pi(t.heading_rad + noise.normal(0.57f64.to_radians()));
        cal.push(&SpeedStep {
            t_s: t0 + w[1].t_s,
            wheel_heading_change_rad: (l - r) / (track * (1.0 + a * v * v)),
            speed_mps: v,
            compass_heading_rad: Some(compass),
        })
        .unwrap();
    }
}

/// Eight vehicles (a from 2 to 8·10⁻⁵ s²/m²), each driving ten 8–11 km drives with its
/// refiner kept between them (as a navigation unit stores it at switch-off): within 10 % of
/// the true `a` at the end, every vehicle. The turns used and the spread are printed
/// (`cargo test --release -p truenorth-calib --test speed_coefficient -- --nocapture`).
#[test]
fn converges_to_within_ten_percent() {
    let (mut worst, mut sq, mut turns) = (0.0f64, 0.0, 0usize);
    let vehicles = 8;
    for v in 0..vehicles {
        let a_true = 2e-5 + 6e-5 * ((v as f64 * 0.618_034) % 1.0);
        let mut cal = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
        for k in 0..10 {
            drive(&mut cal, 100 * v + k, a_true);
        }
        let ratio = cal.coefficient() / a_true;
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "vehicle {v}: a is {ratio:.3} of the true value after {} turns",
            cal.updates()
        );
        worst = worst.max((ratio - 1.0).abs());
        sq += (ratio - 1.0).powi(2);
        turns += cal.updates();
    }
    println!(
        "adaptive a, {vehicles} vehicles × 10 drives: error RMS {:.1} %, worst {:.1} %, {:.0} qualifying turns per vehicle",
        100.0 * (sq / vehicles as f64).sqrt(),
        100.0 * worst,
        turns as f64 / vehicles as f64
    );
}

proptest! {
    #[test]
    fn no_panic_and_a_refused_step_changes_nothing(
        t in proptest::num::f64::ANY, w in proptest::num::f64::ANY,
        v in proptest::num::f64::ANY, c in proptest::option::of(proptest::num::f64::ANY),
    ) {
        let mut cal = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
        cal.push(&SpeedStep { t_s: 0.0, wheel_heading_change_rad: 0.0, speed_mps: 10.0, compass_heading_rad: Some(0.0) }).unwrap();
        let before = cal;
        let step = SpeedStep { t_s: t, wheel_heading_change_rad: w, speed_mps: v, compass_heading_rad: c };
        let valid = t.is_finite() && t > 0.0 && w.is_finite() && v.is_finite() && c.is_none_or(f64::is_finite);
        prop_assert_eq!(cal.push(&step).is_ok(), valid);
        if !valid {
            prop_assert_eq!(cal, before);
        }
    }
}

/// `reset` forgets everything: the same drive after a reset gives the coefficient a new
/// calibrator gives.
#[test]
fn reset_is_a_new_calibrator() {
    let mut fresh = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
    let mut used = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
    drive(&mut used, 4, 5e-5);
    used.reset();
    assert_eq!(used.progress(), fresh.progress());
    drive(&mut used, 4, 5e-5);
    drive(&mut fresh, 4, 5e-5);
    assert_eq!(used.coefficient().to_bits(), fresh.coefficient().to_bits());
    assert_eq!(
        format!("{:?}", used.solve()),
        format!("{:?}", fresh.solve())
    );
}
