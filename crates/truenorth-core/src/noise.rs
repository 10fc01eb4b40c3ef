//! Random errors for sensor models. A small self-contained generator keeps simulations
//! bit-for-bit reproducible for a given seed, whatever version of an RNG crate is around.

#[cfg(not(feature = "std"))]
use crate::Float as _;

/// A source of random numbers for sensor models.
pub trait NoiseSource {
    /// A uniform sample in [0, 1).
    fn uniform(&mut self) -> f64;

    /// A standard normal sample (mean 0, variance 1).
    fn standard_normal(&mut self) -> f64 {
        // Box–Muller (Box & Muller 1958); 1 - u keeps the log argument in (0, 1].
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (core::f64::consts::TAU * u2).cos()
    }

    /// A normal sample with the given standard deviation.
    fn normal(&mut self, sigma: f64) -> f64 {
        sigma * self.standard_normal()
    }
}

/// A source with no randomness: uniform returns 0.5, normal returns 0. Use it to get a
/// sensor model's deterministic errors only.
#[derive(Debug, Clone, Copy, Default)]
pub struct ZeroNoise;

impl NoiseSource for ZeroNoise {
    fn uniform(&mut self) -> f64 {
        0.5
    }
    fn standard_normal(&mut self) -> f64 {
        0.0
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): 64 bits of state, passes BigCrush, and fully
/// determined by its seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed`.
    pub const fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

impl NoiseSource for SplitMix64 {
    fn uniform(&mut self) -> f64 {
        // The top 53 bits give every representable multiple of 2^-53 in [0, 1).
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_moments() {
        let mut r = SplitMix64::new(7);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let x = r.standard_normal();
            s += x;
            s2 += x * x;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.01, "var {var}");
    }

    #[test]
    fn same_seed_same_stream() {
        let mut a = SplitMix64::new(42);
        let mut b = SplitMix64::new(42);
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
    }
}
