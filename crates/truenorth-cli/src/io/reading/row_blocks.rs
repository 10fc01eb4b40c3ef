//! Reading on more than one core: one thread reads the input (and decompresses it) and cuts it
//! into chunks of whole lines (see the `chunks` module), two workers split and parse the
//! chunks into blocks of numbers, and the thread that uses the rows (a fit, a filter, a
//! writer) takes the blocks in file order, so that parsing overlaps itself and the work
//! done with the rows.
//!
//! Chunk `k` goes to worker `k mod W` and its block comes back from that worker, so the
//! blocks arrive in file order without sorting. Chunks and blocks are reused: a fixed
//! number of each exists, nothing is allocated per row, and the memory held does not grow
//! with the file. Each row is parsed by the same code as on one thread, so every number is
//! the same; the first error in file order is the one delivered, after every row before it.
//! The one check that spans rows, that a column increases, is done by each worker inside
//! its chunk and by the consumer at the hand-over from one chunk's last row to the next
//! chunk's first. A consumer that stops early stops every thread (their channels close);
//! a thread that dies (a panic) closes its channels too, which the consumer reports as an
//! error instead of waiting.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, SyncSender, TryRecvError, channel, sync_channel};

use super::chunks::{Chunk, ChunkCutter};
use crate::io::{CliError, CliResult};

/// Rows per block, and so lines per chunk: enough that handing a block over costs nothing
/// beside parsing it, few enough that a block of ten columns stays in the second-level
/// cache (640 KiB).
pub const BLOCK_ROWS: usize = 8192;

/// Blocks per worker (being filled, queued, being read): a worker may run this far ahead.
pub const BLOCKS: usize = 3;

/// The parsing threads: two, or one on a machine with one core.
fn workers() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get().min(2))
}

/// Parsed rows: `numbers[k]` is the row number of the values `values[k·n .. (k+1)·n]`,
/// `n` the columns read; `end` says how the input ended after them, if it did.
#[derive(Debug, Default)]
pub struct Block {
    /// The row numbers (1-based lines of the file).
    pub numbers: Vec<usize>,
    /// The values, row after row.
    pub values: Vec<f64>,
    /// How the input ended after these rows: at its end, or at an error.
    pub end: Option<CliResult>,
    /// The last value of the increasing column that was a number (not NaN), if any row of
    /// the block had one: the value the next chunk's first row must exceed.
    pub last_increasing: Option<f64>,
}

impl Block {
    fn clear(&mut self) {
        self.numbers.clear();
        self.values.clear();
        self.end = None;
        self.last_increasing = None;
    }
}

/// Parses the rows of one chunk into a block; shared by the workers.
pub trait ChunkParser: Send + Sync + 'static {
    /// Appends the rows of `chunk` to `block`, stopping at the first error (in
    /// `block.end`), and sets `block.end` from `chunk.end` when the chunk is the last.
    /// `spans` is the worker's scratch space for field boundaries.
    fn parse_chunk(&self, chunk: &Chunk, block: &mut Block, spans: &mut Vec<(usize, usize)>);

    /// The column whose values must increase strictly from row to row, if any.
    fn increasing(&self) -> Option<usize>;

    /// The error for row `number`, whose increasing column's value `t` does not come after
    /// the previous row's `previous`.
    fn not_after(&self, number: usize, t: f64, previous: f64) -> CliError;
}

/// The consumer's end: the rows in file order, one at a time.
pub struct RowBlocks {
    /// Worker `w`'s blocks, and the way back for them when emptied.
    full: Vec<Receiver<Block>>,
    empty: Vec<SyncSender<Block>>,
    /// The chunk (and worker) whose block comes next.
    chunk: usize,
    current: Option<(usize, Block)>,
    next: usize,
    columns: usize,
    increasing: Option<usize>,
    /// The increasing column's last number in the rows handed out.
    previous: Option<f64>,
    parser: Arc<dyn ChunkParser>,
    done: bool,
}

impl RowBlocks {
    /// Starts the cutter on `cutter` and the workers on `parser`, which reads `columns`
    /// numbers per row.
    pub fn spawn(
        cutter: ChunkCutter,
        parser: impl ChunkParser,
        columns: usize,
    ) -> std::io::Result<Self> {
        Self::spawn_with(cutter, Arc::new(parser), columns, workers())
    }

