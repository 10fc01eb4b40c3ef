//! The small random draws every scenario makes: a value in a range, a sign, a choice.

use truenorth_core::{NoiseSource, SplitMix64};

/// A value uniform in `[lo, hi)`.
pub(crate) fn between(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.uniform()
}

/// −1 or +1, equally likely.
pub(crate) fn either_sign(rng: &mut SplitMix64) -> f64 {
    if rng.uniform() < 0.5 { -1.0 } else { 1.0 }
}

/// One of `from`, equally likely.
pub(crate) fn pick<T: Copy>(rng: &mut SplitMix64, from: &[T]) -> T {
    from[((rng.uniform() * from.len() as f64) as usize).min(from.len() - 1)]
}
