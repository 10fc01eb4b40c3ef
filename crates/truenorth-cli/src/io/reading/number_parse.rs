//! Numbers read from the cells of a CSV, from their bytes.
//!
//! A sensor log's cells are short plain decimals (`-12.345`). Those take a fast path: the
//! digits are gathered into one integer `m` and divided by `10^f`, `f` the number of
//! fraction digits. When `m < 2^53` and `f ≤ 22` both operands are exact `f64`s, so the one
//! correctly rounded division gives the correctly rounded value of the decimal (Clinger,
//! "How to read floating point numbers accurately", PLDI 1990, the fast path), the same
//! `f64` a full parser gives. Any other cell (an exponent, a `+`, more digits, `inf`, text)
//! goes to `fast_float2`, which is correctly rounded too, so the result never depends on
//! the path taken.

/// `10^k` for `k ≤ 22`: every one exact in an `f64` (5^22 < 2^53).
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The largest integer below which every integer is exact in an `f64`.
const EXACT_INTEGERS: u64 = 1 << 53;

/// The largest magnitude a cell may hold: 2^53. No sensor reads more in any unit its column
/// allows (the Earth's field is 6.5e10 in femtotesla, a 32-bit converter's full scale 2.1e9
/// counts), and past it an `f64` no longer holds every integer, so a time or a count would
/// be rounded: a larger number is a wrong column or unit, or a corrupt cell. The fast path
/// never gives one (its integer is below 2^53), so only the general path's cells need the
/// check.
pub const MOST_MAGNITUDE: f64 = EXACT_INTEGERS as f64;

/// What is wrong with `v`, the value of a cell, if anything: not finite (a NaN only where a
/// value is `required`: elsewhere it is no reading), or beyond [`MOST_MAGNITUDE`].
#[inline]
pub fn value_problem(v: f64, required: bool) -> Option<&'static str> {
    if v.abs() <= MOST_MAGNITUDE {
        None
    } else if v.is_nan() {
        required.then_some("is not finite")
    } else if v.is_infinite() {
        Some("is not finite")
    } else {
        Some(
            "is beyond ±2^53 (9.0e15), more than any sensor reads in any unit (the Earth's field is 6.5e10 femtotesla, a 32-bit converter's full scale 2.1e9 counts); check the column and its unit",
        )
    }
}

/// Parses a numeric cell from its bytes (decimal point, optional exponent; `inf` and `nan`
/// are read as such, for the caller to refuse).
pub fn parse_number(cell: &[u8]) -> Option<f64> {
    plain_decimal(cell).or_else(|| fast_float2::parse::<f64, _>(cell).ok())
}

/// The value of a cell of the form `-?[0-9]+(\.[0-9]+)?` whose digits fit the fast path,
/// else `None` (which says nothing about whether the cell is a number).
#[inline]
fn plain_decimal(cell: &[u8]) -> Option<f64> {
    plain_decimal_prefix(cell).and_then(|(v, used)| (used == cell.len()).then_some(v))
}

/// The value of the longest prefix of `bytes` of the form `-?[0-9]+(\.[0-9]+)?` and its
/// length in bytes, if its digits fit the fast path (at most 19, an integer below 2^53);
/// else `None`. What follows the prefix is for the caller to judge.
#[inline]
pub fn plain_decimal_prefix(bytes: &[u8]) -> Option<(f64, usize)> {
    let negative = bytes.first() == Some(&b'-');
    let start = usize::from(negative);
    let (at, m) = digits(bytes, start, 0);
    let whole = at - start;
    let (at, m, fraction) = if bytes.get(at) == Some(&b'.') {
        let (end, m) = digits(bytes, at + 1, m);
        (end, m, end - at - 1)
    } else {
        (at, m, 0)
    };
    // A point needs a digit on each side; more than 19 digits may have wrapped `m`.
    if whole == 0 || (at > start + whole && fraction == 0) || whole + fraction > 19 {
        return None;
    }
    if m >= EXACT_INTEGERS {
        return None;
    }
    let magnitude = m as f64 / POWERS_OF_TEN[fraction];
    Some((if negative { -magnitude } else { magnitude }, at))
}