    /// [`RowBlocks::spawn`] with `workers` parsing threads (at least one).
    pub fn spawn_with(
        mut cutter: ChunkCutter,
        parser: Arc<dyn ChunkParser>,
        columns: usize,
        workers: usize,
    ) -> std::io::Result<Self> {
        let workers = workers.max(1);
        // Chunks in flight: one queued and one being parsed per worker, one being cut.
        let chunks = 2 * workers + 1;
        let (returned_tx, returned) = channel::<Chunk>();
        let mut to_workers = Vec::with_capacity(workers);
        let mut full = Vec::with_capacity(workers);
        let mut empty = Vec::with_capacity(workers);
        for w in 0..workers {
            let (chunk_tx, chunk_rx) = sync_channel::<Chunk>(1);
            let (full_tx, full_rx) = sync_channel::<Block>(BLOCKS);
            let (empty_tx, empty_rx) = sync_channel::<Block>(BLOCKS);
            let returned_tx = returned_tx.clone();
            let parser = Arc::clone(&parser);
            std::thread::Builder::new()
                .name(format!("truenorth-parse-{w}"))
                .spawn(move || work(&*parser, &chunk_rx, &returned_tx, &full_tx, &empty_rx))?;
            to_workers.push(chunk_tx);
            full.push(full_rx);
            empty.push(empty_tx);
        }
        drop(returned_tx);
        std::thread::Builder::new()
            .name("truenorth-read".into())
            .spawn(move || {
                let mut made = 0usize;
                for k in 0.. {
                    // Every worker has gone: stop reading.
                    let Some(mut chunk) = reuse_or_make(&returned, &mut made, chunks) else {
                        return;
                    };
                    if !cutter.next_into(&mut chunk) {
                        return;
                    }
                    let last = chunk.end.is_some();
                    if to_workers[k % workers].send(chunk).is_err() || last {
                        return;
                    }
                }
            })?;
        let increasing = parser.increasing();
        Ok(Self {
            full,
            empty,
            chunk: 0,
            current: None,
            next: 0,
            columns,
            increasing,
            previous: None,
            parser,
            done: false,
        })
    }

    /// Copies the next row's values into `values` and returns its row number; `None` at the
    /// end of the input, the first error in file order where it happened.
    ///
    /// A row of the current block, the usual case, is handed out inline; the change of
    /// block ([`RowBlocks::fill`]) out of line: as one function, its set-up for the loop
    /// over blocks ran for every row and cost more than the copy.
    #[inline]
    pub fn next_into(&mut self, values: &mut [f64]) -> CliResult<Option<usize>> {
        let in_block = matches!(&self.current, Some((_, b)) if self.next < b.numbers.len());
        if !in_block && !self.fill()? {
            return Ok(None);
        }
        let Some((_, block)) = &self.current else {
            return Ok(None);
        };
        let k = self.next;
        self.next += 1;
        let n = self.columns;
        values.copy_from_slice(&block.values[k * n..(k + 1) * n]);
        Ok(Some(block.numbers[k]))
    }

    /// The rows not yet handed out of the current block, or else of the next one, all at
    /// once: their row numbers and their values, row after row (`None` at the end of the
    /// input, the first error in file order where it happened). For a loop over every row,
    /// which then pays no call and no copy a row.
    pub fn next_rows(&mut self) -> CliResult<Option<(&[usize], &[f64])>> {
        if !self.fill()? {
            return Ok(None);
        }
        let Some((_, block)) = &self.current else {
            return Ok(None);
        };
        let k = self.next;
        self.next = block.numbers.len();
        Ok(Some((
            &block.numbers[k..],
            &block.values[k * self.columns..],
        )))
    }

    /// Makes the current block one with rows not yet handed out, taking the next blocks in
    /// file order as needed; `false` at the end of the input, the first error in file order
    /// where it happened.
    #[inline(never)]
    fn fill(&mut self) -> CliResult<bool> {
        loop {
            if let Some((_, block)) = &mut self.current {
                if self.next < block.numbers.len() {
                    return Ok(true);
                }
                if let Some(end) = block.end.take() {
                    self.done = true;
                    return end.map(|()| false);
                }
                // Emptied: back to its worker (which may have stopped; then it is dropped).
                if let Some((w, b)) = self.current.take() {
                    let _ = self.empty[w].try_send(b);
                }
            }
            if self.done {
                return Ok(false);
            }
            let w = self.chunk % self.full.len();
            match self.full[w].recv() {
                Ok(b) => {
                    self.chunk += 1;
                    self.next = 0;
                    if let Err(e) = self.hand_over(&b) {
                        self.done = true;
                        return Err(e);
                    }
                    self.current = Some((w, b));
                }
                // The worker ended without saying how (it panicked): no more rows.
                Err(_) => {
                    self.done = true;
                    return Err(CliError::msg("the reader thread stopped unexpectedly"));
                }
            }
        }
    }

