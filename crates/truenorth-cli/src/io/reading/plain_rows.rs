//! The fast path of the row parser: a row of plain decimals, read in one pass.
//!
//! Nearly every row of a sensor log is plain: numbers like `-12.345` between single-byte
//! delimiters, no quote, no blank, exactly the header's field count. Such a row is read
//! here in one pass over its bytes, each needed cell parsed where it lies. A row with
//! anything else (a quote, a blank, a comment, a byte-order mark, an empty, long or
//! exponent cell, too few or too many fields) is not read here at all but by the general
//! path, which alone decides what it means or what is wrong with it. So on the rows it
//! takes, this path gives exactly the general path's values: the same fields (no quote, and
//! no blank at either end, so splitting at every delimiter is the general split, and there
//! is nothing to trim), the same numbers (`number_parse::plain_decimal_prefix`, the fast
//! path of `parse_number`), and never an error.

use super::number_parse::plain_decimal_prefix;
use super::records::MAX_LINE_BYTES;

/// The most fields a row may have to take the fast path (its cells are held on the stack).
pub const MOST_FIELDS: usize = 64;

/// What the fast path needs to know of the file: its delimiter and which fields are read.
#[derive(Debug, Clone)]
pub struct PlainRows {
    delimiter: u8,
    /// For each field of a row, whether a column reads it.
    needed: Vec<bool>,
}

impl PlainRows {
    /// The fast path for rows of `width` fields split at `delimiter`, of which the fields
    /// at `read` are converted; `None` where it cannot apply (a delimiter that can be part
    /// of a number, or a row too wide).
    pub fn new(delimiter: u8, width: usize, read: impl IntoIterator<Item = usize>) -> Option<Self> {
        if delimiter.is_ascii_digit()
            || matches!(delimiter, b'-' | b'.' | b'"' | b'#')
            || delimiter.is_ascii_whitespace()
            || width > MOST_FIELDS
        {
            return None;
        }
        let mut needed = vec![false; width];
        for k in read {
            *needed.get_mut(k)? = true;
        }
        // A row has at least one field, and one is needed.
        needed.contains(&true).then_some(Self { delimiter, needed })
    }

