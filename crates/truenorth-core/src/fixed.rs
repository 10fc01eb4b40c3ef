//! A computed figure (a coverage, a dilution, a noise, a bound) as a message shows it.

use crate::Readable;

/// Magnitude from which a figure goes to exponent form: an `f64` holds about 16 significant
/// digits, so fixed decimals beyond it would print digits the number does not have (and
/// hundreds of them near `f64::MAX`).
const EXPONENT_FROM: f64 = 1e15;

/// A computed figure with a fixed number of decimals: `Fixed(42.9, 2)` shows `42.90`, exactly
/// as `{:.2}` does, at every magnitude below 10¹⁵; beyond it the short exponent form of
/// [`Readable`] (`3.2e200`, not 201 digits), and `not finite (NaN)` / `not finite (inf)` for a
/// figure that is no number, so that a message about a hostile input stays short and says
/// what the figure was.
///
/// ```
/// use truenorth_core::Fixed;
///
/// assert_eq!(Fixed(187.4, 0).to_string(), "187");
/// assert_eq!(Fixed(3.2e200, 1).to_string(), "3.2e200");
/// assert_eq!(Fixed(f64::NAN, 2).to_string(), "not finite (NaN)");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed(
    /// The figure.
    pub f64,
    /// Decimals shown at everyday magnitudes.
    pub usize,
);

impl core::fmt::Display for Fixed {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let Self(v, decimals) = *self;
        if !v.is_finite() {
            write!(f, "not finite ({v})")
        } else if v.abs() < EXPONENT_FROM {
            write!(f, "{v:.decimals$}")
        } else {
            write!(f, "{}", Readable(v))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate alloc;
    use alloc::format;
    use alloc::string::ToString;
    use proptest::prelude::*;

    #[test]
    fn everyday_figures_read_as_fixed_decimals() {
        for (v, d, want) in [
            (42.9, 2, "42.90"),
            (187.4999, 0, "187"),
            (0.0, 1, "0.0"),
            (-0.04, 1, "-0.0"),
            (1e-300, 2, "0.00"),
            (999_999_999_999_999.0, 0, "999999999999999"),
            (1e15, 1, "1e15"),
            (-f64::MAX, 1, "-1.798e308"),
            (f64::INFINITY, 1, "not finite (inf)"),
            (f64::NEG_INFINITY, 0, "not finite (-inf)"),
        ] {
            assert_eq!(Fixed(v, d).to_string(), want, "{v}");
        }
    }

    /// The longest run of consecutive digits in `s`.
    pub(crate) fn longest_digit_run(s: &str) -> usize {
        s.split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0)
    }

    proptest! {
        /// Below 10¹⁵ the text is `{:.N}`'s; at any value it is short and has no run of
        /// more than 20 digits.
        #[test]
        fn same_as_fixed_decimals_where_those_are_short(bits in any::<u64>(), d in 0usize..5) {
            let v = f64::from_bits(bits);
            let text = Fixed(v, d).to_string();
            if v.is_finite() && v.abs() < 1e15 {
                prop_assert_eq!(&text, &format!("{v:.d$}"));
            }
            prop_assert!(text.len() <= 24, "{}", text);
            prop_assert!(longest_digit_run(&text) <= 20, "{}", text);
        }
    }
}
