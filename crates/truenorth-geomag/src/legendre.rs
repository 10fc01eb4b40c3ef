//! Schmidt semi-normalised associated Legendre functions P̆ₙᵐ(sin φ′) and their derivatives
//! with respect to the geocentric latitude φ′, to degree and order 12.
//!
//! Definition (WMM2025 Technical Report, §1.2, the functions in eq. 1): P̆ₙᵐ(μ) = √(2 (n−m)!/(n+m)!) Pₙᵐ(μ) for
//! m > 0 and P̆ₙ⁰ = Pₙ, where Pₙᵐ(μ) = (1−μ²)^{m/2} dᵐPₙ(μ)/dμᵐ carries no Condon–Shortley
//! phase. With μ = sin φ′ the factor (1−μ²)^{m/2} is cosᵐ φ′.
//!
//! Why the functions are stored divided by cos φ′ for m ≥ 1: the east component of the field
//! (eq. 11) divides by cos φ′, which is zero at the geographic poles. Every P̆ₙᵐ with m ≥ 1
//! contains at least one factor cos φ′, so keeping P̆ₙᵐ / cos φ′ instead makes the east
//! component and the derivatives finite and continuous all the way to ±90° without a
//! special case at the pole.
//!
//! The recursions used (standard properties of Legendre functions, rewritten for the
//! Schmidt normalisation; see e.g. Abramowitz & Stegun, ch. 8, and Langel 1987, "The main
//! field", in *Geomagnetism* vol. 1, ed. Jacobs):
//! - sectoral: P̆₁¹ = cos φ′, P̆ₙⁿ = cos φ′ · √((2n−1)/(2n)) · P̆ₙ₋₁ⁿ⁻¹ (n ≥ 2);
//! - in degree: P̆ₙᵐ = [(2n−1) μ P̆ₙ₋₁ᵐ − √((n−1)²−m²) P̆ₙ₋₂ᵐ] / √(n²−m²) (n > m);
//! - derivative, from (1−μ²) dPₙᵐ/dμ = −n μ Pₙᵐ + (n+m) Pₙ₋₁ᵐ:
//!   cos φ′ · dP̆ₙᵐ/dφ′ = −n μ P̆ₙᵐ + √(n²−m²) P̆ₙ₋₁ᵐ, and for m = 0
//!   dP̆ₙ⁰/dφ′ = √(n(n+1)/2) · P̆ₙ¹.
//!
//! The square-root factors depend only on (n, m), so they are computed once, at compile
//! time, into constant tables: an evaluation does multiplications and additions only.

use crate::coefficients::{MAX_DEGREE, TABLE_LEN, index};

/// √x for the compile-time tables (`f64::sqrt` is not a `const fn`).
///
/// Start from half the binary exponent (within a factor of √2 of the root), take one Newton
/// step, which by the AM–GM inequality lands at or above the root, and iterate while the
/// iterate keeps shrinking: from above, Newton's iteration decreases monotonically until
/// rounding stops it. The result is within one unit in the last place of the correctly
/// rounded root (checked against `f64::sqrt` in the tests).
const fn const_sqrt(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 || x.is_infinite() {
        return 0.0;
    }
    // Halving the biased exponent bits approximates √x for positive normal numbers.
    let guess = f64::from_bits((x.to_bits() >> 1) + (1023u64 << 51));
    let mut y = 0.5 * (guess + x / guess);
    let mut i = 0;
    while i < 100 {
        let next = 0.5 * (y + x / y);
        if next >= y {
            break;
        }
        y = next;
        i += 1;
    }
    y
}

/// Factors of the recursion in degree, per (n, m) with n > m:
/// `a = (2n−1)/√(n²−m²)`, `b = √((n−1)²−m²)/√(n²−m²)`.
struct DegreeFactors {
    a: [f64; TABLE_LEN],
    b: [f64; TABLE_LEN],
}

