//! Tests of [`super`]: the binned ellipse calibrator.

use super::*;
use truenorth_compass::{
    Disturbance, DisturbanceShape, HeadingTruth, MagnetometerModel2d, soft_iron_from_axes,
};
use truenorth_core::{NoiseSource, SensorModel, SplitMix64, angle_diff};

const H: f64 = 20.0;

fn reference() -> MagnetometerModel2d {
    MagnetometerModel2d::new(
        Vector2::new(10.0, -4.0),
        soft_iron_from_axes(1.3, 1.0, 30f64.to_radians()),
        0.01 * H,
    )
    .unwrap()
}

/// Turns of `deg` degrees at 2 samples per degree.
fn drive(c: &mut BinnedEllipseCalibrator, m: &mut MagnetometerModel2d, from: f64, deg: f64) {
    let mut rng = SplitMix64::new(from.to_bits());
    let n = (2.0 * deg) as usize;
    for i in 0..n {
        let truth = HeadingTruth {
            heading_rad: (from + i as f64 * 0.5).to_radians(),
            horizontal_field: H,
        };
        c.push(&Mag2Sample {
            t_s: i as f64,
            mag: m.sample(&truth, 0.05, &mut rng).unwrap(),
        })
        .unwrap();
    }
}

#[test]
fn s_theta_finds_the_minor_axis_and_the_ratio_is_negative_about_it() {
    let mut m = reference();
    let mut c = BinnedEllipseCalibrator::default();
    drive(&mut c, &mut m, 0.0, 450.0);
    c.solve().unwrap();
    let p = c.solve_phasors().unwrap();
    // Major axis at 30°: Ω_e is 120° (mod 180°), r ≈ −0.3/2.3.
    assert!(angle_diff(2.0 * p.omega_e_rad, 2.0 * 120f64.to_radians()).abs() < 0.02);
    assert!((p.ratio + 0.3 / 2.3).abs() < 0.01, "{}", p.ratio);
    assert!((p.earth_magnitude - 1.15 * H).abs() < 0.02 * H);
    let n = p.normalised();
    assert!(angle_diff(2.0 * n.omega_e_rad, 60f64.to_radians()).abs() < 0.02);
}

#[test]
fn stored_parameters_regenerate_the_bins() {
    let mut m = reference();
    let mut c = BinnedEllipseCalibrator::default();
    drive(&mut c, &mut m, 0.0, 60.0);
    // Not enough readings yet to store (claim 14).
    assert!(c.parameters_to_store().is_none());
    drive(&mut c, &mut m, 60.0, 400.0);
    let before = c.solve().unwrap().params;
    let stored = c.parameters_to_store().unwrap();
    let mut on =
        BinnedEllipseCalibrator::from_stored_parameters(BinnedEllipseConfig::default(), &stored)
            .unwrap();
    assert_eq!(on.filled_bins(), 64);
    assert!(on.bin_states().all(|s| s == BinState::Regenerated));
    let after = on.solve().unwrap().params;
    assert!((after.hard_iron - before.hard_iron).norm() < 1e-3 * H);
    assert!((after.soft_iron - before.soft_iron).norm() < 5e-3);
    // New readings replace regenerated values bin by bin.
    drive(&mut on, &mut m, 0.0, 30.0);
    assert!(on.bin_states().any(|s| s == BinState::Measured));
    assert!(
        BinnedEllipseCalibrator::from_stored_parameters(
            BinnedEllipseConfig::default(),
            &EllipsePhasors {
                ratio: 2.0,
                ..stored
            }
        )
        .is_err()
    );
}

#[test]
fn a_new_magnet_restarts_a_passing_lorry_does_not() {
    let mut m = reference();
    let mut c = BinnedEllipseCalibrator::default();
    drive(&mut c, &mut m, 0.0, 720.0);
    assert_eq!(c.restarts(), 0);
    // A lorry passes for a few seconds: a field of half the earth's, briefly.
    let mut lorry = m
        .with_disturbance(Disturbance {
            start_s: m.time_s() + 1.0,
            duration_s: 3.0,
            field_ned: nalgebra::Vector3::new(0.0, 0.5 * H, 0.0),
            shape: DisturbanceShape::RaisedCosine,
        })
        .unwrap();
    drive(&mut c, &mut lorry, 0.0, 720.0);
    assert_eq!(c.restarts(), 0, "a transient restarted calibration");
    // A magnet is fixed near the sensor: the hard iron moves by 0.6 H.
    let mut magnet = MagnetometerModel2d::new(
        m.hard_iron() + Vector2::new(0.6 * H, 0.0),
        m.soft_iron(),
        m.noise_sigma(),
    )
    .unwrap();
    drive(&mut c, &mut magnet, 0.0, 360.0);
    assert!(c.restarts() >= 1, "the magnet went unnoticed");
    drive(&mut c, &mut magnet, 0.0, 450.0);
    let sol = c.solve().unwrap();
    assert!((sol.params.hard_iron - magnet.hard_iron()).norm() < 0.02 * H);
}

