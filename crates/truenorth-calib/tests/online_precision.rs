//! The online calibrators in `f32` against `f64`, on the same readings: simulated turns and
//! tumbles, and the real magcal recordings (../shared/data; skipped visibly where absent,
//! a failure under CI).
//!
//! In `f32` the running sums and retained readings are single precision and the fit runs in
//! `f64` on the sums converted exactly, so the whole difference between the two
//! calibrations comes from the sums' rounding. Each sum of `n` products is off by at most
//! `(n − 1)·u` of the sum of its terms' magnitudes (recursive summation, Higham 2002,
//! "Accuracy and Stability of Numerical Algorithms", §4.2, `u = ε/2`), plus the rounding of
//! the reading and of the product of up to four coordinates (`5u`). A perturbation `δS` of
//! the scatter matrix moves the fitted conic, the eigenvector of its smallest eigenvalue, by
//! at most `‖δS‖ / gap`, where `gap` is the distance to the next eigenvalue (Davis & Kahan
//! 1970, sin θ theorem); relative to `‖S‖` that is `κ = λ_max / gap`. So the hard iron
//! relative to the field and the heading (radians) may differ by `(n + 4)·u·κ` — the
//! tolerance held below, with `κ` computed from the readings.
//!
//! Each test prints its figures: hard-iron difference relative to the field, largest
//! heading difference (degrees), and the tolerance.

mod common;
mod recordings;

use common::Model2;
use nalgebra::{DMatrix, Matrix3, SMatrix, Vector2, Vector3};
use proptest::prelude::*;
use recordings::sunsided_mag;
use truenorth_calib::{
    OnlineEllipseCalibrator, OnlineEllipseConfig, OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
};
use truenorth_compass::{CompassCalibration2d, CompassCalibration3d};
use truenorth_core::{Calibrator, Mag2Sample, Mag3Sample, OnlineCalibrator, angle_diff};

/// The unit roundoff of `f32`.
const U32: f64 = f32::EPSILON as f64 / 2.0;

/// `λ_max / gap` of the scatter matrix `Σ ξ ξᵀ` of the design vectors `ξ` of the
/// readings in the coordinates the fits use (centroid at the origin, RMS radius 1), `gap`
/// the distance between its two smallest eigenvalues.
fn conditioning(design: &[Vec<f64>]) -> f64 {
    let k = design[0].len();
    let mut s = DMatrix::<f64>::zeros(k, k);
    for d in design {
        let v = nalgebra::DVector::from_column_slice(d);
        s += &v * v.transpose();
    }
    let mut e: Vec<f64> = s.symmetric_eigen().eigenvalues.iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e[k - 1] / (e[1] - e[0])
}

/// Centroid and RMS radius of points, for the fits' normalisation.
fn normaliser<const D: usize>(pts: &[SMatrix<f64, D, 1>]) -> (SMatrix<f64, D, 1>, f64) {
    let c = pts.iter().sum::<SMatrix<f64, D, 1>>() / pts.len() as f64;
    let r = (pts.iter().map(|p| (p - c).norm_squared()).sum::<f64>() / pts.len() as f64).sqrt();
    (c, r)
}

fn conditioning_2d(pts: &[Vector2<f64>]) -> f64 {
    let (c, r) = normaliser(pts);
    let design: Vec<Vec<f64>> = pts
        .iter()
        .map(|p| {
            let q = (p - c) / r;
            vec![q.x * q.x, q.x * q.y, q.y * q.y, q.x, q.y, 1.0]
        })
        .collect();
    conditioning(&design)
}

fn conditioning_3d(pts: &[Vector3<f64>]) -> f64 {
    let (c, r) = normaliser(pts);
    let design: Vec<Vec<f64>> = pts
        .iter()
        .map(|p| {
            let q = (p - c) / r;
            vec![
                q.x * q.x,
                q.y * q.y,
                q.z * q.z,
                2.0 * q.y * q.z,
                2.0 * q.x * q.z,
                2.0 * q.x * q.y,
                2.0 * q.x,
                2.0 * q.y,
                2.0 * q.z,
                1.0,
            ]
        })
        .collect();
    conditioning(&design)
}

