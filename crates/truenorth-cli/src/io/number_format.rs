//! How numbers are written into an output CSV: by default the shortest text that reads
//! back as the same `f64` (so the output carries every bit the computation gave, and a
//! value read from the input comes out as it went in), or rounded to a number of
//! significant digits with `--precision`.

use std::fmt::Write as _;
use std::str::FromStr;

/// The most significant digits an `f64` needs to read back exactly (IEEE 754-2008, §5.12.2:
/// 17 for binary64).
pub const MAX_DIGITS: u8 = 17;

/// The precision of written numbers: the shortest round-trip text, or `n` significant
/// digits.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Precision {
    digits: Option<u8>,
}

impl FromStr for Precision {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("shortest") {
            return Ok(Self::default());
        }
        match s.parse::<u8>() {
            Ok(n @ 1..=MAX_DIGITS) => Ok(Self { digits: Some(n) }),
            _ => Err(format!(
                "`{s}` is not a precision: `shortest` or a number of significant digits from 1 to {MAX_DIGITS}"
            )),
        }
    }
}

/// The output option every command that writes a CSV of numbers takes (flatten into its
/// arguments).
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct OutputOptions {
    /// Numbers in the output CSV: `shortest` (the default: the shortest text that reads
    /// back as exactly the computed value) or N significant digits (1 to 17), e.g. 7 for
    /// headings to about 1e-4 degree and smaller files.
    #[arg(long, value_name = "DIGITS", default_value = "shortest")]
    pub precision: Precision,
}

impl Precision {
    /// `n` significant digits.
    #[cfg(test)]
    fn digits(n: u8) -> Self {
        Self { digits: Some(n) }
    }

    /// Appends `v` to `out`; a NaN appends nothing (an empty cell, as reads back as no
    /// value), an infinity `inf` or `-inf`.
    pub fn write(self, out: &mut String, v: f64) {
        if v.is_nan() {
            return;
        }
        if v.is_infinite() {
            out.push_str(if v > 0.0 { "inf" } else { "-inf" });
            return;
        }
        match self.digits {
            // Whole numbers (flags, counts, whole seconds) as integers: `1`, not `1.0`.
            None if v.trunc() == v && v.abs() < 1e15 => {
                let sign = if v.is_sign_negative() { "-" } else { "" };
                let _ = write!(out, "{sign}{}", v.abs() as u64);
            }
            None => out.push_str(zmij::Buffer::new().format_finite(v)),
            Some(n) => write_rounded(out, v, usize::from(n)),
        }
    }
}

/// `v` (finite) rounded to `digits` significant digits: fixed-point for magnitudes from
/// 1e-5 to 1e16 (trailing zeros after the point dropped), scientific otherwise.
fn write_rounded(out: &mut String, v: f64, digits: usize) {
    if v == 0.0 {
        out.push('0');
        return;
    }
    // The decimal exponent of the leading digit; where rounding carries into a new
    // leading digit (9.9996 → 10.00), the extra digit is a trailing zero, dropped below.
    let exp = v.abs().log10().floor() as i32;
    if !(-5..=16).contains(&exp) {
        let _ = write!(out, "{:.*e}", digits - 1, v);
        return;
    }
    let decimals = usize::try_from(digits as i32 - 1 - exp).unwrap_or(0);
    let start = out.len();
    let _ = write!(out, "{v:.decimals$}");
    if decimals > 0 {
        let kept = out[start..]
            .trim_end_matches('0')
            .trim_end_matches('.')
            .len();
        out.truncate(start + kept);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn text(p: Precision, v: f64) -> String {
        let mut s = String::new();
        p.write(&mut s, v);
        s
    }

    #[test]
    fn rounded_and_shortest_texts() {
        let p = Precision::digits(4);
        assert_eq!(text(p, 43.123456), "43.12");
        assert_eq!(text(p, -0.000123456), "-0.0001235");
        assert_eq!(text(p, 99.996), "100");
        assert_eq!(text(p, 1.5e20), "1.500e20");
        assert_eq!(text(p, 0.0), "0");
        assert_eq!(text(Precision::default(), f64::NAN), "");
        assert_eq!(text(Precision::default(), 0.1), "0.1");
        assert_eq!(text(Precision::default(), 1.0), "1");
        assert_eq!(text(Precision::default(), -0.0), "-0");
        assert_eq!(text(Precision::default(), -12.0), "-12");
        assert!("0".parse::<Precision>().is_err() && "18".parse::<Precision>().is_err());
        assert_eq!("shortest".parse::<Precision>(), Ok(Precision::default()));
    }

    proptest! {
        /// The default reads back exactly; n digits read back within half a unit of the
        /// n-th digit.
        #[test]
        fn texts_read_back(
            v in prop::num::f64::NORMAL.prop_filter("away from the subnormals", |v| (1e-200..1e200).contains(&v.abs())),
            n in 1u8..=17,
        ) {
            let exact: f64 = text(Precision::default(), v).parse().unwrap();
            prop_assert_eq!(exact, v);
            let s = text(Precision::digits(n), v);
            let r: f64 = s.parse().unwrap();
            let ulp_n = 10f64.powi(v.abs().log10().floor() as i32 + 1 - i32::from(n));
            // Plus the binary rounding of the decimal text read back (one ulp of v).
            let tolerance = 0.5 * ulp_n * (1.0 + 1e-9) + 2.0 * f64::EPSILON * v.abs();
            prop_assert!((r - v).abs() <= tolerance, "{} -> {}", v, s);
        }
    }
}
