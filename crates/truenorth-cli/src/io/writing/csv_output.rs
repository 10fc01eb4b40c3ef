//! CSVs of numbers written row by row, the text made and written on threads of their own.
//!
//! Writing the shortest text of every number is much of a streaming command's work (a
//! `heading` run spends about half of its time on it): the command hands its rows over in
//! blocks, [`FORMATTERS`] threads take turns to format them, and a writer thread writes
//! their text into the [`AtomicOutput`] in the order of the blocks, while the command
//! computes the next rows. The bytes are those one thread would write, in the same order.
//! The hand-over is bounded (a few blocks), so memory does not grow with the file.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, SyncSender};
use std::thread::JoinHandle;

use super::atomic_write::AtomicOutput;
use super::number_format::Precision;
use crate::io::{CliError, CliResult};

/// Rows handed to a formatter at a time: large enough that the hand-over costs nothing
/// beside the formatting, small enough that a block's values stay in the cache.
const BLOCK_ROWS: usize = 4096;

/// Blocks handed to each formatter and not yet formatted, at most: the command runs ahead
/// of the output by this much and no more.
const BLOCKS_AHEAD: usize = 2;

/// Threads that format blocks, taking turns: formatting is the slowest stage of a
/// streaming command (a `heading` run's one formatter took 44 % of its CPU time, more than
/// the command itself, on `scripts/io_speed.sh`'s 10⁷-row file), and two share it.
const FORMATTERS: usize = 2;

/// Rows on their way to the writer.
#[derive(Debug, Default)]
struct RowBlock {
    /// The rows' numbers, one row after another.
    values: Vec<f64>,
    /// How many numbers each row has.
    widths: Vec<usize>,
    precision: Precision,
}

impl RowBlock {
    fn clear(&mut self) {
        self.values.clear();
        self.widths.clear();
    }

    /// Appends the block's rows to `text`, cells separated by commas. The first cell, every
    /// output's time `t_s`, is written exactly whatever the precision: rounded to N digits an
    /// epoch time (1.7·10⁹ s) would run many rows into one.
    fn write_into(&self, text: &mut String) {
        let mut at = 0;
        for &width in &self.widths {
            for (k, &v) in self.values[at..at + width].iter().enumerate() {
                if k > 0 {
                    text.push(',');
                    self.precision.write(text, v);
                } else {
                    Precision::default().write(text, v);
                }
            }
            text.push('\n');
            at += width;
        }
    }
}

/// What the writer thread gives back: the output (to commit, or to drop, which removes
/// its temporary) and the first write error.
type Written = (AtomicOutput, CliResult);

/// A formatted block on its way to the writer: its text, and the block, to hand back for
/// reuse.
type Formatted = (String, RowBlock);

/// A CSV written row by row into an `AtomicOutput`: numbers in the shortest form that
/// reads back as the same `f64`, or rounded (see [`Precision`]).
pub struct CsvOutput {
    name: PathBuf,
    block: RowBlock,
    /// To each formatter; block `k` goes to formatter `k % FORMATTERS`. Empty once the
    /// hand-over has ended.
    to_formatters: Vec<SyncSender<RowBlock>>,
    /// Blocks handed over so far.
    handed: usize,
    /// Blocks the writer is done with, for reuse.
    written: Receiver<RowBlock>,
    formatters: Vec<JoinHandle<()>>,
    writer: Option<JoinHandle<Written>>,
}

impl std::fmt::Debug for CsvOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvOutput")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

impl CsvOutput {
    /// Starts `path` (`-`: standard output) with its header row.
    pub fn create(path: &Path, header: &[&str]) -> CliResult<Self> {
        let mut out = AtomicOutput::create(path)?;
        out.write_all((header.join(",") + "\n").as_bytes())?;
        let name = out.name().to_path_buf();
        let cannot =
            |e: std::io::Error| CliError::file(path, format!("cannot start the writer: {e}"));
        let (give_back, written) = std::sync::mpsc::sync_channel::<RowBlock>(BLOCKS_AHEAD + 1);
        let mut to_formatters = Vec::with_capacity(FORMATTERS);
        let mut from_formatters = Vec::with_capacity(FORMATTERS);
        let mut formatters = Vec::with_capacity(FORMATTERS);
        for _ in 0..FORMATTERS {
            let (to_formatter, blocks) = std::sync::mpsc::sync_channel::<RowBlock>(BLOCKS_AHEAD);
            let (to_writer, texts) = std::sync::mpsc::sync_channel::<Formatted>(1);
            let (text_back, spare_texts) = std::sync::mpsc::sync_channel::<String>(2);
            let formatter = std::thread::Builder::new()
                .name("truenorth-format".into())
                .spawn(move || {
                    for block in blocks {
                        let mut text = spare_texts.try_recv().unwrap_or_default();
                        text.clear();
                        block.write_into(&mut text);
                        if to_writer.send((text, block)).is_err() {
                            // The writer stopped on an error, which it reports.
                            return;
                        }
                    }
                })
                .map_err(cannot)?;
            to_formatters.push(to_formatter);
            from_formatters.push((texts, text_back));
            formatters.push(formatter);
        }
        let writer = std::thread::Builder::new()
            .name("truenorth-write".into())
            .spawn(move || {
                // The blocks' texts in the order the blocks were handed over: block `k` from
                // formatter `k % FORMATTERS`, until that one has no more (then no later block
                // exists either).
                for (texts, text_back) in from_formatters.iter().cycle() {
                    let Ok((text, block)) = texts.recv() else {
                        break;
                    };
                    if let Err(e) = out.write_all(text.as_bytes()) {
                        return (out, Err(e));
                    }
                    // A full return channel only means the buffer or block is not reused.
                    let _ = text_back.try_send(text);
                    let _ = give_back.try_send(block);
                }
                (out, Ok(()))
            })
            .map_err(cannot)?;
        Ok(Self {
            name,
            block: RowBlock::default(),
            to_formatters,
            handed: 0,
            written,
            formatters,
            writer: Some(writer),
        })
    }

