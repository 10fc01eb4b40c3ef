//! The text of a coefficient file in NOAA's `.COF` format, scanned without allocating and
//! in `const fn`s: its lines, their whitespace-separated fields, the closing line of 9s, and
//! the unsigned integers and decimal numbers of the fields.

/// Index of the next `\n` at or after `start`, or the end of the text.
pub(crate) const fn line_end(b: &[u8], start: usize) -> usize {
    let mut i = start;
    while i < b.len() && b[i] != b'\n' {
        i += 1;
    }
    i
}

const fn is_space(c: u8) -> bool {
    c == b' ' || c == b'\t' || c == b'\r'
}

/// Splits `b[start..end]` at whitespace into at most `out.len()` fields (start, end);
/// returns the number found, `out.len()` meaning "that many or more".
pub(crate) const fn split_fields(
    b: &[u8],
    start: usize,
    end: usize,
    out: &mut [(usize, usize); 7],
) -> usize {
    let end = if end < b.len() { end } else { b.len() };
    let mut count = 0;
    let mut i = start;
    while i < end && count < out.len() {
        while i < end && is_space(b[i]) {
            i += 1;
        }
        if i >= end {
            break;
        }
        let s = i;
        while i < end && !is_space(b[i]) {
            i += 1;
        }
        out[count] = (s, i);
        count += 1;
    }
    count
}

/// The closing line of a `.COF` file is a long run of 9s.
pub(crate) const fn is_terminator(b: &[u8], s: usize, e: usize) -> bool {
    if e <= s || e - s < 8 || e > b.len() {
        return false;
    }
    let mut i = s;
    while i < e {
        if b[i] != b'9' {
            return false;
        }
        i += 1;
    }
    true
}

/// A small unsigned integer (degree or order), at most three digits.
pub(crate) const fn parse_uint(b: &[u8], s: usize, e: usize) -> Option<usize> {
    if e <= s || e - s > 3 || e > b.len() {
        return None;
    }
    let mut v = 0usize;
    let mut i = s;
    while i < e {
        let c = b[i];
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (c - b'0') as usize;
        i += 1;
    }
    Some(v)
}

/// Exact powers of ten (every one up to 10²² is representable in an f64).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A plain decimal `[+-]digits[.digits]`. With at most 15 significant digits the mantissa
/// and the power of ten are both exact, so the single division rounds correctly: the result
/// is the same f64 that `str::parse` gives.
pub(crate) const fn parse_decimal(b: &[u8], s: usize, e: usize) -> Option<f64> {
    if e <= s || e > b.len() {
        return None;
    }
    let mut i = s;
    let negative = b[i] == b'-';
    if b[i] == b'-' || b[i] == b'+' {
        i += 1;
    }
    let mut mantissa: u64 = 0;
    let mut digits = 0;
    let mut frac_digits = 0;
    let mut seen_point = false;
    while i < e {
        let c = b[i];
        if c == b'.' {
            if seen_point {
                return None;
            }
            seen_point = true;
        } else if c.is_ascii_digit() {
            digits += 1;
            if digits > 15 {
                return None;
            }
            mantissa = mantissa * 10 + (c - b'0') as u64;
            if seen_point {
                frac_digits += 1;
            }
        } else {
            return None;
        }
        i += 1;
    }
    if digits == 0 {
        return None;
    }
    let v = mantissa as f64 / POW10[frac_digits];
    Some(if negative { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn decimal_parser_edges() {
        let p = |s: &str| parse_decimal(s.as_bytes(), 0, s.len());
        assert_eq!(p("-29351.8"), Some(-29351.8));
        assert_eq!(p("+0.5"), Some(0.5));
        assert_eq!(p("7."), Some(7.0));
        assert_eq!(p(".25"), Some(0.25));
        assert_eq!(p("-"), None);
        assert_eq!(p("."), None);
        assert_eq!(p("1.2.3"), None);
        assert_eq!(p("1e5"), None);
        assert_eq!(p("1234567890123456"), None);
    }

    proptest! {
        /// Numbers written with at most 15 digits parse to exactly what `str::parse` gives.
        #[test]
        fn decimal_parser_matches_std(int in 0u64..10_000_000, frac in 0u64..100_000_000, neg: bool) {
            let s = format!("{}{int}.{frac}", if neg { "-" } else { "" });
            let ours = parse_decimal(s.as_bytes(), 0, s.len());
            prop_assert_eq!(ours, Some(s.parse::<f64>().unwrap()));
        }
    }
}
