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
    /// headings to about 1e-4 degree and smaller files. The time column `t_s` is always
    /// written exactly, so that rows stay as distinct as the input's.
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
            // Whole numbers (flags, counts, whole seconds) as integers: `1`, not `1.0`. Below
            // 1e15 the cast truncates exactly, so comparing it with `v` is `v.trunc() == v`
            // without the call to the maths library.
            None if v.abs() < 1e15 && (v as i64) as f64 == v => {
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
///
/// The text is the correctly rounded decimal (ties to even, as `format!("{v:.N$}")`
/// rounds), built with integer arithmetic in the fixed-point range; the magnitude
/// decides the layout as `floor(log10 |v|)` does, including where the library logarithm
/// rounds a value just below a power of ten up to it.
fn write_rounded(out: &mut String, v: f64, digits: usize) {
    if v == 0.0 {
        out.push('0');
        return;
    }
    // The decimal exponent of the leading digit; where rounding carries into a new
    // leading digit (9.9996 → 10.00), the extra digit is a trailing zero, dropped below.
    let exp = leading_exponent(v.abs());
    if !(FIXED_MIN_EXP..=FIXED_MAX_EXP).contains(&exp) {
        let _ = write!(out, "{:.*e}", digits - 1, v);
        return;
    }
    let decimals = usize::try_from(digits as i32 - 1 - exp).unwrap_or(0);
    match scaled_to_integer(v.abs(), decimals) {
        Some(n) => push_fixed(out, v.is_sign_negative(), n, decimals),
        None => write_fixed_std(out, v, decimals),
    }
}

/// The decimal exponents written in fixed point (leading digit from 1e-5 to 1e16).
const FIXED_MIN_EXP: i32 = -5;
/// See [`FIXED_MIN_EXP`].
const FIXED_MAX_EXP: i32 = 16;

/// The `f64` nearest each power of ten from 1e-5 to 1e17 (`10^k` at `k + 5`).
const POWERS_OF_TEN: [f64; 23] = [
    1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17,
];

/// How close to a power of ten (relative) a magnitude must be for its exponent to be
/// taken from `log10`: the library logarithm is within a few units in the last place
/// (below 1e-14 for results under 17 in magnitude), so farther than this from a power
/// of ten its floor is the exact one, and nearer it is what `log10` says.
const NEAR_POWER: f64 = 1e-12;

/// `floor(log10(a))` for a finite `a > 0`, as the library `log10` gives it, without
/// calling it except within [`NEAR_POWER`] of a power of ten or outside 1e-5..1e17.
fn leading_exponent(a: f64) -> i32 {
    if (POWERS_OF_TEN[0]..POWERS_OF_TEN[22]).contains(&a) {
        // floor(log2 a) (a is normal here), then floor(e2 · log10 2) by the integer
        // multiply-shift of Adams, "Ryū", PLDI 2018 (78913 / 2^18 is log10 2 to 8e-7;
        // `exponent_estimate_is_the_floor` checks the range used); the decimal exponent is
        // that or one more.
        let e2 = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
        let low = (e2 * 78_913) >> 18;
        let next = POWERS_OF_TEN[(low + 6) as usize];
        let k = if a >= next { low + 1 } else { low };
        let below = POWERS_OF_TEN[(k + 5) as usize];
        let above = POWERS_OF_TEN[(k + 6) as usize];
        if a > below * (1.0 + NEAR_POWER) && a < above * (1.0 - NEAR_POWER) {
            return k;
        }
    }
    a.log10().floor() as i32
}

/// 5^k for k = 0..=21 (the most decimals the fixed-point range writes: 17 digits of a
/// leading digit at 1e-5).
const POWERS_OF_FIVE: [u64; 22] = {
    let mut table = [1u64; 22];
    let mut k = 1;
    while k < 22 {
        table[k] = table[k - 1] * 5;
        k += 1;
    }
    table
};

/// `a · 10^decimals` (a finite, normal, positive) rounded to the nearest integer, ties to
/// even, exactly: `a = m · 2^e`, so `a · 10^d = m · 5^d · 2^(e + d)`, an integer product
/// (below 2^102) shifted. `None` where that does not fit (not in the fixed-point range).
fn scaled_to_integer(a: f64, decimals: usize) -> Option<u64> {
    let five = u128::from(*POWERS_OF_FIVE.get(decimals)?);
    let bits = a.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    if biased == 0 {
        return None;
    }
    let mantissa = (bits & ((1 << 52) - 1)) | (1 << 52);
    let product = u128::from(mantissa) * five;
    let shift = biased - 1075 + decimals as i32;
    let n = if shift >= 0 {
        if product.leading_zeros() <= shift as u32 {
            return None;
        }
        product << shift
    } else {
        let drop = shift.unsigned_abs();
        if drop >= 128 {
            return None;
        }
        let whole = product >> drop;
        let rest = product - (whole << drop);
        let half = 1u128 << (drop - 1);
        if rest > half || (rest == half && whole & 1 == 1) {
            whole + 1
        } else {
            whole
        }
    };
    u64::try_from(n).ok()
}

/// Appends `n / 10^decimals` (sign first), as `{:.decimals$}` writes it, less the trailing
/// zeros after the point (and the point if nothing follows it).
fn push_fixed(out: &mut String, negative: bool, n: u64, decimals: usize) {
    let mut rest = n;
    let mut fraction = decimals;
    while fraction > 0 && rest.is_multiple_of(10) {
        rest /= 10;
        fraction -= 1;
    }
    // Right to left: the fraction (zero-padded to its width), the point, the whole part
    // (at least one digit), the sign. At most 21 + 1 + 20 + 1 bytes.
    let mut buf = [0u8; 44];
    let mut start = buf.len();
    if fraction > 0 {
        for _ in 0..fraction {
            start -= 1;
            buf[start] = b'0' + (rest % 10) as u8;
            rest /= 10;
        }
        start -= 1;
        buf[start] = b'.';
    }
    loop {
        start -= 1;
        buf[start] = b'0' + (rest % 10) as u8;
        rest /= 10;
        if rest == 0 {
            break;
        }
    }
    if negative {
        start -= 1;
        buf[start] = b'-';
    }
    // Byte by byte as chars (all ASCII): for a dozen bytes, cheaper than validating them as
    // UTF-8 to push them as one `str` (the `number_format` bench).
    out.reserve(buf.len() - start);
    for &b in &buf[start..] {
        out.push(char::from(b));
    }
}

/// `v` to `decimals` places through the standard library's exact formatting, trailing
/// zeros after the point dropped: the same text as [`push_fixed`], for a scaled value too
/// large for it (not reached in the fixed-point range).
fn write_fixed_std(out: &mut String, v: f64, decimals: usize) {
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

/// The writer `write_rounded` replaced (the logarithm, then the standard library's exact
/// formatting), kept as the reference its output must equal byte for byte.
#[cfg(test)]
fn write_rounded_reference(out: &mut String, v: f64, digits: usize) {
    if v == 0.0 {
        out.push('0');
        return;
    }
    let exp = v.abs().log10().floor() as i32;
    if !(-5..=16).contains(&exp) {
        let _ = write!(out, "{:.*e}", digits - 1, v);
        return;
    }
    let decimals = usize::try_from(digits as i32 - 1 - exp).unwrap_or(0);
    write_fixed_std(out, v, decimals);
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

    /// The new writer's text and the reference's, for `v` at `n` digits.
    fn both(v: f64, n: usize) -> (String, String) {
        let (mut new, mut reference) = (String::new(), String::new());
        write_rounded(&mut new, v, n);
        write_rounded_reference(&mut reference, v, n);
        (new, reference)
    }

    /// Every precision gives the reference's bytes for `v` (and for `-v`).
    fn same_as_reference(v: f64) -> Result<(), TestCaseError> {
        for v in [v, -v] {
            for n in 1..=usize::from(MAX_DIGITS) {
                let (new, reference) = both(v, n);
                prop_assert_eq!(
                    &new,
                    &reference,
                    "{:e} ({:#x}) at {} digits",
                    v,
                    v.to_bits(),
                    n
                );
            }
        }
        Ok(())
    }

    /// `v` moved by `ulps` units in the last place (`v` positive and finite).
    fn step(v: f64, ulps: i64) -> f64 {
        f64::from_bits(v.to_bits().saturating_add_signed(ulps))
    }

    #[test]
    fn exponent_estimate_is_the_floor() {
        // The binary exponents of 1e-5..1e17.
        for e2 in -17..=56 {
            let exact = (f64::from(e2) * std::f64::consts::LOG10_2).floor() as i32;
            assert_eq!((e2 * 78_913) >> 18, exact, "2^{e2}");
        }
    }

    #[test]
    fn exact_ties_round_to_even_as_the_standard_library() {
        let p = Precision::digits;
        assert_eq!(text(p(2), 0.125), "0.12");
        assert_eq!(text(p(2), 0.375), "0.38");
        assert_eq!(text(p(1), 2.5), "2");
        assert_eq!(text(p(1), 3.5), "4");
        assert_eq!(text(p(4), -1234.5), "-1234");
        assert_eq!(text(p(3), 0.0625), "0.0625");
        assert_eq!(text(p(2), 0.0625), "0.062");
        // Just below a power of ten, where the logarithm rounds up to the power: one
        // digit fewer, as the reference writes it.
        assert_eq!(text(p(17), 99.99999999999999), "99.99999999999999");
        for v in [
            0.125,
            2.5,
            1234.5,
            99.99999999999999,
            9.999999999999999e-6,
            1e-5,
            1e17,
        ] {
            same_as_reference(v).unwrap();
        }
    }

    /// `d` in 0..=21 as an exact power of ten.
    fn ten_to(d: u32) -> f64 {
        format!("1e{d}").parse().unwrap()
    }

    proptest! {
        /// The whole-number test of the shortest form is `trunc` below 1e15, for any bits.
        #[test]
        fn whole_numbers_are_told_by_the_cast_as_by_trunc(bits in any::<u64>(), small in -1e16f64..1e16) {
            for v in [f64::from_bits(bits), small, small.round()] {
                prop_assume!(v.is_finite());
                prop_assert_eq!(
                    v.abs() < 1e15 && (v as i64) as f64 == v,
                    v.trunc() == v && v.abs() < 1e15
                );
            }
        }
    }

    proptest! {
        /// Any finite bit pattern (most far outside the fixed-point range).
        #[test]
        fn rounded_equals_reference_for_any_bits(bits in any::<u64>()) {
            let v = f64::from_bits(bits);
            prop_assume!(v.is_finite());
            same_as_reference(v)?;
        }

        /// Any mantissa with a binary exponent around the fixed-point range (1e-5..1e17).
        #[test]
        fn rounded_equals_reference_in_fixed_range(mantissa in 0u64..1 << 52, e2 in -20i32..60) {
            let biased = u64::try_from(e2 + 1023).unwrap();
            same_as_reference(f64::from_bits(biased << 52 | mantissa))?;
        }

        /// Values within a few units in the last place of a decimal tie `(w + 1/2) / 10^d`,
        /// including the carries `9.99…95` (w = 10^L − 1).
        #[test]
        fn rounded_equals_reference_near_decimal_ties(
            whole in prop_oneof![0u64..100_000_000_000_000_000, (1u32..=17).prop_map(|l| 10u64.pow(l) - 1)],
            decimals in 0u32..=21,
            ulps in -4i64..=4,
        ) {
            let tie = (whole as f64 + 0.5) / ten_to(decimals);
            same_as_reference(step(tie, ulps))?;
        }

        /// Exact binary fractions, whose decimal ties are exact (0.125 to two places), and
        /// their neighbours.
        #[test]
        fn rounded_equals_reference_near_binary_ties(odd in 0u64..1 << 30, places in 1i32..=60, ulps in -2i64..=2) {
            let v = (2 * odd + 1) as f64 * 2f64.powi(-places);
            same_as_reference(step(v, ulps))?;
        }

        /// Powers of ten and their neighbours, where the logarithm decides the layout.
        #[test]
        fn rounded_equals_reference_near_powers_of_ten(k in -8i32..=19, ulps in -64i64..=64) {
            let power: f64 = format!("1e{k}").parse().unwrap();
            same_as_reference(step(power, ulps))?;
        }
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
