//! The contract every calibrator keeps, checked on random turns:
//!
//! * `progress().ready` agrees with `solve().is_ok()`, in both directions, on arcs of
//!   150°–400°, noise of 0–3 % of the field and random hard and soft iron, at several points
//!   of each turn (the agreement rate is printed: `cargo test -p truenorth-calib --test
//!   calibrator_contract -- --nocapture agreement`);
//! * `solve` does not change the calibrator;
//! * snapshot → restore → the rest of the pushes gives bit-identical pushes, estimates and
//!   solutions to a calibrator that never stopped;
//! * a non-finite value anywhere in a sample is a typed error and changes nothing.

use std::cell::Cell;

use nalgebra::{Matrix3, Rotation3, Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use truenorth_calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, EllipsoidCalibrator, MeritCircleCalibrator,
    TurnCompassCalibrator,
};
use truenorth_compass::{
    CompassCalibration2d, HeadingTruth, MagnetometerModel2d, soft_iron_from_axes,
};
use truenorth_core::{
    Calibrator, CompassQuality, Error, Mag2Sample, Mag3Sample, NoiseSource, OnlineCalibrator,
    Persistent, SensorModel, Snapshot, SplitMix64,
};

const H: f64 = 20.0;

/// A turn of `span_deg` from `start_deg` at 2 samples per degree.
fn turn(
    hard: Vector2<f64>,
    ratio: f64,
    angle: f64,
    noise: f64,
    start_deg: f64,
    span_deg: f64,
    seed: u64,
) -> Vec<Mag2Sample> {
    let mut m =
        MagnetometerModel2d::new(hard, soft_iron_from_axes(ratio, 1.0, angle), noise * H).unwrap();
    let mut rng = SplitMix64::new(seed);
    let n = (2.0 * span_deg).round() as usize;
    (0..=n)
        .map(|i| {
            let truth = HeadingTruth {
                heading_rad: (start_deg + span_deg * i as f64 / n as f64).to_radians(),
                horizontal_field: H,
            };
            Mag2Sample {
                t_s: 0.05 * i as f64,
                mag: m.sample(&truth, 0.05, &mut rng).unwrap(),
            }
        })
        .collect()
}

/// Checks `ready == solve().is_ok()` after pushing each of `checkpoints` prefixes of
/// `samples`, and that neither call changes what a later solve returns.
fn check_agreement<C>(
    mut c: C,
    samples: &[Mag2Sample],
    checkpoints: usize,
    tally: &Tally,
) -> Result<(), TestCaseError>
where
    C: Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>
        + Clone,
{
    let every = samples.len().div_ceil(checkpoints).max(1);
    for (i, s) in samples.iter().enumerate() {
        c.push(s)
            .map_err(|e| TestCaseError::fail(format!("sample {i} refused: {e}")))?;
        if (i + 1) % every == 0 || i + 1 == samples.len() {
            let ready = c.progress().ready;
            let first = c.solve();
            let again = c.solve();
            tally.count(ready == first.is_ok());
            prop_assert_eq!(ready, first.is_ok(), "after {} samples: {:?}", i + 1, first);
            prop_assert_eq!(&first, &again, "solve changed the calibrator");
        }
    }
    Ok(())
}

fn noise() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), 0.0f64..0.03]
}

/// Checks made and checks where `ready` agreed with `solve`.
#[derive(Default)]
struct Tally {
    checked: Cell<usize>,
    agreed: Cell<usize>,
}

impl Tally {
    fn count(&self, agreed: bool) {
        self.checked.set(self.checked.get() + 1);
        self.agreed.set(self.agreed.get() + usize::from(agreed));
    }
}

fn runner() -> TestRunner {
    TestRunner::new(Config {
        cases: 48,
        failure_persistence: None,
        ..Config::default()
    })
}

/// A random 2-D turn: arc, start, noise (share of the field), seed, hard iron, soft-iron
/// ratio and angle.
fn any_turn() -> impl Strategy<Value = Vec<Mag2Sample>> {
    (
        150.0f64..400.0,
        0.0f64..360.0,
        noise(),
        0u64..1000,
        -0.6f64..0.6,
        -0.6f64..0.6,
        1.0f64..1.4,
        -1.6f64..1.6,
    )
        .prop_map(|(span, start, noise, seed, hx, hy, ratio, angle)| {
            turn(
                Vector2::new(hx, hy) * H,
                ratio,
                angle,
                noise,
                start,
                span,
                seed,
            )
        })
}