    /// Checks the first row of a chunk's block against the last of the chunks before it,
    /// and carries the increasing column's last number on.
    fn hand_over(&mut self, block: &Block) -> CliResult {
        let Some(k) = self.increasing else {
            return Ok(());
        };
        if let (Some(previous), Some(&number)) = (self.previous, block.numbers.first()) {
            let t = block.values[k];
            if t.partial_cmp(&previous) != Some(std::cmp::Ordering::Greater) {
                return Err(self.parser.not_after(number, t, previous));
            }
        }
        self.previous = block.last_increasing.or(self.previous);
        Ok(())
    }
}

/// A worker: parses each chunk it is given into a block, gives the chunk back to the
/// cutter and sends the block on, until a channel closes or the input ends.
fn work(
    parser: &dyn ChunkParser,
    chunks: &Receiver<Chunk>,
    returned: &Sender<Chunk>,
    full: &SyncSender<Block>,
    empty: &Receiver<Block>,
) {
    let mut made = 0usize;
    let mut spans = Vec::new();
    while let Ok(chunk) = chunks.recv() {
        // The consumer has gone.
        let Some(mut block) = reuse_or_make(empty, &mut made, BLOCKS) else {
            return;
        };
        block.clear();
        parser.parse_chunk(&chunk, &mut block, &mut spans);
        let _ = returned.send(chunk);
        let last = block.end.is_some();
        if full.send(block).is_err() || last {
            return;
        }
    }
}

