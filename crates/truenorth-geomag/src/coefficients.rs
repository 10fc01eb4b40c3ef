//! The model's Gauss coefficients: data, kept apart from the code that evaluates them.
//!
//! The WMM2025 coefficient file (`data/WMM.COF`, public domain, see `data/README.md`) is
//! compiled into the crate with `include_str!` and parsed by a `const fn` at compile time,
//! so there is no file I/O, no allocation and no parse cost at run time, and a damaged file
//! is a build error rather than a run-time surprise.

use core::fmt;

use crate::cof_text::{is_terminator, line_end, parse_decimal, parse_uint, split_fields};

/// Highest degree (and order) of the WMM spherical-harmonic expansion (WMM2025 Technical
/// Report, eq. 1: N = 12).
pub const MAX_DEGREE: usize = 12;

/// Slots in a triangular (n, m) table for 0 ≤ m ≤ n ≤ [`MAX_DEGREE`]; slot (0, 0) is unused
/// by the model but kept so that the index formula stays simple.
pub(crate) const TABLE_LEN: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 2) / 2;

/// Years a WMM release is valid for after its epoch (the WMM is issued every five years:
/// WMM2025 is valid 2025.0–2030.0).
pub const VALIDITY_YEARS: f64 = 5.0;

/// Longest model name kept from the coefficient file's header.
const NAME_CAPACITY: usize = 16;

/// Position of (n, m) in a triangular table. Callers guarantee `m <= n <= MAX_DEGREE`.
#[inline(always)]
pub(crate) const fn index(n: usize, m: usize) -> usize {
    n * (n + 1) / 2 + m
}

/// One term of the expansion: the Gauss coefficients of degree n and order m at the model
/// epoch and their secular variation (WMM2025 Technical Report, eq. 9 uses them as
/// g(t) = g(t₀) + (t − t₀)·ġ(t₀)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussTerm {
    /// g_n^m at the epoch, nT.
    pub g_nt: f64,
    /// h_n^m at the epoch, nT (zero for m = 0).
    pub h_nt: f64,
    /// ġ_n^m, nT per year.
    pub g_sv_nt_per_yr: f64,
    /// ḣ_n^m, nT per year.
    pub h_sv_nt_per_yr: f64,
}

/// A complete set of WMM coefficients to degree and order [`MAX_DEGREE`].
///
/// [`WMM2025`] is the one built into the crate; [`Coefficients::from_cof`] parses another
/// release in the same format (also at compile time, in a `const`/`static`).
#[derive(Debug, Clone, PartialEq)]
pub struct Coefficients {
    epoch_year: f64,
    name: [u8; NAME_CAPACITY],
    name_len: usize,
    pub(crate) g: [f64; TABLE_LEN],
    pub(crate) h: [f64; TABLE_LEN],
    pub(crate) g_sv: [f64; TABLE_LEN],
    pub(crate) h_sv: [f64; TABLE_LEN],
}

/// The World Magnetic Model 2025 coefficients (epoch 2025.0, valid 2025.0–2030.0), parsed
/// from the embedded `data/WMM.COF` at compile time.
pub static WMM2025: Coefficients = match Coefficients::from_cof(include_str!("../data/WMM.COF")) {
    Ok(c) => c,
    // Evaluated by the compiler: a damaged data file fails the build, never a user's program.
    Err(_) => panic!("data/WMM.COF is not a valid WMM coefficient file"),
};

/// What is wrong with a coefficient file, and on which line (1-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CofError {
    /// 1-based line number (0 when the problem is the file as a whole).
    pub line: usize,
    /// The problem.
    pub kind: CofErrorKind,
}

/// The kinds of [`CofError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CofErrorKind {
    /// No header line (`epoch name date`) before the coefficients.
    MissingHeader,
    /// A field that should be a number is not one.
    BadNumber,
    /// A coefficient line does not have exactly six fields `n m g h ġ ḣ`.
    WrongFieldCount,
    /// Degree n outside 1..=12 or order m outside 0..=n.
    BadDegreeOrOrder,
    /// The same (n, m) appears twice.
    Duplicate,
    /// Some (n, m) with 1 ≤ n ≤ 12, 0 ≤ m ≤ n never appears.
    MissingTerm {
        /// Degree.
        n: usize,
        /// Order.
        m: usize,
    },
    /// The file ends without the closing line of 9s.
    MissingTerminator,
}

