//! The input cut into chunks of whole lines, each knowing the number of the line before
//! it, so that several threads can parse chunks at once and still name every row by its
//! line in the file.
//!
//! The cutter only reads (and, through its source, decompresses), counts line breaks and
//! finds the last one in a chunk; the lines are split and parsed by whoever takes the
//! chunk. A line longer than [`MAX_LINE_BYTES`] in a chunk is left for the parser to
//! refuse; a line longer than that at the end of the input, or cut by a read error, is
//! refused here, at the row where a read of one line at a time fails.

use std::io::BufRead;

use super::records::{MAX_LINE_BYTES, RecordError};

/// The bytes read per chunk (128 KiB): some thousands of a sensor log's rows, so that
/// handing a chunk to a thread costs nothing beside parsing it, and more than a longest
/// line, so that a full chunk without a line break is a line too long.
pub const CHUNK_BYTES: usize = 128 * 1024;

/// How the input ended: `Ok` at its end, or the record error at the row (1-based line)
/// where it failed.
pub type ChunkEnd = Result<(), (usize, RecordError)>;

/// Whole lines of the input: each ends with a line break, except the input's last line
/// when the input ends without one.
#[derive(Debug, Default)]
pub struct Chunk {
    /// The buffer: the lines are `bytes[..len]`.
    pub bytes: Vec<u8>,
    /// The length of the lines in `bytes`.
    pub len: usize,
    /// The 1-based number of the line before the first (0 for the file's first line).
    pub line_before: usize,
    /// How the input ended after these lines, if it did.
    pub end: Option<ChunkEnd>,
}

