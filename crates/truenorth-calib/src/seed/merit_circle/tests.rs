//! Tests of [`super`]: the merit circle calibrator.

use nalgebra::Vector2;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Calibrator, Error, Mag2Sample, OnlineCalibrator, Pushed, Result, Solution};

use crate::seed::seed_quality::SeedJob;

use super::calibrator::*;
use super::config::*;
use truenorth_core::{NoiseSource, SplitMix64};

fn feed(c: &mut MeritCircleCalibrator, pts: impl Iterator<Item = Vector2<f64>>) {
    for (i, p) in pts.enumerate() {
        c.push(&Mag2Sample {
            t_s: i as f64,
            mag: p,
        })
        .unwrap();
    }
}

fn circle(c: Vector2<f64>, r: f64, from: f64, deg: f64) -> impl Iterator<Item = Vector2<f64>> {
    (0..(deg * 2.0) as usize).map(move |i| {
        let a = (from + i as f64 * 0.5).to_radians();
        c + Vector2::new(a.cos(), a.sin()) * r
    })
}

#[test]
fn on_a_circle_every_centre_is_exact_and_the_merit_falls_as_weight_builds() {
    let ctr = Vector2::new(7.0, -3.0);
    let mut c = MeritCircleCalibrator::default();
    feed(&mut c, circle(ctr, 20.0, 0.0, 120.0));
    let first = *c.state();
    assert!(first.centres >= 1);
    assert!((first.centre.unwrap() - ctr).norm() < 1e-9);
    feed(&mut c, circle(ctr, 20.0, 120.0, 600.0));
    let s = c.state();
    assert!(s.centres > first.centres);
    assert!(s.last_merit < 0.3, "{}", s.last_merit);
    assert!(s.centre_mse < 1e-18);
    assert!((c.solve().unwrap().params.hard_iron - ctr).norm() < 1e-9);
}

#[test]
fn noise_on_a_stationary_compass_makes_no_data_points() {
    let mut rng = SplitMix64::new(4);
    let mut c = MeritCircleCalibrator::default();
    feed(
        &mut c,
        (0..2000).map(|_| Vector2::new(20.0 + rng.normal(0.2), rng.normal(0.2))),
    );
    assert!(c.state().data_points <= 1, "{:?}", c.state());
    assert!(matches!(c.solve(), Err(Error::TooFewPoints { .. })));
}

#[test]
fn an_outlying_centre_gets_a_small_merit() {
    let ctr = Vector2::new(0.0, 0.0);
    let mut c = MeritCircleCalibrator::default();
    feed(&mut c, circle(ctr, 20.0, 0.0, 720.0));
    let mut rng = SplitMix64::new(8);
    // Add scatter so the MSE is not zero, then one reading far off the circle.
    feed(
        &mut c,
        circle(ctr, 20.0, 0.0, 360.0).map(|p| p + Vector2::new(rng.normal(0.2), rng.normal(0.2))),
    );
    let before = c.state().centre.unwrap();
    let mut out = c.clone();
    feed(&mut out, core::iter::once(Vector2::new(60.0, 60.0)));
    let after = out.state().centre.unwrap();
    assert!(
        (after - before).norm() < 0.5,
        "moved {}",
        (after - before).norm()
    );
}

/// A snapshot taken at any push (refresh due, every step of its quality report, idle)
/// restores to a calibrator that saves the same state and continues bit-identically.
#[test]
fn snapshot_at_every_push_continues_identically() {
    use truenorth_core::Persistent;
    let stream: Vec<_> = circle(Vector2::new(3.0, -2.0), 20.0, 0.0, 400.0)
        .enumerate()
        .map(|(i, p)| {
            let wobble = 0.01 * ((i * 7919) % 13) as f64;
            Mag2Sample {
                t_s: i as f64,
                mag: p + Vector2::new(wobble, -wobble),
            }
        })
        .collect();
    let mut straight = MeritCircleCalibrator::default();
    let mut steps = std::collections::BTreeSet::new();
    for (k, s) in stream.iter().enumerate() {
        steps.insert(straight.seed.as_ref().map(|j| j.steps()));
        let snap = straight.snapshot();
        let mut resumed = MeritCircleCalibrator::restore(snap.clone()).unwrap();
        assert_eq!(resumed.snapshot(), snap, "push {k}");
        let mut copy = straight.clone();
        for t in &stream[k..(k + 6).min(stream.len())] {
            assert_eq!(copy.push(t).unwrap(), resumed.push(t).unwrap(), "push {k}");
            assert_eq!(copy.estimate(), resumed.estimate(), "push {k}");
        }
        assert_eq!(copy.snapshot(), resumed.snapshot(), "push {k}");
        straight.push(s).unwrap();
    }
    // Snapshots were taken with no refresh running and at every step of one.
    let all: std::collections::BTreeSet<_> = core::iter::once(None)
        .chain((0..SeedJob::STEPS).map(Some))
        .collect();
    assert_eq!(steps, all);
    assert!(straight.estimate().is_some());
}

/// The estimate a staged refresh publishes is exactly `solve` of the state it started
/// from.
#[test]
fn staged_refresh_publishes_the_solve_of_its_start() {
    let mut c = MeritCircleCalibrator::default();
    let mut published = 0;
    let mut started: Option<Result<Solution<CompassCalibration2d>>> = None;
    for p in circle(Vector2::new(-4.0, 1.0), 15.0, 30.0, 500.0) {
        let due = c.refresh_due && c.seed.is_none();
        let before = c.solve();
        let pushed = c.push(&Mag2Sample { t_s: 0.0, mag: p }).unwrap();
        if due {
            started = Some(before);
            if c.seed.is_none() {
                assert!(started.as_ref().unwrap().is_err());
                assert_eq!(c.estimate(), None);
            }
        }
        if pushed == Pushed::NewEstimate && c.seed.is_none() && !due {
            assert_eq!(Some(c.estimate().unwrap()), started.clone().unwrap().ok());
            published += 1;
        }
    }
    assert!(published > 3, "{published}");
}

#[test]
fn config_is_validated() {
    for cfg in [
        MeritCircleConfig {
            min_turn_rad: -1.0,
            ..Default::default()
        },
        MeritCircleConfig {
            weight_memory: 0.0,
            ..Default::default()
        },
        MeritCircleConfig {
            max_amplification: 0.5,
            ..Default::default()
        },
    ] {
        assert!(MeritCircleCalibrator::new(cfg).is_err());
    }
}