/// The figures of one comparison.
struct Figures {
    hard_rel: f64,
    heading_deg: f64,
    tol: f64,
}

impl Figures {
    fn check(&self, what: &str) {
        println!(
            "{what}: hard-iron difference {:.2e} of the field, heading difference {:.2e}°, tolerance {:.2e} (rad or of the field)",
            self.hard_rel, self.heading_deg, self.tol
        );
        assert!(self.hard_rel <= self.tol, "{what}: hard iron");
        assert!(self.heading_deg.to_radians() <= self.tol, "{what}: heading");
    }
}

/// The 2-D calibrators in both precisions over `pts`; the f32 calibration's headings
/// against the f64 one's on every reading.
fn compare_2d(pts: &[Vector2<f64>]) -> Figures {
    let cfg = OnlineEllipseConfig::default();
    let mut wide = OnlineEllipseCalibrator::new(cfg).unwrap();
    let mut narrow = OnlineEllipseCalibrator::<f32>::with_precision(cfg).unwrap();
    for (k, &p) in pts.iter().enumerate() {
        let s = Mag2Sample {
            t_s: k as f64,
            mag: p,
        };
        wide.push(&s).unwrap();
        narrow.push_reading(k as f64, &p.map(|x| x as f32)).unwrap();
    }
    let w = wide.solve().unwrap();
    let n = narrow.solve().unwrap();
    // The f32 calibration in f64 (exact), so only the calibrations differ, not their use.
    let n64 = CompassCalibration2d {
        hard_iron: n.params.hard_iron.map(f64::from),
        soft_iron: n.params.soft_iron.map(f64::from),
    };
    let field = w.quality.field_magnitude;
    let heading = pts
        .iter()
        .map(|p| angle_diff(n64.heading_rad(p), w.params.heading_rad(p)).abs())
        .fold(0.0, f64::max);
    // The estimate comes back in f32 as well.
    assert!(narrow.estimate().is_some());
    Figures {
        hard_rel: (n64.hard_iron - w.params.hard_iron).norm() / field,
        heading_deg: heading.to_degrees(),
        tol: (pts.len() as f64 + 4.0) * U32 * conditioning_2d(pts),
    }
}

/// As [`compare_2d`] for the ellipsoid; the heading is the direction of the calibrated
/// field (the angle between the two calibrations' corrected readings).
fn compare_3d(pts: &[Vector3<f64>]) -> Figures {
    let cfg = OnlineEllipsoidConfig::default();
    let mut wide = OnlineEllipsoidCalibrator::new(cfg).unwrap();
    let mut narrow = OnlineEllipsoidCalibrator::<f32>::with_precision(cfg).unwrap();
    for (k, &p) in pts.iter().enumerate() {
        let s = Mag3Sample {
            t_s: k as f64,
            mag: p,
        };
        wide.push(&s).unwrap();
        narrow.push_reading(k as f64, &p.map(|x| x as f32)).unwrap();
    }
    let w = wide.solve().unwrap();
    let n = narrow.solve().unwrap();
    let n64 = CompassCalibration3d {
        hard_iron: n.params.hard_iron.map(f64::from),
        soft_iron: n.params.soft_iron.map(f64::from),
    };
    let field = w.quality.field_magnitude;
    let heading = pts
        .iter()
        .map(|p| n64.correct(p).angle(&w.params.correct(p)))
        .fold(0.0, f64::max);
    Figures {
        hard_rel: (n64.hard_iron - w.params.hard_iron).norm() / field,
        heading_deg: heading.to_degrees(),
        tol: (pts.len() as f64 + 4.0) * U32 * conditioning_3d(pts),
    }
}

#[test]
fn simulated_turns_f32_against_f64() {
    // (hard iron relative to the field, axis ratio, noise relative to the field)
    for (hard, ratio, noise) in [(0.3, 1.2, 0.005), (1.5, 1.4, 0.01), (3.0, 1.1, 0.002)] {
        let model = Model2::new(
            Vector2::new(hard * 30.0, -0.4 * hard * 30.0),
            ratio,
            0.5,
            30.0,
        );
        let pts: Vec<Vector2<f64>> = model
            .turn(720, 10.0, 720.0, noise * 30.0, 11)
            .into_iter()
            .map(|(_, p)| p)
            .collect();
        compare_2d(&pts).check(&format!(
            "simulated turn, hard iron {hard} × field, axis ratio {ratio}, noise {noise}"
        ));
    }
}

