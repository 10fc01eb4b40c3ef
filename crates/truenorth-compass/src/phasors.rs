//! The binned-ellipse heading formulas (EP 0634001, claims 7–11).
//!
//! About its origin, the sensed field of a compass with hard and soft iron traces an ellipse
//! that the seed models as two counter-rotating phasors (claim 7):
//!
//! `z(θ) = E_L e^{iθ} + E_R e^{i(φ_R − θ)}`, `φ_R = 2Ω_e`,
//!
//! with `z = (X − X_c) + i(Y − Y_c)` in the raw reading's axes, `E_L` the earth field, `E_R`
//! the soft-iron term and Ω_e the rotation of the ellipse. Rotating by −Ω_e gives
//! `X' = E_L(1 + r) cos(θ − Ω_e)`, `Y' = E_L(1 − r) sin(θ − Ω_e)` with `r = E_R/E_L`, so the
//! ellipse's semi-axis along Ω_e is `|E_L|(1 + r)` and across it `|E_L|(1 − r)`.
//!
//! ## Heading convention
//! θ is the phase of the *earth* phasor, counter-clockwise from the raw x axis. A level
//! compass at heading ψ reads `(H cos ψ, −H sin ψ)`, phase −ψ; a symmetric soft iron
//! `R(α)·diag(s₁, s₂)·R(α)ᵀ` acting on it gives exactly the phasor pair above with θ = −ψ,
//! `E_L = H(s₁ + s₂)/2`, `E_R = H(s₁ − s₂)/2`, `Ω_e = α`. So **heading = −θ_L**. (A rotation
//! of the sensor within its mount is not visible in the locus and is not modelled.)
//!
//! ## Sign of r
//! `r` may be negative: then Ω_e points along the *minor* axis. That is what the seed's S(θ)
//! minimisation returns (see `truenorth-calib`'s binned-ellipse calibrator), and the formulas
//! hold unchanged. [`EllipsePhasors::normalised`] gives the equivalent parameters with `r ≥ 0`.

use core::f64::consts::FRAC_PI_2;

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, check_finite, check_finite2, wrap_pi};

use crate::CompassCalibration2d;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Largest number of steps [`EllipsePhasors::earth_phase_iterative`] takes. The iteration is a
/// contraction with rate `|r|`, so even `|r| = 0.5` reaches 1e-13 in about 45 steps.
pub const ITERATIVE_MAX_STEPS: usize = 64;

/// The seed's ellipse parameters: origin, rotation Ω_e, ratio `r = E_R/E_L` and `|E_L|`.
///
/// Plain serde data, so a compass can store them when switched off and regenerate its bins
/// from them when switched on (claims 13–14).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EllipsePhasors {
    /// Centre of the locus (the hard iron), raw input unit.
    pub origin: Vector2<f64>,
    /// Ω_e: direction of the ellipse axis the parameters refer to, radians counter-clockwise
    /// from the raw x axis. `φ_R = 2Ω_e`.
    pub omega_e_rad: f64,
    /// `r = E_R/E_L`, in (-1, 1). Negative when Ω_e is the minor axis.
    pub ratio: f64,
    /// `|E_L|`: the earth field's magnitude in the raw input unit (the mean of the two
    /// semi-axes).
    pub earth_magnitude: f64,
}

impl EllipsePhasors {
    /// Validated parameters: finite, `|r| < 1`, `|E_L| > 0`.
    pub fn new(
        origin: Vector2<f64>,
        omega_e_rad: f64,
        ratio: f64,
        earth_magnitude: f64,
    ) -> Result<Self> {
        let p = Self {
            origin,
            omega_e_rad,
            ratio,
            earth_magnitude,
        };
        p.validate()?;
        Ok(p)
    }

    /// Checks the invariants of [`Self::new`] (e.g. after deserialising stored parameters).
    pub fn validate(&self) -> Result<()> {
        check_finite2("ellipse origin", &self.origin)?;
        check_finite("ellipse rotation Ω_e", self.omega_e_rad)?;
        check_finite("ellipse ratio E_R/E_L", self.ratio)?;
        check_finite("ellipse |E_L|", self.earth_magnitude)?;
        if self.ratio.abs() >= 1.0 {
            return Err(Error::OutOfRange {
                what: "ellipse ratio E_R/E_L",
                value: self.ratio,
                min: -1.0,
                max: 1.0,
            });
        }
        if self.earth_magnitude <= 0.0 {
            return Err(Error::OutOfRange {
                what: "ellipse |E_L|",
                value: self.earth_magnitude,
                min: f64::MIN_POSITIVE,
                max: f64::INFINITY,
            });
        }
        Ok(())
    }

