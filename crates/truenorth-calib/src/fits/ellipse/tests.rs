//! Tests of the least-squares ellipse fit.

use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
use truenorth_core::Error;

use super::config::*;
use super::direct::*;
use super::fit::*;
use crate::fits::normalise::Normaliser;

fn ellipse_points(n: usize, span_deg: f64) -> Vec<Vector2<f64>> {
    let c = Vector2::new(3.0, -2.0);
    let th = 0.5_f64;
    let r = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
    (0..n)
        .map(|k| {
            let a = (span_deg * k as f64 / n as f64).to_radians();
            c + r * Vector2::new(5.0 * a.cos(), 3.0 * a.sin())
        })
        .collect()
}

#[test]
fn sampson_jacobian_matches_finite_differences() {
    let pts = ellipse_points(40, 360.0)
        .into_iter()
        .enumerate()
        .map(|(k, p)| p * (1.0 + 0.05 * ((k * 7 % 11) as f64 / 11.0 - 0.5)))
        .collect::<Vec<_>>();
    let norm = Normaliser::of(&pts).unwrap();
    let p0 = SVector::<f64, 5>::new(0.1, -0.05, 1.1, 0.2, 0.9);
    // Check the gradient Jᵀr against the numerical derivative of cost/2.
    let ne = sampson_normal_equations(&pts, &norm, &p0).unwrap();
    for i in 0..5 {
        let h = 1e-6;
        let mut a = p0;
        let mut b = p0;
        a[i] += h;
        b[i] -= h;
        let ca = sampson_normal_equations(&pts, &norm, &a).unwrap().cost;
        let cb = sampson_normal_equations(&pts, &norm, &b).unwrap().cost;
        let num = (ca - cb) / (4.0 * h);
        assert!(
            (num - ne.jtr[i]).abs() < 1e-6 * (1.0 + num.abs()),
            "{i}: {num} vs {}",
            ne.jtr[i]
        );
    }
}

/// The normal equations in `(c, B)` obtained through `A = B²` equal those summed from
/// the Jacobian rows taken directly with respect to `B`.
#[test]
fn normal_equations_through_b_squared_match_direct_rows() {
    let pts = ellipse_points(97, 360.0)
        .into_iter()
        .enumerate()
        .map(|(k, p)| p * (1.0 + 0.05 * ((k * 7 % 11) as f64 / 11.0 - 0.5)))
        .collect::<Vec<_>>();
    let norm = Normaliser::of(&pts).unwrap();
    let p = SVector::<f64, 5>::new(0.1, -0.05, 1.1, 0.2, 0.9);
    let (c, b) = (
        Vector2::new(p[0], p[1]),
        Matrix2::new(p[2], p[3], p[3], p[4]),
    );
    let (mut jtj, mut jtr, mut cost) = (SMatrix::<f64, 5, 5>::zeros(), SVector::zeros(), 0.0);
    for m in &pts {
        let v = norm.apply(m) - c;
        let (w, z) = (b * v, b * b * v);
        let (y, s) = (b * z, z.norm());
        let r = (w.norm_squared() - 1.0) / (2.0 * s);
        let k = r / s;
        let jc = (-z + (b * y) * k) / s;
        let e11 = w.x * v.x - k * (z.x * w.x + y.x * v.x);
        let e12 = (w.x * v.y + w.y * v.x) - k * (z.x * w.y + z.y * w.x + y.x * v.y + y.y * v.x);
        let e22 = w.y * v.y - k * (z.y * w.y + y.y * v.y);
        let j = SVector::<f64, 5>::new(jc.x, jc.y, e11 / s, e12 / s, e22 / s);
        jtj += j * j.transpose();
        jtr += j * r;
        cost += r * r;
    }
    let ne = sampson_normal_equations(&pts, &norm, &p).unwrap();
    assert!((ne.cost - cost).abs() < 1e-12 * cost);
    assert!((ne.jtj - jtj).amax() < 1e-12 * jtj.amax());
    assert!((ne.jtr - jtr).amax() < 1e-12 * jtj.amax());
}

#[test]
fn exact_ellipse_is_recovered() {
    let pts = ellipse_points(50, 360.0);
    for refine in [false, true] {
        let opts = EllipseConfig {
            refine,
            ..Default::default()
        };
        let sol = fit_ellipse(&pts, &opts).unwrap();
        assert!((sol.params.hard_iron - Vector2::new(3.0, -2.0)).norm() < 1e-9);
        assert!((sol.quality.field_magnitude - 15.0_f64.sqrt()).abs() < 1e-9);
        assert!(sol.quality.fit.residual_rms_rel < 1e-9);
        assert!((sol.params.soft_iron.determinant() - 1.0).abs() < 1e-9);
    }
    let e = fit_ellipse_direct(&pts).unwrap();
    let (a, b) = e.semi_axes().unwrap();
    assert!((a - 5.0).abs() < 1e-9 && (b - 3.0).abs() < 1e-9);
}

#[test]
fn refusals() {
    assert!(matches!(
        fit_ellipse(&ellipse_points(5, 360.0), &Default::default()),
        Err(Error::TooFewPoints { got: 5, need: 6 })
    ));
    let line: Vec<_> = (0..20)
        .map(|k| Vector2::new(k as f64, 2.0 * k as f64))
        .collect();
    assert!(matches!(
        fit_ellipse(&line, &Default::default()),
        Err(Error::Degenerate { .. })
    ));
    let hyperbola: Vec<_> = (0..40)
        .map(|k| {
            let t = -1.5 + 3.0 * (k % 20) as f64 / 19.0;
            let s = if k < 20 { 1.0 } else { -1.0 };
            Vector2::new(s * t.cosh(), t.sinh())
        })
        .collect();
    assert!(matches!(
        fit_ellipse(&hyperbola, &Default::default()),
        Err(Error::NotAnEllipse { .. })
    ));
    let mut nan = ellipse_points(20, 360.0);
    nan[3].x = f64::NAN;
    assert!(matches!(
        fit_ellipse(&nan, &Default::default()),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        fit_ellipse(&ellipse_points(100, 150.0), &Default::default()),
        Err(Error::InsufficientCoverage { .. })
    ));
}
