//! The joint fit's parameters (see `solve`): their layout in the parameter vector, the
//! model they unpack to, the level frame a shot's pointing axis is measured in, and how much
//! of the readings a pass keeps at once.

// `!(x > limit)` is deliberate: it is true for NaN, so a NaN fails the check instead of
// slipping through it.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::{Matrix3, Rotation3, SVector, Vector3};

/// Number of parameters: `c_a` (3), `B_a` (6), `c_m` (3), `B_m` (6), `ω` (3), `s`, and the
/// pointing axis's two offsets from x.
pub(crate) const P: usize = 24;
pub(crate) const CA: usize = 0;
pub(crate) const BA: usize = 3;
pub(crate) const CM: usize = 9;
pub(crate) const BM: usize = 12;
pub(crate) const OMEGA: usize = 18;
pub(crate) const S: usize = 21;
pub(crate) const PT: usize = 22;

/// Index pairs of the six free entries of a symmetric matrix, in parameter order.
pub(crate) const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// The symmetric matrix of six parameters.
pub(crate) fn sym(b: &[f64]) -> Matrix3<f64> {
    let mut m = Matrix3::zeros();
    for (k, &(r, c)) in PAIRS.iter().enumerate() {
        m[(r, c)] = b[k];
        m[(c, r)] = b[k];
    }
    m
}

/// The six parameters of a symmetric matrix.
pub(crate) fn unsym(m: &Matrix3<f64>) -> [f64; 6] {
    PAIRS.map(|(r, c)| 0.5 * (m[(r, c)] + m[(c, r)]))
}

/// The pointing axis with offsets `(α, β)` from x: `(1, α, β)/|·|`.
pub(crate) fn pointing(alpha: f64, beta: f64) -> Vector3<f64> {
    Vector3::new(1.0, alpha, beta).normalize()
}

/// The parameters, unpacked.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Model {
    pub c_a: Vector3<f64>,
    pub b_a: Matrix3<f64>,
    pub c_m: Vector3<f64>,
    pub b_m: Matrix3<f64>,
    pub rot: Matrix3<f64>,
    pub s: f64,
    pub p: Vector3<f64>,
}

impl Model {
    pub fn of(theta: &SVector<f64, P>, r0: &Rotation3<f64>) -> Self {
        let t = theta.as_slice();
        Self {
            c_a: Vector3::new(t[CA], t[CA + 1], t[CA + 2]),
            b_a: sym(&t[BA..BA + 6]),
            c_m: Vector3::new(t[CM], t[CM + 1], t[CM + 2]),
            b_m: sym(&t[BM..BM + 6]),
            rot: (r0 * Rotation3::new(Vector3::new(t[OMEGA], t[OMEGA + 1], t[OMEGA + 2])))
                .into_inner(),
            s: t[S],
            p: pointing(t[PT], t[PT + 1]),
        }
    }
}

/// The direction of `p` in the level frame of a reading whose unit specific force is `u`
/// and unit field (in the same frame) `g`: `(e₁·p, e₂·p, e₃·p)` with `e₃ = u`,
/// `e₂ = u × g/|u × g|`, `e₁ = e₂ × e₃`. For a specific force (pointing up) the frame is
/// (north, west, up). `None` when gravity and the field are parallel.
pub(crate) fn level_direction(
    u: &Vector3<f64>,
    g: &Vector3<f64>,
    p: &Vector3<f64>,
) -> Option<Vector3<f64>> {
    let n = u.cross(g);
    let nn = n.norm();
    if !(nn > 1e-9) {
        return None;
    }
    let e2 = n / nn;
    let e1 = e2.cross(u);
    Some(Vector3::new(e1.dot(p), e2.dot(p), u.dot(p)))
}

/// How much of the readings a pass of the joint fit keeps at once; past that, it passes
/// over them again instead.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Limits {
    /// The most shots of a run kept for its rows (about 650 bytes each with their
    /// Jacobians); a longer run takes two more passes.
    pub run_shots: usize,
    /// The most level frames the run search keeps (80 bytes each); a stretch of shots
    /// aimed one way longer than twice that takes more passes.
    pub stretch_frames: usize,
}

/// The limits of the fit: a few megabytes each.
pub(crate) const LIMITS: Limits = Limits {
    run_shots: 1 << 12,
    stretch_frames: 1 << 16,
};