    /// φ_R = 2Ω_e, the phase difference of the two phasors.
    #[inline]
    pub fn phi_r_rad(&self) -> f64 {
        2.0 * self.omega_e_rad
    }

    /// The semi-axes `(along Ω_e, across Ω_e) = (|E_L|(1 + r), |E_L|(1 − r))`.
    pub fn semi_axes(&self) -> (f64, f64) {
        (
            self.earth_magnitude * (1.0 + self.ratio),
            self.earth_magnitude * (1.0 - self.ratio),
        )
    }

    /// The same ellipse with `r ≥ 0` (Ω_e on the major axis) and Ω_e in (-π/2, π/2].
    pub fn normalised(&self) -> Self {
        let (omega, ratio) = if self.ratio < 0.0 {
            (self.omega_e_rad + FRAC_PI_2, -self.ratio)
        } else {
            (self.omega_e_rad, self.ratio)
        };
        // Ω_e is an axis: defined modulo π.
        let omega = 0.5 * wrap_pi(2.0 * omega);
        Self {
            omega_e_rad: omega,
            ratio,
            ..*self
        }
    }

    /// The sensed (raw) vector when the earth phasor has phase `theta_l_rad`:
    /// `origin + E_L e^{iθ} + E_R e^{i(φ_R − θ)}`.
    pub fn sensed(&self, theta_l_rad: f64) -> Vector2<f64> {
        let (s, c) = theta_l_rad.sin_cos();
        let (s2, c2) = (self.phi_r_rad() - theta_l_rad).sin_cos();
        let el = self.earth_magnitude;
        let er = self.ratio * el;
        self.origin + Vector2::new(el * c + er * c2, el * s + er * s2)
    }

    /// The sensed (raw) vector at magnetic heading `heading_rad` (θ_L = −ψ).
    pub fn sensed_at_heading(&self, heading_rad: f64) -> Vector2<f64> {
        self.sensed(-heading_rad)
    }

    /// The point of the locus whose direction about the origin is `direction_rad`
    /// (counter-clockwise from the raw x axis). Used to regenerate heading bins from stored
    /// parameters (claim 13).
    pub fn point_at_direction(&self, direction_rad: f64) -> Vector2<f64> {
        let (a, b) = self.semi_axes();
        let rel = direction_rad - self.omega_e_rad;
        let (s, c) = rel.sin_cos();
        // tan φ' = (b sin u)/(a cos u) ⇒ u = atan2(a sin φ', b cos φ') (a, b > 0).
        let u = (a * s).atan2(b * c);
        let (su, cu) = u.sin_cos();
        let (so, co) = self.omega_e_rad.sin_cos();
        let (x, y) = (a * cu, b * su);
        self.origin + Vector2::new(x * co - y * so, x * so + y * co)
    }

    /// The rotated coordinates `(X', Y')` of claim 9:
    /// `X' = (X − X_c) cos Ω_e + (Y − Y_c) sin Ω_e`, `Y' = (Y − Y_c) cos Ω_e − (X − X_c) sin Ω_e`.
    #[inline]
    pub fn rotated(&self, raw: &Vector2<f64>) -> Vector2<f64> {
        let d = raw - self.origin;
        let (s, c) = self.omega_e_rad.sin_cos();
        Vector2::new(d.x * c + d.y * s, d.y * c - d.x * s)
    }

    /// θ_L by the closed form (claim 10, restored from the geometry; the printed formula is
    /// garbled): `θ_L = atan2(Y'/(1 − r), X'/(1 + r)) + Ω_e`, wrapped to (-π, π].
    #[inline]
    pub fn earth_phase_closed_form(&self, raw: &Vector2<f64>) -> f64 {
        let p = self.rotated(raw);
        wrap_pi((p.y / (1.0 - self.ratio)).atan2(p.x / (1.0 + self.ratio)) + self.omega_e_rad)
    }

