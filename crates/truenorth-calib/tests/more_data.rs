//! More readings consistent with the same calibration never turn an acceptance into a
//! refusal: for random recordings that a calibrator accepts, random supersets — readings
//! swaying about one heading, dwelling at one heading or attitude, another arc or a turn
//! about one axis, all from the same sensor — are accepted too, shuffled (every calibrator
//! that does not read its readings in time order: the batch and online least-squares
//! fits, 2-D and 3-D) or appended in time order (the seed methods, which follow a turn).
//!
//! Every one of these calibrators refuses on coverage (an arc, the orientations seen); a
//! measure of coverage that more readings in the same orientations could lower — the net
//! turning of the raw locus in time order, or a condition number or dilution that weighs
//! each reading alike, so that a long dwell drowns the turn — fails here.

mod common;

use common::*;
use nalgebra::{Rotation3, Vector2, Vector3};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use truenorth_calib::quality::{self, MIN_ARC_DEG};
use truenorth_calib::{
    BinnedEllipseCalibrator, EllipsoidCalibrator, MERIT_CIRCLE_MIN_ARC_DEG, MagAccelCalibrator,
    MagAccelSample, OnlineEllipsoidCalibrator,
};
use truenorth_core::{Calibrator, CompassQuality, Error, Mag2Sample, Mag3Sample, SplitMix64};

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        // Fixed, so that a run is reproducible; the property is over every draw.
        rng_seed: RngSeed::Fixed(17),
        ..ProptestConfig::default()
    }
}

fn solved<C: Calibrator>(
    c: &mut C,
    samples: &[C::Sample],
) -> Result<truenorth_core::Solution<C::Params, C::Quality>, Error> {
    for s in samples {
        c.push(s)?;
    }
    c.solve()
}

/// A recording of a 2-D compass: a turn of `span_deg` from `start_deg` with `n` readings,
/// then `extra` readings of kind `kind` where the turn ended (0: swaying ±35° about that
/// heading, 1: dwelling there, 2: an arc of 120° back from there, 3: the turn going on by
/// `extra` more steps), one per 0.05 s.
#[allow(clippy::too_many_arguments)]
fn recording_2d(
    m: &Model2,
    noise: f64,
    start_deg: f64,
    span_deg: f64,
    n: usize,
    kind: usize,
    extra: usize,
    seed: u64,
) -> (Vec<Vector2<f64>>, Vec<Vector2<f64>>) {
    let mut rng = SplitMix64::new(seed);
    let step = span_deg / n as f64;
    let at_deg = start_deg + step * n as f64;
    let base: Vec<_> = (0..n)
        .map(|k| m.raw((start_deg + step * k as f64).to_radians(), &mut rng, noise))
        .collect();
    let more: Vec<_> = (0..extra)
        .map(|k| {
            let psi = match kind {
                0 => at_deg + 35.0 * (0.13 * k as f64).sin(),
                1 => at_deg,
                2 => at_deg - 120.0 * k as f64 / extra as f64,
                _ => start_deg + step * (n + k) as f64,
            };
            m.raw(psi.to_radians(), &mut rng, noise)
        })
        .collect();
    (base, more)
}

/// Whether the binned ellipse accepts `s` with its bound (3σ plus systematic) within half
/// its limit.
fn binned_accepts_with_margin(s: &[Mag2Sample]) -> bool {
    let mut c = BinnedEllipseCalibrator::default();
    let limit = c.config().max_heading_error_bound_deg;
    s.iter().all(|x| c.push(x).is_ok())
        && c.solve()
            .is_ok_and(|sol| sol.quality.heading_error_bound_deg() <= 0.5 * limit)
}

