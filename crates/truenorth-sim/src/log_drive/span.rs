//! A range a quantity of a drive is drawn from: the physical range of a sensor or a habit,
//! sampled once per drive from its seed.

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SplitMix64, check_range};

/// The closed range `[lo, hi]` a quantity is drawn from once per drive (`lo == hi` fixes it).
/// Each field that holds one says whether it is drawn uniformly or log-uniformly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Span {
    /// Smallest value.
    pub lo: f64,
    /// Largest value.
    pub hi: f64,
}

impl Span {
    /// The range `[lo, hi]`.
    pub const fn new(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }

    /// The single value `x`.
    pub const fn fixed(x: f64) -> Self {
        Self { lo: x, hi: x }
    }

    /// Checks that both ends are finite, `min ≤ lo ≤ hi ≤ max`; `what` names the quantity in
    /// the error.
    pub fn check(&self, what: &'static str, min: f64, max: f64) -> Result<()> {
        check_range(what, self.lo, min, max)?;
        check_range(what, self.hi, self.lo, max)?;
        Ok(())
    }

    /// Whether `x` lies in the range.
    pub fn contains(&self, x: f64) -> bool {
        (self.lo..=self.hi).contains(&x)
    }

    /// A value drawn uniformly.
    pub fn draw(&self, rng: &mut SplitMix64) -> f64 {
        self.lo + (self.hi - self.lo) * rng.uniform()
    }

    /// A value drawn log-uniformly (every factor of ten as likely as the next), for
    /// quantities whose physical range spans decades; uniformly when `lo` is 0, where no
    /// logarithm exists.
    pub fn draw_log(&self, rng: &mut SplitMix64) -> f64 {
        if self.lo <= 0.0 {
            return self.draw(rng);
        }
        let (a, b) = (self.lo.ln(), self.hi.ln());
        (a + (b - a) * rng.uniform()).exp().clamp(self.lo, self.hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn draws_stay_in_the_range(lo in 1e-6f64..10.0, width in 0.0f64..100.0, seed in any::<u64>()) {
            let s = Span::new(lo, lo + width);
            prop_assert!(s.check("x", 0.0, 1e9).is_ok());
            let mut rng = SplitMix64::new(seed);
            for _ in 0..20 {
                prop_assert!(s.contains(s.draw(&mut rng)));
                prop_assert!(s.contains(s.draw_log(&mut rng)));
            }
        }
    }

    #[test]
    fn reversed_or_non_finite_ranges_are_refused() {
        assert!(Span::new(2.0, 1.0).check("x", 0.0, 10.0).is_err());
        assert!(Span::new(f64::NAN, 1.0).check("x", 0.0, 10.0).is_err());
        assert!(
            Span::new(0.0, f64::INFINITY)
                .check("x", 0.0, f64::MAX)
                .is_err()
        );
        assert!(Span::new(-1.0, 1.0).check("x", 0.0, 10.0).is_err());
        assert!(Span::fixed(3.0).check("x", 0.0, 10.0).is_ok());
    }

    #[test]
    fn log_uniform_draws_spread_over_the_decades() {
        // A factor of 1000: each decade holds about a third of the draws.
        let s = Span::new(0.01, 10.0);
        let mut rng = SplitMix64::new(1);
        let n = 3000;
        let below = (0..n).filter(|_| s.draw_log(&mut rng) < 0.1).count();
        assert!((800..1200).contains(&below), "{below}");
    }
}