const DEGREE_FACTORS: DegreeFactors = {
    let mut a = [0.0; TABLE_LEN];
    let mut b = [0.0; TABLE_LEN];
    let mut n = 1;
    while n <= MAX_DEGREE {
        let mut m = 0;
        while m < n {
            let root = const_sqrt((n * n - m * m) as f64);
            a[index(n, m)] = (2 * n - 1) as f64 / root;
            // (n−1)² − m² ≥ 0 because m ≤ n − 1.
            b[index(n, m)] = const_sqrt(((n - 1) * (n - 1) - m * m) as f64) / root;
            m += 1;
        }
        n += 1;
    }
    DegreeFactors { a, b }
};

/// Sectoral factors √((2n−1)/(2n)) for n ≥ 2 (slot 0 and 1 unused).
const SECTORAL: [f64; MAX_DEGREE + 1] = {
    let mut s = [0.0; MAX_DEGREE + 1];
    let mut n = 2;
    while n <= MAX_DEGREE {
        s[n] = const_sqrt((2 * n - 1) as f64 / (2 * n) as f64);
        n += 1;
    }
    s
};

/// Derivative factors: √(n²−m²) for m ≥ 1, √(n(n+1)/2) for m = 0.
const DERIVATIVE: [f64; TABLE_LEN] = {
    let mut d = [0.0; TABLE_LEN];
    let mut n = 1;
    while n <= MAX_DEGREE {
        d[index(n, 0)] = const_sqrt((n * (n + 1)) as f64 / 2.0);
        let mut m = 1;
        while m <= n {
            d[index(n, m)] = const_sqrt((n * n - m * m) as f64);
            m += 1;
        }
        n += 1;
    }
    d
};

/// The Schmidt semi-normalised associated Legendre functions and their latitude derivatives
/// at one geocentric latitude φ′, for 0 ≤ m ≤ n ≤ 12.
///
/// Lives on the stack (two tables of 91 numbers); building one allocates nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct SchmidtLegendre {
    cos_lat: f64,
    /// P̆ₙ⁰ for m = 0; P̆ₙᵐ / cos φ′ for m ≥ 1 (finite at the poles).
    pub(crate) scaled: [f64; TABLE_LEN],
    /// dP̆ₙᵐ/dφ′.
    pub(crate) deriv: [f64; TABLE_LEN],
}

impl SchmidtLegendre {
    /// The functions at the geocentric latitude whose sine is `sin_lat` and cosine
    /// `cos_lat` (cos φ′ ≥ 0). Passing both avoids a square root and keeps the poles exact.
    pub fn new(sin_lat: f64, cos_lat: f64) -> Self {
        let x = sin_lat;
        let s = cos_lat;
        let mut q = [0.0; TABLE_LEN];
        let mut d = [0.0; TABLE_LEN];
        let fac = &DEGREE_FACTORS;

        // Sectoral terms, stored divided by cos φ′: P̆₁¹/cos φ′ = 1, then the sectoral step.
        q[index(0, 0)] = 1.0;
        q[index(1, 1)] = 1.0;
        for n in 2..=MAX_DEGREE {
            q[index(n, n)] = SECTORAL[n] * s * q[index(n - 1, n - 1)];
        }
        // Recursion in degree for each order. The step is linear in the P̆ of lower degree,
        // so it applies unchanged to the scaled values of orders m ≥ 1.
        for m in 0..MAX_DEGREE {
            // n = m + 1: the P̆ₙ₋₂ᵐ term is absent.
            let k = index(m + 1, m);
            q[k] = fac.a[k] * x * q[index(m, m)];
            for n in (m + 2)..=MAX_DEGREE {
                let k = index(n, m);
                q[k] = fac.a[k] * x * q[index(n - 1, m)] - fac.b[k] * q[index(n - 2, m)];
            }
        }
        // Derivatives with respect to φ′.
        for n in 1..=MAX_DEGREE {
            let nf = n as f64;
            // m = 0: dP̆ₙ⁰/dφ′ = √(n(n+1)/2) P̆ₙ¹ = √(n(n+1)/2) · cos φ′ · (P̆ₙ¹ / cos φ′).
            d[index(n, 0)] = DERIVATIVE[index(n, 0)] * s * q[index(n, 1)];
            // m ≥ 1: divide cos φ′ dP̆ₙᵐ/dφ′ = −n μ P̆ₙᵐ + √(n²−m²) P̆ₙ₋₁ᵐ by cos φ′, which
            // turns every P̆ on the right into a stored scaled value.
            for m in 1..=n {
                let lower = if m < n { q[index(n - 1, m)] } else { 0.0 };
                d[index(n, m)] = -nf * x * q[index(n, m)] + DERIVATIVE[index(n, m)] * lower;
            }
        }
        Self {
            cos_lat: s,
            scaled: q,
            deriv: d,
        }
    }