proptest! {
    #![proptest_config(config(256))]

    /// 2-D, every calibrator: a recording it accepts, with more readings after it, is
    /// accepted; for those that do not read the order, shuffled too.
    #[test]
    fn more_2d_readings_never_turn_an_acceptance_into_a_refusal(
        span in 150.0f64..720.0, start in 0.0f64..360.0, noise in prop_oneof![Just(0.0), 0.0f64..0.08],
        n in 20usize..400, hx in -0.6f64..0.6, hy in -0.6f64..0.6, ratio in 1.0f64..1.4,
        angle in -1.6f64..1.6, kind in 0usize..4, extra_share in 0.0f64..3.0,
        seed in 0u64..10_000,
    ) {
        let m = Model2::new(Vector2::new(hx, hy), ratio, angle, 1.0);
        let extra = (extra_share * n as f64) as usize;
        let (base, more) = recording_2d(&m, noise, start, span, n, kind, extra, seed);
        let mut all = base.clone();
        all.extend(&more);
        let mut shuffled = all.clone();
        shuffle(&mut shuffled, &mut SplitMix64::new(seed ^ 0x5eed));
        for (which, name) in NAMES_2D.iter().enumerate() {
            // A decision near its limit is taken on figures that noise moves: the arc's ends
            // are its outermost readings, which the calibrators allow 3σ of noise each, and
            // the online one keeps one reading per 5° slot, which a later reading (or, shuffled,
            // any reading of the slot) replaces, so its arc's ends may each sit a slot inside
            // the turn's. The property is over accepted turns that clear their shortest
            // accepted arc by more than that (6σ and two slots); nearer the limit more
            // readings can move a decision either way, as fewer can.
            // The merit circle fits a circle (US 5,297,063): it measures its arc about the
            // centre of circles through readings of an ellipse, which moves as the spread of
            // the readings changes — by tens of degrees of arc at a soft iron of 1.3 : 1
            // (found here). The property is held where its model holds, within 1.1 : 1.
            if which == 3 && ratio > 1.1 {
                continue;
            }
            let min_arc = if which == 3 { MERIT_CIRCLE_MIN_ARC_DEG } else { MIN_ARC_DEG };
            if span < min_arc + (6.0 * noise).to_degrees() + 10.0 {
                continue;
            }
            // The turn method reads one steady turn (EP 0640207): what follows it may only
            // go on turning the same way or stand still; a turn that reverses is refused,
            // truly, as one that changed direction.
            if which == 4 && (kind == 0 || kind == 2) {
                continue;
            }
            // The binned ellipse measures its arc about an origin that the interpolation of
            // its empty bins biases, and which moves by a little as later readings replace
            // earlier ones in the bins: near its minimum arc the measure wobbles by a few
            // degrees either way. Its configuration says it needs about 250° in practice;
            // from there on, more readings never refuse (this property found the wobble).
            if which == 2 && span < 250.0 {
                continue;
            }
            // It also keeps one reading per bin (EP 0634001 claim 2), so its bound does not
            // shrink as readings come: a reading replacing another in a bin moves it either
            // way. Its acceptances with the bound within half the limit are held.
            if which == 2 && !binned_accepts_with_margin(&stamped_2d(&base)) {
                continue;
            }
            if solve_2d(which, &stamped_2d(&base)).is_err() {
                continue;
            }
            let r = solve_2d(which, &stamped_2d(&all));
            prop_assert!(r.is_ok(), "{name}: accepted a turn of {span:.0}° ({n} readings, noise {:.1} %), refused it with {extra} readings of kind {kind} after it: {}", 100.0 * noise, r.unwrap_err());
            if which < 2 {
                let r = solve_2d(which, &stamped_2d(&shuffled));
                prop_assert!(r.is_ok(), "{name}: refused the same readings shuffled: {}", r.unwrap_err());
            }
        }
    }
}

/// A recording of a three-axis magnetometer (and accelerometer at rest): `n` attitudes of
/// kind `base_kind` (0: a tumble; 1: a cap of field directions within `cap_deg` of one; 2:
/// turns about two axes), then `extra` of kind `kind` (0: one attitude, 1: a turn about one
/// axis, 2: more of the tumble).
fn recording_3d(
    m: &Model3,
    base_kind: usize,
    cap_deg: f64,
    n: usize,
    kind: usize,
    extra: usize,
    seed: u64,
) -> (Vec<MagAccelSample>, Vec<MagAccelSample>) {
    let mut rng = SplitMix64::new(seed);
    let base: Vec<Rotation3<f64>> = match base_kind {
        0 => tumble_attitudes(&mut rng, n),
        1 => {
            let centre = uniform_rotation(&mut rng);
            (0..n)
                .map(|_| {
                    loop {
                        let r = uniform_rotation(&mut rng);
                        if (r.inverse() * centre).angle() <= cap_deg.to_radians() {
                            break r;
                        }
                    }
                })
                .collect()
        }
        _ => {
            let mut a = axis_turn_attitudes(&mut rng, n / 2, 360.0, 1.0);
            a.extend(axis_turn_attitudes(&mut rng, n - n / 2, 360.0, 1.0));
            a
        }
    };
    let more: Vec<Rotation3<f64>> = match kind {
        0 => vec![uniform_rotation(&mut rng); extra],
        1 => axis_turn_attitudes(&mut rng, extra, 360.0, 2.0),
        _ => tumble_attitudes(&mut rng, extra),
    };
    let sample = |r: &Rotation3<f64>, rng: &mut SplitMix64| MagAccelSample {
        t_s: 0.0,
        mag: m.raw(r, rng),
        acc: m.acc(r, rng, 0.02),
    };
    (
        base.iter().map(|r| sample(r, &mut rng)).collect(),
        more.iter().map(|r| sample(r, &mut rng)).collect(),
    )
}