impl Chunk {
    /// The lines.
    pub fn lines(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// Cuts a source into [`Chunk`]s of at most `max_lines` lines.
pub struct ChunkCutter {
    source: Box<dyn BufRead + Send>,
    /// Bytes read and not yet handed out (whole lines and the start of the next).
    carry: Vec<u8>,
    /// Lines handed out so far.
    lines: usize,
    eof: bool,
    /// The read error met, to report once the lines before it are handed out.
    failed: Option<String>,
    max_lines: usize,
    done: bool,
}

impl ChunkCutter {
    /// Cuts `source`, preceded by `start` (bytes already read from it, beginning at a line
    /// start after `lines` lines; `eof` if the source has already ended).
    pub fn new(
        source: Box<dyn BufRead + Send>,
        start: Vec<u8>,
        lines: usize,
        eof: bool,
        max_lines: usize,
    ) -> Self {
        Self {
            source,
            carry: start,
            lines,
            eof,
            failed: None,
            max_lines: max_lines.max(1),
            done: false,
        }
    }

    /// Fills `chunk` (its buffer reused) with the next lines; `false` once the chunk with
    /// the end has been handed out.
    pub fn next_into(&mut self, chunk: &mut Chunk) -> bool {
        if self.done {
            return false;
        }
        // The buffer keeps its length from chunk to chunk, so that it is zeroed once only.
        let carried = self.carry.len();
        let size = CHUNK_BYTES.max(carried);
        if chunk.bytes.len() < size {
            chunk.bytes.resize(size, 0);
        }
        chunk.bytes[..carried].copy_from_slice(&self.carry);
        self.carry.clear();
        chunk.end = None;
        chunk.line_before = self.lines;
        let filled = self.fill(&mut chunk.bytes, carried);
        let buf = &chunk.bytes[..filled];
        let (cut, count) = last_break(buf, self.max_lines);
        if count > 0 {
            self.carry.extend_from_slice(&buf[cut..]);
            chunk.len = cut;
            self.lines += count;
            return true;
        }
        // No line break: the input's last line, or a line too long, or a failed read.
        self.done = true;
        let row = self.lines + 1;
        chunk.len = filled;
        chunk.end = Some(if filled > MAX_LINE_BYTES {
            chunk.len = 0;
            Err((row, RecordError::TooLong))
        } else if let Some(e) = self.failed.take() {
            chunk.len = 0;
            Err((row, RecordError::Io(e)))
        } else {
            Ok(())
        });
        true
    }

    /// Reads after the first `filled` bytes of `buf` until it holds [`CHUNK_BYTES`], the
    /// input ends or a read fails; returns the bytes it then holds.
    fn fill(&mut self, buf: &mut [u8], mut filled: usize) -> usize {
        while filled < CHUNK_BYTES && !self.eof && self.failed.is_none() {
            match self.source.read(&mut buf[filled..CHUNK_BYTES]) {
                Ok(0) => self.eof = true,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => self.failed = Some(e.to_string()),
            }
        }
        filled
    }
}

/// The end of the `max_lines`-th line break of `bytes`, or of its last if it has fewer,
/// and the number of lines before it.
fn last_break(bytes: &[u8], max_lines: usize) -> (usize, usize) {
    // Counting compiles to a vector loop; walking from break to break is needed only when
    // the lines are shorter than a chunk over `max_lines`.
    let count = count_breaks(bytes);
    if count <= max_lines {
        let end = memchr::memrchr(b'\n', bytes).map_or(0, |i| i + 1);
        return (end, count);
    }
    let i = memchr::memchr_iter(b'\n', bytes)
        .nth(max_lines - 1)
        .unwrap_or_default();
    (i + 1, max_lines)
}

/// The line breaks in `bytes`, counted 64 bytes at a time into one byte each (which
/// compiles to vector compares and sums).
fn count_breaks(bytes: &[u8]) -> usize {
    let blocks = bytes.chunks_exact(64);
    let tail = blocks.remainder();
    let whole: usize = blocks
        .map(|b| usize::from(b.iter().map(|&c| u8::from(c == b'\n')).sum::<u8>()))
        .sum();
    whole + tail.iter().filter(|&&c| c == b'\n').count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    /// A source handing out at most `step` bytes a read, then an error if `fail`.
    struct Trickle {
        bytes: Vec<u8>,
        at: usize,
        step: usize,
        fail: bool,
    }

    impl Read for Trickle {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            let n = self.step.min(out.len()).min(self.bytes.len() - self.at);
            if n == 0 && self.fail {
                return Err(std::io::Error::other("broken"));
            }
            out[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    fn cut(
        text: &[u8],
        step: usize,
        fail: bool,
        max_lines: usize,
    ) -> (Vec<Vec<u8>>, Option<ChunkEnd>) {
        let source = Trickle {
            bytes: text.to_vec(),
            at: 0,
            step,
            fail,
        };
        let source = std::io::BufReader::with_capacity(7, source);
        let mut cutter = ChunkCutter::new(Box::new(source), Vec::new(), 0, false, max_lines);
        let mut chunk = Chunk::default();
        let mut out = Vec::new();
        let mut lines = 0;
        while cutter.next_into(&mut chunk) {
            assert_eq!(chunk.line_before, lines);
            let breaks = count_breaks(chunk.lines());
            assert_eq!(
                breaks,
                chunk.lines().iter().filter(|&&c| c == b'\n').count()
            );
            assert!(breaks <= max_lines);
            lines += breaks;
            out.push(chunk.lines().to_vec());
            if chunk.end.is_some() {
                return (out, chunk.end.take());
            }
        }
        unreachable!("the last chunk carries the end")
    }

    proptest::proptest! {
        /// The chunks are whole lines which, joined, are the input, whatever the read sizes
        /// and the line limit.
        #[test]
        fn chunks_are_whole_lines_of_the_input(
            lines in proptest::collection::vec("[a-z0-9,]{0,30}", 0..300),
            last in "[a-z0-9]{0,5}",
            step in 1usize..500,
            max_lines in 1usize..50,
        ) {
            let text = format!("{}{last}", lines.iter().map(|l| format!("{l}\n")).collect::<String>());
            let (chunks, end) = cut(text.as_bytes(), step, false, max_lines);
            proptest::prop_assert_eq!(end, Some(Ok(())));
            for c in &chunks[..chunks.len() - 1] {
                proptest::prop_assert!(c.is_empty() || c.ends_with(b"\n"));
            }
            proptest::prop_assert_eq!(chunks.concat(), text.into_bytes());
        }
    }

    #[test]
    fn an_endless_line_or_a_failed_read_ends_at_its_row() {
        let mut text = b"a\nb\n".to_vec();
        text.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES + 1));
        let (_, end) = cut(&text, 1000, false, 10);
        assert_eq!(end, Some(Err((3, RecordError::TooLong))));
        // A last line of the limit is read; the failed read is reported after it.
        let mut text = b"a\n".to_vec();
        text.extend(std::iter::repeat_n(b'7', MAX_LINE_BYTES));
        let (chunks, end) = cut(&text, 1000, false, 10);
        assert_eq!((chunks.concat(), end), (text.clone(), Some(Ok(()))));
        let (chunks, end) = cut(b"a\nb\nc", 3, true, 10);
        assert_eq!(chunks.concat(), b"a\nb\n");
        assert_eq!(end, Some(Err((3, RecordError::Io("broken".into())))));
    }
}
