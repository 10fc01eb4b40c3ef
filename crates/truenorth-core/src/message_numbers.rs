//! Numbers as messages show them: [`Readable`] for values and ranges, [`Precise`] where
//! every digit may matter, [`Fixed`] for computed figures with a fixed number of decimals.
//! Each stays short at any magnitude, so that a hostile input cannot make a message hundreds
//! of digits long.

/// A number as a message shows it: integers and everyday magnitudes in plain decimals with
/// at most six significant digits, very large or very small ones in exponent form (`1e308`,
/// not 309 digits), so that a range or a rejected value reads at a glance.
pub struct Readable(pub f64);

impl core::fmt::Display for Readable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (v, a) = (self.0, self.0.abs());
        if !v.is_finite() || v == 0.0 {
            return write!(f, "{v}");
        }
        let mut buf = [0u8; 48];
        let mut w = SliceWriter {
            buf: &mut buf,
            len: 0,
        };
        if (1e-3..1e6).contains(&a) {
            // Six significant digits: as many decimals as the integer part leaves.
            let mut digits = 0usize;
            let mut x = a;
            while x >= 1.0 {
                x /= 10.0;
                digits += 1;
            }
            let decimals = if digits == 0 { 8 } else { 6 - digits };
            core::fmt::write(&mut w, format_args!("{v:.decimals$}"))?;
        } else {
            core::fmt::write(&mut w, format_args!("{v:.3e}"))?;
        }
        let len = w.len;
        let text = core::str::from_utf8(&buf[..len]).map_err(|_| core::fmt::Error)?;
        let (mantissa, exponent) = match text.find('e') {
            Some(i) => text.split_at(i),
            None => (text, ""),
        };
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        f.write_str(mantissa)?;
        f.write_str(exponent)
    }
}

/// A number as a message shows it when every digit may matter (a timestamp that names the
/// row, a gap): its shortest form that reads back exactly, in plain decimals for everyday
/// magnitudes (`17664.399999999998`, as `{}` shows it) and in exponent form outside them
/// (`1e308`, `5e-324`), where plain decimals would run to hundreds of digits.
pub struct Precise(pub f64);

impl core::fmt::Display for Precise {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (v, a) = (self.0, self.0.abs());
        if !v.is_finite() || v == 0.0 || (1e-4..1e15).contains(&a) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

/// A `core::fmt::Write` into a fixed buffer (the crate is `no_std`).
struct SliceWriter<'a> {
    buf: &'a mut [u8],
    len: usize,
}

impl core::fmt::Write for SliceWriter<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let dest = self.buf.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        dest.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

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