impl fmt::Display for CofError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self.kind {
            CofErrorKind::MissingHeader => "missing header line `epoch name date`",
            CofErrorKind::BadNumber => "a field is not a number",
            CofErrorKind::WrongFieldCount => "a coefficient line needs exactly `n m g h gdot hdot`",
            CofErrorKind::BadDegreeOrOrder => "degree outside 1..=12 or order outside 0..=n",
            CofErrorKind::Duplicate => "the same (n, m) appears twice",
            CofErrorKind::MissingTerm { n, m } => {
                return write!(f, "WMM coefficient file: term n = {n}, m = {m} is missing");
            }
            CofErrorKind::MissingTerminator => "the file does not end with a line of 9s",
        };
        write!(f, "WMM coefficient file, line {}: {what}", self.line)
    }
}

impl core::error::Error for CofError {}

impl Coefficients {
    /// Parses a coefficient file in NOAA's `.COF` format: a header `epoch name date`, one
    /// line `n m g h ġ ḣ` per term for 1 ≤ n ≤ 12, 0 ≤ m ≤ n, then a line of 9s.
    ///
    /// A `const fn`, so a release can be embedded and checked at compile time:
    /// `static MY: Coefficients = match Coefficients::from_cof(include_str!("WMM.COF")) { … }`.
    /// At run time it neither allocates nor panics; anything malformed is a [`CofError`].
    pub const fn from_cof(text: &str) -> Result<Self, CofError> {
        let b = text.as_bytes();
        let mut c = Coefficients {
            epoch_year: 0.0,
            name: [0; NAME_CAPACITY],
            name_len: 0,
            g: [0.0; TABLE_LEN],
            h: [0.0; TABLE_LEN],
            g_sv: [0.0; TABLE_LEN],
            h_sv: [0.0; TABLE_LEN],
        };
        // Bit k set once the term at table index k has been read (91 slots fit in a u128).
        let mut seen: u128 = 0;
        let mut have_header = false;
        let mut pos = 0;
        let mut line = 0;
        while pos < b.len() {
            line += 1;
            let end = line_end(b, pos);
            let mut fields = [(0usize, 0usize); 7];
            let count = split_fields(b, pos, end, &mut fields);
            pos = end + 1;
            if count == 0 {
                continue;
            }
            let (s0, e0) = fields[0];
            if is_terminator(b, s0, e0) {
                return c.complete(have_header, seen, line);
            }
            let read = if have_header {
                c.read_term(b, &fields, count, line, &mut seen)
            } else {
                c.read_header(b, &fields, count, line)
            };
            if let Err(e) = read {
                return Err(e);
            }
            have_header = true;
        }
        Err(CofError {
            line,
            kind: if have_header {
                CofErrorKind::MissingTerminator
            } else {
                CofErrorKind::MissingHeader
            },
        })
    }

    /// At the terminator (on `line`): the coefficients, if the header and every term (bits
    /// of `seen`) were read.
    const fn complete(self, have_header: bool, seen: u128, line: usize) -> Result<Self, CofError> {
        if !have_header {
            return Err(CofError {
                line,
                kind: CofErrorKind::MissingHeader,
            });
        }
        match first_missing(seen) {
            Some((n, m)) => Err(CofError {
                line: 0,
                kind: CofErrorKind::MissingTerm { n, m },
            }),
            None => Ok(self),
        }
    }

    /// The header `line` (its `count` fields of `b`): epoch, model name, release date (the
    /// date is informative only).
    const fn read_header(
        &mut self,
        b: &[u8],
        fields: &[(usize, usize); 7],
        count: usize,
        line: usize,
    ) -> Result<(), CofError> {
        let (s0, e0) = fields[0];
        let Some(epoch) = parse_decimal(b, s0, e0) else {
            return Err(CofError {
                line,
                kind: CofErrorKind::MissingHeader,
            });
        };
        self.epoch_year = epoch;
        if count >= 2 {
            let (s1, e1) = fields[1];
            let mut k = 0;
            while k < NAME_CAPACITY && s1 + k < e1 && s1 + k < b.len() {
                self.name[k] = b[s1 + k];
                k += 1;
            }
            // Keep the name valid UTF-8 if a multi-byte character was cut.
            while k > 0 && self.name[k - 1] >= 0x80 {
                k -= 1;
            }
            self.name_len = k;
        }
        Ok(())
    }

