//! The records of a delimited text file, as bytes: one line at a time into one reused
//! buffer, split into field spans, with no allocation per row and no UTF-8 check (numeric
//! fields are parsed from their bytes; only the header and error messages are decoded).
//!
//! A line is at most [`MAX_LINE_BYTES`] long: a longer one, or an input that never ends a
//! line (`/dev/zero`), is an error naming the row instead of an ever-growing buffer.

use std::io::{BufRead, Read};

use super::columns::Delimiter;

/// The longest line read, in bytes (64 KiB): far more than any sensor log's row (a few
/// hundred bytes), and small enough that a file with no line breaks fails at once.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The UTF-8 byte-order mark a spreadsheet may put before the header.
const BOM: &[u8] = b"\xef\xbb\xbf";

/// Why the next record could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RecordError {
    /// The operating system's read failed.
    Io(String),
    /// A line longer than [`MAX_LINE_BYTES`].
    TooLong,
}

impl std::fmt::Display for RecordError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Io(e) => write!(f, "cannot read: {e}"),
            Self::TooLong => write!(
                f,
                "line longer than {} KiB (the longest line read): not a sensor log's row, or a file without line breaks",
                MAX_LINE_BYTES / 1024
            ),
        }
    }
}

/// The records of a file, one line each: blank lines and lines starting with `#` are
/// skipped (and counted, so that row numbers are the file's line numbers). A field may be
/// enclosed in double quotes, which are dropped; a quoted field cannot span lines (sensor
/// logs never need it).
pub struct Records {
    source: Box<dyn BufRead + Send>,
    delimiter: Delimiter,
    line: Vec<u8>,
    spans: Vec<(usize, usize)>,
    line_number: usize,
    /// Whether the current record's line ended without a line break (the file's last).
    unterminated: bool,
}

impl Records {
    /// Records of `source` split at `delimiter` (not `Auto`: detect it first).
    pub fn new(source: Box<dyn BufRead + Send>, delimiter: Delimiter) -> Self {
        Self {
            source,
            delimiter,
            line: Vec::with_capacity(256),
            spans: Vec::new(),
            line_number: 0,
            unterminated: false,
        }
    }

    /// Advances to the next record; `Ok(false)` at the end. On an error, [`Records::line`]
    /// is the row that failed.
    pub fn advance(&mut self) -> Result<bool, RecordError> {
        loop {
            self.line.clear();
            let limit = MAX_LINE_BYTES as u64 + 1;
            let n = (&mut self.source)
                .take(limit)
                .read_until(b'\n', &mut self.line)
                .map_err(|e| {
                    self.line_number += 1;
                    RecordError::Io(e.to_string())
                })?;
            if n == 0 {
                return Ok(false);
            }
            self.line_number += 1;
            self.unterminated = self.line.last() != Some(&b'\n');
            if self.unterminated && self.line.len() > MAX_LINE_BYTES {
                return Err(RecordError::TooLong);
            }
            let (a, b) = self.content();
            let text = &self.line[a..b];
            if text.is_empty() || text[0] == b'#' {
                continue;
            }
            self.split(a, b);
            return Ok(true);
        }
    }

    /// The current line without its byte-order mark, line break and surrounding blanks.
    fn content(&self) -> (usize, usize) {
        let line = &self.line[..];
        let a = if line.starts_with(BOM) { BOM.len() } else { 0 };
        trim(line, a, line.len())
    }

    /// Finds the fields of `line[a..b]`.
    fn split(&mut self, a: usize, b: usize) {
        self.spans.clear();
        let line = &self.line[..b];
        match self.delimiter {
            // Without a quote on the line (a sensor log's rows), every delimiter splits: one
            // comparison a byte.
            Delimiter::Byte(d) if !line[a..].contains(&b'"') => {
                let mut start = a;
                for (i, &c) in line.iter().enumerate().skip(a) {
                    if c == d {
                        self.spans.push(field_span(line, start, i));
                        start = i + 1;
                    }
                }
                self.spans.push(field_span(line, start, b));
            }
            Delimiter::Byte(d) => {
                let mut start = a;
                let mut quoted = false;
                for (i, &c) in line.iter().enumerate().skip(a) {
                    if c == b'"' {
                        quoted = !quoted;
                    } else if c == d && !quoted {
                        self.spans.push(field_span(line, start, i));
                        start = i + 1;
                    }
                }
                self.spans.push(field_span(line, start, b));
            }
            _ => {
                let mut i = a;
                while i < b {
                    while i < b && is_blank(line[i]) {
                        i += 1;
                    }
                    let s = i;
                    while i < b && !is_blank(line[i]) {
                        i += 1;
                    }
                    if i > s {
                        self.spans.push((s, i));
                    }
                }
            }
        }
    }

    /// Splits the current record again at `delimiter`, and the following ones too (once
    /// the first line has shown which it is).
    pub fn resplit(&mut self, delimiter: Delimiter) {
        self.delimiter = delimiter;
        let (a, b) = self.content();
        self.split(a, b);
    }

    /// The current record's line as text (without byte-order mark, line break and
    /// surrounding blanks; invalid UTF-8 replaced).
    pub fn text(&self) -> String {
        let (a, b) = self.content();
        String::from_utf8_lossy(&self.line[a..b]).into_owned()
    }

    /// Field `i` of the current record, as bytes.
    pub fn field(&self, i: usize) -> Option<&[u8]> {
        self.spans.get(i).map(|&(a, b)| &self.line[a..b])
    }

