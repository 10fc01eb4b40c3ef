//! Reading on a second core: a reader thread splits and parses the rows of a file into
//! blocks of numbers and hands them, in file order, over a bounded channel to the thread
//! that uses them (a fit, a filter, a writer), so that parsing overlaps the work done with
//! the rows.
//!
//! The blocks are reused: at most [`BLOCKS`] exist, each of [`BLOCK_ROWS`] rows, and a block
//! the consumer has emptied goes back to the reader. Nothing is allocated per row, and the
//! memory held does not grow with the file. The parsing is the same code in the same order
//! as a read on one thread, so every number (and the first error, at the row where it
//! happens) is the same; the consumer sees an error only after every row before it.

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use super::CliResult;

/// Rows per block: enough that handing a block over costs nothing beside parsing it, few
/// enough that a block of ten columns stays in the second-level cache (640 KiB).
pub const BLOCK_ROWS: usize = 8192;

/// Blocks in flight (being filled, queued, being read): the reader may run this far ahead.
pub const BLOCKS: usize = 4;

/// Parses one row into `values` (the columns read, in order) and returns its row number,
/// or `None` at the end of the input.
pub trait RowSource: Send + 'static {
    /// The next row, written into `values`.
    fn parse_next(&mut self, values: &mut [f64]) -> CliResult<Option<usize>>;
}

/// Parsed rows: `numbers[k]` is the row number of the values `values[k·n .. (k+1)·n]`,
/// `n` the columns read; `end` says how the input ended after them, if it did.
struct Block {
    numbers: Vec<usize>,
    values: Vec<f64>,
    end: Option<CliResult>,
}

/// The consumer's end: the rows in file order, one at a time.
pub struct RowBlocks {
    full: Receiver<Block>,
    empty: SyncSender<Block>,
    current: Option<Block>,
    next: usize,
    columns: usize,
    done: bool,
}

impl RowBlocks {
    /// Starts the reader thread on `source`, which reads `columns` numbers per row.
    pub fn spawn(mut source: impl RowSource, columns: usize) -> std::io::Result<Self> {
        let (full_tx, full) = sync_channel::<Block>(BLOCKS);
        let (empty, empty_rx) = sync_channel::<Block>(BLOCKS);
        std::thread::Builder::new()
            .name("truenorth-reader".into())
            .spawn(move || {
                let mut made = 0usize;
                let mut values = vec![0.0f64; columns];
                loop {
                    // A block given back, else a new one while fewer than BLOCKS exist.
                    let mut block = match empty_rx.try_recv() {
                        Ok(b) => b,
                        Err(_) if made < BLOCKS => {
                            made += 1;
                            Block {
                                numbers: Vec::with_capacity(BLOCK_ROWS),
                                values: Vec::with_capacity(BLOCK_ROWS * columns),
                                end: None,
                            }
                        }
                        Err(_) => match empty_rx.recv() {
                            Ok(b) => b,
                            // The consumer has gone: stop reading.
                            Err(_) => return,
                        },
                    };
                    block.numbers.clear();
                    block.values.clear();
                    block.end = None;
                    while block.numbers.len() < BLOCK_ROWS {
                        match source.parse_next(&mut values) {
                            Ok(Some(number)) => {
                                block.numbers.push(number);
                                block.values.extend_from_slice(&values);
                            }
                            Ok(None) => {
                                block.end = Some(Ok(()));
                                break;
                            }
                            Err(e) => {
                                block.end = Some(Err(e));
                                break;
                            }
                        }
                    }
                    let last = block.end.is_some();
                    if full_tx.send(block).is_err() || last {
                        return;
                    }
                }
            })?;
        Ok(Self {
            full,
            empty,
            current: None,
            next: 0,
            columns,
            done: false,
        })
    }

    /// Copies the next row's values into `values` and returns its row number; `None` at the
    /// end of the input, the reader's error where it stopped.
    pub fn next_into(&mut self, values: &mut [f64]) -> CliResult<Option<usize>> {
        loop {
            if let Some(block) = &mut self.current {
                if self.next < block.numbers.len() {
                    let k = self.next;
                    self.next += 1;
                    let n = self.columns;
                    values.copy_from_slice(&block.values[k * n..(k + 1) * n]);
                    return Ok(Some(block.numbers[k]));
                }
                if let Some(end) = block.end.take() {
                    self.done = true;
                    return end.map(|()| None);
                }
                // Emptied: back to the reader (which may have stopped; then it is dropped).
                if let Some(b) = self.current.take() {
                    let _ = self.empty.try_send(b);
                }
            }
            if self.done {
                return Ok(None);
            }
            match self.full.recv() {
                Ok(b) => {
                    self.current = Some(b);
                    self.next = 0;
                }
                // The reader thread ended without saying how (it panicked): no more rows.
                Err(_) => {
                    self.done = true;
                    return Err(super::CliError::msg(
                        "the reader thread stopped unexpectedly",
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::CliError;

    /// Rows `k = 1..=n` of values `(k, −k)`, then the end or an error at row `fail`.
    struct Counting {
        k: usize,
        n: usize,
        fail: Option<usize>,
    }

    impl RowSource for Counting {
        fn parse_next(&mut self, values: &mut [f64]) -> CliResult<Option<usize>> {
            self.k += 1;
            if Some(self.k) == self.fail {
                return Err(CliError::msg(format!("bad row {}", self.k)));
            }
            if self.k > self.n {
                return Ok(None);
            }
            values[0] = self.k as f64;
            values[1] = -(self.k as f64);
            Ok(Some(self.k))
        }
    }

    fn drain(src: Counting) -> (Vec<usize>, CliResult) {
        let mut blocks = RowBlocks::spawn(src, 2).unwrap();
        let mut v = [0.0; 2];
        let mut seen = Vec::new();
        loop {
            match blocks.next_into(&mut v) {
                Ok(Some(n)) => {
                    assert_eq!(v, [n as f64, -(n as f64)]);
                    seen.push(n);
                }
                Ok(None) => return (seen, Ok(())),
                Err(e) => return (seen, Err(e)),
            }
        }
    }

    #[test]
    fn every_row_in_order_then_the_end_or_the_error() {
        for n in [
            0,
            1,
            BLOCK_ROWS - 1,
            BLOCK_ROWS,
            3 * BLOCKS * BLOCK_ROWS + 5,
        ] {
            let (seen, end) = drain(Counting {
                k: 0,
                n,
                fail: None,
            });
            assert_eq!(seen, (1..=n).collect::<Vec<_>>());
            assert!(end.is_ok());
            // After the end it stays at the end.
        }
        let fail = 2 * BLOCK_ROWS + 7;
        let (seen, end) = drain(Counting {
            k: 0,
            n: 10 * BLOCK_ROWS,
            fail: Some(fail),
        });
        assert_eq!(seen.len(), fail - 1);
        assert!(
            end.unwrap_err()
                .to_string()
                .contains(&format!("bad row {fail}"))
        );
    }

    #[test]
    fn a_consumer_that_stops_early_stops_the_reader() {
        let mut blocks = RowBlocks::spawn(
            Counting {
                k: 0,
                n: usize::MAX,
                fail: None,
            },
            2,
        )
        .unwrap();
        let mut v = [0.0; 2];
        assert_eq!(blocks.next_into(&mut v).unwrap(), Some(1));
        drop(blocks);
    }
}