    /// Appends one row, the numbers written at `precision` (see [`Precision`]); a NaN is
    /// written as an empty cell (no value, as an empty cell reads on input).
    pub fn row(&mut self, values: &[f64], precision: Precision) -> CliResult {
        if precision != self.block.precision && !self.block.widths.is_empty() {
            self.hand_over()?;
        }
        self.block.precision = precision;
        self.block.values.extend_from_slice(values);
        self.block.widths.push(values.len());
        if self.block.widths.len() >= BLOCK_ROWS {
            self.hand_over()?;
        }
        Ok(())
    }

    /// Hands the rows so far to the next formatter, and starts a new block (a reused one
    /// when the writer has given one back).
    fn hand_over(&mut self) -> CliResult {
        let mut next = self.written.try_recv().unwrap_or_default();
        next.clear();
        next.precision = self.block.precision;
        let full = std::mem::replace(&mut self.block, next);
        let sent = match self.to_formatters.get(self.handed % FORMATTERS) {
            Some(to_formatter) => to_formatter.send(full).is_ok(),
            None => false,
        };
        self.handed += 1;
        if sent {
            Ok(())
        } else {
            // The writer stopped on an error (and the formatters with it): that error is
            // the one to report.
            self.stop().map(drop)
        }
    }

    /// Ends the hand-over and waits for the formatters and the writer: the output, or the
    /// first error.
    fn stop(&mut self) -> CliResult<AtomicOutput> {
        self.to_formatters.clear();
        let Some(writer) = self.writer.take() else {
            return Err(CliError::file(
                &self.name,
                "the output was already finished",
            ));
        };
        let stopped = || {
            CliError::file(
                &self.name,
                "the writer thread stopped unexpectedly; the output was not finished",
            )
        };
        let mut formatted = Ok(());
        for formatter in self.formatters.drain(..) {
            if formatter.join().is_err() {
                formatted = Err(stopped());
            }
        }
        match writer.join() {
            Ok((out, Ok(()))) => formatted.map(|()| out),
            Ok((_, Err(e))) => Err(e),
            Err(_) => Err(stopped()),
        }
    }

    /// Finishes the file (see `AtomicOutput::commit`).
    pub fn commit(mut self) -> CliResult {
        if !self.block.widths.is_empty() {
            self.hand_over()?;
        }
        self.stop()?.commit()
    }
}

impl Drop for CsvOutput {
    /// An output dropped unfinished (an error on the way) hands over its last rows and
    /// waits for its threads, after which the writer drops the output: a temporary is
    /// removed before the run ends, and standard output, a device or a FIFO gets every row
    /// written before the error, as a single-threaded writer flushing on drop would give
    /// it.
    fn drop(&mut self) {
        if self.writer.is_some() {
            if !self.block.widths.is_empty() {
                let _ = self.hand_over();
            }
            let _ = self.stop();
        }
    }
}

/// Writes a CSV with a header row and rows of numbers, whole or not at all.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
    precision: Precision,
) -> CliResult {
    let mut out = CsvOutput::create(path, header)?;
    for r in rows {
        out.row(&r, precision)?;
    }
    out.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_across_blocks_come_out_in_order_at_their_precision() {
        let scratch = crate::io::scratch::scratch_dir("csv-blocks");
        let path = scratch.path().join("out.csv");
        let mut out = CsvOutput::create(&path, &["a", "b"]).unwrap();
        let mut want = String::from("a,b\n");
        for k in 0..(2 * BLOCK_ROWS + 7) {
            let precision = if k < BLOCK_ROWS + 3 {
                Precision::default()
            } else {
                "3".parse().unwrap()
            };
            let row: Vec<f64> = (0..=k % 2).map(|j| k as f64 / 7.0 - j as f64).collect();
            out.row(&row, precision).unwrap();
            let cells: Vec<String> = row
                .iter()
                .enumerate()
                .map(|(j, &v)| {
                    let mut s = String::new();
                    // The first cell, the time, is written exactly at any precision.
                    let p = if j == 0 {
                        Precision::default()
                    } else {
                        precision
                    };
                    p.write(&mut s, v);
                    s
                })
                .collect();
            want += &(cells.join(",") + "\n");
        }
        out.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), want);
    }

    #[test]
    fn a_full_device_is_an_error_at_the_latest_on_commit() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            eprintln!("SKIPPED: no /dev/full here");
            return;
        }
        let mut out = CsvOutput::create(full, &["a"]).unwrap();
        let mut failed = None;
        for k in 0..(4 * BLOCK_ROWS) {
            if let Err(e) = out.row(&[k as f64], Precision::default()) {
                failed = Some(e);
                break;
            }
        }
        let e = match failed {
            Some(e) => e,
            None => out.commit().expect_err("/dev/full takes nothing"),
        };
        assert!(e.to_string().contains("cannot write"), "{e}");
    }
}
