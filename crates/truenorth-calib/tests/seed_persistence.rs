//! The one-turn calibrator (EP 0640207) and the speed-coefficient refiner (US 4,788,645)
//! saved part-way, written to JSON and read back, continue bit for bit as if they had never
//! stopped; a snapshot of another version or a damaged state is refused.

use nalgebra::Vector2;
use proptest::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;
use truenorth_calib::{
    SpeedCoefficientCalibrator, SpeedCoefficientConfig, SpeedStep, TurnCalibrator, TurnConfig,
    TurnSample,
};
use truenorth_core::{Calibrator, Error, NoiseSource, Persistent, Snapshot, SplitMix64};

/// JSON text of `v`: two equal texts are two bit-identical values (serde_json writes the
/// shortest form that reads back exactly; non-finite numbers are written by name).
fn json<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap()
}

/// Through JSON and back.
fn through_json<S: Serialize + DeserializeOwned>(s: &S) -> S {
    serde_json::from_str(&json(s)).unwrap()
}

/// Pushes every sample into one calibrator, and into another stopped after `cut`, saved to
/// JSON, restored and continued: every push, progress and solve after the cut, and the final
/// state, must agree bit for bit; the snapshot under another version is refused.
fn check_continues<C>(make: impl Fn() -> C, samples: &[C::Sample], cut: usize)
where
    C: Calibrator + Persistent,
    C::Params: Serialize,
    C::Quality: Serialize,
{
    let mut whole = make();
    let mut first = make();
    for s in &samples[..cut] {
        assert_eq!(json(&first.push(s).ok()), json(&whole.push(s).ok()));
    }
    let saved = through_json(&first.snapshot());
    let mut second = C::restore(saved.clone()).unwrap();
    assert_eq!(
        json(&second.state()),
        json(&first.state()),
        "state at the cut"
    );
    for (k, s) in samples.iter().enumerate().skip(cut) {
        let (a, b) = (whole.push(s).ok(), second.push(s).ok());
        assert_eq!(json(&a), json(&b), "push {k} after a cut at {cut}");
        if k % 16 == 0 {
            assert_eq!(whole.progress(), second.progress(), "progress at {k}");
        }
    }
    assert_eq!(
        json(&whole.solve().ok()),
        json(&second.solve().ok()),
        "solve"
    );
    assert_eq!(json(&second.state()), json(&whole.state()), "final state");
    let wrong = Snapshot {
        version: saved.version + 1,
        state: saved.state,
    };
    assert!(matches!(
        C::restore(wrong),
        Err(Error::SnapshotVersion { .. })
    ));
}

/// `rest_s` at rest, then `turns` turns at `rate_dps` (negative: left), at 20 Hz, with a
/// gyro of zero 0.01 rad/s reading 2 % high, a compass with hard and soft iron, and noise
/// of `noise` of the field on both.
fn turn_record(seed: u64, rest_s: f64, turns: f64, rate_dps: f64, noise: f64) -> Vec<TurnSample> {
    let mut rng = SplitMix64::new(seed);
    let rate = rate_dps.to_radians();
    let turn_s = turns * 360.0 / rate_dps.abs();
    let n = ((rest_s + turn_s) / 0.05) as usize;
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.05;
            let turning = t >= rest_s;
            let psi = if turning { rate * (t - rest_s) } else { 0.0 };
            let gyr = 0.01 + if turning { 1.02 * rate } else { 0.0 } + rng.normal(noise * 0.05);
            let mag = Vector2::new(4.0 + 24.0 * psi.cos(), -2.0 - 18.0 * psi.sin())
                + Vector2::new(rng.normal(noise * 20.0), rng.normal(noise * 20.0));
            TurnSample {
                t_s: t,
                gyr_z_rps: gyr,
                mag,
            }
        })
        .collect()
}

