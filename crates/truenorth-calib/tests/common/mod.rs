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

    /// A random compass of unit field: hard iron of any direction up to `max_hard` of the
    /// field, soft iron up to 1.4 : 1 at any angle.
    #[allow(dead_code)]
    pub fn random(rng: &mut SplitMix64, max_hard: f64) -> Self {
        let a = std::f64::consts::TAU * rng.uniform();
        let hard = Vector2::new(a.cos(), a.sin()) * max_hard * rng.uniform();
        Self::new(
            hard,
            1.0 + 0.4 * rng.uniform(),
            std::f64::consts::PI * rng.uniform(),
            1.0,
        )
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

/// Readings as samples 0.05 s apart, in their order.
#[allow(dead_code)]
pub fn stamped_2d(pts: &[Vector2<f64>]) -> Vec<Mag2Sample> {
    pts.iter()
        .enumerate()
        .map(|(k, &mag)| Mag2Sample {
            t_s: 0.05 * k as f64,
            mag,
        })
        .collect()
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

/// A direction drawn uniformly on the unit sphere.
pub fn uniform_direction(rng: &mut SplitMix64) -> Vector3<f64> {
    loop {
        let v = Vector3::new(rng.normal(1.0), rng.normal(1.0), rng.normal(1.0));
        let n = v.norm();
        if n > 1e-9 {
            return v / n;
        }
    }
}

/// A rotation drawn uniformly (Haar measure: a uniform unit quaternion).
pub fn uniform_rotation(rng: &mut SplitMix64) -> Rotation3<f64> {
    let q = nalgebra::Quaternion::new(
        rng.normal(1.0),
        rng.normal(1.0),
        rng.normal(1.0),
        rng.normal(1.0),
    );
    nalgebra::UnitQuaternion::from_quaternion(q).to_rotation_matrix()
}

/// A three-axis magnetometer with hard and soft iron and isotropic per-axis noise, in a
/// field of magnitude `field` at dip `dip_rad` (NED: north and down components), carried
/// through attitudes (body → NED); its accelerometer reads the specific force at rest with
/// its own per-axis noise, in m/s².
#[derive(Debug, Clone, Copy)]
pub struct Model3 {
    pub hard: Vector3<f64>,
    pub w: Matrix3<f64>,
    pub field: f64,
    pub dip_rad: f64,
    /// Per-axis noise, relative to the field.
    pub noise_rel: f64,
}

impl Model3 {
    /// A random installation: hard iron up to `hard_max` × the field, soft-iron semi-axes
    /// within `1 ± soft` (unit determinant) at a random orientation, dip 30–75°.
    pub fn random(
        rng: &mut SplitMix64,
        field: f64,
        hard_max: f64,
        soft: f64,
        noise_rel: f64,
    ) -> Self {
        let hard = uniform_direction(rng) * field * hard_max * rng.uniform();
        let a = 1.0 + soft * (2.0 * rng.uniform() - 1.0);
        let b = 1.0 + soft * (2.0 * rng.uniform() - 1.0);
        Self {
            hard,
            w: soft3(&uniform_rotation(rng), a, b),
            field,
            dip_rad: (30.0 + 45.0 * rng.uniform()).to_radians(),
            noise_rel,
        }
    }

    /// The field in body axes at `attitude`.
    pub fn body_field(&self, attitude: &Rotation3<f64>) -> Vector3<f64> {
        let (s, c) = self.dip_rad.sin_cos();
        attitude.inverse() * Vector3::new(c, 0.0, s) * self.field
    }

    /// The raw reading at `attitude`.
    pub fn raw(&self, attitude: &Rotation3<f64>, rng: &mut SplitMix64) -> Vector3<f64> {
        let sigma = self.noise_rel * self.field;
        self.hard
            + self.w * self.body_field(attitude)
            + Vector3::new(rng.normal(sigma), rng.normal(sigma), rng.normal(sigma))
    }

    /// The accelerometer at rest at `attitude`, m/s², with per-axis noise `sigma_mps2`.
    pub fn acc(
        &self,
        attitude: &Rotation3<f64>,
        rng: &mut SplitMix64,
        sigma_mps2: f64,
    ) -> Vector3<f64> {
        attitude.inverse() * Vector3::new(0.0, 0.0, -9.80665)
            + Vector3::new(
                rng.normal(sigma_mps2),
                rng.normal(sigma_mps2),
                rng.normal(sigma_mps2),
            )
    }
}

/// `n` attitudes drawn uniformly: a tumble in every direction.
pub fn tumble_attitudes(rng: &mut SplitMix64, n: usize) -> Vec<Rotation3<f64>> {
    (0..n).map(|_| uniform_rotation(rng)).collect()
}

/// `n` attitudes of a turn through `span_deg` about one body axis (random), from a random
/// start, each tilted by a random wobble of standard deviation `wobble_deg` (a hand-held
/// turn).
pub fn axis_turn_attitudes(
    rng: &mut SplitMix64,
    n: usize,
    span_deg: f64,
    wobble_deg: f64,
) -> Vec<Rotation3<f64>> {
    let start = uniform_rotation(rng);
    let axis = nalgebra::Unit::new_normalize(uniform_direction(rng));
    (0..n)
        .map(|k| {
            let turn = Rotation3::from_axis_angle(
                &axis,
                (span_deg * k as f64 / n.max(2).saturating_sub(1) as f64).to_radians(),
            );
            let tilt_axis = nalgebra::Unit::new_normalize(uniform_direction(rng));
            let wobble =
                Rotation3::from_axis_angle(&tilt_axis, rng.normal(wobble_deg.to_radians()));
            start * turn * wobble
        })
        .collect()
}

/// Shuffles `v` in place (Fisher–Yates).
pub fn shuffle<T>(v: &mut [T], rng: &mut SplitMix64) {
    for i in (1..v.len()).rev() {
        let j = ((rng.uniform() * (i + 1) as f64) as usize).min(i);
        v.swap(i, j);
    }
}

/// Pushes every sample into `c` and solves; only whether it was accepted.
pub fn solve<C: truenorth_core::Calibrator>(
    mut c: C,
    samples: &[C::Sample],
) -> Result<(), truenorth_core::Error> {
    for s in samples {
        c.push(s)?;
    }
    c.solve().map(|_| ())
}

/// The 2-D calibrators, by name, in the order [`solve_2d`] takes them.
pub const NAMES_2D: [&str; 5] = [
    "ellipse",
    "online-ellipse",
    "binned-ellipse",
    "merit-circle",
    "turn",
];

/// Solves `s` with the 2-D calibrator `NAMES_2D[which]`, in its default configuration.
pub fn solve_2d(which: usize, s: &[Mag2Sample]) -> Result<(), truenorth_core::Error> {
    use truenorth_calib::{
        BinnedEllipseCalibrator, EllipseCalibrator, MeritCircleCalibrator, OnlineEllipseCalibrator,
        TurnCompassCalibrator,
    };
    match which {
        0 => solve(EllipseCalibrator::default(), s),
        1 => solve(OnlineEllipseCalibrator::new(Default::default()).unwrap(), s),
        2 => solve(BinnedEllipseCalibrator::default(), s),
        3 => solve(MeritCircleCalibrator::default(), s),
        _ => solve(TurnCompassCalibrator::default(), s),
    }
}
