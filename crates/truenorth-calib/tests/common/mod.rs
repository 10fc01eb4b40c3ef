//! The tiny forward model the least-squares tests share (raw = hard + W·h + noise, W
//! symmetric), independent of the compass crate's model, so the fits are checked against
//! first principles.

// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

use std::f64::consts::PI;

use nalgebra::{Matrix2, Matrix3, Rotation3, Vector2, Vector3};
use proptest::prelude::*;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Mag2Sample, Mag3Sample, NoiseSource, SplitMix64};

/// Rotation by `a` radians in the plane.
pub fn rot2(a: f64) -> Matrix2<f64> {
    let (s, c) = a.sin_cos();
    Matrix2::new(c, -s, s, c)
}

/// A level two-axis compass: `raw = hard + W·h(ψ) + noise`, `h = H (cos ψ, −sin ψ)`,
/// W symmetric positive definite (induced soft iron).
#[derive(Debug, Clone, Copy)]
pub struct Model2 {
    pub hard: Vector2<f64>,
    pub w: Matrix2<f64>,
    pub field: f64,
}

impl Model2 {
    /// W with semi-axis ratio `ratio`, major axis at `angle` from x, unit determinant.
    pub fn new(hard: Vector2<f64>, ratio: f64, angle: f64, field: f64) -> Self {
        let d = Matrix2::new(ratio.sqrt(), 0.0, 0.0, 1.0 / ratio.sqrt());
        Self {
            hard,
            w: rot2(angle) * d * rot2(angle).transpose(),
            field,
        }
    }

    /// The reading at heading `psi` with per-axis noise `sigma`.
    pub fn raw(&self, psi: f64, noise: &mut impl NoiseSource, sigma: f64) -> Vector2<f64> {
        let h = Vector2::new(self.field * psi.cos(), -self.field * psi.sin());
        self.hard + self.w * h + Vector2::new(noise.normal(sigma), noise.normal(sigma))
    }

    /// The exact calibration, in the fits' convention (det soft iron = 1), and its field.
    pub fn truth(&self) -> (CompassCalibration2d, f64) {
        let s = self.w.try_inverse().unwrap();
        let s = s / s.determinant().sqrt();
        (
            CompassCalibration2d {
                hard_iron: self.hard,
                soft_iron: s,
            },
            self.field * self.w.determinant().sqrt(),
        )
    }

    /// `n` headings evenly over `span_deg` from `start_deg`, with per-axis noise `sigma`.
    pub fn turn(
        &self,
        n: usize,
        start_deg: f64,
        span_deg: f64,
        sigma: f64,
        seed: u64,
    ) -> Vec<(f64, Vector2<f64>)> {
        let mut rng = SplitMix64::new(seed);
        (0..n)
            .map(|k| {
                let psi = (start_deg + span_deg * k as f64 / n as f64).to_radians();
                (psi, self.raw(psi, &mut rng, sigma))
            })
            .collect()
    }

    /// [`Model2::turn`] as timestamped samples, one second apart.
    pub fn samples(
        &self,
        n: usize,
        start_deg: f64,
        span_deg: f64,
        sigma: f64,
        seed: u64,
    ) -> Vec<(f64, Mag2Sample)> {
        self.turn(n, start_deg, span_deg, sigma, seed)
            .into_iter()
            .enumerate()
            .map(|(k, (psi, mag))| (psi, Mag2Sample { t_s: k as f64, mag }))
            .collect()
    }
}

/// `n` Fibonacci-sphere directions of a field `field` seen through `raw = hard + W·h`.
pub fn sphere_turn(
    hard: Vector3<f64>,
    w: &Matrix3<f64>,
    field: f64,
    n: usize,
    sigma: f64,
    seed: u64,
) -> Vec<Vector3<f64>> {
    let mut rng = SplitMix64::new(seed);
    let golden = PI * (3.0 - 5.0_f64.sqrt());
    (0..n)
        .map(|k| {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            let h = Vector3::new(r * c, r * s, z) * field;
            hard + w * h + Vector3::new(rng.normal(sigma), rng.normal(sigma), rng.normal(sigma))
        })
        .collect()
}

/// [`sphere_turn`] as timestamped samples, one second apart.
pub fn sphere_samples(
    hard: Vector3<f64>,
    w: &Matrix3<f64>,
    field: f64,
    n: usize,
    sigma: f64,
    seed: u64,
) -> Vec<Mag3Sample> {
    sphere_turn(hard, w, field, n, sigma, seed)
        .into_iter()
        .enumerate()
        .map(|(k, mag)| Mag3Sample { t_s: k as f64, mag })
        .collect()
}

/// A symmetric positive-definite soft iron with semi-axes `a`, `b`, `1/(ab)` oriented by
/// `rot` (unit determinant).
pub fn soft3(rot: &Rotation3<f64>, a: f64, b: f64) -> Matrix3<f64> {
    let d = Matrix3::from_diagonal(&Vector3::new(a, b, 1.0 / (a * b)));
    rot.matrix() * d * rot.matrix().transpose()
}

/// Any rotation, as roll, pitch and yaw.
pub fn any_rotation() -> impl Strategy<Value = Rotation3<f64>> {
    (-PI..PI, -1.5f64..1.5, -PI..PI).prop_map(|(r, p, y)| Rotation3::from_euler_angles(r, p, y))
}

/// Circular standard deviation of angles (radians): `√(−2 ln R̄)`, `R̄` the length of their
/// mean unit vector (Mardia & Jupp 2000, *Directional Statistics*).
pub fn circular_std(a: &[f64]) -> f64 {
    let (s, c) = a
        .iter()
        .fold((0.0, 0.0), |(s, c), x| (s + x.sin(), c + x.cos()));
    let r = (s * s + c * c).sqrt() / a.len() as f64;
    (-2.0 * r.ln()).max(0.0).sqrt()
}
