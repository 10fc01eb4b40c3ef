//! The same turns sampled more densely never turn an acceptance into a refusal: a
//! recording of a compass turning, accepted by a 2-D calibrator, is accepted too when the
//! same turns are sampled `k` times as densely (the same path, fresh noise on every
//! reading), for every 2-D calibrator.
//!
//! Why it holds at any density, per calibrator:
//! - `ellipse`, `online-ellipse` (least squares): the normal equations are means over the
//!   readings, which converge as the readings multiply; the refusal statistics (axis ratio,
//!   residual RMS relative to the field, heading-error bound) are ratios of those means or
//!   shrink with the count.
//! - `binned-ellipse`: a bin keeps the newest reading in its direction about the origin, so
//!   density changes which reading that is, not what it is; the one way density entered was
//!   the readings close to the initial origin (which lies on the locus), whose directions are
//!   their noise's: a dense start filled every bin with them. Readings within five noise σ of
//!   the origin are not binned, at any density. And each full-set update merges a few
//!   readings (re-binning about the moved origin), so the updates must come per angle turned:
//!   a bin's readings count towards the next update only up to a cap per update, which a
//!   dense recording's readings dithering across a bin's edge reach as a sparse one's do.
//! - `merit-circle`, `turn`: they follow the locus reading by reading and judge the arc it
//!   turned through and the scatter about their circle, neither of which grows with the
//!   number of readings along the same path.
//!
//! Run here up to 200 readings per degree (72 000 per turn): the binned ellipse refused the
//! io_speed recording from about 800 per degree.

mod common;

use common::*;
use nalgebra::Vector2;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use truenorth_core::{Mag2Sample, NoiseSource, SplitMix64};

/// `turns` turns of `m` from `start_deg` at `per_deg` readings per degree, 0.01 s apart,
/// with per-axis noise `sigma`.
fn recording(
    m: &Model2,
    turns: f64,
    start_deg: f64,
    per_deg: f64,
    sigma: f64,
    seed: u64,
) -> Vec<Mag2Sample> {
    let n = (360.0 * turns * per_deg) as usize;
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|k| {
            let psi = (start_deg + k as f64 / per_deg).to_radians();
            Mag2Sample {
                t_s: 0.01 * k as f64,
                mag: m.raw(psi, &mut rng, sigma),
            }
        })
        .collect()
}

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(23),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config(12))]

    #[test]
    fn denser_sampling_of_the_same_turns_never_turns_an_acceptance_into_a_refusal(
        seed in any::<u64>(),
        turns in 1.0f64..2.0,
        start_deg in 0.0f64..360.0,
        sigma in 0.005f64..0.03,
        denser in 10.0f64..100.0,
    ) {
        let m = Model2::random(&mut SplitMix64::new(seed), 2.0);
        let sparse = recording(&m, turns, start_deg, 2.0, sigma, seed ^ 1);
        let dense = recording(&m, turns, start_deg, 2.0 * denser, sigma, seed ^ 2);
        for (which, name) in NAMES_2D.iter().enumerate() {
            if solve_2d(which, &sparse).is_ok() {
                let dense_verdict = solve_2d(which, &dense);
                prop_assert!(dense_verdict.is_ok(), "{name}: accepted at 2/°, refused at {:.0}/°: {:?}", 2.0 * denser, dense_verdict);
            }
        }
    }
}

/// `turns` turns of the recording of `scripts/io_speed.sh` (a tilted ellipse with uniform
/// noise of ±0.5 on a field of about 30) at `per_deg` readings per degree.
fn io_speed_ellipse(turns: f64, per_deg: f64) -> Vec<Mag2Sample> {
    let mut rng = SplitMix64::new(1);
    let n = (360.0 * turns * per_deg) as usize;
    (0..n)
        .map(|k| {
            let a = (k as f64 / per_deg).to_radians();
            let mut u = || rng.uniform() - 0.5;
            let mag = Vector2::new(
                20.0 + 31.0 * a.cos() + 2.0 * a.sin() + u(),
                -10.0 + 4.0 * a.cos() + 27.0 * a.sin() + u(),
            );
            Mag2Sample {
                t_s: 0.01 * k as f64,
                mag,
            }
        })
        .collect()
}

/// The `io_speed` ellipse at 20 and at 2 000 readings per degree: every 2-D calibrator that
/// accepts the first accepts the second.
#[test]
fn the_io_speed_ellipse_is_accepted_at_any_density() {
    let ellipse = io_speed_ellipse;
    // One turn, one and a half and two (the script writes ten).
    for turns in [1.0, 1.5, 2.0] {
        let (sparse, dense) = (ellipse(turns, 20.0), ellipse(turns, 2000.0));
        for (which, name) in NAMES_2D.iter().enumerate() {
            let s = solve_2d(which, &sparse);
            let d = solve_2d(which, &dense);
            println!("{turns} turns, {name}: sparse {:?}, dense {d:?}", s.is_ok());
            if s.is_ok() {
                assert!(d.is_ok(), "{turns} turns, {name}: {d:?}");
            }
        }
    }
}

/// One turn of the `io_speed` ellipse, swept from 2 to 2 000 readings per degree: once the
/// binned ellipse accepts it, it accepts every denser sampling of it. (Counting a bin's
/// readings towards the next update per run of readings in a row, it accepted up to 200
/// per degree and refused from 500, for 185° of measured turning: the readings dithering
/// across each bin's edge ran 318 updates in the turn instead of 4–8, and each re-binning
/// merged readings until 27 of 64 bins were left.)
#[test]
fn one_turn_of_the_binned_ellipse_is_accepted_at_every_denser_sampling() {
    let binned = NAMES_2D
        .iter()
        .position(|&n| n == "binned-ellipse")
        .unwrap_or(2);
    let mut accepted_at = None;
    for per_deg in [
        2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0,
    ] {
        let verdict = solve_2d(binned, &io_speed_ellipse(1.0, per_deg));
        match (accepted_at, &verdict) {
            (None, Ok(())) => accepted_at = Some(per_deg),
            (Some(first), Err(e)) => {
                panic!("accepted at {first}/°, refused at {per_deg}/°: {e}")
            }
            _ => {}
        }
    }
    assert_eq!(
        accepted_at,
        Some(2.0),
        "one full turn is accepted when sparse"
    );
}
