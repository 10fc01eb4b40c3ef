//! What a refusal promises, measured on families of recordings the calibrators were never
//! tuned on (`cargo test --release -p truenorth-calib --test families -- --nocapture` prints
//! the counts):
//!
//! * **well determined** — full turns (2-D) and tumbles in every direction (3-D), any hard
//!   iron up to 0.6 of the field, soft iron up to 1.4 : 1 (2-D) or ±15 % (3-D), noise up to
//!   8 % of the field per axis, then extra readings appended (swaying ±35° about one heading,
//!   dwelling at one heading or attitude, a partial turn, a turn about one axis) and the whole
//!   shuffled: never refused;
//! * **degenerate** — half turns and less (2-D; in time order and shuffled), turns about one
//!   axis and half of them (3-D, with a hand's wobble up to 5°), one attitude: never
//!   accepted.
//!
//! Every batch and online least-squares calibrator is run on the well-determined family (the
//! seed methods read their readings in time order and are left to `more_data.rs`), every
//! calibrator on the degenerate one.

mod common;

use common::*;
use nalgebra::{Rotation3, Vector2};
use truenorth_calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, EllipsoidCalibrator, MagAccelCalibrator,
    MagAccelSample, MeritCircleCalibrator, OnlineEllipseCalibrator, OnlineEllipsoidCalibrator,
    TurnCompassCalibrator,
};
use truenorth_core::{Calibrator, Error, Mag2Sample, Mag3Sample, NoiseSource, SplitMix64};

/// Recordings per family and method: enough that a refusal rate of 1 % would show (the
/// chance of none in 150 at 1 % is 22 %; at 3 %, 1 %).
const CASES: u64 = 150;

/// Largest per-axis noise of the families, relative to the field.
const MAX_NOISE: f64 = 0.08;

/// Counts of one method on one family.
#[derive(Default)]
struct Tally {
    cases: usize,
    hits: usize,
    first: Vec<String>,
}

impl Tally {
    fn count(&mut self, hit: bool, what: impl FnOnce() -> String) {
        self.cases += 1;
        if hit {
            self.hits += 1;
            if self.first.len() < 3 {
                self.first.push(what());
            }
        }
    }
}

fn solve_2d<C>(mut c: C, samples: &[Mag2Sample]) -> Result<(), Error>
where
    C: Calibrator<Sample = Mag2Sample>,
{
    for s in samples {
        c.push(s)?;
    }
    c.solve().map(|_| ())
}

fn solve_3d<C>(mut c: C, samples: &[Mag3Sample]) -> Result<(), Error>
where
    C: Calibrator<Sample = Mag3Sample>,
{
    for s in samples {
        c.push(s)?;
    }
    c.solve().map(|_| ())
}

/// A well-determined 2-D recording: one to three full turns, then extras, shuffled.
fn determined_2d(seed: u64) -> (String, Vec<Mag2Sample>) {
    let mut rng = SplitMix64::new(seed);
    let m = Model2::random(&mut rng, 0.6);
    let noise = MAX_NOISE * rng.uniform();
    let n = 60 + (540.0 * rng.uniform()) as usize;
    let turns = 1 + (3.0 * rng.uniform()) as usize;
    let start = 360.0 * rng.uniform();
    let mut pts: Vec<Vector2<f64>> = (0..n * turns)
        .map(|k| {
            let psi = (start + 360.0 * k as f64 / n as f64).to_radians();
            m.raw(psi, &mut rng, noise)
        })
        .collect();
    let extra = (3.0 * n as f64 * rng.uniform()) as usize;
    let at = 360.0 * rng.uniform();
    let kind = seed % 4;
    for k in 0..extra {
        let psi_deg = match kind {
            0 => at + 35.0 * (k as f64 * 0.13).sin(),
            1 => at,
            2 => at + 120.0 * k as f64 / extra as f64,
            _ => break,
        };
        pts.push(m.raw(psi_deg.to_radians(), &mut rng, noise));
    }
    shuffle(&mut pts, &mut rng);
    let what = format!(
        "seed {seed}: {turns} turn(s) of {n}, noise {:.1} %, extra {extra} of kind {kind}",
        100.0 * noise
    );
    (what, stamped_2d(&pts))
}

