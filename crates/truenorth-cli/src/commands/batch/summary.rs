//! The summary at the end of a batch: how many files were ok, refused, failed and skipped,
//! the samples read, the wall time and the throughput; and the exit code that follows.

use std::time::Duration;

use truenorth::core::Readable;

use super::results::{Row, Status};

/// Exit code: every file ok, refused or skipped as done.
pub const EXIT_OK: u8 = 0;
/// Exit code: the batch itself could not run (arguments, the journal, the table).
pub const EXIT_BATCH_ERROR: u8 = 1;
/// Exit code: at least one file failed, in this batch or in an earlier one whose failure
/// still stands (clap's usage errors take 2).
pub const EXIT_FILES_FAILED: u8 = 3;

/// The counts of a batch.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Files whose command succeeded now.
    pub ok: usize,
    /// Files whose command declined the data now.
    pub refused: usize,
    /// Files that failed now.
    pub failed: usize,
    /// Files skipped as done by an earlier batch.
    pub skipped: usize,
    /// Of those, files whose earlier run failed (its command's own error, not run again
    /// without `--retry-failed`): their failure still stands.
    pub failed_before: usize,
    /// Files never reached (a stop).
    pub not_run: usize,
    /// Rows read by the commands run now.
    pub samples: u64,
    /// Files whose command ran now.
    pub run: usize,
}

impl Counts {
    /// Counts `rows` (this batch's) out of `total` files.
    pub fn of(rows: &[Row], total: usize) -> Self {
        let mut c = Self {
            not_run: total.saturating_sub(rows.len()),
            ..Self::default()
        };
        for r in rows {
            match r.status {
                Status::Ok => c.ok += 1,
                Status::Refused => c.refused += 1,
                Status::Failed => c.failed += 1,
                Status::SkippedDone => {
                    c.skipped += 1;
                    c.failed_before += usize::from(r.outcome == Status::Failed);
                }
            }
            if r.status != Status::SkippedDone {
                c.run += 1;
                c.samples += r.samples.unwrap_or(0);
            }
        }
        c
    }

    /// The exit code (see the constants).
    pub fn exit_code(&self) -> u8 {
        if self.failed + self.failed_before > 0 {
            EXIT_FILES_FAILED
        } else {
            EXIT_OK
        }
    }

    /// The summary line: counts, samples, wall time, files/s and samples/s (of the files
    /// run, so a rerun that skips everything shows 0 files/s).
    pub fn line(&self, wall: Duration) -> String {
        let secs = wall.as_secs_f64();
        let per_s = |n: f64| if secs > 0.0 { n / secs } else { 0.0 };
        let before = if self.failed_before > 0 {
            format!(
                " ({} of them failed in an earlier run: --retry-failed runs them again)",
                self.failed_before
            )
        } else {
            String::new()
        };
        let not_run = if self.not_run > 0 {
            format!(", {} not run (stopped)", self.not_run)
        } else {
            String::new()
        };
        format!(
            "batch: {} ok, {} refused, {} failed, {} skipped-done{before}{not_run}; {} samples in {} s: {} files/s, {} samples/s",
            self.ok,
            self.refused,
            self.failed,
            self.skipped,
            self.samples,
            Readable(hundredths(secs)),
            Readable(hundredths(per_s(self.run as f64))),
            Readable(per_s(self.samples as f64).round()),
        )
    }
}

/// `x` to two decimals, as the summary shows times and rates.
fn hundredths(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failure_makes_the_exit_code_and_skips_count_no_samples() {
        let row = |status, samples| Row {
            path: String::new(),
            hash: String::new(),
            status,
            outcome: status,
            exit_code: None,
            message: String::new(),
            samples,
            seconds: 0.0,
            output: String::new(),
            verdict: None,
        };
        let rows = [
            row(Status::Ok, Some(10)),
            row(Status::SkippedDone, Some(100)),
            row(Status::Refused, Some(5)),
        ];
        let c = Counts::of(&rows, 4);
        assert_eq!((c.ok, c.refused, c.skipped, c.not_run), (1, 1, 1, 1));
        assert_eq!((c.samples, c.run), (15, 2));
        assert_eq!(c.exit_code(), EXIT_OK);
        let c = Counts::of(&[row(Status::Failed, None)], 1);
        assert_eq!(c.exit_code(), EXIT_FILES_FAILED);
        assert!(c.line(Duration::from_secs(2)).contains("1 failed"));
    }
}
