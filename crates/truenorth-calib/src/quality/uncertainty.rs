//! What the readings determine: the geometry's dilution of precision and the predicted
//! standard deviations of the hard and soft iron, from the information matrix of the
//! module documentation.
//!
//! # The dilution `G` (derivation)
//!
//! With `A = Σ φ(uᵢ)φ(uᵢ)ᵀ` the information matrix of `N` calibrated directions and `g(u)`
//! the gradient of the heading (3-D: field-direction) error at direction `u` (see the
//! module documentation of `quality`), define
//!
//! `G = max_u √(N · g(u)ᵀ A⁻¹ g(u))`   (3-D: `√(N · trace(G(u) A⁻¹ G(u)ᵀ))`).
//!
//! It depends only on the directions, not on their units or noise, and says two things:
//! * **Random errors.** Independent per-reading errors of standard deviation `σ` (relative to
//!   the field) give a heading error of standard deviation `σ·G/√N` at the worst direction:
//!   the 3σ bound of the report is `3σG/√N`. It falls as `1/√N`: noise is averaged.
//! * **Any errors.** Per-reading errors `eᵢ` of RMS `ε` — systematic ones too (an
//!   unmodelled non-linearity, a field gradient across the site), which do not average
//!   out — move the least-squares parameters by `δp = A⁻¹ Σ φᵢ eᵢ`, so the heading error
//!   `g(u)ᵀδp = Σ (g(u)ᵀA⁻¹φᵢ) eᵢ` is at most `√(Σ (g(u)ᵀA⁻¹φᵢ)²) · √(Σ eᵢ²)` (Cauchy–Schwarz)
//!   `= √(g(u)ᵀA⁻¹g(u)) · √N·ε = G·ε` radians, whatever `N`.
//!
//! Readings spread evenly round a circle have `G = 2` ([`DILUTION_EVEN_CIRCLE`]), an
//! evenly covered sphere `G = √13.5 ≈ 3.67` ([`DILUTION_EVEN_SPHERE`]; both found by the
//! tests from the moments of the uniform distribution); a few dozen well-chosen shots a
//! few times more. Readings confined to a great circle make `A` singular (`G` infinite); a
//! hand-held turn about one axis with a few degrees of wobble gives `G` in the thousands; a
//! hemisphere about 18.
//!
//! The dilution reported, and judged, is that of the *support* (the `support` module): each
//! direction cell counted once, so that it is a property of the orientations seen and not
//! of how many readings were taken in each — more readings in the same orientations never
//! change it.
//!
//! # The test
//!
//! A calibration is determined by its orientations when `G · ε_model`, the largest
//! field-direction error that a per-reading error of [`MODEL_ERROR_REL`] — what a consumer
//! magnetometer keeps after calibration, and which more readings do not average away —
//! could cause on the support, stays within the largest bound the calibrator accepts. The
//! test reads neither the number of readings nor their noise: twenty-four shots in
//! well-chosen orientations pass, a single-axis turn does not however many readings it has,
//! and a noisy sensor tumbled in every direction passes (its noise is judged apart, by the
//! 3σ bound, which falls as the readings grow, and by the verdict).

use nalgebra::SMatrix;

use truenorth_core::compass_quality::{
    DILUTION_EVEN_CIRCLE, DILUTION_EVEN_SPHERE, MODEL_ERROR_REL,
};
use truenorth_core::{CompassQuality, CompassUncertainty, Error, Result};

use super::bounds::{bound_deg, t_factor_exact_small, whitened};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The 3σ bound of the module documentation of `quality` (degrees) and the uncertainty,
/// from an information matrix of `P` parameters (the first `dimensions` the hard iron
/// relative to the field, the rest the soft-iron perturbation), the residual sum of squares
/// of `n` readings and the field, with the support's `dilution` (see `support_dilution`,
/// computed apart so that a staged caller can spread the two); `worst` computes
/// `max_u ‖L⁻¹g(u)‖²` over the test directions. Infinite bound and
/// [`CompassUncertainty::UNDETERMINED`] when `n ≤ P` or `A` is not positive definite.
pub(super) fn bound_and_uncertainty<const P: usize>(
    info: &SMatrix<f64, P, P>,
    dilution: f64,
    sum_sq: f64,
    n: usize,
    field: f64,
    dimensions: usize,
    worst: impl Fn(&SMatrix<f64, P, P>) -> f64,
) -> (f64, CompassUncertainty) {
    let Some((l_inv, sigma)) = whitened(info, sum_sq.max(0.0), n) else {
        return (f64::INFINITY, CompassUncertainty::UNDETERMINED);
    };
    let w = worst(&l_inv);
    (
        bound_deg(sigma, w),
        uncertainty_from_factor(Some(&l_inv), sigma, field, dimensions, dilution),
    )
}

