//! The records of a delimited text file, as bytes: one line at a time into one reused
//! buffer, split into field spans, with no allocation per row and no UTF-8 check (numeric
//! fields are parsed from their bytes; only the header and error messages are decoded).
//!
//! A line is at most [`MAX_LINE_BYTES`] long: a longer one, or an input that never ends a
//! line (`/dev/zero`), is an error naming the row instead of an ever-growing buffer.

use std::io::{BufRead, Read};
use std::str::FromStr;

/// The longest line read, in bytes (64 KiB): far more than any sensor log's row (a few
/// hundred bytes), and small enough that a file with no line breaks fails at once.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// The read buffer (1 MiB): lines are split where they lie in it, so that a row is never
/// copied; large enough that refilling it (and moving the line cut at its end to the
/// front) costs nothing beside parsing the rows in it. Holds at least one longest line.
const BUFFER_BYTES: usize = 1 << 20;

/// The UTF-8 byte-order mark a spreadsheet may put before the header.
const BOM: &[u8] = b"\xef\xbb\xbf";

/// How the fields of a row are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Delimiter {
    /// Detected from the first line: the most frequent of `,` `;` tab, else runs of blanks.
    #[default]
    Auto,
    /// One byte.
    Byte(u8),
    /// Runs of spaces and tabs.
    Whitespace,
}

impl FromStr for Delimiter {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "auto" => Self::Auto,
            "comma" => Self::Byte(b','),
            "semicolon" => Self::Byte(b';'),
            "tab" | "\\t" | "\t" => Self::Byte(b'\t'),
            "whitespace" | "space" | " " => Self::Whitespace,
            "pipe" => Self::Byte(b'|'),
            _ if s.len() == 1 && s.is_ascii() && s != "\"" => Self::Byte(s.as_bytes()[0]),
            _ => {
                return Err(format!(
                    "`{s}` is not a delimiter: use auto, `,`, `;`, tab, whitespace or one character"
                ));
            }
        })
    }
}

impl Delimiter {
    /// The delimiter of a file whose first line (comments skipped) is `line`: the most
    /// frequent of `,` `;` tab, or runs of blanks when it has none of them.
    pub fn detect(line: &str) -> Self {
        let count = |c: char| line.chars().filter(|&x| x == c).count();
        let best = [',', ';', '\t']
            .into_iter()
            .map(|c| (count(c), c))
            .max_by_key(|&(n, _)| n);
        match best {
            Some((n, c)) if n > 0 => Self::Byte(c as u8),
            _ if line.split_whitespace().count() > 1 => Self::Whitespace,
            _ => Self::Byte(b','),
        }
    }
}

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
///
/// The lines are split where they lie in one large read buffer; only the part of a line
/// cut by the end of the buffer is moved, to the front, before the buffer is refilled.
pub struct Records {
    source: Box<dyn BufRead + Send>,
    delimiter: Delimiter,
    buffer: Vec<u8>,
    /// The bytes read: `buffer[..filled]`.
    filled: usize,
    /// The current line: `buffer[start..end]`, without its line break.
    start: usize,
    end: usize,
    /// Where the next line starts.
    next: usize,
    /// Whether the source has ended.
    eof: bool,
    spans: Vec<(usize, usize)>,
    line_number: usize,
}

impl Records {
    /// Records of `source` split at `delimiter` (not `Auto`: detect it first).
    pub fn new(source: Box<dyn BufRead + Send>, delimiter: Delimiter) -> Self {
        Self {
            source,
            delimiter,
            buffer: vec![0; BUFFER_BYTES],
            filled: 0,
            start: 0,
            end: 0,
            next: 0,
            eof: false,
            spans: Vec::new(),
            line_number: 0,
        }
    }