/// A well-determined 3-D recording: a tumble in every direction, then extras, shuffled;
/// with the accelerometer at rest beside the magnetometer.
fn determined_3d(seed: u64) -> (String, Vec<MagAccelSample>) {
    let mut rng = SplitMix64::new(seed);
    let noise = MAX_NOISE * rng.uniform();
    let m = Model3::random(&mut rng, 50.0, 0.6, 0.15, noise);
    let n = 300 + (2700.0 * rng.uniform()) as usize;
    let mut att = tumble_attitudes(&mut rng, n);
    let extra = (2.0 * n as f64 * rng.uniform()) as usize;
    let kind = seed % 3;
    match kind {
        0 => att.extend(std::iter::repeat_n(uniform_rotation(&mut rng), extra)),
        1 => att.extend(axis_turn_attitudes(&mut rng, extra, 360.0, 2.0)),
        _ => {}
    }
    shuffle(&mut att, &mut rng);
    let samples = joint(&m, &att, &mut rng);
    let what = format!(
        "seed {seed}: tumble of {n}, noise {:.1} %, extra {extra} of kind {kind}",
        100.0 * noise
    );
    (what, samples)
}

fn joint(m: &Model3, att: &[Rotation3<f64>], rng: &mut SplitMix64) -> Vec<MagAccelSample> {
    att.iter()
        .enumerate()
        .map(|(k, r)| MagAccelSample {
            t_s: 0.01 * k as f64,
            mag: m.raw(r, rng),
            acc: m.acc(r, rng, 0.02),
        })
        .collect()
}

fn mags(s: &[MagAccelSample]) -> Vec<Mag3Sample> {
    s.iter()
        .map(|s| Mag3Sample {
            t_s: s.t_s,
            mag: s.mag,
        })
        .collect()
}

fn report(family: &str, name: &str, verb: &str, t: &Tally) {
    println!(
        "{family}: {name}: {verb} {} of {}{}",
        t.hits,
        t.cases,
        if t.first.is_empty() {
            String::new()
        } else {
            format!(" — {}", t.first.join("; "))
        }
    );
}

/// The least-squares 2-D calibrators (batch and online) on `s`, in the order of [`LSQ_2D`].
fn lsq_2d(s: &[Mag2Sample]) -> [Result<(), Error>; 2] {
    [
        solve_2d(EllipseCalibrator::default(), s),
        solve_2d(OnlineEllipseCalibrator::new(Default::default()).unwrap(), s),
    ]
}

/// Names of [`lsq_2d`]'s calibrators.
const LSQ_2D: [&str; 2] = ["ellipse", "online-ellipse"];

/// Every 3-D calibrator on `s` (the magnetometer alone, then with the accelerometer), in
/// the order of [`ALL_3D`].
fn all_3d(s: &[MagAccelSample]) -> [Result<(), Error>; 3] {
    let m = mags(s);
    let mut joint = MagAccelCalibrator::default();
    [
        solve_3d(EllipsoidCalibrator::default(), &m),
        solve_3d(
            OnlineEllipsoidCalibrator::new(Default::default()).unwrap(),
            &m,
        ),
        s.iter()
            .try_for_each(|x| joint.push(x).map(|_| ()))
            .and_then(|()| joint.solve().map(|_| ())),
    ]
}

/// Names of [`all_3d`]'s calibrators.
const ALL_3D: [&str; 3] = ["ellipsoid", "online-ellipsoid", "ellipsoid-accel"];

#[test]
fn well_determined_recordings_are_never_refused() {
    let mut t2 = [Tally::default(), Tally::default()];
    for seed in 0..CASES {
        let (what, s) = determined_2d(seed);
        for (t, r) in t2.iter_mut().zip(lsq_2d(&s)) {
            t.count(r.is_err(), || format!("{what}: {}", r.unwrap_err()));
        }
    }
    let mut t3 = [Tally::default(), Tally::default(), Tally::default()];
    for seed in 0..CASES {
        let (what, s) = determined_3d(1000 + seed);
        for (t, r) in t3.iter_mut().zip(all_3d(&s)) {
            t.count(r.is_err(), || format!("{what}: {}", r.unwrap_err()));
        }
    }
    for (n, t) in LSQ_2D.iter().zip(&t2) {
        report("well determined 2-D", n, "refused", t);
    }
    for (n, t) in ALL_3D.iter().zip(&t3) {
        report("well determined 3-D", n, "refused", t);
    }
    let refused: usize = t2.iter().chain(&t3).map(|t| t.hits).sum();
    assert_eq!(refused, 0, "well-determined recordings refused");
}