/// What the readings determine, from the inverse Cholesky factor `L⁻¹` of the information
/// matrix (`A⁻¹ = L⁻ᵀL⁻¹`, in the parameters of [`bound_and_uncertainty`], scaled so that
/// `σ²A⁻¹` is the parameters' covariance), the per-reading noise `sigma` (relative to the
/// field), the field, and the support's `dilution`; without a factor (the information
/// matrix not positive definite) the parameters are undetermined. Non-finite figures are
/// reported as +∞.
pub(crate) fn uncertainty_from_factor<const P: usize>(
    l_inv: Option<&SMatrix<f64, P, P>>,
    sigma: f64,
    field: f64,
    dimensions: usize,
    dilution: f64,
) -> CompassUncertainty {
    let finite = |v: f64| if v.is_finite() { v } else { f64::INFINITY };
    let Some(l_inv) = l_inv else {
        return CompassUncertainty {
            dilution: finite(dilution),
            ..CompassUncertainty::UNDETERMINED
        };
    };
    // (A⁻¹)_kk = ‖column k of L⁻¹‖², since A⁻¹ = L⁻ᵀL⁻¹.
    let var = |k: usize| l_inv.column(k).norm_squared();
    let mut hard_iron_sigma = [0.0; 3];
    for (k, h) in hard_iron_sigma.iter_mut().enumerate().take(dimensions) {
        *h = field.abs() * sigma * var(k).sqrt();
    }
    let soft_iron_sigma_rel = (dimensions..P)
        .map(|k| sigma * var(k).sqrt())
        .fold(0.0, f64::max);
    CompassUncertainty {
        dilution: finite(dilution),
        hard_iron_sigma: hard_iron_sigma.map(finite),
        soft_iron_sigma_rel: finite(soft_iron_sigma_rel),
    }
}

/// Refuses a calibration that its orientations do not determine (see the module
/// documentation): when `G · MODEL_ERROR_REL` exceeds `max_error_deg`, with
/// [`Error::Undetermined`] carrying the figures and `hint` (what to record instead).
/// `dimensions` (2 or 3) names the even shape the dilution is compared with.
pub fn require_determined(
    u: &CompassUncertainty,
    dimensions: usize,
    max_error_deg: f64,
    hint: &'static str,
) -> Result<()> {
    let error_deg = u.geometry_error_deg();
    if error_deg <= max_error_deg {
        Ok(())
    } else {
        let (even_dilution, even_shape) = if dimensions == 2 {
            (DILUTION_EVEN_CIRCLE, "circle")
        } else {
            (DILUTION_EVEN_SPHERE, "sphere")
        };
        Err(Error::Undetermined {
            dilution: u.dilution,
            even_dilution,
            even_shape,
            model_error_rel: MODEL_ERROR_REL,
            error_deg,
            max_deg: max_error_deg,
            hint,
        })
    }
}

/// The largest product of the per-reading noise (relative to the field) and the dilution
/// `G` at which a least-squares calibration's own figures are trusted: 0.5 rad.
///
/// The 3σ bound, the predicted σ's and the dilution itself come from the first-order
/// (linearised) analysis of the fit about its solution; the terms it leaves out are of
/// relative size `(σG)²/2` — 12 % at 0.5 — and, unlike the noise in the first-order ones,
/// they do not average out with more readings. Beyond it the fit can drift along what the
/// orientations leave loose and, through the calibration it drifted to, its readings can
/// look well spread: a turn about one axis wobbling by 4° at 1.8 % noise fits a soft iron
/// of 1.43 : 1 and a centre 20 % of the field away, through which its dilution reads 33
/// where the truth's is 120 (`tests/families.rs`; σG = 0.59 there and 0.66 for a 3° wobble
/// at 8 % noise). A sensor tumbled in every direction keeps σG below 0.3 at 8 % noise
/// (G ≈ 3.7), so noise alone, with orientations that determine the calibration, never
/// reaches it.
pub const MAX_NOISE_DILUTION: f64 = 0.5;

/// Refuses a calibration whose per-reading noise `noise_rel` times its dilution `u.dilution`
/// exceeds `max_product` (by default [`MAX_NOISE_DILUTION`]), with
/// [`Error::TooNoisyForOrientations`].
pub fn require_linear(u: &CompassUncertainty, noise_rel: f64, max_product: f64) -> Result<()> {
    let product = noise_rel * u.dilution;
    if product <= max_product {
        Ok(())
    } else {
        Err(Error::TooNoisyForOrientations {
            noise_rel,
            dilution: u.dilution,
            product,
            max_product,
        })
    }
}