#[test]
fn simulated_tumble_f32_against_f64() {
    let w = Matrix3::new(1.1, 0.05, -0.02, 0.05, 0.95, 0.04, -0.02, 0.04, 1.0);
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let m = 1000;
    let pts: Vec<Vector3<f64>> = (0..m)
        .map(|j| {
            let z = 1.0 - (2.0 * j as f64 + 1.0) / m as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * j as f64).sin_cos();
            Vector3::new(15.0, -25.0, 10.0) + 50.0 * (w * Vector3::new(r * c, r * s, z))
        })
        .collect();
    compare_3d(&pts).check("simulated tumble, hard iron 0.6 × field");
}

/// The single-axis turns of the sunsided recording, each on the two axes perpendicular to
/// its turn (as `real_data.rs`), and its full-sphere tumble in 3-D.
#[test]
fn real_magcal_f32_against_f64() {
    for (rec, i, j) in [
        ("rotate-ccw-around-z-pointing-up", 0usize, 1usize),
        ("rotate-ccw-around-x-pointing-up", 1, 2),
        ("rotate-ccw-around-x-pointing-forward", 1, 2),
        ("rotate-ccw-around-y-pointing-left", 0, 2),
    ] {
        let Some(pts3) = sunsided_mag(rec) else {
            return;
        };
        let pts: Vec<Vector2<f64>> = pts3.iter().map(|p| Vector2::new(p[i], p[j])).collect();
        compare_2d(&pts).check(&format!("sunsided {rec}, {} readings", pts.len()));
    }
    let Some(pts) = sunsided_mag("full-sphere") else {
        return;
    };
    compare_3d(&pts).check(&format!("sunsided full-sphere, {} readings", pts.len()));
}

/// Any `f32` (NaN, infinities, subnormals, huge values) and any timestamp: every push is
/// accepted or refused with an error, and progress, solve and estimate answer, without a
/// panic.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<f32>(),
        -100.0f32..100.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::MAX),
        Just(f32::MIN_POSITIVE),
        Just(0.0f32),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn f32_ellipse_never_panics(
        readings in prop::collection::vec((any::<f64>(), any_f32(), any_f32()), 0..200),
        turn in any::<bool>(),
    ) {
        let cfg = OnlineEllipseConfig { refresh_interval_samples: 7, ..Default::default() };
        let mut cal = OnlineEllipseCalibrator::<f32>::with_precision(cfg).unwrap();
        for (k, &(t, x, y)) in readings.iter().enumerate() {
            let _ = cal.push_reading(t, &Vector2::new(x, y));
            if turn {
                // Interleaved with a real turn, so that refreshes succeed and sort readings.
                let psi = (k as f32 * 7.0).to_radians();
                let _ = cal.push_reading(k as f64, &Vector2::new(3.0 + 2.0 * psi.cos(), -1.0 - psi.sin()));
            }
            let _ = cal.push(&Mag2Sample { t_s: t, mag: Vector2::new(f64::from(x) * 1e300, f64::from(y)) });
        }
        let p = cal.progress();
        prop_assert!(p.coverage.is_finite());
        let _ = cal.solve();
        let _ = cal.estimate();
    }

    #[test]
    fn f32_ellipsoid_never_panics(
        readings in prop::collection::vec((any::<f64>(), any_f32(), any_f32(), any_f32()), 0..150),
    ) {
        let cfg = OnlineEllipsoidConfig { refresh_interval_samples: 5, ..Default::default() };
        let mut cal = OnlineEllipsoidCalibrator::<f32>::with_precision(cfg).unwrap();
        for &(t, x, y, z) in &readings {
            let _ = cal.push_reading(t, &Vector3::new(x, y, z));
        }
        let p = cal.progress();
        prop_assert!(p.coverage.is_finite());
        let _ = cal.solve();
        let _ = cal.estimate();
    }
}