/// `progress().ready == solve().is_ok()` for every calibrator family on random turns
/// (arcs 150°–400°, noise 0–3 % of the field, hard and soft iron), checked at several points
/// of each turn; prints the agreement rate.
#[test]
fn ready_agrees_with_solve_on_random_turns() {
    let tally = Tally::default();
    let families: [(&str, usize); 4] = [
        ("merit circle", 0),
        ("turn", 1),
        ("binned ellipse", 2),
        ("least-squares ellipse", 3),
    ];
    for (name, which) in families {
        let before = tally.checked.get();
        runner()
            .run(&any_turn(), |data| match which {
                0 => check_agreement(MeritCircleCalibrator::default(), &data, 6, &tally),
                1 => check_agreement(TurnCompassCalibrator::default(), &data, 6, &tally),
                2 => check_agreement(BinnedEllipseCalibrator::default(), &data, 6, &tally),
                _ => check_agreement(EllipseCalibrator::default(), &data, 4, &tally),
            })
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{name}: {} checks", tally.checked.get() - before);
    }
    let before = tally.checked.get();
    runner()
        .run(
            &(
                -1.0f64..0.9,
                noise(),
                0u64..1000,
                20usize..400,
                -0.6f64..0.6,
                0.85f64..1.2,
                0.85f64..1.2,
                (-3.0f64..3.0, -1.5f64..1.5, -3.0f64..3.0),
            ),
            |(z_min, noise, seed, n, hx, a1, a2, (r, p, y))| {
                // Directions over the cap z ≥ z_min of the sphere (a small cap does not
                // determine an ellipsoid; the whole sphere does).
                let rot = Rotation3::from_euler_angles(r, p, y);
                let d = Matrix3::from_diagonal(&Vector3::new(a1, a2, 1.0 / (a1 * a2)));
                let w = rot.matrix() * d * rot.matrix().transpose();
                let hard = Vector3::new(hx, -hx, 0.5 * hx) * H;
                let mut rng = SplitMix64::new(seed);
                let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
                let mut c = EllipsoidCalibrator::default();
                let every = n.div_ceil(4);
                for k in 0..n {
                    let z = 1.0 - (1.0 - z_min) * (k as f64 + 0.5) / n as f64;
                    let rr = (1.0 - z * z).max(0.0).sqrt();
                    let (s, co) = (golden * k as f64).sin_cos();
                    let e = Vector3::new(
                        rng.normal(noise * H),
                        rng.normal(noise * H),
                        rng.normal(noise * H),
                    );
                    let mag = hard + w * Vector3::new(rr * co, rr * s, z) * H + e;
                    c.push(&Mag3Sample { t_s: k as f64, mag }).unwrap();
                    if (k + 1) % every == 0 || k + 1 == n {
                        let ready = c.progress().ready;
                        let sol = c.solve();
                        tally.count(ready == sol.is_ok());
                        prop_assert_eq!(ready, sol.is_ok(), "after {} samples: {:?}", k + 1, sol);
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("least-squares ellipsoid: {e}"));
    println!(
        "least-squares ellipsoid: {} checks",
        tally.checked.get() - before
    );
    let (checked, agreed) = (tally.checked.get(), tally.agreed.get());
    println!(
        "ready/solve agreement: {agreed} of {checked} checks ({:.1} %)",
        100.0 * agreed as f64 / checked as f64
    );
    assert_eq!(agreed, checked);
}

/// Pushes `samples`, snapshots after `cut` of them, restores a clone of the snapshot, and
/// pushes the rest into both; every push result, estimate and the final solve must be
/// identical.
fn check_round_trip<C>(
    samples: &[Mag2Sample],
    cut: usize,
    estimate: impl Fn(&C) -> Option<truenorth_core::Solution<CompassCalibration2d>>,
) -> Result<(), TestCaseError>
where
    C: Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>
        + Persistent
        + Default,
{
    let mut a = C::default();
    for s in &samples[..cut] {
        a.push(s)
            .map_err(|e| TestCaseError::fail(format!("refused: {e}")))?;
    }
    let snap: Snapshot<C::State> = a.snapshot();
    // Through JSON, as a user stores it: the state read back must be the state written.
    let json = serde_json::to_string(&snap).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    let read: Snapshot<C::State> =
        serde_json::from_str(&json).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    let mut b = C::restore(read).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    prop_assert_eq!(estimate(&a), estimate(&b));
    for s in &samples[cut..] {
        prop_assert_eq!(a.push(s), b.push(s));
        prop_assert_eq!(estimate(&a), estimate(&b));
    }
    prop_assert_eq!(a.solve(), b.solve());
    prop_assert_eq!(a.progress(), b.progress());
    // Another layout version is refused.
    let wrong = Snapshot {
        version: snap.version + 1,
        state: snap.state,
    };
    let refused = matches!(C::restore(wrong), Err(Error::SnapshotVersion { .. }));
    prop_assert!(refused);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn snapshot_restore_continue_is_bit_identical(
        span in 150.0f64..800.0, start in 0.0f64..360.0, noise in noise(), seed in 0u64..1000,
        hx in -0.6f64..0.6, hy in -0.6f64..0.6, ratio in 1.0f64..1.4, angle in -1.6f64..1.6,
        cut_frac in 0.0f64..1.0,
    ) {
        let data = turn(Vector2::new(hx, hy) * H, ratio, angle, noise, start, span, seed);
        let cut = ((data.len() as f64) * cut_frac) as usize;
        check_round_trip::<MeritCircleCalibrator>(&data, cut, |c| c.estimate())?;
        check_round_trip::<BinnedEllipseCalibrator>(&data, cut, |c| c.estimate())?;
        check_round_trip::<TurnCompassCalibrator>(&data, cut, |_| None)?;
    }

    /// NaN or an infinity in any field of a sample: a typed error, and every later result
    /// is what it would have been without that sample.
    #[test]
    fn non_finite_samples_are_refused_and_change_nothing(
        span in 200.0f64..500.0, start in 0.0f64..360.0, seed in 0u64..1000,
        at_frac in 0.0f64..1.0, field in 0usize..3,
        bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ) {
        let data = turn(Vector2::new(4.0, -3.0), 1.2, 0.4, 0.01, start, span, seed);
        let at = ((data.len() as f64) * at_frac) as usize;
        let mut poisoned = data[at.min(data.len() - 1)];
        match field {
            0 => poisoned.t_s = bad,
            1 => poisoned.mag.x = bad,
            _ => poisoned.mag.y = bad,
        }
        fn run<C>(data: &[Mag2Sample], at: usize, poisoned: &Mag2Sample) -> Result<(), TestCaseError>
        where
            C: Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>
                + Default + std::fmt::Debug,
        {
            let (mut clean, mut dirty) = (C::default(), C::default());
            for (i, s) in data.iter().enumerate() {
                if i == at {
                    let r = dirty.push(poisoned);
                    prop_assert!(matches!(r, Err(Error::NonFinite { .. })), "{:?}", r);
                }
                prop_assert_eq!(clean.push(s), dirty.push(s));
            }
            prop_assert_eq!(clean.solve(), dirty.solve());
            prop_assert_eq!(clean.progress(), dirty.progress());
            Ok(())
        }
        run::<MeritCircleCalibrator>(&data, at, &poisoned)?;
        run::<BinnedEllipseCalibrator>(&data, at, &poisoned)?;
        run::<TurnCompassCalibrator>(&data, at, &poisoned)?;
        run::<EllipseCalibrator>(&data, at, &poisoned)?;
    }

    #[test]
    fn non_finite_3d_samples_are_refused_and_change_nothing(
        seed in 0u64..1000, at in 0usize..200, field in 0usize..4,
        bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ) {
        let mut rng = SplitMix64::new(seed);
        let data: Vec<Mag3Sample> = (0..200)
            .map(|k| {
                let v = Vector3::new(rng.normal(1.0), rng.normal(1.0), rng.normal(1.0));
                Mag3Sample { t_s: k as f64, mag: Vector3::new(5.0, -2.0, 1.0) + v.normalize() * H }
            })
            .collect();
        let mut poisoned = data[at];
        match field {
            0 => poisoned.t_s = bad,
            1 => poisoned.mag.x = bad,
            2 => poisoned.mag.y = bad,
            _ => poisoned.mag.z = bad,
        }
        let (mut clean, mut dirty) = (EllipsoidCalibrator::default(), EllipsoidCalibrator::default());
        for (i, s) in data.iter().enumerate() {
            if i == at {
                let refused = matches!(dirty.push(&poisoned), Err(Error::NonFinite { .. }));
                prop_assert!(refused);
            }
            prop_assert_eq!(clean.push(s), dirty.push(s));
        }
        prop_assert_eq!(clean.solve(), dirty.solve());
    }
}

/// A snapshot whose contents were damaged is refused with a typed error.
#[test]
fn damaged_snapshots_are_refused() {
    let data = turn(Vector2::new(4.0, -3.0), 1.2, 0.4, 0.01, 10.0, 450.0, 3);
    let mut merit = MeritCircleCalibrator::default();
    let mut binned = BinnedEllipseCalibrator::default();
    let mut turn_cal = TurnCompassCalibrator::default();
    for s in &data {
        merit.push(s).unwrap();
        binned.push(s).unwrap();
        turn_cal.push(s).unwrap();
    }
    let mut m = merit.snapshot();
    m.state.step_sum = f64::NAN;
    assert!(matches!(
        MeritCircleCalibrator::restore(m),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut m = merit.snapshot();
    m.state.config.weight_memory = -1.0;
    assert!(MeritCircleCalibrator::restore(m).is_err());
    let mut b = binned.snapshot();
    b.state.origin = Some(Vector2::new(f64::INFINITY, 0.0));
    assert!(matches!(
        BinnedEllipseCalibrator::restore(b),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut b = binned.snapshot();
    b.state.config.bins = 32;
    assert!(BinnedEllipseCalibrator::restore(b).is_err());
    let mut t = turn_cal.snapshot();
    t.state.slots.pop();
    assert!(matches!(
        TurnCompassCalibrator::restore(t),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut t = turn_cal.snapshot();
    t.state.last_t_s = None;
    assert!(TurnCompassCalibrator::restore(t).is_err());
}