/// Refuses a calibration whose own heading-error bound (3σ plus systematic), widened to the
/// Student-t quantile of the `dof` degrees of freedom its σ was estimated from (readings
/// less parameters), exceeds `max_bound_deg`, with [`Error::TooUncertain`]: too few readings
/// for their noise and the orientations they cover. More readings lower it as `1/√N`.
pub fn require_certain(q: &CompassQuality, dof: f64, max_bound_deg: f64) -> Result<()> {
    let t = t_factor_exact_small(dof);
    let bound_deg = q.heading_error_bound_deg() * t;
    if bound_deg <= max_bound_deg {
        return Ok(());
    }
    Err(Error::TooUncertain {
        bound_deg,
        max_deg: max_bound_deg,
        points: q.fit.points,
        noise_rel: q.heading_noise_rms_deg.to_radians(),
        widened: if t > WIDENING_WORTH_SAYING {
            ", widened for a noise estimated from few readings"
        } else {
            ""
        },
    })
}

/// The Student-t widening below which [`require_certain`] does not mention it: 1 %, the
/// accuracy of the Cornish–Fisher series it comes from (reached at about 250 degrees of
/// freedom).
const WIDENING_WORTH_SAYING: f64 = 1.01;

#[cfg(test)]
mod tests {
    use super::super::{assess_2d, assess_3d};
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;
    use nalgebra::{Rotation3, Unit, Vector2, Vector3};
    use proptest::prelude::*;
    use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
    use truenorth_core::{NoiseSource, SplitMix64};

    fn fibonacci(n: usize) -> Vec<Vector3<f64>> {
        let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
        (0..n)
            .map(|k| {
                let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let (s, c) = (golden * k as f64).sin_cos();
                Vector3::new(r * c, r * s, z)
            })
            .collect()
    }

    fn noisy(points: &[Vector3<f64>], rng: &mut SplitMix64, sigma: f64) -> Vec<Vector3<f64>> {
        points
            .iter()
            .map(|p| p * (1.0 + rng.normal(sigma)))
            .collect()
    }

    fn u3(points: &[Vector3<f64>]) -> CompassUncertainty {
        assess_3d(points, &CompassCalibration3d::identity(), 1.0).uncertainty
    }

    /// The constants are the dilutions of the uniform distributions, and a noise-free even
    /// set (the residual is zero, so only the geometry enters) reaches them.
    #[test]
    fn even_coverage_reaches_the_documented_dilutions() {
        let mut rng = SplitMix64::new(1);
        let sphere = u3(&noisy(&fibonacci(20_000), &mut rng, 0.01));
        assert!(
            (sphere.dilution / DILUTION_EVEN_SPHERE - 1.0).abs() < 1e-3,
            "{}",
            sphere.dilution
        );
        assert!((13.5f64.sqrt() - DILUTION_EVEN_SPHERE).abs() < 1e-15);
        // Ten readings 36° apart: as good per reading as a continuous circle.
        let ten: Vec<Vector2<f64>> = (0..10)
            .map(|k| {
                let a = core::f64::consts::TAU * k as f64 / 10.0;
                Vector2::new(a.cos(), a.sin()) * (1.0 + rng.normal(0.01))
            })
            .collect();
        // The 2-D support takes each reading at the centre of its 0.5° bin, at most 0.25°
        // (4.4·10⁻³ rad) from it; these readings lie on bin boundaries, the worst case, and
        // a direction error δ moves the dilution of an even set by about δ relative
        // (measured 2.2·10⁻³): the limit is 2δ.
        let c = assess_2d(&ten, &CompassCalibration2d::identity(), 1.0)
            .quality
            .uncertainty;
        let delta = 0.25f64.to_radians();
        assert!(
            (c.dilution / DILUTION_EVEN_CIRCLE - 1.0).abs() < 2.0 * delta,
            "{}",
            c.dilution
        );
        assert!((c.efficiency(2) - 1.0).abs() < 4.0 * delta);
    }

    /// σ·G/√N is the standard deviation of the heading error (the 3σ bound over three), and
    /// the hard-iron σ of an even sphere is `σ·F·√3/√N` (its `A/N` block is `I/3`).
    #[test]
    fn predicted_sigmas_match_the_closed_forms() {
        let mut rng = SplitMix64::new(2);
        let n = 4000;
        let pts: Vec<_> = noisy(&fibonacci(n), &mut rng, 0.01)
            .iter()
            .map(|p| p * 50.0)
            .collect();
        let a = assess_3d(&pts, &CompassCalibration3d::identity(), 50.0);
        let sigma = 0.01 * (n as f64 / (n - 9) as f64).sqrt();
        let expect_h = sigma * 50.0 * 3f64.sqrt() / (n as f64).sqrt();
        for h in a.uncertainty.hard_iron_sigma {
            assert!((h / expect_h - 1.0).abs() < 0.1, "{h} vs {expect_h}");
        }
        let g = a.heading_error_3sigma_deg.to_radians() / 3.0;
        let expect_g = a.fit.residual_rms_rel * a.uncertainty.dilution / (n as f64).sqrt();
        assert!((g / expect_g - 1.0).abs() < 0.01, "{g} vs {expect_g}");
    }

