//! What the vehicle estimator says about what it does not know: states the motion cannot
//! separate, a calibration carried to the next drive, gaps in the log, and a time base or
//! unit the motion contradicts.

use truenorth_core::{Error, HeadingEstimator, NavEstimate, VehicleSample};
use truenorth_fusion::vehicle::nav_filter::{BIAS, GAIN_NEG, GAIN_POS, WHEEL_DIFF};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};

const TRACK_M: f64 = 1.55;

/// A car on a circle of `radius_m` at `speed_mps` to the right, after `rest_s` standing
/// still, sampled at 50 Hz for `drive_s`: exact wheels, a gyro with `bias_rps` and no other
/// error, no compass.
fn circle(
    rest_s: f64,
    drive_s: f64,
    radius_m: f64,
    speed_mps: f64,
    bias_rps: f64,
) -> Vec<VehicleSample> {
    let rate = speed_mps / radius_m;
    (0..=((rest_s + drive_s) * 50.0) as usize)
        .map(|k| {
            let t = k as f64 / 50.0;
            let moving = (t - rest_s).max(0.0);
            let d = speed_mps * moving;
            let turn = 0.5 * TRACK_M * rate * moving;
            let r = if t > rest_s { rate } else { 0.0 };
            VehicleSample::at(t)
                .with_wheels(d + turn, d - turn)
                .with_gyro(r + bias_rps)
        })
        .collect()
}

fn run(samples: &[VehicleSample]) -> (VehicleEstimator, NavEstimate) {
    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let mut last = None;
    for s in samples {
        last = Some(nav.update(s).unwrap());
    }
    (nav, last.unwrap())
}

/// On a steady circle from the start a gyro bias and a wheel-size difference turn the
/// heading alike: the estimate leans on the priors, says that neither is determined, and
/// its σ covers what that leaves. A standstill first measures the bias and settles it.
#[test]
fn a_steady_circle_cannot_tell_a_gyro_bias_from_a_wheel_difference_and_says_so() {
    let bias = 0.5f64.to_radians();
    let truth_turn = |s: &[VehicleSample]| {
        let t = s.last().unwrap().t_s;
        (5.0 / 20.0) * (t - (t - 60.0))
    };
    let moving = circle(0.0, 60.0, 20.0, 5.0, bias);
    let (nav, e) = run(&moving);
    let u = e.status.unobserved;
    assert!(u.gyro_bias && u.wheel_diff, "{u:?}");
    let error = truenorth_core::angle_diff(e.heading.rad(), truth_turn(&moving));
    assert!(
        error.abs() <= 3.0 * e.heading_sigma_rad,
        "heading {:.1}° off with σ {:.1}°",
        error.to_degrees(),
        e.heading_sigma_rad.to_degrees()
    );
    // The two are known in combination: strongly correlated.
    let f = nav.filter();
    let rho = f.p[BIAS][WHEEL_DIFF] / (f.sigma(BIAS) * f.sigma(WHEEL_DIFF));
    assert!(rho.abs() > 0.9, "correlation {rho:.3}");

    let resting = circle(5.0, 60.0, 20.0, 5.0, bias);
    let (nav, e) = run(&resting);
    assert!(!e.status.unobserved.gyro_bias, "{:?}", e.status.unobserved);
    let b = nav.filter().x[BIAS];
    assert!(
        (b - bias).abs() < 3.0 * nav.filter().sigma(BIAS),
        "bias {:.3} ± {:.3}°/s",
        b.to_degrees(),
        nav.filter().sigma(BIAS).to_degrees()
    );
    let error = truenorth_core::angle_diff(e.heading.rad(), truth_turn(&resting));
    assert!(error.to_degrees().abs() < 1.0, "{:.2}°", error.to_degrees());
}

