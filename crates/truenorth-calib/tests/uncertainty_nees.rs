//! The predicted σ of the hard iron is a promise: over an ensemble of independent
//! recordings, the normalised estimation error squared (NEES, `Σₖ eₖ²/σₖ²` over the hard
//! iron's components, averaged over the trials and divided by their number) of every
//! least-squares calibrator, batch and online, is near 1 — the reported σ neither hides the
//! error nor inflates it.
//!
//! Tolerance, from the method: for `M` trials of `D` components the mean NEES of a
//! consistent estimator is `χ²(M·D)/(M·D)`, whose 99.9 % interval for `M·D = 400–600` is
//! about `1 ± 0.2`; the σ's come from the first-order (linearised) analysis, whose
//! neglected terms are of relative size `(σ_noise·G)²/2` < 10⁻³ at the 1 % noise used, and
//! the online calibrators weight their running sums, which the reported σ accounts for
//! through the effective count. The test takes `[0.7, 1.4]`.

use nalgebra::{Rotation3, Vector2, Vector3};
use truenorth_calib::{
    EllipseCalibrator, EllipsoidCalibrator, OnlineEllipseCalibrator, OnlineEllipseConfig,
    OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
};
use truenorth_core::{Calibrator, CompassQuality, Mag2Sample, Mag3Sample};

mod common;
use common::*;

const TRIALS: u64 = 200;
const NOISE: f64 = 0.01;

fn nees(errors: &[f64], sigmas: &[f64]) -> f64 {
    errors
        .iter()
        .zip(sigmas)
        .map(|(e, s)| (e / s).powi(2))
        .sum()
}

/// Mean NEES per component of a 2-D calibrator over the ensemble.
fn ensemble_2d<C>(make: impl Fn() -> C) -> f64
where
    C: Calibrator<
            Sample = Mag2Sample,
            Params = truenorth_compass::CompassCalibration2d,
            Quality = CompassQuality,
        >,
{
    let model = Model2::new(Vector2::new(0.3, -0.2), 1.3, 0.5, 1.0);
    let mut total = 0.0;
    for seed in 0..TRIALS {
        let mut cal = make();
        for (_, s) in model.samples(360, 0.0, 360.0, NOISE, 1000 + seed) {
            cal.push(&s).unwrap();
        }
        let sol = cal.solve().unwrap();
        let e = sol.params.hard_iron - model.hard;
        let s = sol.quality.uncertainty.hard_iron_sigma;
        total += nees(&[e.x, e.y], &s[..2]);
    }
    total / (2 * TRIALS) as f64
}

/// Mean NEES per component of a 3-D calibrator over the ensemble.
fn ensemble_3d<C>(make: impl Fn() -> C) -> f64
where
    C: Calibrator<
            Sample = Mag3Sample,
            Params = truenorth_compass::CompassCalibration3d,
            Quality = CompassQuality,
        >,
{
    let hard = Vector3::new(0.3, -0.2, 0.1);
    let w = soft3(&Rotation3::from_euler_angles(0.3, -0.2, 0.5), 1.2, 0.9);
    let mut total = 0.0;
    for seed in 0..TRIALS {
        let mut cal = make();
        for s in sphere_samples(hard, &w, 1.0, 600, NOISE, 5000 + seed) {
            cal.push(&s).unwrap();
        }
        let sol = cal.solve().unwrap();
        let e = sol.params.hard_iron - hard;
        let s = sol.quality.uncertainty.hard_iron_sigma;
        total += nees(&[e.x, e.y, e.z], &s);
    }
    total / (3 * TRIALS) as f64
}

fn check(name: &str, nees: f64) {
    println!("{name}: mean NEES per hard-iron component {nees:.3}");
    assert!((0.7..=1.4).contains(&nees), "{name}: NEES {nees:.3}");
}

#[test]
fn the_hard_iron_sigma_of_every_least_squares_calibrator_covers_its_error() {
    check("ellipse", ensemble_2d(EllipseCalibrator::default));
    check(
        "online-ellipse",
        ensemble_2d(|| OnlineEllipseCalibrator::new(OnlineEllipseConfig::default()).unwrap()),
    );
    check("ellipsoid", ensemble_3d(EllipsoidCalibrator::default));
    check(
        "online-ellipsoid",
        ensemble_3d(|| OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default()).unwrap()),
    );
}