    /// A term `line` `n m g h ġ ḣ` (its `count` fields of `b`), stored at its table index
    /// and marked in `seen`; a term seen before is refused.
    const fn read_term(
        &mut self,
        b: &[u8],
        fields: &[(usize, usize); 7],
        count: usize,
        line: usize,
        seen: &mut u128,
    ) -> Result<(), CofError> {
        if count != 6 {
            return Err(CofError {
                line,
                kind: CofErrorKind::WrongFieldCount,
            });
        }
        let (Some(n), Some(m)) = (
            parse_uint(b, fields[0].0, fields[0].1),
            parse_uint(b, fields[1].0, fields[1].1),
        ) else {
            return Err(CofError {
                line,
                kind: CofErrorKind::BadNumber,
            });
        };
        if n < 1 || n > MAX_DEGREE || m > n {
            return Err(CofError {
                line,
                kind: CofErrorKind::BadDegreeOrOrder,
            });
        }
        let (Some(g), Some(h), Some(gd), Some(hd)) = (
            parse_decimal(b, fields[2].0, fields[2].1),
            parse_decimal(b, fields[3].0, fields[3].1),
            parse_decimal(b, fields[4].0, fields[4].1),
            parse_decimal(b, fields[5].0, fields[5].1),
        ) else {
            return Err(CofError {
                line,
                kind: CofErrorKind::BadNumber,
            });
        };
        let k = index(n, m);
        if *seen & (1u128 << k) != 0 {
            return Err(CofError {
                line,
                kind: CofErrorKind::Duplicate,
            });
        }
        *seen |= 1u128 << k;
        self.g[k] = g;
        self.h[k] = h;
        self.g_sv[k] = gd;
        self.h_sv[k] = hd;
        Ok(())
    }

    /// The model epoch t₀ as a decimal year (2025.0 for WMM2025).
    pub const fn epoch_year(&self) -> f64 {
        self.epoch_year
    }

    /// First decimal year of validity (the epoch).
    pub const fn valid_from_year(&self) -> f64 {
        self.epoch_year
    }

    /// Last decimal year of validity (epoch + [`VALIDITY_YEARS`]; 2030.0 for WMM2025).
    pub const fn valid_to_year(&self) -> f64 {
        self.epoch_year + VALIDITY_YEARS
    }

    /// The model name from the file header (`"WMM-2025"`).
    pub fn name(&self) -> &str {
        let len = self.name_len.min(NAME_CAPACITY);
        let (bytes, _) = self.name.split_at(len);
        core::str::from_utf8(bytes).unwrap_or("")
    }

    /// The term of degree `n` and order `m`, or `None` unless 1 ≤ n ≤ 12 and m ≤ n.
    pub fn term(&self, n: usize, m: usize) -> Option<GaussTerm> {
        if !(1..=MAX_DEGREE).contains(&n) || m > n {
            return None;
        }
        let k = index(n, m);
        Some(GaussTerm {
            g_nt: *self.g.get(k)?,
            h_nt: *self.h.get(k)?,
            g_sv_nt_per_yr: *self.g_sv.get(k)?,
            h_sv_nt_per_yr: *self.h_sv.get(k)?,
        })
    }
}