    /// θ_L by the iteration of claim 11:
    /// `θ_L(n+1) = θ_E − r sin(φ_R − θ_L(n) − θ_E)`, from `θ_L(0) = θ_E` (θ_E: phase of the
    /// sensed vector about the origin), until the step is below 1e-13 rad or after
    /// [`ITERATIVE_MAX_STEPS`] steps. Allocation-free.
    ///
    /// Its fixed point is not exactly the closed form's: the exact relation is
    /// `sin δ = r sin(φ_R − θ_L − θ_E)` with `δ = θ_E − θ_L`, and the claim uses δ for sin δ. The
    /// two differ by at most [`Self::iterative_bias_bound_rad`] (≈ r³/6).
    pub fn earth_phase_iterative(&self, raw: &Vector2<f64>) -> f64 {
        let d = raw - self.origin;
        let theta_e = d.y.atan2(d.x);
        let phi_r = self.phi_r_rad();
        let mut theta_l = theta_e;
        for _ in 0..ITERATIVE_MAX_STEPS {
            let next = theta_e - self.ratio * (phi_r - theta_l - theta_e).sin();
            let step = (next - theta_l).abs();
            theta_l = next;
            if step <= 1e-13 || step.is_nan() {
                break;
            }
        }
        wrap_pi(theta_l)
    }

    /// Bound on |claim-11 fixed point − closed form|, radians: with `δ_max = asin|r|`, the
    /// claim's residual `|δ − sin δ| ≤ δ_max³/6`, divided by the slope `1 − |r|` of the
    /// fixed-point equation.
    pub fn iterative_bias_bound_rad(&self) -> f64 {
        let r = self.ratio.abs().min(1.0);
        let dmax = r.asin();
        dmax * dmax * dmax / 6.0 / (1.0 - r)
    }

    /// Heading (radians clockwise from magnetic north, (-π, π]) by the closed form: −θ_L.
    #[inline]
    pub fn heading_closed_form(&self, raw: &Vector2<f64>) -> f64 {
        wrap_pi(-self.earth_phase_closed_form(raw))
    }

    /// Heading by the iterative form of claim 11: −θ_L.
    pub fn heading_iterative(&self, raw: &Vector2<f64>) -> f64 {
        wrap_pi(-self.earth_phase_iterative(raw))
    }

    /// The closed form as the affine map of a [`CompassCalibration2d`]:
    /// `hard_iron = origin`, `soft_iron = R(Ω_e) · diag(1/(1 + r), 1/(1 − r)) · R(Ω_e)ᵀ`.
    ///
    /// The corrected reading is `|E_L|·(cos θ_L, sin θ_L)`: a circle of radius `|E_L|` (the
    /// horizontal field in the input unit), and its heading equals [`Self::heading_closed_form`].
    pub fn to_calibration(&self) -> CompassCalibration2d {
        let (s, c) = self.omega_e_rad.sin_cos();
        let rot = Matrix2::new(c, -s, s, c);
        let scale = Matrix2::new(1.0 / (1.0 + self.ratio), 0.0, 0.0, 1.0 / (1.0 - self.ratio));
        CompassCalibration2d {
            hard_iron: self.origin,
            soft_iron: rot * scale * rot.transpose(),
        }
    }
}