/// Straights of 6 s and turns of `turn_deg` over 4 s at `speed_mps`, at 10 Hz, wheels that
/// over-state every turn by a·V² (a = 5·10⁻⁵ s²/m²) and a compass of `noise_deg` read on
/// most steps; every seventh cycle the compass is disturbed, so that the turn after it
/// starts without a consistent offset.
fn speed_steps(
    seed: u64,
    cycles: usize,
    turn_deg: f64,
    speed_mps: f64,
    noise_deg: f64,
) -> Vec<SpeedStep> {
    let mut rng = SplitMix64::new(seed);
    let (mut t, mut psi) = (0.0, 0.0f64);
    let mut out = Vec::new();
    for cycle in 0..cycles {
        for k in 0..100 {
            let rate = if k >= 60 {
                turn_deg.to_radians() / 4.0
            } else {
                0.0
            };
            let dpsi = rate * 0.1;
            psi += dpsi;
            t += 0.1;
            let disturbed = cycle % 7 == 3 && k < 60;
            let sigma = if disturbed { 20.0 } else { noise_deg };
            let compass = (k % 5 != 4).then(|| psi + rng.normal(sigma.to_radians()));
            out.push(SpeedStep {
                t_s: t,
                wheel_heading_change_rad: dpsi * (1.0 + 5e-5 * speed_mps * speed_mps),
                speed_mps,
                compass_heading_rad: compass,
            });
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn a_restored_turn_calibrator_continues_bit_for_bit(
        seed in 0u64..1000,
        rest_s in 0.5f64..4.0,
        turns in 0.8f64..2.2,
        rate_dps in prop::sample::select(vec![-30.0, -15.0, 12.0, 25.0]),
        noise in 0.0f64..0.02,
        cut_share in 0.0f64..1.0,
    ) {
        let samples = turn_record(seed, rest_s, turns, rate_dps, noise);
        let cut = (cut_share * samples.len() as f64) as usize;
        check_continues(|| TurnCalibrator::new(TurnConfig::default()).unwrap(), &samples, cut);
    }

    #[test]
    fn a_restored_speed_coefficient_continues_bit_for_bit(
        seed in 0u64..1000,
        turn_deg in prop::sample::select(vec![-120.0, -60.0, 30.0, 90.0, 200.0]),
        speed_mps in 5.0f64..22.0,
        noise_deg in 0.0f64..1.5,
        cut_share in 0.0f64..1.0,
    ) {
        let steps = speed_steps(seed, 16, turn_deg, speed_mps, noise_deg);
        let cut = (cut_share * steps.len() as f64) as usize;
        check_continues(
            || SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap(),
            &steps,
            cut,
        );
    }
}

/// A turn waited out without a consistent offset before it carries a NaN offset in its
/// state: it is written by name, read back, and the refiner continues bit for bit.
#[test]
fn a_turn_without_an_offset_before_it_survives_json() {
    let steps = speed_steps(5, 8, 90.0, 12.0, 0.3);
    let cal = || SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
    let mut probe = cal();
    let cut = steps
        .iter()
        .position(|s| {
            probe.push(s).unwrap();
            json(&probe.state()).contains("\"NaN\"")
        })
        .expect("a disturbed straight leaves the next turn without an offset");
    check_continues(cal, &steps, cut + 1);
    let mut whole = cal();
    for s in &steps {
        whole.push(s).unwrap();
    }
    assert!(
        whole.updates() > 0,
        "no turn refined a: the test saw no update"
    );
}

/// Cut in the middle of the turn, after the standstill's zero was found: the restored
/// calibrator solves as the one that never stopped, and the record does solve.
#[test]
fn a_turn_calibrator_cut_mid_turn_solves_as_if_never_stopped() {
    let samples = turn_record(11, 3.0, 1.5, 20.0, 0.005);
    let cal = || TurnCalibrator::new(TurnConfig::default()).unwrap();
    check_continues(cal, &samples, samples.len() / 2);
    let mut whole = cal();
    for s in &samples {
        whole.push(s).unwrap();
    }
    assert!(whole.solve().is_ok(), "{:?}", whole.solve());
}

/// A fresh turn calibrator saves its `-inf` "no reading kept yet" by name and reads it back.
#[test]
fn a_fresh_turn_calibrator_round_trips() {
    let c = TurnCalibrator::new(TurnConfig::default()).unwrap();
    let text = json(&c.snapshot());
    assert!(text.contains("\"-inf\""), "{text}");
    let back = TurnCalibrator::restore(serde_json::from_str(&text).unwrap()).unwrap();
    assert_eq!(json(&back.state()), json(&c.state()));
}

#[test]
fn damaged_states_are_refused() {
    let samples = turn_record(7, 3.0, 1.5, 20.0, 0.005);
    let mut turn = TurnCalibrator::new(TurnConfig::default()).unwrap();
    for s in &samples[..samples.len() / 2] {
        turn.push(s).unwrap();
    }
    let good = turn.snapshot();
    assert!(TurnCalibrator::restore(good.clone()).is_ok());
    let mut nan_rate = good.clone();
    nan_rate.state.last_rate_rps = f64::NAN;
    assert!(matches!(
        TurnCalibrator::restore(nan_rate),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut no_clock = good.clone();
    no_clock.state.first_t_s = None;
    assert!(matches!(
        TurnCalibrator::restore(no_clock),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut ring = good.clone();
    ring.state.ring_next += 1;
    assert!(matches!(
        TurnCalibrator::restore(ring),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut bad_config = good;
    bad_config.state.config.max_gap_s = -1.0;
    assert!(TurnCalibrator::restore(bad_config).is_err());

    let steps = speed_steps(3, 4, 90.0, 12.0, 0.3);
    let mut speed = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default()).unwrap();
    for s in &steps {
        speed.push(s).unwrap();
    }
    let good = speed.snapshot();
    assert!(SpeedCoefficientCalibrator::restore(good.clone()).is_ok());
    let mut inf_a = good.clone();
    inf_a.state.coefficient_s2_per_m2 = f64::INFINITY;
    assert!(matches!(
        SpeedCoefficientCalibrator::restore(inf_a),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut counts = good.clone();
    counts.state.updates = counts.state.steps + 1;
    assert!(matches!(
        SpeedCoefficientCalibrator::restore(counts),
        Err(Error::InvalidSnapshot { .. })
    ));
    let mut bad_config = good;
    bad_config.state.config.filter_constant = 0.0;
    assert!(SpeedCoefficientCalibrator::restore(bad_config).is_err());
}
