//! Tests of the least-squares ellipsoid fit.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use truenorth_core::Error;

use super::config::*;
use super::fit::*;
use crate::fits::ellipsoid::direct::PAIRS;
use crate::fits::ellipsoid::direct::from_params;
use crate::fits::ellipsoid::direct::moments;
use crate::fits::ellipsoid::fit::radial_normal_equations;
use crate::fits::normalise::Normaliser;

fn sphere_points(n: usize) -> Vec<Vector3<f64>> {
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

fn distorted(n: usize) -> (Vec<Vector3<f64>>, Matrix3<f64>, Vector3<f64>) {
    let w = Matrix3::new(1.2, 0.1, -0.05, 0.1, 0.9, 0.08, -0.05, 0.08, 1.05);
    let b = Vector3::new(0.3, -0.7, 0.2);
    let pts = sphere_points(n)
        .into_iter()
        .map(|u| b + w * u * 50.0)
        .collect();
    (pts, w, b)
}

#[test]
fn radial_jacobian_matches_finite_differences() {
    let (pts, _, _) = distorted(60);
    let pts: Vec<_> = pts
        .iter()
        .enumerate()
        .map(|(k, p)| p * (1.0 + 0.03 * ((k * 5 % 13) as f64 / 13.0 - 0.5)))
        .collect();
    let norm = Normaliser::of(&pts).unwrap();
    let p0 = SVector::<f64, 9>::from([0.05, -0.1, 0.02, 1.1, 0.1, -0.05, 0.9, 0.07, 1.0]);
    let ne = radial_normal_equations(&pts, &norm, &p0).unwrap();
    for i in 0..9 {
        let h = 1e-6;
        let (mut a, mut b) = (p0, p0);
        a[i] += h;
        b[i] -= h;
        let ca = radial_normal_equations(&pts, &norm, &a).unwrap().cost;
        let cb = radial_normal_equations(&pts, &norm, &b).unwrap().cost;
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
    let (pts, _, _) = distorted(61);
    let norm = Normaliser::of(&pts).unwrap();
    let p = SVector::<f64, 9>::from([0.05, -0.1, 0.02, 1.1, 0.1, -0.05, 0.9, 0.07, 1.0]);
    let e = from_params(&p);
    let (mut jtj, mut jtr, mut cost) = (SMatrix::<f64, 9, 9>::zeros(), SVector::zeros(), 0.0);
    for m in &pts {
        let v = norm.apply(m) - e.centre;
        let w = e.unit_map * v;
        let rho = w.norm();
        let jc = -(e.unit_map * w) / rho;
        let mut j = SVector::<f64, 9>::zeros();
        j.fixed_rows_mut::<3>(0).copy_from(&jc);
        for (k, &(a, b)) in PAIRS.iter().enumerate() {
            j[3 + k] = if a == b {
                w[a] * v[a]
            } else {
                w[a] * v[b] + w[b] * v[a]
            } / rho;
        }
        let r = rho - 1.0;
        jtj += j * j.transpose();
        jtr += j * r;
        cost += r * r;
    }
    let ne = radial_normal_equations(&pts, &norm, &p).unwrap();
    assert!((ne.cost - cost).abs() < 1e-12 * cost);
    assert!((ne.jtj - jtj).amax() < 1e-12 * jtj.amax());
    assert!((ne.jtr - jtr).amax() < 1e-12 * jtj.amax());
}

/// The scatter matrix from the 35 monomial sums equals `Σ d dᵀ` summed directly.
#[test]
fn moments_match_outer_products() {
    let (pts, _, _) = distorted(75);
    let norm = Normaliser::of(&pts).unwrap();
    let (s, cov) = moments(&pts, &norm).unwrap();
    let mut reference = SMatrix::<f64, 10, 10>::zeros();
    for p in &pts {
        let q = norm.apply(p);
        let (x, y, z) = (q.x, q.y, q.z);
        let d = SVector::<f64, 10>::from([
            x * x,
            y * y,
            z * z,
            2.0 * y * z,
            2.0 * x * z,
            2.0 * x * y,
            2.0 * x,
            2.0 * y,
            2.0 * z,
            1.0,
        ]);
        reference += d * d.transpose();
    }
    assert!((s - reference).amax() < 1e-12 * reference.amax());
    assert_eq!(s[(9, 9)], pts.len() as f64);
    assert!((cov.trace() - 1.0).abs() < 1e-12);
}

#[test]
fn exact_ellipsoid_is_recovered() {
    let (pts, w, b) = distorted(300);
    // The symmetric soft iron is w⁻¹ up to the scale fixed by det = 1.
    let truth = w.try_inverse().unwrap();
    let truth = truth / truth.determinant().cbrt();
    for refine in [false, true] {
        let opts = EllipsoidConfig {
            refine,
            ..Default::default()
        };
        let sol = fit_ellipsoid(&pts, &opts).unwrap();
        assert!(
            (sol.params.hard_iron - b).norm() < 1e-8,
            "{}",
            sol.params.hard_iron
        );
        assert!((sol.params.soft_iron - truth).norm() < 1e-9);
        assert!(sol.quality.fit.residual_rms_rel < 1e-10);
        assert!((sol.quality.field_magnitude - 50.0 * w.determinant().cbrt()).abs() < 1e-8);
    }
}

#[test]
fn refusals() {
    let (pts, _, _) = distorted(300);
    assert!(matches!(
        fit_ellipsoid(&pts[..9], &Default::default()),
        Err(Error::TooFewPoints { got: 9, need: 10 })
    ));
    let ring: Vec<_> = (0..100)
        .map(|k| {
            let a = k as f64 * 0.1;
            Vector3::new(a.cos(), a.sin(), 0.3)
        })
        .collect();
    assert!(fit_ellipsoid(&ring, &Default::default()).is_err());
    let mut bad = pts.clone();
    bad[7].z = f64::INFINITY;
    assert!(matches!(
        fit_ellipsoid(&bad, &Default::default()),
        Err(Error::NonFinite { .. })
    ));
    // A hyperboloid of one sheet, x² + y² − z² = 1, sampled all round.
    let hyp: Vec<_> = (0..400)
        .map(|k| {
            let t = -1.2 + 2.4 * (k % 20) as f64 / 19.0;
            let a = (k / 20) as f64 * core::f64::consts::TAU / 20.0;
            Vector3::new(t.cosh() * a.cos(), t.cosh() * a.sin(), t.sinh())
        })
        .collect();
    let r = fit_ellipsoid(&hyp, &Default::default());
    assert!(matches!(r, Err(Error::NotAnEllipse { .. })), "{r:?}");
}