    /// Advances to the next record; `Ok(false)` at the end. On an error, [`Records::line`]
    /// is the row that failed.
    pub fn advance(&mut self) -> Result<bool, RecordError> {
        loop {
            if !self.next_line()? {
                return Ok(false);
            }
            let line = &self.buffer[self.start..self.end];
            if let Some((a, b)) = record_bounds(line) {
                split_fields(line, a, b, self.delimiter, &mut self.spans);
                return Ok(true);
            }
        }
    }

    /// Moves to the next line (a record or not), reading more of the source when the
    /// buffer holds no whole line; `Ok(false)` at the end of the source.
    fn next_line(&mut self) -> Result<bool, RecordError> {
        loop {
            let rest = &self.buffer[self.next..self.filled];
            if let Some(i) = memchr::memchr(b'\n', rest) {
                self.line_number += 1;
                if i > MAX_LINE_BYTES {
                    return Err(RecordError::TooLong);
                }
                (self.start, self.end) = (self.next, self.next + i);
                self.next += i + 1;
                return Ok(true);
            }
            if rest.len() > MAX_LINE_BYTES {
                self.line_number += 1;
                return Err(RecordError::TooLong);
            }
            if self.eof {
                if rest.is_empty() {
                    return Ok(false);
                }
                self.line_number += 1;
                (self.start, self.end) = (self.next, self.filled);
                self.next = self.filled;
                return Ok(true);
            }
            self.refill().inspect_err(|_| self.line_number += 1)?;
        }
    }

    /// Moves the unread bytes to the front and reads more after them (at least one byte,
    /// or sets `eof`).
    fn refill(&mut self) -> Result<(), RecordError> {
        self.buffer.copy_within(self.next..self.filled, 0);
        self.filled -= self.next;
        (self.start, self.end, self.next) = (0, 0, 0);
        loop {
            match self.source.read(&mut self.buffer[self.filled..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(n) => {
                    self.filled += n;
                    return Ok(());
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(RecordError::Io(e.to_string())),
            }
        }
    }

    /// Splits the current record again at `delimiter`, and the following ones too (once
    /// the first line has shown which it is).
    pub fn resplit(&mut self, delimiter: Delimiter) {
        self.delimiter = delimiter;
        let line = &self.buffer[self.start..self.end];
        let (a, b) = record_bounds(line).unwrap_or((0, 0));
        split_fields(line, a, b, delimiter, &mut self.spans);
    }

    /// The current record's line as text (without byte-order mark, line break and
    /// surrounding blanks; invalid UTF-8 replaced).
    pub fn text(&self) -> String {
        let line = &self.buffer[self.start..self.end];
        let (a, b) = record_bounds(line).unwrap_or((0, 0));
        String::from_utf8_lossy(&line[a..b]).into_owned()
    }

    /// Field `i` of the current record, as bytes.
    pub fn field(&self, i: usize) -> Option<&[u8]> {
        let line = &self.buffer[self.start..self.end];
        self.spans.get(i).map(|&(a, b)| &line[a..b])
    }

    /// Number of fields of the current record.
    pub fn len(&self) -> usize {
        self.spans.len()
    }

    /// The 1-based line of the current record.
    pub fn line(&self) -> usize {
        self.line_number
    }

    /// Whether the current record is the file's last line and has no line break after it
    /// (the next line would start right after it). The parsers see this in their chunks.
    #[cfg(test)]
    pub fn unterminated(&self) -> bool {
        self.next == self.end
    }

    /// Ends the line-by-line read: the source, the bytes read from it and not yet returned
    /// as records (from the current record's line on when `again`, else from the line
    /// after it), the number of lines before those bytes, and whether the source has ended.
    pub fn into_rest(self, again: bool) -> (Box<dyn BufRead + Send>, Vec<u8>, usize, bool) {
        let (from, lines) = if again {
            (self.start, self.line_number.saturating_sub(1))
        } else {
            (self.next, self.line_number)
        };
        let mut buffer = self.buffer;
        buffer.truncate(self.filled);
        buffer.drain(..from);
        (self.source, buffer, lines, self.eof)
    }

    /// The fields of the current record as text (invalid UTF-8 replaced), for a header.
    pub fn text_fields(&self) -> Vec<String> {
        (0..self.len())
            .map(|i| String::from_utf8_lossy(self.field(i).unwrap_or_default()).into_owned())
            .collect()
    }
}

/// The record in `line` (without its line break): the byte range left after a byte-order
/// mark and surrounding blanks, or `None` for a blank or `#` comment line.
pub fn record_bounds(line: &[u8]) -> Option<(usize, usize)> {
    let a = if line.starts_with(BOM) { BOM.len() } else { 0 };
    let (a, b) = trim(line, a, line.len());
    (a < b && line[a] != b'#').then_some((a, b))
}

/// Finds the fields of the record `line[a..b]` into `spans` (cleared first).
pub fn split_fields(
    line: &[u8],
    a: usize,
    b: usize,
    delimiter: Delimiter,
    spans: &mut Vec<(usize, usize)>,
) {
    spans.clear();
    let line = &line[..b];
    match delimiter {
        Delimiter::Byte(d) => {
            // Without a quote on the line (a sensor log's rows), every delimiter splits: one
            // pass, two comparisons a byte; a quote starts over with the quote-aware split.
            let mut start = a;
            for (i, &c) in line.iter().enumerate().skip(a) {
                if c == d {
                    spans.push(field_span(line, start, i));
                    start = i + 1;
                } else if c == b'"' {
                    return split_quoted(line, a, d, spans);
                }
            }
            spans.push(field_span(line, start, b));
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
                    spans.push((s, i));
                }
            }
        }
    }
}

