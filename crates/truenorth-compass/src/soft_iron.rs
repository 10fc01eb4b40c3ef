//! Building and reading 2-D soft-iron matrices by their axes.
//!
//! A symmetric soft-iron distortion stretches the horizontal field by `gain_major` along one
//! axis and by `gain_minor` along the perpendicular one, which turns the circle a level compass
//! should trace into an ellipse. These helpers go between that description (what a test or a
//! simulation states: "axis ratio 1.3 rotated 30°") and the matrix.

use nalgebra::Matrix2;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The axes of a symmetric 2×2 matrix: its eigenvalues and the direction of the larger one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipseAxes {
    /// The larger eigenvalue.
    pub major: f64,
    /// The smaller eigenvalue.
    pub minor: f64,
    /// Direction of the major axis, radians counter-clockwise from the x axis of the raw
    /// reading, in (-π/2, π/2].
    pub angle_rad: f64,
}

impl EllipseAxes {
    /// `major / minor`: 1 for a circle; infinite or NaN for a singular matrix.
    pub fn ratio(&self) -> f64 {
        self.major / self.minor
    }
}

/// The symmetric matrix `R(angle) · diag(gain_major, gain_minor) · R(angle)ᵀ`: a stretch by
/// `gain_major` along the direction `angle_rad` (counter-clockwise from the raw x axis) and by
/// `gain_minor` across it.
pub fn soft_iron_from_axes(gain_major: f64, gain_minor: f64, angle_rad: f64) -> Matrix2<f64> {
    let (s, c) = angle_rad.sin_cos();
    let mean = 0.5 * (gain_major + gain_minor);
    let half = 0.5 * (gain_major - gain_minor);
    // R diag(g1, g2) Rᵀ = mean·I + half·[cos 2a, sin 2a; sin 2a, −cos 2a].
    let c2 = c * c - s * s;
    let s2 = 2.0 * s * c;
    Matrix2::new(mean + half * c2, half * s2, half * s2, mean - half * c2)
}

/// The axes of the symmetric part of `m` (closed-form 2×2 eigen decomposition).
pub fn ellipse_axes(m: &Matrix2<f64>) -> EllipseAxes {
    let a = m[(0, 0)];
    let b = 0.5 * (m[(0, 1)] + m[(1, 0)]);
    let d = m[(1, 1)];
    let mean = 0.5 * (a + d);
    let half_diff = 0.5 * (a - d);
    let radius = half_diff.hypot(b);
    EllipseAxes {
        major: mean + radius,
        minor: mean - radius,
        angle_rad: normalise_axis(0.5 * b.atan2(half_diff)),
    }
}

/// An axis direction is defined modulo π; bring it into (-π/2, π/2].
fn normalise_axis(a: f64) -> f64 {
    use core::f64::consts::{FRAC_PI_2, PI};
    if a > FRAC_PI_2 {
        a - PI
    } else if a <= -FRAC_PI_2 {
        a + PI
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn axes_round_trip(major in 1.0f64..3.0, shrink in 0.2f64..0.95, angle in -1.5f64..1.5) {
            let minor = major * shrink;
            let m = soft_iron_from_axes(major, minor, angle);
            let ax = ellipse_axes(&m);
            prop_assert!((ax.major - major).abs() < 1e-12);
            prop_assert!((ax.minor - minor).abs() < 1e-12);
            prop_assert!(truenorth_core::angle_diff(2.0 * ax.angle_rad, 2.0 * angle).abs() < 1e-9);
        }
    }

    #[test]
    fn stretches_along_the_stated_axis() {
        let a = 30f64.to_radians();
        let m = soft_iron_from_axes(1.3, 1.0, a);
        let along = nalgebra::Vector2::new(a.cos(), a.sin());
        let across = nalgebra::Vector2::new(-a.sin(), a.cos());
        assert!(((m * along).norm() - 1.3).abs() < 1e-12);
        assert!(((m * across).norm() - 1.0).abs() < 1e-12);
    }
}