/// A 3-D calibrator's report of `s`, and the dilution of the readings' orientations seen
/// through its calibration.
fn solve_3d(which: usize, s: &[MagAccelSample]) -> Result<(CompassQuality, f64), Error> {
    let stamped: Vec<MagAccelSample> = s
        .iter()
        .enumerate()
        .map(|(k, x)| MagAccelSample {
            t_s: 0.01 * k as f64,
            ..*x
        })
        .collect();
    let mags: Vec<Mag3Sample> = stamped
        .iter()
        .map(|x| Mag3Sample {
            t_s: x.t_s,
            mag: x.mag,
        })
        .collect();
    let (cal, q) = match which {
        0 => solved(&mut EllipsoidCalibrator::default(), &mags).map(|s| (s.params, s.quality)),
        1 => solved(
            &mut OnlineEllipsoidCalibrator::new(Default::default()).unwrap(),
            &mags,
        )
        .map(|s| (s.params, s.quality)),
        _ => solved(&mut MagAccelCalibrator::default(), &stamped)
            .map(|s| (s.params.mag, s.quality.mag)),
    }?;
    let raw: Vec<Vector3<f64>> = mags.iter().map(|m| m.mag).collect();
    let g = quality::assess_3d(&raw, &cal, q.field_magnitude)
        .uncertainty
        .dilution;
    Ok((q, g))
}

/// Whether a 3-D report clears each limit it was judged by with a fifth to spare: the
/// geometry (the dilution times the model error against the largest bound), the noise
/// times the dilution, and the bound. More readings can raise the dilution by at most
/// `√((K + 1)/K)` per new direction cell, and the noise is estimated afresh from them;
/// nearer its limits a decision goes either way by chance, as with fewer readings.
fn clears_its_limits((q, g): (CompassQuality, f64)) -> bool {
    let limit = 0.8;
    (g * quality::MODEL_ERROR_REL).to_degrees() <= limit * 10.0
        && q.heading_noise_rms_deg.to_radians() * g <= limit * quality::MAX_NOISE_DILUTION
        && q.heading_error_bound_deg() <= limit * 10.0
}

const NAMES_3D: [&str; 3] = ["ellipsoid", "online-ellipsoid", "ellipsoid-accel"];

proptest! {
    #![proptest_config(config(128))]

    /// 3-D, every calibrator: a recording it accepts, with more readings from the same
    /// sensor, shuffled, is accepted.
    #[test]
    fn more_3d_readings_never_turn_an_acceptance_into_a_refusal(
        base_kind in 0usize..3, cap in 60.0f64..180.0, n in 30usize..1500,
        noise in prop_oneof![Just(0.0), 0.0f64..0.08], kind in 0usize..3,
        extra_share in 0.0f64..3.0, seed in 0u64..10_000,
    ) {
        let mut rng = SplitMix64::new(seed);
        let m = Model3::random(&mut rng, 50.0, 0.6, 0.15, noise);
        let extra = (extra_share * n as f64) as usize;
        let (base, more) = recording_3d(&m, base_kind, cap, n, kind, extra, seed);
        let mut all = base.clone();
        all.extend(&more);
        shuffle(&mut all, &mut rng);
        for (which, name) in NAMES_3D.iter().enumerate() {
            if !solve_3d(which, &base).is_ok_and(clears_its_limits) {
                continue;
            }
            let r = solve_3d(which, &all);
            prop_assert!(r.is_ok(), "{name}: accepted {n} readings of kind {base_kind} (noise {:.1} %), refused them with {extra} of kind {kind}, shuffled: {}", 100.0 * noise, r.unwrap_err());
        }
    }
}

/// The recording of the issue that led here, as a check that fails without the fix: two
/// full turns, then 100 s of swaying ±35° about one heading. The batch ellipse once read
/// the raw locus's turning in time order and refused it as covering 161° of heading.
#[test]
fn two_turns_then_swaying_calibrate() {
    let m = Model2::new(Vector2::new(0.3, -0.2), 1.25, 0.5, 1.0);
    let mut rng = SplitMix64::new(3);
    let rate_hz = 20.0;
    let turn_s = 24.0;
    let pts: Vec<Vector2<f64>> = (0..((turn_s + 100.0) * rate_hz) as usize)
        .map(|k| {
            let t = k as f64 / rate_hz;
            let psi_deg = if t < turn_s {
                30.0 * t
            } else {
                720.0 + 35.0 * (std::f64::consts::TAU * (t - turn_s) / 7.0).sin()
            };
            m.raw(psi_deg.to_radians(), &mut rng, 0.01)
        })
        .collect();
    // What the old measure read: the locus's tangent turning along the readings in time
    // order, on chords of a quarter of the field (the swaying goes back and forth, and each
    // reversal adds half a turn of either sign).
    let old = truenorth_calib::quality::locus_turning_rad(&pts, 0.25).to_degrees();
    println!("the raw locus turns {old:.0}° in time order");
    assert!(old < 200.0, "{old}");
    for (which, name) in NAMES_2D.iter().enumerate().take(3) {
        let first_minute = solve_2d(which, &stamped_2d(&pts[..(60.0 * rate_hz) as usize]));
        assert!(first_minute.is_ok(), "{name}: {first_minute:?}");
        let all = solve_2d(which, &stamped_2d(&pts));
        assert!(all.is_ok(), "{name}: {all:?}");
    }
}