    /// P̆ₙᵐ(sin φ′), or `None` unless m ≤ n ≤ 12.
    pub fn p(&self, n: usize, m: usize) -> Option<f64> {
        let v = self.p_over_cos(n, m)?;
        Some(if m == 0 { v } else { v * self.cos_lat })
    }

    /// P̆ₙᵐ(sin φ′) / cos φ′ for m ≥ 1 (finite at the poles), P̆ₙ⁰ for m = 0; `None` unless
    /// m ≤ n ≤ 12.
    pub fn p_over_cos(&self, n: usize, m: usize) -> Option<f64> {
        if n > MAX_DEGREE || m > n {
            return None;
        }
        self.scaled.get(index(n, m)).copied()
    }

    /// dP̆ₙᵐ/dφ′, or `None` unless m ≤ n ≤ 12.
    pub fn dp_dlat(&self, n: usize, m: usize) -> Option<f64> {
        if n > MAX_DEGREE || m > n {
            return None;
        }
        self.deriv.get(index(n, m)).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn at(lat: f64) -> SchmidtLegendre {
        SchmidtLegendre::new(lat.sin(), lat.cos())
    }

    #[test]
    fn const_tables_match_runtime_sqrt() {
        let close = |a: f64, b: f64| (a - b).abs() <= 2.0 * f64::EPSILON * b.abs();
        for n in 1..=MAX_DEGREE {
            for m in 0..n {
                let k = index(n, m);
                let root = ((n * n - m * m) as f64).sqrt();
                assert!(
                    close(DEGREE_FACTORS.a[k], (2 * n - 1) as f64 / root),
                    "a {n} {m}"
                );
                let b = (((n - 1) * (n - 1) - m * m) as f64).sqrt() / root;
                assert!(close(DEGREE_FACTORS.b[k], b), "b {n} {m}");
            }
        }
        for (n, &s) in SECTORAL.iter().enumerate().skip(2) {
            let want = ((2 * n - 1) as f64 / (2 * n) as f64).sqrt();
            assert!(close(s, want), "sectoral {n}");
        }
        for n in 1..=MAX_DEGREE {
            let d0 = ((n * (n + 1)) as f64 / 2.0).sqrt();
            assert!(close(DERIVATIVE[index(n, 0)], d0), "derivative {n} 0");
            for m in 1..=n {
                let want = ((n * n - m * m) as f64).sqrt();
                assert!(close(DERIVATIVE[index(n, m)], want), "derivative {n} {m}");
            }
        }
        for x in [
            0.5,
            2.0,
            3.0,
            78.0,
            143.0,
            1e-300,
            1e300,
            f64::MIN_POSITIVE,
            7.0e22,
        ] {
            assert!(close(const_sqrt(x), x.sqrt()), "{x}");
        }
    }

    /// Closed forms of the low-degree Schmidt functions (μ = sin φ′, c = cos φ′).
    #[test]
    fn low_degrees_match_closed_forms() {
        let s3 = 3f64.sqrt();
        for lat in [-1.5, -0.7, 0.0, 0.3, 1.2, core::f64::consts::FRAC_PI_2] {
            let (mu, c) = (f64::sin(lat), f64::cos(lat));
            let l = at(lat);
            let want = [
                (1, 0, mu),
                (1, 1, c),
                (2, 0, 1.5 * mu * mu - 0.5),
                (2, 1, s3 * mu * c),
                (2, 2, 0.5 * s3 * c * c),
                (3, 0, 0.5 * (5.0 * mu.powi(3) - 3.0 * mu)),
                (3, 1, (3.0f64 / 8.0).sqrt() * c * (5.0 * mu * mu - 1.0)),
                (3, 2, 0.5 * 15f64.sqrt() * mu * c * c),
                (3, 3, (5.0f64 / 8.0).sqrt() * c.powi(3)),
            ];
            for (n, m, v) in want {
                let got = l.p(n, m).unwrap();
                assert!((got - v).abs() < 1e-14, "P({n},{m}) at {lat}: {got} vs {v}");
            }
        }
    }

    /// Schmidt semi-normalisation: ∫₋₁¹ (P̆ₙᵐ)² dμ = 2/(2n+1) for m = 0 and 4/(2n+1) for
    /// m > 0 (the unnormalised integral 2/(2n+1)·(n+m)!/(n−m)! times the factor
    /// 2 (n−m)!/(n+m)!). Composite Simpson's rule on 20 000 intervals integrates these
    /// polynomials of degree ≤ 24 to ~1e-12; a wrong normalisation is off by a factor.
    #[test]
    fn schmidt_normalisation_integral() {
        let steps = 20_000;
        let w = 2.0 / steps as f64;
        let mut sums = [0.0; TABLE_LEN];
        for i in 0..=steps {
            let mu = (-1.0 + i as f64 * w).clamp(-1.0, 1.0);
            let weight = if i == 0 || i == steps {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            } * w
                / 3.0;
            let l = SchmidtLegendre::new(mu, (1.0 - mu * mu).max(0.0).sqrt());
            for n in 1..=MAX_DEGREE {
                for m in 0..=n {
                    sums[index(n, m)] += l.p(n, m).unwrap().powi(2) * weight;
                }
            }
        }
        for n in 1..=MAX_DEGREE {
            for m in 0..=n {
                let sum = sums[index(n, m)];
                let want = if m == 0 { 2.0 } else { 4.0 } / (2 * n + 1) as f64;
                assert!(
                    (sum - want).abs() < 1e-10 * want,
                    "n {n} m {m}: {sum} vs {want}"
                );
            }
        }
    }

    #[test]
    fn out_of_range_orders_are_none() {
        let l = at(0.4);
        assert!(l.p(13, 0).is_none());
        assert!(l.p(2, 3).is_none());
        assert!(l.dp_dlat(12, 13).is_none());
        assert!(l.p_over_cos(12, 12).is_some());
    }

    proptest! {
        /// The analytic derivative agrees with a central difference of P̆ for every (n, m).
        #[test]
        fn derivative_matches_finite_difference(lat in -1.5f64..1.5) {
            let h = 1e-6;
            let (lo, mid, hi) = (at(lat - h), at(lat), at(lat + h));
            for n in 1..=MAX_DEGREE {
                for m in 0..=n {
                    let fd = (hi.p(n, m).unwrap() - lo.p(n, m).unwrap()) / (2.0 * h);
                    let an = mid.dp_dlat(n, m).unwrap();
                    prop_assert!((fd - an).abs() < 1e-6 * (1.0 + an.abs()),
                        "n {} m {}: fd {} analytic {}", n, m, fd, an);
                }
            }
        }

        /// Scaled values are P̆ / cos φ′ away from the poles.
        #[test]
        fn scaled_values_are_p_over_cos(lat in -1.5f64..1.5) {
            let l = at(lat);
            for n in 1..=MAX_DEGREE {
                for m in 1..=n {
                    let p = l.p(n, m).unwrap();
                    let q = l.p_over_cos(n, m).unwrap();
                    prop_assert!((q * lat.cos() - p).abs() < 1e-13);
                }
            }
        }
    }
}