/// A snapshot taken at any push of a whole update cycle (every phase: refresh on idle
/// and working pushes, precheck, assessment, application) restores to a calibrator that
/// continues bit-identically.
#[test]
fn snapshot_at_every_phase_of_an_update_continues_identically() {
    use truenorth_core::Persistent;
    let mut m = reference();
    let mut rng = SplitMix64::new(3);
    let stream: Vec<_> = (0..900)
        .map(|i| {
            let truth = HeadingTruth {
                heading_rad: (i as f64 * 0.5).to_radians(),
                horizontal_field: H,
            };
            Mag2Sample {
                t_s: i as f64,
                mag: m.sample(&truth, 0.05, &mut rng).unwrap(),
            }
        })
        .collect();
    let mut straight = BinnedEllipseCalibrator::default();
    let mut phases = std::collections::BTreeSet::new();
    let mut assess_steps = std::collections::BTreeSet::new();
    let mut waited = false;
    for (k, s) in stream.iter().enumerate() {
        if k >= 600 {
            phases.insert(format!("{:?}", straight.update_phase().map(|p| p.0)));
            waited |= straight.waiting_readings() > 0;
            if let Some(u) = &straight.update
                && u.phase == UpdatePhase::Assess
            {
                assess_steps.insert(u.assess_steps);
            }
            let mut resumed = BinnedEllipseCalibrator::restore(straight.snapshot()).unwrap();
            assert_eq!(resumed, straight, "push {k}");
            let mut copy = straight.clone();
            for t in &stream[k..(k + 5).min(stream.len())] {
                assert_eq!(copy.push(t).unwrap(), resumed.push(t).unwrap(), "push {k}");
                assert_eq!(copy.estimate(), resumed.estimate());
            }
            assert_eq!(copy, resumed);
        }
        straight.push(s).unwrap();
    }
    // Every phase was visited, and every step of the staged quality report.
    assert_eq!(phases.len(), 5, "{phases:?}");
    let all: std::collections::BTreeSet<_> =
        (0..crate::seed::seed_quality::SeedJob::STEPS).collect();
    assert!(all.is_subset(&assess_steps), "{assess_steps:?}");
    // And readings were still waiting to be binned after an update.
    assert!(waited);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 24, failure_persistence: None, ..Default::default() })]
    /// Binning the readings that waited for an update over several pushes gives, once
    /// they are all binned, exactly the calibrator that bins them at once (every push
    /// returning the same and publishing the same estimate meanwhile), for any update
    /// interval (short ones start the next update while readings still wait).
    #[test]
    fn spreading_the_waiting_readings_equals_binning_them_at_once(
        interval in 4usize..200, seed in 0u64..1000, step_deg in 0.3f64..3.0,
    ) {
        let mut m = reference();
        let mut rng = SplitMix64::new(seed);
        let config = BinnedEllipseConfig {
            update_interval: interval,
            ..Default::default()
        };
        let mut spread = BinnedEllipseCalibrator::new(config).unwrap();
        let mut at_once = spread.clone();
        let mut drained = 0;
        for i in 0..1500 {
            let truth = HeadingTruth {
                heading_rad: (i as f64 * step_deg).to_radians(),
                horizontal_field: H,
            };
            let s = Mag2Sample { t_s: i as f64, mag: m.sample(&truth, 0.05, &mut rng).unwrap() };
            proptest::prop_assert_eq!(spread.push(&s).unwrap(), at_once.push(&s).unwrap(), "push {}", i);
            at_once.drain(false);
            proptest::prop_assert_eq!(at_once.backlog_len, 0);
            proptest::prop_assert_eq!(spread.estimate(), at_once.estimate(), "push {}", i);
            if spread.backlog_len == 0 {
                proptest::prop_assert_eq!(&spread, &at_once, "push {}", i);
            } else {
                drained += 1;
            }
        }
        // Readings did wait, where the next update is due only after they are binned
        // (with a shorter interval they are all binned at once).
        if interval >= 2 * REFRESH_PUSHES {
            proptest::prop_assert!(drained > 0);
        }
    }
}

#[test]
fn config_is_validated() {
    let bad = [
        BinnedEllipseConfig {
            bins: 63,
            ..Default::default()
        },
        BinnedEllipseConfig {
            bins: 256,
            ..Default::default()
        },
        BinnedEllipseConfig {
            init_samples: 0,
            ..Default::default()
        },
        BinnedEllipseConfig {
            restart_threshold: f64::NAN,
            ..Default::default()
        },
    ];
    for cfg in bad {
        assert!(BinnedEllipseCalibrator::new(cfg).is_err(), "{cfg:?}");
    }
}

