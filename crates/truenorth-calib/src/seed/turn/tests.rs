//! The one-turn compass calibration on noise-free turns: the figures it finds and the
//! records it refuses.

use core::f64::consts::TAU;

use nalgebra::{Matrix2, Vector2};
use truenorth_core::{Calibrator, Error, Mag2Sample};

use super::*;
use crate::seed::extrema::ExtremaConfig;
use truenorth_compass::{HeadingTruth, MagnetometerModel2d};
use truenorth_core::SensorModel;

/// Noise-free readings along a heading profile (degrees), 1 sample per 0.5°.
fn run(headings: impl Iterator<Item = f64>) -> TurnCompassCalibrator {
    let m = MagnetometerModel2d::new(
        Vector2::new(5.0, -2.0),
        Matrix2::new(1.2, 0.0, 0.0, 0.9),
        0.0,
    )
    .unwrap();
    let mut c = TurnCompassCalibrator::default();
    for (i, h) in headings.enumerate() {
        let truth = HeadingTruth {
            heading_rad: h.to_radians(),
            horizontal_field: 20.0,
        };
        c.push(&Mag2Sample {
            t_s: i as f64,
            mag: m.ideal(&truth).unwrap(),
        })
        .unwrap();
    }
    c
}

fn sweep(from: f64, span: f64) -> impl Iterator<Item = f64> {
    let n = (span.abs() * 2.0) as usize;
    (0..=n).map(move |i| from + span * i as f64 / n as f64)
}

#[test]
fn a_turn_and_a_half_gives_centre_radii_and_the_signed_angle() {
    let c = run(sweep(20.0, 540.0));
    let fit = c.extrema().solve().unwrap();
    assert!(
        (fit.turned_rad.to_degrees() - 540.0).abs() < 1.0,
        "{}",
        fit.turned_rad.to_degrees()
    );
    assert!((fit.centre - Vector2::new(5.0, -2.0)).norm() < 1e-3);
    assert!((fit.radii - Vector2::new(24.0, 18.0)).norm() < 1e-2);
    assert!(c.solve().is_ok());
    // The pairs the gyro half will use: half a turn apart, within one revolution; the
    // tags (here timestamps, 2 samples per degree) are 360 samples apart.
    for p in c.extrema().x_pairs().chain(c.extrema().y_pairs()) {
        assert!(((p.max.tag.tag - p.min.tag.tag).abs() - 360.0).abs() <= 2.0);
    }
    // A left turn is negative.
    let left = run(sweep(20.0, -540.0));
    assert!(left.extrema().solve().unwrap().turned_rad < -TAU);
}

#[test]
fn less_than_a_full_turn_is_refused() {
    // 340° from just before the X maximum: both axes pass a maximum and a minimum, and
    // the refusal gives the angle turned about the centre they place.
    let c = run(sweep(-10.0, 340.0));
    match c.solve() {
        Err(Error::IncompleteTurn { turned_deg, .. }) => {
            assert!((turned_deg - 340.0).abs() < 1.0, "{turned_deg}")
        }
        other => panic!("{other:?}"),
    }
    // 300° from 40° passes no X maximum, a third of a turn no extremum pair at all:
    // there is no centre to measure the angle about, and the refusal says so without a
    // figure.
    let c = run(sweep(40.0, 300.0));
    assert!(matches!(c.solve(), Err(Error::Degenerate { .. })));
    let c = run(sweep(40.0, 120.0));
    match c.solve() {
        Err(Error::Degenerate { reason }) => assert!(reason.contains("360°"), "{reason}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_extremum_at_the_edge_is_refused() {
    // Exactly one turn from north: the X maximum is at both ends of the record.
    let c = run(sweep(0.0, 360.0));
    assert!(
        matches!(c.solve(), Err(Error::Degenerate { .. })),
        "{:?}",
        c.solve()
    );
    // A quarter turn more fixes it.
    assert!(run(sweep(0.0, 450.0)).solve().is_ok());
}

#[test]
fn a_reversed_turn_is_refused() {
    let there = sweep(30.0, 300.0);
    let back = sweep(330.0, -300.0);
    let c = run(there.chain(back).chain(sweep(30.0, 300.0)));
    assert!(c.solve().is_err());
}

#[test]
fn too_few_samples_and_bad_input() {
    let mut c = run(sweep(0.0, 5.0));
    assert!(matches!(c.solve(), Err(Error::TooFewPoints { .. })));
    assert!(
        c.push(&Mag2Sample {
            t_s: 1e9,
            mag: Vector2::new(f64::NAN, 0.0)
        })
        .is_err()
    );
    assert!(
        TurnCompassCalibrator::new(TurnConfig {
            extrema: ExtremaConfig {
                swing_fraction: 1.5,
                noise_multiple: 8.0
            },
            ..Default::default()
        })
        .is_err()
    );
}