/// One buffer of a pool of at most `max` reused ones: one given back, else a new one while
/// fewer than `max` exist (`made` counts them), else the next one given back; `None` once
/// none can come back (the other end has gone).
fn reuse_or_make<T: Default>(returned: &Receiver<T>, made: &mut usize, max: usize) -> Option<T> {
    match returned.try_recv() {
        Ok(x) => Some(x),
        Err(TryRecvError::Empty) if *made < max => {
            *made += 1;
            Some(T::default())
        }
        Err(_) => returned.recv().ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows `k = 1..=n`, one a line, of values `(k, −k)`, and an error at row `fail`.
    struct Counting {
        fail: Option<usize>,
    }

    impl ChunkParser for Counting {
        fn parse_chunk(&self, chunk: &Chunk, block: &mut Block, _: &mut Vec<(usize, usize)>) {
            let lines = chunk.lines().iter().filter(|&&c| c == b'\n').count();
            for k in chunk.line_before + 1..=chunk.line_before + lines {
                if Some(k) == self.fail {
                    block.end = Some(Err(CliError::msg(format!("bad row {k}"))));
                    return;
                }
                block.numbers.push(k);
                block.values.extend_from_slice(&[k as f64, -(k as f64)]);
                block.last_increasing = Some(k as f64);
            }
            block.end = chunk.end.as_ref().map(|_| Ok(()));
        }

        fn increasing(&self) -> Option<usize> {
            Some(0)
        }

        fn not_after(&self, number: usize, t: f64, previous: f64) -> CliError {
            CliError::msg(format!("row {number}: {t} after {previous}"))
        }
    }

    /// `n` lines of one byte each, cut in chunks of `chunk_lines`.
    fn counting(n: usize, fail: Option<usize>, chunk_lines: usize, workers: usize) -> RowBlocks {
        let text: Box<dyn std::io::BufRead + Send> =
            Box::new(std::io::Cursor::new(b"x\n".repeat(n)));
        let cutter = ChunkCutter::new(text, Vec::new(), 0, false, chunk_lines);
        RowBlocks::spawn_with(cutter, Arc::new(Counting { fail }), 2, workers).unwrap()
    }

    /// Every row of `blocks`, and how they ended: one row at a time, or, `by_rows`, taking
    /// a row and then the rest of its block by turns (so both ways, and their mix, are held).
    fn drain(mut blocks: RowBlocks, by_rows: bool) -> (Vec<usize>, CliResult) {
        let mut v = [0.0; 2];
        let mut seen = Vec::new();
        let mut take_rest = false;
        loop {
            if by_rows && take_rest {
                match blocks.next_rows() {
                    Ok(Some((numbers, values))) => {
                        assert!(!numbers.is_empty());
                        assert_eq!(values.len(), 2 * numbers.len());
                        for (&n, v) in numbers.iter().zip(values.chunks_exact(2)) {
                            assert_eq!(v, [n as f64, -(n as f64)]);
                            seen.push(n);
                        }
                    }
                    Ok(None) => {
                        assert!(matches!(blocks.next_rows(), Ok(None)));
                        return (seen, Ok(()));
                    }
                    Err(e) => return (seen, Err(e)),
                }
                take_rest = false;
                continue;
            }
            take_rest = true;
            match blocks.next_into(&mut v) {
                Ok(Some(n)) => {
                    assert_eq!(v, [n as f64, -(n as f64)]);
                    seen.push(n);
                }
                Ok(None) => {
                    // After the end it stays at the end.
                    assert!(matches!(blocks.next_into(&mut v), Ok(None)));
                    return (seen, Ok(()));
                }
                Err(e) => return (seen, Err(e)),
            }
        }
    }

    #[test]
    fn every_row_in_order_then_the_end_or_the_error() {
        for (workers, by_rows) in [(1, false), (2, false), (3, false), (1, true), (2, true)] {
            for n in [
                0,
                1,
                BLOCK_ROWS - 1,
                BLOCK_ROWS,
                3 * BLOCKS * BLOCK_ROWS + 5,
            ] {
                let (seen, end) = drain(counting(n, None, BLOCK_ROWS, workers), by_rows);
                assert_eq!(seen, (1..=n).collect::<Vec<_>>());
                assert!(end.is_ok());
            }
            let fail = 2 * BLOCK_ROWS + 7;
            let (seen, end) = drain(
                counting(10 * BLOCK_ROWS, Some(fail), BLOCK_ROWS, workers),
                by_rows,
            );
            assert_eq!(seen.len(), fail - 1);
            assert!(
                end.unwrap_err()
                    .to_string()
                    .contains(&format!("bad row {fail}"))
            );
            // Chunks of one line: the error in the first row of a chunk, after every row
            // before it.
            let (seen, end) = drain(counting(50, Some(17), 1, workers), by_rows);
            assert_eq!(seen, (1..17).collect::<Vec<_>>());
            assert!(end.unwrap_err().to_string().contains("bad row 17"));
        }
    }

    #[test]
    fn a_consumer_that_stops_early_stops_the_reader() {
        let mut blocks = counting(100 * BLOCK_ROWS, None, BLOCK_ROWS, 2);
        let mut v = [0.0; 2];
        assert_eq!(blocks.next_into(&mut v).unwrap(), Some(1));
        drop(blocks);
    }

    /// Fails in its chunk `k`: a worker that dies.
    struct Panicking;

    impl ChunkParser for Panicking {
        fn parse_chunk(&self, chunk: &Chunk, block: &mut Block, s: &mut Vec<(usize, usize)>) {
            assert!(chunk.line_before < 5, "a parser that breaks");
            Counting { fail: None }.parse_chunk(chunk, block, s);
        }

        fn increasing(&self) -> Option<usize> {
            None
        }

        fn not_after(&self, _: usize, _: f64, _: f64) -> CliError {
            CliError::msg("unused")
        }
    }

    #[test]
    fn a_worker_that_dies_is_an_error_not_a_hang() {
        for workers in [1, 2] {
            let text: Box<dyn std::io::BufRead + Send> =
                Box::new(std::io::Cursor::new(b"x\n".repeat(100)));
            let cutter = ChunkCutter::new(text, Vec::new(), 0, false, 1);
            let blocks = RowBlocks::spawn_with(cutter, Arc::new(Panicking), 2, workers).unwrap();
            let (seen, end) = drain(blocks, workers == 2);
            assert_eq!(seen, (1..=5).collect::<Vec<_>>());
            assert!(
                end.unwrap_err()
                    .to_string()
                    .contains("stopped unexpectedly")
            );
        }
    }
}