/// The first (n, m) of the model never read, if any.
const fn first_missing(seen: u128) -> Option<(usize, usize)> {
    let mut n = 1;
    while n <= MAX_DEGREE {
        let mut m = 0;
        while m <= n {
            if seen & (1u128 << index(n, m)) == 0 {
                return Some((n, m));
            }
            m += 1;
        }
        n += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const COF: &str = include_str!("../data/WMM.COF");

    #[test]
    fn wmm2025_header_and_first_terms() {
        assert_eq!(WMM2025.epoch_year(), 2025.0);
        assert_eq!(WMM2025.valid_to_year(), 2030.0);
        assert_eq!(WMM2025.name(), "WMM-2025");
        let t = WMM2025.term(1, 0).unwrap();
        assert_eq!(
            (t.g_nt, t.h_nt, t.g_sv_nt_per_yr, t.h_sv_nt_per_yr),
            (-29351.8, 0.0, 12.0, 0.0)
        );
        let t = WMM2025.term(12, 12).unwrap();
        assert_eq!(
            (t.g_nt, t.h_nt, t.g_sv_nt_per_yr, t.h_sv_nt_per_yr),
            (-0.7, 0.2, -0.1, -0.1)
        );
        assert!(WMM2025.term(0, 0).is_none());
        assert!(WMM2025.term(13, 0).is_none());
        assert!(WMM2025.term(3, 4).is_none());
    }

    /// The const parser must agree with the standard library's float parser on every number
    /// of the real file (this is what makes "parsed at compile time" trustworthy).
    #[test]
    fn const_parser_matches_std_parse_on_every_line() {
        let mut lines = 0;
        for line in COF.lines().skip(1) {
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() != 6 {
                continue;
            }
            let n: usize = f[0].parse().unwrap();
            let m: usize = f[1].parse().unwrap();
            let t = WMM2025.term(n, m).unwrap();
            let want: Vec<f64> = f[2..].iter().map(|s| s.parse().unwrap()).collect();
            assert_eq!(
                [t.g_nt, t.h_nt, t.g_sv_nt_per_yr, t.h_sv_nt_per_yr].to_vec(),
                want,
                "line {line}"
            );
            lines += 1;
        }
        assert_eq!(lines, 90, "12 degrees give 2+3+…+13 = 90 terms");
    }

    #[test]
    fn malformed_files_are_typed_errors() {
        let kind = |t: &str| Coefficients::from_cof(t).map(|_| ()).unwrap_err().kind;
        assert_eq!(kind(""), CofErrorKind::MissingHeader);
        assert_eq!(kind("9999999999999999"), CofErrorKind::MissingHeader);
        assert_eq!(kind("2025.0 X 1/1/2025\n"), CofErrorKind::MissingTerminator);
        assert_eq!(kind("2025.0 X d\n1 0 1.0\n"), CofErrorKind::WrongFieldCount);
        assert_eq!(kind("2025.0 X d\n1 0 1.x 0 0 0\n"), CofErrorKind::BadNumber);
        assert_eq!(
            kind("2025.0 X d\n13 0 1 0 0 0\n"),
            CofErrorKind::BadDegreeOrOrder
        );
        assert_eq!(
            kind("2025.0 X d\n1 2 1 0 0 0\n"),
            CofErrorKind::BadDegreeOrOrder
        );
        assert_eq!(
            kind("2025.0 X d\n1 0 1 0 0 0\n1 0 1 0 0 0\n"),
            CofErrorKind::Duplicate
        );
        assert_eq!(
            kind("2025.0 X d\n1 0 1 0 0 0\n999999999999\n"),
            CofErrorKind::MissingTerm { n: 1, m: 1 }
        );
        // Dropping any single coefficient line of the real file is caught.
        let without_12_5: String = COF
            .lines()
            .filter(|l| !l.trim_start().starts_with("12  5"))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(
            kind(&without_12_5),
            CofErrorKind::MissingTerm { n: 12, m: 5 }
        );
        let e = Coefficients::from_cof("2025.0 X d\n1 0 1.x 0 0 0\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.to_string().contains("line 2"));
    }

    proptest! {
        /// Any text, however broken, gives a typed error naming a line of it (or the file
        /// as a whole, line 0), never a panic; 400 characters cannot hold the 90 terms of a
        /// degree-12 model, so none is accepted.
        #[test]
        fn parser_never_panics(text in ".{0,400}") {
            match Coefficients::from_cof(&text) {
                Ok(c) => prop_assert!(false, "accepted {:?}", c.name()),
                Err(e) => prop_assert!(e.line <= text.lines().count() + 1, "{e:?}"),
            }
        }

        /// Random damage to the real file never panics either: the file parses to the model
        /// when the damage changed nothing, and otherwise to a model of finite coefficients
        /// (a digit changed into another) or a typed error naming a line of the file.
        #[test]
        fn damaged_real_file_never_panics(cut in 0usize..4557, byte in any::<u8>()) {
            let mut bytes = COF.as_bytes().to_vec();
            if cut < bytes.len() {
                bytes[cut] = byte;
            }
            let text = String::from_utf8_lossy(&bytes);
            match Coefficients::from_cof(&text) {
                Ok(c) => {
                    prop_assert!(c.g.iter().chain(&c.h).chain(&c.g_sv).chain(&c.h_sv).all(|x| x.is_finite()));
                    if text == COF {
                        prop_assert!(c == WMM2025);
                    }
                }
                Err(e) => {
                    prop_assert!(text != COF);
                    prop_assert!(e.line <= text.lines().count() + 1, "{e:?}");
                }
            }
        }

    }
}
