//! The progress line on standard error while a batch runs (files done of all, failures,
//! files per second and the time left), redrawn in place; only on a terminal, and not with
//! `--quiet`.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

/// How often the line is redrawn at most.
const REDRAW: Duration = Duration::from_millis(100);

/// The progress line.
#[derive(Debug)]
pub struct Progress {
    shown: bool,
    total: usize,
    done: usize,
    failed: usize,
    run: usize,
    start: Instant,
    last: Option<Instant>,
}

impl Progress {
    /// A line for `total` files, shown when standard error is a terminal and not `quiet`.
    pub fn new(total: usize, quiet: bool) -> Self {
        Self {
            shown: !quiet && std::io::stderr().is_terminal(),
            total,
            done: 0,
            failed: 0,
            run: 0,
            start: Instant::now(),
            last: None,
        }
    }

    /// Counts one finished file (`ran`: its command was run, not skipped).
    pub fn finished(&mut self, failed: bool, ran: bool) {
        self.done += 1;
        self.failed += usize::from(failed);
        self.run += usize::from(ran);
        if self.shown
            && self
                .last
                .is_none_or(|t| t.elapsed() >= REDRAW || self.done == self.total)
        {
            self.last = Some(Instant::now());
            crate::io::write_stderr(format_args!("\r\x1b[K{}", self.line()));
        }
    }

    /// Clears the line (before the summary).
    pub fn clear(&self) {
        if self.shown && self.last.is_some() {
            crate::io::write_stderr(format_args!("\r\x1b[K"));
        }
    }

    /// The text of the line.
    fn line(&self) -> String {
        let secs = self.start.elapsed().as_secs_f64();
        let rate = if secs > 0.0 {
            self.run as f64 / secs
        } else {
            0.0
        };
        let left = self.total - self.done;
        let eta = if rate > 0.0 {
            format!("{:.0} s left", left as f64 / rate)
        } else {
            "time left unknown".into()
        };
        format!(
            "batch: {}/{} files, {} failed, {rate:.1} files/s, {eta}",
            self.done, self.total, self.failed
        )
    }
}