impl From<&EllipsePhasors> for CompassCalibration2d {
    fn from(p: &EllipsePhasors) -> Self {
        p.to_calibration()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
    use proptest::prelude::*;
    use truenorth_core::{SensorModel, angle_diff};

    fn any_phasors() -> impl Strategy<Value = EllipsePhasors> {
        (
            -50.0f64..50.0,
            -50.0f64..50.0,
            -3.2f64..3.2,
            -0.6f64..0.6,
            1.0f64..60.0,
        )
            .prop_map(|(x, y, o, r, e)| EllipsePhasors::new(Vector2::new(x, y), o, r, e).unwrap())
    }

    proptest! {
        #[test]
        fn closed_form_is_the_affine_calibration(
            p in any_phasors(), x in -200.0f64..200.0, y in -200.0f64..200.0,
        ) {
            let raw = Vector2::new(x, y);
            prop_assume!((raw - p.origin).norm() > 1e-6);
            let cal = p.to_calibration();
            prop_assert!(angle_diff(cal.heading_rad(&raw), p.heading_closed_form(&raw)).abs() < 1e-10);
        }

        #[test]
        fn closed_form_inverts_the_phasor_model(p in any_phasors(), heading in -3.2f64..3.2) {
            let raw = p.sensed_at_heading(heading);
            prop_assert!(angle_diff(p.heading_closed_form(&raw), heading).abs() < 1e-9);
            // The corrected reading lies on a circle of radius |E_L|.
            let c = p.to_calibration().correct(&raw);
            prop_assert!((c.norm() - p.earth_magnitude).abs() < 1e-9 * p.earth_magnitude);
        }

        #[test]
        fn iterative_agrees_with_closed_form(p in any_phasors(), heading in -3.2f64..3.2) {
            let raw = p.sensed_at_heading(heading);
            let closed = p.heading_closed_form(&raw);
            let iter = p.heading_iterative(&raw);
            let bound = p.iterative_bias_bound_rad() + 1e-10;
            prop_assert!(angle_diff(iter, closed).abs() <= bound,
                "iter {} closed {} bound {}", iter, closed, bound);
        }

        #[test]
        fn normalised_gives_the_same_headings(p in any_phasors(), heading in -3.2f64..3.2) {
            let raw = p.sensed_at_heading(heading);
            let n = p.normalised();
            prop_assert!(n.ratio >= 0.0);
            prop_assert!(angle_diff(n.heading_closed_form(&raw), heading).abs() < 1e-9);
            prop_assert!((n.sensed_at_heading(heading) - raw).norm() < 1e-9 * p.earth_magnitude);
        }

        #[test]
        fn point_at_direction_is_on_the_locus_in_that_direction(p in any_phasors(), dir in -3.2f64..3.2) {
            let q = p.point_at_direction(dir);
            let d = q - p.origin;
            prop_assert!(angle_diff(d.y.atan2(d.x), dir).abs() < 1e-9);
            let c = p.to_calibration().correct(&q);
            prop_assert!((c.norm() - p.earth_magnitude).abs() < 1e-9 * p.earth_magnitude);
        }

        #[test]
        fn the_model_is_a_phasor_pair(
            g1 in 0.6f64..1.6, g2 in 0.6f64..1.6, alpha in -1.5f64..1.5,
            hx in -30.0f64..30.0, hy in -30.0f64..30.0, heading in -3.2f64..3.2,
        ) {
            // A symmetric soft iron R(α)diag(g1, g2)R(α)ᵀ is E_L = H(g1+g2)/2, r = (g1−g2)/(g1+g2), Ω_e = α.
            let h = 20.0;
            let m = MagnetometerModel2d::new(Vector2::new(hx, hy), soft_iron_from_axes(g1, g2, alpha), 0.0).unwrap();
            let p = EllipsePhasors::new(Vector2::new(hx, hy), alpha, (g1 - g2) / (g1 + g2), h * (g1 + g2) / 2.0).unwrap();
            let raw = m.ideal(&HeadingTruth { heading_rad: heading, horizontal_field: h }).unwrap();
            prop_assert!((p.sensed_at_heading(heading) - raw).norm() < 1e-9 * h);
        }
    }

    #[test]
    fn iteration_is_exact_for_a_circle_and_close_for_ratio_1_3() {
        let circle = EllipsePhasors::new(Vector2::new(1.0, 2.0), 0.3, 0.0, 10.0).unwrap();
        let raw = circle.sensed_at_heading(1.0);
        assert!(angle_diff(circle.heading_iterative(&raw), 1.0).abs() < 1e-12);
        // Axis ratio 1.3: r = 0.3/2.3; the two forms differ by < 0.03°.
        let p = EllipsePhasors::new(Vector2::zeros(), 30f64.to_radians(), 0.3 / 2.3, 10.0).unwrap();
        assert!(p.iterative_bias_bound_rad().to_degrees() < 0.03);
        let worst = (0..3600)
            .map(|i| {
                let raw = p.sensed_at_heading(f64::from(i) * 0.1f64.to_radians());
                angle_diff(p.heading_iterative(&raw), p.heading_closed_form(&raw)).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst <= p.iterative_bias_bound_rad(), "{worst}");
    }

    #[test]
    fn validation_and_serde() {
        assert!(EllipsePhasors::new(Vector2::zeros(), 0.0, 1.0, 1.0).is_err());
        assert!(EllipsePhasors::new(Vector2::zeros(), 0.0, 0.1, 0.0).is_err());
        assert!(EllipsePhasors::new(Vector2::new(f64::NAN, 0.0), 0.0, 0.1, 1.0).is_err());
        let p = EllipsePhasors::new(Vector2::new(3.0, -1.0), 0.4, -0.2, 12.0).unwrap();
        let json = serde_json::to_string(&p).unwrap();
        let back: EllipsePhasors = serde_json::from_str(&json).unwrap();
        assert_eq!(back, p);
        assert!(back.validate().is_ok());
    }
}
