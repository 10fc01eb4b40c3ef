//! The joint fit's normal equations weighted after the groups' sums are those of the
//! weighted rows, whether from a pass over the readings or from the one remembered.

use nalgebra::{Rotation3, SVector, Vector3};
use proptest::prelude::*;

use crate::fits::mag_accel::MagAccelSample;
use crate::fits::mag_accel::data::{Data, Weights, add_row};
use crate::fits::mag_accel::model::{BA, BM, LIMITS, Model, P, S};
use crate::fits::mag_accel::readings::{Sensor, SensorReadings};
use crate::fits::mag_accel::solve::{normal_equations, reading_rows};
use crate::fits::normalise::Normaliser;

/// Readings of two sensors turned through many attitudes (not a consistent instrument: the
/// normal equations need only readings away from the centres).
fn samples(n: usize) -> Vec<MagAccelSample> {
    (0..n)
        .map(|k| {
            let (a, b) = (0.37 * k as f64, 0.11 * k as f64);
            let d = Vector3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos());
            MagAccelSample {
                t_s: k as f64,
                acc: Vector3::new(0.1, -0.2, 0.3) + d * 9.81,
                mag: Vector3::new(12.0, 5.0, -3.0) + Vector3::new(d.y, d.z, d.x) * 48.0,
            }
        })
        .collect()
}

/// A point near a calibration: unit matrices, centres a little off, a small turn.
fn theta() -> SVector<f64, P> {
    let mut t = SVector::<f64, P>::zeros();
    for b in [BA, BM] {
        for (k, v) in [1.0, 0.01, 0.0, 0.98, -0.02, 1.03].into_iter().enumerate() {
            t[b + k] = v;
        }
    }
    t[2] = 0.05;
    t[S] = 0.4;
    t
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn weighting_the_sums_is_weighting_the_rows(
        acc in 0.0f64..1e3, mag in 0.0f64..1e3, dip in 0.0f64..1e3,
        other in 0.0f64..1e3,
    ) {
        let readings = samples(300);
        let na = Normaliser::of_finite(&SensorReadings::new(&readings, Sensor::Acc), "point").unwrap();
        let nm = Normaliser::of_finite(&SensorReadings::new(&readings, Sensor::Mag), "point").unwrap();
        let data = Data::new(&readings, na, nm, LIMITS);
        let r0 = Rotation3::from_euler_angles(0.1, -0.2, 0.3);
        let t = theta();
        let w = Weights { acc, mag, dip, aim: 1.0 };
        // The first call passes over the readings with other weights; the second is
        // weighted from the sums it remembered.
        let first = Weights { acc: other, mag: 1.0, dip: 2.0, aim: 1.0 };
        let (_, _) = normal_equations(&data, &[], &first, &r0, &t).unwrap().unwrap();
        let (remembered, sums) = normal_equations(&data, &[], &w, &r0, &t).unwrap().unwrap();
        let fresh = Data::new(&readings, na, nm, LIMITS);
        let (passed, _) = normal_equations(&fresh, &[], &w, &r0, &t).unwrap().unwrap();
        // The reference: every row weighted, one rank-one update at a time.
        let mut jtj = nalgebra::SMatrix::<f64, P, P>::zeros();
        let mut jtr = SVector::<f64, P>::zeros();
        let mut cost = 0.0;
        let mut n = 0;
        let model = Model::of(&t, &r0);
        data.replay(|a, m| {
            let rows = reading_rows(&model, a, m).unwrap();
            for ((row, r), wg) in rows.into_iter().zip([w.acc, w.mag, w.dip]) {
                add_row(&mut jtj, &mut jtr, &mut cost, &(row * wg), r * wg);
            }
            n += 1;
        })
        .unwrap();
        prop_assert_eq!(sums.acc.1, n);
        // Another point is not the one remembered.
        let mut moved = t;
        moved[0] += 0.01;
        let (at_moved, _) = normal_equations(&data, &[], &w, &r0, &moved).unwrap().unwrap();
        let fresh_moved = Data::new(&readings, na, nm, LIMITS);
        let (moved_passed, _) =
            normal_equations(&fresh_moved, &[], &w, &r0, &moved).unwrap().unwrap();
        prop_assert_eq!(at_moved, moved_passed);
        for (ne, what) in [(&remembered, "remembered"), (&passed, "passed")] {
            // The pointing axis's prior (no runs) adds nothing to the cost or Jᵀr at an
            // axis of x, and `1e8` to its two diagonal entries of JᵀJ.
            prop_assert!((ne.cost - cost).abs() <= 1e-9 * cost,
                "{what}: cost {} vs {}", ne.cost, cost);
            let jscale = jtj.amax().max(1e-300);
            for a in 0..P {
                for b in a..P {
                    let prior = if a == b && a >= P - 2 { 1e8 } else { 0.0 };
                    prop_assert!((ne.jtj[(a, b)] - jtj[(a, b)] - prior).abs() <= 1e-9 * jscale,
                        "{what}: JᵀJ[{a},{b}] {} vs {}", ne.jtj[(a, b)], jtj[(a, b)] + prior);
                }
                prop_assert!((ne.jtr[a] - jtr[a]).abs() <= 1e-9 * (jscale * cost).sqrt(),
                    "{what}: Jᵀr[{a}] {} vs {}", ne.jtr[a], jtr[a]);
            }
        }
    }
}