/// The run of ASCII digits at `bytes[at..]` appended to `m` (wrapping), and where the run
/// ends.
#[inline(always)]
fn digits(bytes: &[u8], mut at: usize, mut m: u64) -> (usize, u64) {
    while let Some(d) = bytes
        .get(at)
        .map(|c| c.wrapping_sub(b'0'))
        .filter(|d| *d < 10)
    {
        m = m.wrapping_mul(10).wrapping_add(u64::from(d));
        at += 1;
    }
    (at, m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn full(cell: &[u8]) -> Option<f64> {
        fast_float2::parse::<f64, _>(cell).ok()
    }

    fn same(a: Option<f64>, b: Option<f64>) -> bool {
        match (a, b) {
            (Some(x), Some(y)) => x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
            (None, None) => true,
            _ => false,
        }
    }

    #[test]
    fn numbers_plain_and_not() {
        assert_eq!(parse_number(b"-1.5e3"), Some(-1500.0));
        assert_eq!(parse_number(b"+2"), Some(2.0));
        assert_eq!(parse_number(b"1,5"), None);
        assert_eq!(parse_number(b""), None);
        assert_eq!(parse_number(b"-"), None);
        assert_eq!(parse_number(b"0.1"), Some(0.1));
        assert_eq!(
            parse_number(b"-0").map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        assert_eq!(
            parse_number(b"9007199254740993"),
            Some(9_007_199_254_740_992.0)
        );
        assert!(parse_number(b"inf").is_some_and(f64::is_infinite));
        // The fast path takes these, the full parser the rest.
        assert!(plain_decimal(b"-12.345").is_some());
        assert!(plain_decimal(b"9007199254740993").is_none());
        assert!(plain_decimal(b"1.").is_none() && plain_decimal(b".5").is_none());
    }

    #[test]
    fn long_and_short_prefixes() {
        assert_eq!(plain_decimal_prefix(b"-1234567890123456.125,"), None);
        assert_eq!(
            plain_decimal_prefix(b"-123456789012.125,7"),
            Some((-123_456_789_012.125, 17))
        );
        assert_eq!(plain_decimal_prefix(b"12.5.3"), Some((12.5, 4)));
        assert_eq!(plain_decimal_prefix(b"12.,"), None);
    }

    proptest! {
        /// Whatever the cell, the value (or its absence) is bit for bit the full parser's:
        /// plain decimals of every length around the fast path's limits, and any text.
        #[test]
        fn the_fast_path_never_changes_a_value(
            sign in prop::sample::select(vec!["", "-", "+"]),
            whole in "[0-9]{0,22}",
            point in prop::bool::ANY,
            fraction in "[0-9]{0,25}",
            tail in prop::sample::select(vec!["", "e3", "e-400", "x", ".", " "]),
        ) {
            let cell = format!("{sign}{whole}{}{fraction}{tail}", if point { "." } else { "" });
            let b = cell.as_bytes();
            prop_assert!(same(parse_number(b), full(b)), "{cell}");
            // The fast path never gives a value the bound would refuse: the reader checks
            // only the general path's.
            if let Some((v, _)) = plain_decimal_prefix(b) {
                prop_assert!(value_problem(v, true).is_none(), "{cell}: {v}");
            }
        }

        /// A finite value is refused exactly when it is beyond 2^53; an infinite one
        /// always; a NaN only where a value is required.
        #[test]
        fn value_problems_are_the_bound_and_finiteness(bits in any::<u64>(), required in any::<bool>()) {
            let v = f64::from_bits(bits);
            let problem = value_problem(v, required);
            if v.is_nan() {
                prop_assert_eq!(problem.is_some(), required);
            } else if v.is_infinite() {
                prop_assert!(problem.is_some_and(|p| p.contains("not finite")));
            } else {
                prop_assert_eq!(problem.is_some(), v.abs() > 9_007_199_254_740_992.0, "{}", v);
            }
        }

        #[test]
        fn any_bytes_parse_as_the_full_parser_does(cell in prop::collection::vec(any::<u8>(), 0..30)) {
            prop_assert!(same(parse_number(&cell), full(&cell)));
        }

        /// Every finite f64 written shortest, or with a few decimals, reads back as the
        /// full parser reads it.
        #[test]
        fn written_doubles_read_back_alike(bits in any::<u64>(), decimals in 0usize..20) {
            let v = f64::from_bits(bits);
            prop_assume!(v.is_finite());
            for text in [format!("{v}"), format!("{v:.decimals$}")] {
                prop_assert!(same(parse_number(text.as_bytes()), full(text.as_bytes())), "{text}");
            }
        }
    }
}