    /// A field rotated about one axis (a great circle, or a cone when the axis is not
    /// perpendicular to the field) determines nothing; with hand-held wobble it is still far
    /// from determined. A hemisphere is determined, five times worse than a sphere.
    #[test]
    fn single_axis_turns_are_undetermined_and_a_hemisphere_is_not() {
        let mut rng = SplitMix64::new(3);
        let dip = 65f64.to_radians();
        let field = Vector3::new(dip.cos(), 0.0, dip.sin());
        let turn = |wobble_deg: f64, rng: &mut SplitMix64| -> Vec<Vector3<f64>> {
            (0..720)
                .map(|k| {
                    let yaw = Rotation3::from_axis_angle(
                        &Vector3::z_axis(),
                        k as f64 * 0.5f64.to_radians(),
                    );
                    let axis = Unit::new_normalize(Vector3::new(
                        rng.normal(1.0),
                        rng.normal(1.0),
                        rng.normal(1.0),
                    ));
                    let wobble =
                        Rotation3::from_axis_angle(&axis, rng.normal(wobble_deg.to_radians()));
                    (yaw * wobble).inverse() * field * (1.0 + rng.normal(0.005))
                })
                .collect()
        };
        let flat = u3(&turn(0.0, &mut rng));
        assert!(require_determined(&flat, 3, 10.0, "").is_err(), "{flat:?}");
        for wobble in [1.0, 3.0, 10.0] {
            let u = u3(&turn(wobble, &mut rng));
            assert!(u.dilution > 200.0, "wobble {wobble}: {}", u.dilution);
            assert!(require_determined(&u, 3, 10.0, "").is_err());
        }
        let upper: Vec<_> = fibonacci(4000).into_iter().filter(|p| p.z > 0.0).collect();
        let h = u3(&noisy(&upper, &mut rng, 0.005));
        assert!((15.0..22.0).contains(&h.dilution), "{}", h.dilution);
        assert!(require_determined(&h, 3, 10.0, "").is_ok());
    }

    proptest! {
        /// The dilution does not depend on how the readings are turned (it is a property of
        /// their directions relative to each other), to the resolution of the fixed lattice
        /// of test directions its maximum is taken over (256 directions, about 13° apart:
        /// the worst direction falls between them differently), and the geometric error is
        /// the dilution times the model error. The directions are drawn at least 45° apart,
        /// more than the widest equal-area cell (41°, the polar ones), so that turning them
        /// never puts two into one cell and the support weighs each alike: which readings
        /// share a cell does depend on the turn.
        #[test]
        fn dilution_is_invariant_under_rotation(
            axis in proptest::array::uniform3(-1.0f64..1.0),
            angle in -3.0f64..3.0,
            seed in 0u64..1000,
        ) {
            prop_assume!(Vector3::from(axis).norm() > 0.1);
            let rot = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::from(axis)), angle);
            let mut rng = SplitMix64::new(seed);
            let mut pts: Vec<Vector3<f64>> = Vec::new();
            // Eleven: well short of the ~14 at which random caps of 22.5° jam the sphere.
            while pts.len() < 11 {
                let d = Vector3::new(rng.normal(1.0), rng.normal(1.0), rng.normal(1.0)).normalize();
                if pts.iter().all(|p| p.normalize().dot(&d) < 45f64.to_radians().cos()) {
                    pts.push(d * (1.0 + rng.normal(0.01)));
                }
            }
            let turned: Vec<_> = pts.iter().map(|p| rot * p).collect();
            let (a, b) = (u3(&pts).dilution, u3(&turned).dilution);
            prop_assert!((a / b - 1.0).abs() < 0.05, "{a} vs {b}");
            let u = u3(&pts);
            let expect = (u.dilution * MODEL_ERROR_REL).to_degrees();
            prop_assert!(u.geometry_error_deg() == expect || (expect.is_infinite() && u.geometry_error_deg().is_infinite()));
        }

        /// Any finite or non-finite readings: a report without panic, and never a finite
        /// dilution from fewer readings than parameters.
        #[test]
        fn no_panic_on_any_input(v in proptest::collection::vec(proptest::array::uniform3(proptest::num::f64::ANY), 0..12)) {
            let pts: Vec<Vector3<f64>> = v.into_iter().map(Vector3::from).collect();
            let u = u3(&pts);
            if pts.len() <= 9 {
                prop_assert!(u.dilution.is_infinite());
            }
            prop_assert!((0.0..=1.0).contains(&u.efficiency(3)));
        }
    }
}