    /// Reads the row at the start of `text` (the rest of a chunk: the row, its line break
    /// and what follows) if it is plain: the values of the needed fields are written into
    /// `cells` at their field positions, and the row's length without its line break is
    /// returned. `None` (with `cells` partly written) when the row is not plain and must go
    /// to the general path.
    #[inline]
    pub fn read(&self, text: &[u8], cells: &mut [f64; MOST_FIELDS]) -> Option<usize> {
        // A comment, a byte-order mark (0xEF), or blanks before the row (which may hide a
        // comment): the general path. Other blanks change nothing here: an unused cell is
        // not read, a needed one is digits to its end, and trimming never removes a
        // delimiter (a delimiter is not a blank).
        match text.first() {
            Some(&c) if c == b'#' || c == 0xEF || c.is_ascii_whitespace() => return None,
            _ => {}
        }
        let mut at = 0;
        let last = self.needed.len() - 1;
        for (field, &needed) in self.needed.iter().enumerate() {
            let rest = &text[at..];
            at += if needed {
                let (v, used) = plain_decimal_prefix(rest)?;
                cells[field] = v;
                used
            } else {
                // A quote could hide a delimiter: stop there, and the row goes to the
                // general path below. A needed cell stops at a quote as at any byte
                // that is not part of its number.
                memchr::memchr3(self.delimiter, b'"', b'\n', rest).unwrap_or(rest.len())
            };
            match text.get(at) {
                Some(&c) if c == self.delimiter && field < last => at += 1,
                Some(b'\n') | None if field == last => {
                    return (at <= MAX_LINE_BYTES).then_some(at);
                }
                _ => return None,
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::reading::number_parse::parse_number;
    use crate::io::reading::records::Delimiter;
    use crate::io::reading::records::{record_bounds, split_fields};
    use proptest::prelude::*;

    fn read(p: &PlainRows, line: &str) -> Option<Vec<f64>> {
        let mut cells = [f64::NAN; MOST_FIELDS];
        let text = format!("{line}\n9,9,9\n");
        let plain = p.read(text.as_bytes(), &mut cells);
        // Terminated or not, a row reads alike.
        let mut again = [f64::NAN; MOST_FIELDS];
        assert_eq!(p.read(line.as_bytes(), &mut again), plain, "{line:?}");
        plain.map(|len| {
            assert_eq!(len, line.len());
            cells[..p.needed.len()].to_vec()
        })
    }

    #[test]
    fn plain_rows_and_the_rest() {
        let p = PlainRows::new(b',', 3, [0, 2]).unwrap();
        let got = read(&p, "0.01,text,-12.5").unwrap();
        assert_eq!((got[0], got[2]), (0.01, -12.5));
        for not_plain in [
            "",
            "0.01,1",
            "0.01,1,2,3",
            "0.01,1,",
            ",1,2",
            " 0.01,1,2",
            "0.01,1,2\r",
            "#1,2,3",
            "1,\"2\",3",
            "1e3,1,2",
            "+1,1,2",
            "1,1,2.",
            "1,1,.2",
            "\u{feff}1,1,2",
        ] {
            assert!(read(&p, not_plain).is_none(), "{not_plain:?}");
        }
        // An unused field is not parsed, so its text does not matter.
        assert!(read(&p, "1, x y,3").is_some());
        assert!(read(&p, "1,,3").is_some());
        assert!(PlainRows::new(b'.', 3, [0]).is_none());
        assert!(PlainRows::new(b' ', 3, [0]).is_none());
        assert!(PlainRows::new(b',', 3, [3]).is_none());
        assert!(PlainRows::new(b',', MOST_FIELDS + 1, [0]).is_none());
        assert!(PlainRows::new(b',', 3, []).is_none());
    }

    proptest! {
        /// A row the fast path takes is one the general path splits into exactly the
        /// header's fields, whose needed cells parse to the same finite values, bit for
        /// bit; rows are drawn from the bytes that make the general path differ.
        #[test]
        fn the_fast_path_reads_what_the_general_path_reads(
            cells in prop::collection::vec(
                prop_oneof![
                    3 => "-?[0-9]{1,10}(\\.[0-9]{1,12})?",
                    1 => "[-0-9.,;e+ \t\r\"#x]{0,9}",
                ],
                1..6,
            ),
            needed in prop::collection::vec(any::<bool>(), 6),
            delimiter in prop::sample::select(vec![b',', b';']),
            bom in any::<bool>(),
        ) {
            let width = cells.len();
            let mut read: Vec<usize> = (0..width).filter(|&k| needed[k]).collect();
            if read.is_empty() {
                read.push(width - 1);
            }
            let p = PlainRows::new(delimiter, width, read.iter().copied()).unwrap();
            let mut line = if bom { b"\xef\xbb\xbf".to_vec() } else { Vec::new() };
            line.extend_from_slice(cells.join(&(delimiter as char).to_string()).as_bytes());
            let mut got = [f64::NAN; MOST_FIELDS];
            if let Some(len) = p.read(&line, &mut got) {
                prop_assert_eq!(len, line.len());
                let (a, b) = record_bounds(&line).expect("a record");
                let mut spans = Vec::new();
                split_fields(&line, a, b, Delimiter::Byte(delimiter), &mut spans);
                prop_assert_eq!(spans.len(), width);
                for &k in &read {
                    let (a, b) = spans[k];
                    let want = parse_number(&line[a..b]).expect("a number");
                    prop_assert!(want.is_finite());
                    prop_assert_eq!(got[k].to_bits(), want.to_bits());
                }
            }
        }
    }
}