/// What a drive learned comes back at the next start widened by what it may drift
/// between drives, never beyond its prior: a gain never exercised comes back as it started.
#[test]
fn a_restored_calibration_is_widened_by_drift_and_never_beyond_its_prior() {
    let (nav, _) = run(&circle(5.0, 60.0, 20.0, 5.0, 0.01));
    let learned = nav.calibration();
    let restored = VehicleEstimator::with_calibration(VehicleConfig::default(), &learned).unwrap();
    let fresh = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let prior = fresh.priors();
    // Only right turns were driven: the left gain was never learned.
    assert!(
        (learned.gyro_gain_error_left.sigma / prior.gyro_gain_sigma - 1.0).abs() < 1e-5,
        "{}",
        learned.gyro_gain_error_left.sigma
    );
    let f = restored.filter();
    assert!(
        (f.sigma(GAIN_NEG) - prior.gyro_gain_sigma).abs() < 1e-12,
        "left gain restored at σ {}",
        f.sigma(GAIN_NEG)
    );
    // The right gain was learned: widened by a tenth of its prior, in quadrature.
    let s = learned.gyro_gain_error_right.sigma;
    let expect = (s * s + (0.1 * prior.gyro_gain_sigma).powi(2)).sqrt();
    assert!((f.sigma(GAIN_POS) - expect).abs() < 1e-12);
    assert!(f.sigma(GAIN_POS) < prior.gyro_gain_sigma);
}

/// A log that stops for an hour: the row after the gap says so, and the track's and the
/// gyro bias's uncertainty grew across it; nothing is guessed.
#[test]
fn an_hour_long_gap_is_flagged_and_widens_what_it_left_unknown() {
    let mut samples = circle(5.0, 30.0, 50.0, 10.0, 0.003);
    let last = *samples.last().unwrap();
    let w = last.wheels.unwrap();
    // An hour later the car has moved 1 km and turned; the log resumes.
    for k in 0..100 {
        let t = last.t_s + 3600.0 + 0.02 * k as f64;
        samples.push(
            VehicleSample::at(t)
                .with_wheels(
                    w.dist_l_m + 1000.0 + 0.2 * k as f64,
                    w.dist_r_m + 990.0 + 0.2 * k as f64,
                )
                .with_gyro(0.003),
        );
    }
    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let mut before = None;
    let mut flagged = Vec::new();
    for s in &samples {
        let e = nav.update(s).unwrap();
        if e.status.gap {
            flagged.push(s.t_s);
        }
        if s.t_s <= last.t_s {
            before = Some((e, nav.filter().sigma(BIAS)));
        }
    }
    // One row carries both sensors after the gap: it alone is flagged.
    assert_eq!(flagged.len(), 1, "{flagged:?}");
    assert!(
        flagged
            .iter()
            .all(|&t| t > last.t_s + 3600.0 - 1e-9 && t < last.t_s + 3600.1)
    );
    let (e0, bias0) = before.unwrap();
    let e1 = nav.estimate();
    assert!(nav.filter().sigma(BIAS) > 2.0 * bias0);
    let p0 = e0.position_cov_m2.trace().sqrt();
    let p1 = e1.position_cov_m2.trace().sqrt();
    assert!(p1 > p0 + 10.0, "track σ {p0:.1} → {p1:.1} m");
}

/// A gyro logged in °/s turns 57 times what the wheels turn: refused, with the likely
/// mistake named; the estimator is left as it was.
#[test]
fn a_gyro_in_degrees_per_second_is_named() {
    let samples: Vec<VehicleSample> = circle(2.0, 60.0, 20.0, 5.0, 0.0)
        .into_iter()
        .map(|s| VehicleSample {
            gyr_z_rps: s.gyr_z_rps.map(f64::to_degrees),
            ..s
        })
        .collect();
    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let mut refused = None;
    for s in &samples {
        let before = nav.estimate();
        match nav.update(s) {
            Ok(_) => {}
            Err(e) => {
                assert_eq!(nav.estimate(), before);
                refused = Some(e);
                break;
            }
        }
    }
    match refused {
        Some(Error::Implausible { value, hint, .. }) => {
            assert!((value - 57.3).abs() < 10.0, "{value}");
            assert!(hint.contains("deg/s"));
        }
        other => panic!("{other:?}"),
    }
}
