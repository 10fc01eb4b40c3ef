//! A noisy sensor is not a degenerate geometry: a hand-tumbled three-axis magnetometer with
//! 6 % of the field of noise per reading and axis — the kind of recording a QMC5883L on a
//! hobby board gives, 19,743 readings in every direction — calibrates, with a small bound
//! (its noise averages out of the parameters) and the verdict `usable` *because the sensor
//! is noisy*. A determination test that multiplied the dilution by the per-reading residual
//! refused it as "degenerate geometry", sending the user to record orientations that would
//! not have helped.

mod common;

use common::*;
use nalgebra::{Rotation3, Vector3};
use truenorth_calib::quality::{self, Cause, Grade, Verdict};
use truenorth_calib::{
    EllipsoidCalibrator, EllipsoidConfig, OnlineEllipsoidCalibrator, fit_ellipsoid,
};
use truenorth_core::{Calibrator, Mag3Sample, SplitMix64};
use truenorth_sim::{HandheldParams, handheld_motion};

/// Per-axis noise, relative to the field.
const NOISE: f64 = 0.06;

/// The recording: 197.42 s of hand-held tumbling at 100 Hz (19,743 readings), the sensor
/// turned at up to 3 rad/s about every axis, hard iron 0.4 of the field, soft iron within
/// ±10 %, field 50 units at a dip of 64°.
fn tumble(seed: u64) -> (Vec<Vector3<f64>>, Model3) {
    let motion = handheld_motion(&HandheldParams {
        duration_s: 197.42,
        rate_hz: 100.0,
        rate_amplitude_rps: 3.0,
        accel_amplitude_mps2: 0.5,
        seed,
    })
    .unwrap();
    let m = Model3 {
        hard: Vector3::new(0.3, -0.2, 0.15) * 50.0,
        w: soft3(&Rotation3::from_euler_angles(0.4, -0.3, 1.1), 1.1, 0.93),
        field: 50.0,
        dip_rad: 64f64.to_radians(),
        noise_rel: NOISE,
    };
    let mut rng = SplitMix64::new(seed);
    let pts = motion
        .iter()
        .map(|t| m.raw(&t.attitude.to_rotation_matrix(), &mut rng))
        .collect();
    (pts, m)
}

/// The RMS over the sphere of the angle, degrees, between the true field direction and the
/// calibrated one: the error the calibration itself leaves.
///
/// The report's 3σ bound is per direction (three standard deviations at the worst
/// heading), not a bound on the worst over all directions at once. Over the sphere, the
/// mean square of one calibration's direction error is a quadratic form of its parameter
/// error, a weighted χ² of at most 9 degrees of freedom whose mean is at most σ² at the
/// worst heading: its 99.7 % point is below 2.8σ² (that of χ²₉/9), so the RMS stays below
/// 1.67σ, 0.56 of the 3σ bound. The tests hold it under the bound: room for what the
/// linear analysis leaves out, and no more.
fn rms_direction_error_deg(cal: &truenorth_compass::CompassCalibration3d, m: &Model3) -> f64 {
    let mut rng = SplitMix64::new(99);
    let n = 2000;
    let ss: f64 = (0..n)
        .map(|_| {
            let u = uniform_direction(&mut rng);
            let raw = m.hard + m.w * u * m.field;
            cal.correct(&raw).angle(&u).powi(2)
        })
        .sum();
    (ss / n as f64).sqrt().to_degrees()
}

/// Five tumbles (five motions and noise draws): every one calibrates, each bound covers the
/// error its calibration leaves, and each verdict blames the noise.
#[test]
fn a_noisy_sensor_tumbled_in_every_direction_calibrates_and_is_judged_noisy() {
    for seed in 7..12 {
        check(seed);
    }
}