/// A degenerate 2-D recording: an arc of at most half a turn, or one heading.
fn degenerate_2d(seed: u64) -> (String, Vec<Mag2Sample>) {
    let mut rng = SplitMix64::new(seed);
    let m = Model2::random(&mut rng, 0.6);
    let noise = MAX_NOISE * rng.uniform();
    let n = 10 + (790.0 * rng.uniform()) as usize;
    let span = if seed.is_multiple_of(5) {
        0.0
    } else {
        1.0 + 179.0 * rng.uniform()
    };
    let start = 360.0 * rng.uniform();
    let mut pts: Vec<Vector2<f64>> = (0..=n)
        .map(|k| {
            let psi = (start + span * k as f64 / n as f64).to_radians();
            m.raw(psi, &mut rng, noise)
        })
        .collect();
    let shuffled = seed % 2 == 1;
    if shuffled {
        shuffle(&mut pts, &mut rng);
    }
    let what = format!(
        "seed {seed}: arc {span:.0}° of {n}, noise {:.1} %{}",
        100.0 * noise,
        if shuffled { ", shuffled" } else { "" }
    );
    (what, stamped_2d(&pts))
}

/// A degenerate 3-D recording: a turn about one axis (full or half, hand-held wobble up to
/// 5°), or one attitude.
fn degenerate_3d(seed: u64) -> (String, Vec<MagAccelSample>) {
    let mut rng = SplitMix64::new(seed);
    let noise = MAX_NOISE * rng.uniform();
    let m = Model3::random(&mut rng, 50.0, 0.6, 0.15, noise);
    let n = 50 + (2950.0 * rng.uniform()) as usize;
    let wobble = 5.0 * rng.uniform();
    let (kind, att) = match seed % 3 {
        0 => (
            "one-axis turn",
            axis_turn_attitudes(&mut rng, n, 360.0, wobble),
        ),
        1 => (
            "half one-axis turn",
            axis_turn_attitudes(&mut rng, n, 180.0, wobble),
        ),
        _ => ("one attitude", vec![uniform_rotation(&mut rng); n]),
    };
    let samples = joint(&m, &att, &mut rng);
    let what = format!(
        "seed {seed}: {kind} of {n}, wobble {wobble:.1}°, noise {:.1} %",
        100.0 * noise
    );
    (what, samples)
}

#[test]
fn degenerate_recordings_are_never_accepted() {
    let names2: Vec<&str> = LSQ_2D
        .iter()
        .copied()
        .chain(["binned-ellipse", "merit-circle", "turn"])
        .collect();
    let mut t2: Vec<Tally> = names2.iter().map(|_| Tally::default()).collect();
    for seed in 0..CASES {
        let (what, s) = degenerate_2d(seed);
        let r = lsq_2d(&s).into_iter().chain([
            solve_2d(BinnedEllipseCalibrator::default(), &s),
            solve_2d(MeritCircleCalibrator::default(), &s),
            solve_2d(TurnCompassCalibrator::default(), &s),
        ]);
        for (t, r) in t2.iter_mut().zip(r) {
            t.count(r.is_ok(), || what.clone());
        }
    }
    let mut t3 = [Tally::default(), Tally::default(), Tally::default()];
    for seed in 0..CASES {
        let (what, s) = degenerate_3d(2000 + seed);
        for (t, r) in t3.iter_mut().zip(all_3d(&s)) {
            t.count(r.is_ok(), || what.clone());
        }
    }
    for (n, t) in names2.iter().zip(&t2) {
        report("degenerate 2-D", n, "accepted", t);
    }
    for (n, t) in ALL_3D.iter().zip(&t3) {
        report("degenerate 3-D", n, "accepted", t);
    }
    let accepted: usize = t2.iter().chain(&t3).map(|t| t.hits).sum();
    assert_eq!(accepted, 0, "degenerate recordings accepted");
}
