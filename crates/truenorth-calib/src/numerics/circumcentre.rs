//! The circle through three points, and how strongly its centre amplifies noise on them.

use nalgebra::Vector2;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Squared amplification of an equilateral triangle inscribed in its circle (the best
/// possible triple): `γ² = 2/3`.
pub const BEST_AMPLIFICATION_SQ: f64 = 2.0 / 3.0;

/// The circle through three points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circumcircle {
    /// Its centre.
    pub centre: Vector2<f64>,
    /// Its radius.
    pub radius: f64,
    /// γ: the RMS per-axis error of the centre per unit of independent isotropic noise on the
    /// three points (dimensionless; `√(2/3)` for an equilateral triangle, unbounded as the
    /// points approach a line or each other).
    pub amplification: f64,
}

/// The circumcircle of `p1`, `p2`, `p3`, or `None` when they are (nearly) collinear,
/// coincident or not finite.
///
/// The centre solves `2(p₂ − p₁)·c = |p₂|² − |p₁|²`, `2(p₃ − p₁)·c = |p₃|² − |p₁|²`, i.e.
/// `A c' = b` with `A = [p₂ − p₁; p₃ − p₁]`, `c' = c − p₁`. Differentiating, a move `dpᵢ` of
/// one point moves the centre by `Jᵢ dpᵢ` with `J₁ = A⁻¹(1, 1)ᵀ(c − p₁)ᵀ`,
/// `J₂ = A⁻¹e₁(p₂ − c)ᵀ`, `J₃ = A⁻¹e₂(p₃ − c)ᵀ`; so with isotropic noise σ per coordinate the
/// centre's per-axis variance is `σ²·γ²`, `γ² = ½ Σ‖Jᵢ‖²_F = ½ ρ² (|A⁻¹e₁|² + |A⁻¹e₂|² +
/// |A⁻¹(e₁ + e₂)|²)`.
pub fn circumcircle(
    p1: &Vector2<f64>,
    p2: &Vector2<f64>,
    p3: &Vector2<f64>,
) -> Option<Circumcircle> {
    let u = p2 - p1;
    let v = p3 - p1;
    let det = u.x * v.y - u.y * v.x;
    let scale = u.norm() * v.norm();
    if !(det.is_finite() && scale.is_finite()) || det.abs() <= 1e-12 * scale || scale == 0.0 {
        return None;
    }
    let (bu, bv) = (0.5 * u.norm_squared(), 0.5 * v.norm_squared());
    // A⁻¹ = (1/det)·[v.y, −u.y; −v.x, u.x]; its columns are A⁻¹e₁ and A⁻¹e₂.
    let col1 = Vector2::new(v.y, -v.x) / det;
    let col2 = Vector2::new(-u.y, u.x) / det;
    let rel = col1 * bu + col2 * bv;
    let radius = rel.norm();
    let gamma_sq = 0.5
        * radius
        * radius
        * (col1.norm_squared() + col2.norm_squared() + (col1 + col2).norm_squared());
    let out = Circumcircle {
        centre: p1 + rel,
        radius,
        amplification: gamma_sq.sqrt(),
    };
    (out.centre.x.is_finite() && out.centre.y.is_finite() && out.amplification.is_finite())
        .then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::{NoiseSource, SplitMix64};

    fn on_circle(c: Vector2<f64>, r: f64, deg: f64) -> Vector2<f64> {
        let a = deg.to_radians();
        c + r * Vector2::new(a.cos(), a.sin())
    }

    proptest! {
        #[test]
        fn finds_the_circle(cx in -100.0f64..100.0, cy in -100.0f64..100.0, r in 0.1f64..100.0,
                            a in 0.0f64..360.0, b in 20.0f64..170.0, c in 20.0f64..170.0) {
            let ctr = Vector2::new(cx, cy);
            let cc = circumcircle(&on_circle(ctr, r, a), &on_circle(ctr, r, a + b), &on_circle(ctr, r, a + b + c)).unwrap();
            prop_assert!((cc.centre - ctr).norm() < 1e-8 * (r + ctr.norm()));
            prop_assert!((cc.radius - r).abs() < 1e-8 * (r + ctr.norm()));
            prop_assert!(cc.amplification >= BEST_AMPLIFICATION_SQ.sqrt() - 1e-9);
        }

        /// Any three points: a circle through them, finite and equidistant from all three
        /// to rounding (scaled by the triple's own amplification of errors), or none — never
        /// a panic.
        #[test]
        fn never_panics(v in proptest::array::uniform6(prop_oneof![
            3 => -100.0f64..100.0,
            1 => proptest::num::f64::ANY,
        ])) {
            let p = [Vector2::new(v[0], v[1]), Vector2::new(v[2], v[3]), Vector2::new(v[4], v[5])];
            if let Some(c) = circumcircle(&p[0], &p[1], &p[2]) {
                prop_assert!(c.centre.iter().all(|x| x.is_finite()) && c.radius.is_finite());
                let scale = p.iter().map(|q| q.norm()).fold(c.radius, f64::max);
                for q in &p {
                    prop_assert!(((q - c.centre).norm() - c.radius).abs() <= 1e-6 * scale * c.amplification.max(1.0));
                }
            }
        }
    }

    #[test]
    fn degenerate_triples_are_refused() {
        let a = Vector2::new(0.0, 0.0);
        let b = Vector2::new(1.0, 1.0);
        assert!(circumcircle(&a, &b, &Vector2::new(2.0, 2.0)).is_none());
        assert!(circumcircle(&a, &a, &b).is_none());
        assert!(circumcircle(&a, &b, &Vector2::new(f64::NAN, 0.0)).is_none());
    }

    #[test]
    fn amplification_predicts_the_centre_scatter() {
        // Three points 40° apart on a unit circle, noise 0.001: measured scatter ≈ γ·σ.
        let pts = [
            on_circle(Vector2::zeros(), 1.0, 0.0),
            on_circle(Vector2::zeros(), 1.0, 40.0),
            on_circle(Vector2::zeros(), 1.0, 80.0),
        ];
        let gamma = circumcircle(&pts[0], &pts[1], &pts[2])
            .unwrap()
            .amplification;
        let mut rng = SplitMix64::new(9);
        let sigma = 1e-4;
        let n = 4000;
        let mut ss = 0.0;
        for _ in 0..n {
            let q: Vec<_> = pts
                .iter()
                .map(|p| p + Vector2::new(rng.normal(sigma), rng.normal(sigma)))
                .collect();
            ss += circumcircle(&q[0], &q[1], &q[2])
                .unwrap()
                .centre
                .norm_squared();
        }
        let per_axis = (ss / (2.0 * n as f64)).sqrt() / sigma;
        assert!(
            (per_axis / gamma - 1.0).abs() < 0.1,
            "measured {per_axis} predicted {gamma}"
        );
        let eq = circumcircle(
            &on_circle(Vector2::zeros(), 1.0, 90.0),
            &on_circle(Vector2::zeros(), 1.0, 210.0),
            &on_circle(Vector2::zeros(), 1.0, 330.0),
        )
        .unwrap();
        assert!((eq.amplification.powi(2) - BEST_AMPLIFICATION_SQ).abs() < 1e-12);
    }
}