fn check(seed: u64) {
    let (pts, m) = tumble(seed);
    assert_eq!(pts.len(), 19_743);
    let sol = fit_ellipsoid(&pts, &EllipsoidConfig::default()).unwrap();
    let q = sol.quality;
    let a = quality::assess_3d(&pts, &sol.params, q.field_magnitude);
    let g = a.uncertainty.dilution;
    // The per-reading noise is found: the radial residual of isotropic per-axis noise σ has
    // standard deviation σ, to second order (+σ²/2 relative, 3 %) and a sampling spread of
    // 1/√(2N) (0.5 %); 5 % holds both.
    let sigma = q.heading_noise_rms_deg.to_radians();
    assert!((sigma / NOISE - 1.0).abs() < 0.05, "noise {sigma}");
    // The bound falls as 1/√N: every other reading (the same orientations, half as many
    // readings in each) leaves a bound √2 times as large, to within the sampling spread of
    // σ̂ and of the dilution between the two sets (a few per cent; 5 % allowed).
    let every_other: Vec<Vector3<f64>> = pts.iter().step_by(2).copied().collect();
    let half = fit_ellipsoid(&every_other, &EllipsoidConfig::default()).unwrap();
    let ratio = half.quality.heading_error_3sigma_deg / q.heading_error_3sigma_deg;
    assert!((ratio / 2f64.sqrt() - 1.0).abs() < 0.05, "{ratio}");
    // The noise averages out of the parameters: the 3σ part, which was the whole bound
    // before the fit reported the noise's second-order bias (which does not average out)
    // as its systematic part; `tests/bias_bound.rs` holds that part.
    assert!(q.heading_error_3sigma_deg < 0.5, "{q:?}");
    // And it holds: the error the calibration itself leaves (see `rms_direction_error_deg`).
    let worst = rms_direction_error_deg(&sol.params, &m);
    assert!(worst <= q.heading_error_bound_deg(), "{worst} > {q:?}");
    // The orientations determine it, whatever the noise: an evenly tumbled sensor's
    // dilution, a few times the even sphere's.
    assert!(g < 2.0 * quality::DILUTION_EVEN_SPHERE, "{g}");
    // The old test, dilution times residual against the 10° bound, refused it.
    let old_deg = (g * q.fit.residual_rms_rel).to_degrees();
    println!(
        "19,743 readings at {:.1} % noise: dilution {g:.2}, bound {:.3}° (3σ) + {:.3}° (bias), RMS direction error {worst:.3}°, noise {:.2}° per reading; the dilution times the residual reads {old_deg:.1}°",
        100.0 * sigma,
        q.heading_error_3sigma_deg,
        q.heading_error_systematic_deg,
        q.heading_noise_rms_deg
    );
    assert!(old_deg > 10.0, "{old_deg}");
    // The verdict names the noise, with its figures.
    let v = Verdict::of(&q);
    assert_eq!((v.grade, v.cause), (Grade::Usable, Cause::Noise), "{v}");
    let reason = v.to_string();
    assert!(reason.contains("the sensor is noisy"), "{reason}");
    assert!(reason.contains(&format!("{:.2} deg RMS", q.heading_noise_rms_deg)));
    assert!(reason.contains(&format!(
        "determined to {:.2} deg",
        q.heading_error_bound_deg()
    )));
    // The calibrators agree.
    let mut batch = EllipsoidCalibrator::default();
    let mut online = OnlineEllipsoidCalibrator::new(Default::default()).unwrap();
    for (k, p) in pts.iter().enumerate() {
        let s = Mag3Sample {
            t_s: 0.01 * k as f64,
            mag: *p,
        };
        batch.push(&s).unwrap();
        online.push(&s).unwrap();
    }
    assert!(batch.progress().ready);
    let o = online.solve().unwrap();
    // The online fit has no geometric refinement: its second-order bias is part of its bound
    // (the systematic part), and the bound covers what it leaves.
    let online_worst = rms_direction_error_deg(&o.params, &m);
    println!(
        "online: RMS direction error {online_worst:.3}°, bound {:.3}° (3σ {:.3}° + bias {:.3}°)",
        o.quality.heading_error_bound_deg(),
        o.quality.heading_error_3sigma_deg,
        o.quality.heading_error_systematic_deg
    );
    assert!(online_worst <= o.quality.heading_error_bound_deg());
    assert_eq!(Verdict::of(&o.quality).cause, Cause::Noise);
}