/// What a dense noisy turn leaves in the bins is a reading taken at the direction it shows:
/// on 1.5 turns at 200 readings per degree with noise 5 % of the field, the readings the
/// bins keep lag their true headings by a fraction of the noise σ on average (0.07 σ here,
/// up to 0.7 σ over other draws), where keeping the last reading of each bin kept the last
/// noise excursion back across the edge the turn crossed (2.0 σ here, 2.5–2.8 σ over other
/// draws: see `bins::store_reading`).
#[test]
fn a_dense_noisy_turn_keeps_readings_at_their_own_directions() {
    let sigma = 0.05;
    let (hard, w) = (Vector2::new(0.4, -0.3), soft_iron_from_axes(1.8, 1.0, 0.7));
    let w_inv = w.try_inverse().unwrap();
    let mut rng = SplitMix64::new(3);
    let per_deg = 200.0;
    let readings: Vec<(f64, Vector2<f64>)> = (0..(540.0 * per_deg) as usize)
        .map(|k| {
            let psi = (k as f64 / per_deg).to_radians();
            let noise = Vector2::new(rng.normal(sigma), rng.normal(sigma));
            (psi, hard + w * Vector2::new(psi.cos(), psi.sin()) + noise)
        })
        .collect();
    let mut c = BinnedEllipseCalibrator::default();
    for (k, (_, p)) in readings.iter().enumerate() {
        c.push(&Mag2Sample {
            t_s: k as f64 * 0.01,
            mag: *p,
        })
        .unwrap();
    }
    let (mut sum, mut n) = (0.0, 0usize);
    for b in c.bins[..64]
        .iter()
        .filter(|b| b.state == BinState::Measured)
    {
        // Bins that merged two readings hold neither.
        if let Some((psi, p)) = readings.iter().find(|(_, p)| *p == b.value) {
            let d = w_inv * (p - hard);
            sum += angle_diff(*psi, d.y.atan2(d.x)) / sigma;
            n += 1;
        }
    }
    let mean_lag = sum / n as f64;
    assert!(
        mean_lag.abs() < 1.25,
        "the kept readings lag by {mean_lag:.2} σ"
    );
    assert!(n >= 16, "{n} bins hold a single reading");
}

/// A state saved before the bins' counts of the interval before were kept restores (all
/// zero: every bin is fresh) and calibrates on.
#[test]
fn a_state_without_the_counts_of_the_interval_before_restores() {
    use truenorth_core::Persistent;
    let mut m = reference();
    let mut c = BinnedEllipseCalibrator::default();
    drive(&mut c, &mut m, 0.0, 200.0);
    let mut saved = serde_json::to_value(c.snapshot()).unwrap();
    let fields = saved["state"].as_object_mut().unwrap();
    assert!(fields.remove("counted_before").is_some());
    let state = serde_json::from_value(saved).unwrap();
    let mut on = BinnedEllipseCalibrator::restore(state).unwrap();
    assert!(on.counted_before.iter().all(|&k| k == 0));
    drive(&mut on, &mut m, 200.0, 250.0);
    assert!(on.solve().is_ok());
}

/// Before the first origin a refusal counts readings; after it, direction bins. A half turn
/// of 5400 readings fills fewer bins than solving needs: the refusal says so with the
/// count of bins, and asks for more headings rather than more readings.
#[test]
fn a_dense_half_turn_is_refused_for_its_bins_not_its_readings() {
    let mut m = reference();
    let mut c = BinnedEllipseCalibrator::default();
    let mut rng = SplitMix64::new(7);
    let per_deg = 30.0;
    let readings = (180.0 * per_deg) as usize;
    for i in 0..readings {
        if i == 5 {
            assert_eq!(
                c.solve().map(|_| ()),
                Err(Error::TooFewPoints { got: 5, need: 8 })
            );
        }
        let truth = HeadingTruth {
            heading_rad: (i as f64 / per_deg).to_radians(),
            horizontal_field: H,
        };
        c.push(&Mag2Sample {
            t_s: i as f64 * 0.01,
            mag: m.sample(&truth, 0.01, &mut rng).unwrap(),
        })
        .unwrap();
    }
    let e = c.solve().map(|_| ()).unwrap_err();
    let Error::TooFewBins { filled, need, bins } = e else {
        panic!("{e:?}");
    };
    assert_eq!((need, bins), (16, 64));
    assert!(filled < need, "{e}");
    let text = e.to_string();
    assert!(!text.contains("too few points"), "{text}");
    assert!(text.contains("turn through more headings"), "{text}");
}