/// The fields of `line[a..]` split at `d` outside double quotes.
fn split_quoted(line: &[u8], a: usize, d: u8, spans: &mut Vec<(usize, usize)>) {
    spans.clear();
    let mut start = a;
    let mut quoted = false;
    for (i, &c) in line.iter().enumerate().skip(a) {
        if c == b'"' {
            quoted = !quoted;
        } else if c == d && !quoted {
            spans.push(field_span(line, start, i));
            start = i + 1;
        }
    }
    spans.push(field_span(line, start, line.len()));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delimiters_are_detected() {
        assert_eq!(Delimiter::detect("t_s;mag_x;mag_y"), Delimiter::Byte(b';'));
        assert_eq!(Delimiter::detect("a\tb\tc"), Delimiter::Byte(b'\t'));
        assert_eq!(Delimiter::detect("-163 64 1"), Delimiter::Whitespace);
        assert_eq!(Delimiter::detect("t_s,mag_x"), Delimiter::Byte(b','));
        assert_eq!(Delimiter::detect("t_s"), Delimiter::Byte(b','));
        assert_eq!("tab".parse::<Delimiter>(), Ok(Delimiter::Byte(b'\t')));
        assert!("ab".parse::<Delimiter>().is_err());
    }

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
    fn lines_cut_by_the_end_of_the_buffer_are_read_whole() {
        // More than one buffer of lines: the line cut by the end of the first read is moved
        // to the front and completed by the next.
        let text: String = (0..120_000).map(|k| format!("{k},{}\n", k * 7)).collect();
        assert!(text.len() > BUFFER_BYTES);
        let source = std::io::BufReader::new(std::io::Cursor::new(text));
        let mut r = Records::new(Box::new(source), Delimiter::Byte(b','));
        let mut k = 0usize;
        while r.advance().unwrap() {
            assert_eq!(r.line(), k + 1);
            assert_eq!(r.text_fields(), vec![k.to_string(), (k * 7).to_string()]);
            k += 1;
        }
        assert_eq!(k, 120_000);
    }

    #[test]
    fn long_cells_are_shown_cut() {
        let long = vec![b'x'; 1000];
        let s = shown(&long);
        assert!(s.len() < 80 && s.contains("1000 bytes"), "{s}");
    }
}