    /// Number of fields of the current record.
    pub fn len(&self) -> usize {
        self.spans.len()
    }

    /// The 1-based line of the current record.
    pub fn line(&self) -> usize {
        self.line_number
    }

    /// Whether the current record is the file's last line and has no line break after it.
    pub fn unterminated(&self) -> bool {
        self.unterminated
    }

    /// The fields of the current record as text (invalid UTF-8 replaced), for a header.
    pub fn text_fields(&self) -> Vec<String> {
        (0..self.len())
            .map(|i| String::from_utf8_lossy(self.field(i).unwrap_or_default()).into_owned())
            .collect()
    }
}

fn is_blank(c: u8) -> bool {
    c == b' ' || c == b'\t' || c == b'\r' || c == b'\n'
}

/// `line[a..b]` without surrounding ASCII blanks.
fn trim(line: &[u8], mut a: usize, mut b: usize) -> (usize, usize) {
    while a < b && line[a].is_ascii_whitespace() {
        a += 1;
    }
    while b > a && line[b - 1].is_ascii_whitespace() {
        b -= 1;
    }
    (a, b)
}

/// The byte range of the field `line[a..b]` without surrounding blanks and quotes.
fn field_span(line: &[u8], a: usize, b: usize) -> (usize, usize) {
    let (mut a, mut b) = trim(line, a, b);
    if b - a >= 2 && line[a] == b'"' && line[b - 1] == b'"' {
        a += 1;
        b -= 1;
    }
    (a, b)
}

/// A cell for an error message: whole when short, else its start and its length, so that
/// a huge cell never becomes a huge message.
pub fn shown(cell: &[u8]) -> String {
    const SHOWN: usize = 40;
    if cell.len() <= SHOWN {
        String::from_utf8_lossy(cell).into_owned()
    } else {
        format!(
            "{}… ({} bytes)",
            String::from_utf8_lossy(&cell[..SHOWN]),
            cell.len()
        )
    }
}

/// Parses a numeric cell from its bytes (decimal point, optional exponent; `inf` and `nan`
/// are read as such, for the caller to refuse).
pub fn parse_number(cell: &[u8]) -> Option<f64> {
    fast_float2::parse::<f64, _>(cell).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn records(text: &[u8], d: Delimiter) -> Records {
        Records::new(Box::new(std::io::Cursor::new(text.to_vec())), d)
    }

    fn all(text: &[u8], d: Delimiter) -> Result<Vec<(usize, Vec<String>, bool)>, RecordError> {
        let mut r = records(text, d);
        let mut out = Vec::new();
        while r.advance()? {
            out.push((r.line(), r.text_fields(), r.unterminated()));
        }
        Ok(out)
    }

    #[test]
    fn splits_quotes_bom_crlf_and_comments() {
        let got = all(
            b"\xef\xbb\xbfa, \"b,c\" ;x\r\n# note\n\n1,2\n3",
            Delimiter::Byte(b','),
        )
        .unwrap();
        let row = |n, f: &[&str], u| (n, f.iter().map(|s| s.to_string()).collect(), u);
        assert_eq!(
            got,
            vec![
                row(1, &["a", "\"b,c\" ;x"], false),
                row(4, &["1", "2"], false),
                row(5, &["3"], true)
            ]
        );
        let got = all(b"  1 \t 2  3\n", Delimiter::Whitespace).unwrap();
        assert_eq!(got[0].1, vec!["1", "2", "3"]);
    }

    proptest::proptest! {
        /// A line without quotes splits at every delimiter, each field trimmed of blanks,
        /// as `str::split` would.
        #[test]
        fn lines_without_quotes_split_at_every_delimiter(
            cells in proptest::collection::vec("[ 0-9.eE+-]{0,6}", 1..8),
            d in proptest::sample::select(vec![b',', b';', b'\t', b'|']),
        ) {
            let line = cells.join(&(d as char).to_string());
            proptest::prop_assume!(!line.trim().is_empty());
            let got = all(format!("{line}\n").as_bytes(), Delimiter::Byte(d)).unwrap();
            let want: Vec<String> = line
                .trim()
                .split(d as char)
                .map(|c| c.trim().to_string())
                .collect();
            proptest::prop_assert_eq!(&got[0].1, &want);
        }
    }

    #[test]
    fn an_endless_line_is_an_error_naming_its_row() {
        let mut text = b"a,b\n1,2\n".to_vec();
        text.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES + 10));
        let mut r = records(&text, Delimiter::Byte(b','));
        assert!(r.advance().unwrap() && r.advance().unwrap());
        assert_eq!(r.advance(), Err(RecordError::TooLong));
        assert_eq!(r.line(), 3);
        // A line of exactly the limit is read.
        let mut text = vec![b'1'; MAX_LINE_BYTES - 1];
        text.push(b'\n');
        assert_eq!(all(&text, Delimiter::Byte(b',')).unwrap().len(), 1);
    }

    #[test]
    fn numbers_and_shown_cells() {
        assert_eq!(parse_number(b"-1.5e3"), Some(-1500.0));
        assert_eq!(parse_number(b"+2"), Some(2.0));
        assert_eq!(parse_number(b"1,5"), None);
        assert_eq!(parse_number(b""), None);
        assert!(parse_number(b"inf").is_some_and(f64::is_infinite));
        let long = vec![b'x'; 1000];
        let s = shown(&long);
        assert!(s.len() < 80 && s.contains("1000 bytes"), "{s}");
    }
}
