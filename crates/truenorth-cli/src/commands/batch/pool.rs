//! The worker pool: `--jobs` threads take the files in turn, hash each, skip it when the
//! journal settles it, and otherwise run its command as a child process; the finished files
//! come back to the calling thread (which alone writes the journal) in the order they end.
//! A stop stops the handing out of files; an abort also stops the running children.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

use super::child;
use super::journal::{Entry, Known};
use super::passthrough::Passthrough;
use super::results::{Row, Status};
use crate::io::CliResult;

/// A file with its output.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The input as the command is given it.
    pub input: PathBuf,
    /// The output's name under the output folder (the journal's key).
    pub name: String,
    /// The output's path.
    pub output: PathBuf,
}

/// What the workers share.
#[derive(Debug)]
pub struct Context<'a> {
    /// The executable run per file.
    pub exe: &'a Path,
    /// The command run.
    pub command: &'a Passthrough,
    /// The journal as it was when the batch started.
    pub known: &'a Known,
    /// Rerun files whose command failed with its own message.
    pub retry_failed: bool,
    /// Set: hand out no more files.
    pub stop: &'a AtomicBool,
    /// Set: stop the running children too.
    pub abort: &'a AtomicBool,
}

/// One finished file.
#[derive(Debug)]
pub struct Finished {
    /// The file's place in the plan.
    pub index: usize,
    /// Its journal entry: the run's, or the earlier one that settles it.
    pub entry: Entry,
    /// Whether its command ran (false: skipped as done).
    pub ran: bool,
}

/// Runs `plan` on `workers` threads, calling `on_done` for each finished file as it ends.
/// An error from `on_done` stops the batch (running files are stopped) and is returned.
pub fn run_all(
    plan: &[Planned],
    ctx: &Context<'_>,
    workers: usize,
    mut on_done: impl FnMut(Finished) -> CliResult,
) -> CliResult {
    let next = AtomicUsize::new(0);
    let (send, receive) = mpsc::channel::<Finished>();
    std::thread::scope(|s| {
        for _ in 0..workers.clamp(1, plan.len().max(1)) {
            let send = send.clone();
            let next = &next;
            s.spawn(move || {
                while !ctx.stop.load(Ordering::Relaxed) {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let Some(p) = plan.get(index) else {
                        break;
                    };
                    let (entry, ran) = one(p, ctx);
                    if ctx.abort.load(Ordering::Relaxed) && ran && entry.row.exit_code.is_none() {
                        // Stopped by the abort: not the file's doing, so not journaled.
                        continue;
                    }
                    if send.send(Finished { index, entry, ran }).is_err() {
                        break;
                    }
                }
            });
        }
        drop(send);
        let mut result = Ok(());
        for finished in receive {
            if result.is_ok()
                && let Err(e) = on_done(finished)
            {
                ctx.stop.store(true, Ordering::Relaxed);
                ctx.abort.store(true, Ordering::Relaxed);
                result = Err(e);
            }
        }
        result
    })
}

/// Hashes one file and runs it unless the journal settles it.
fn one(p: &Planned, ctx: &Context<'_>) -> (Entry, bool) {
    let path = p.input.display().to_string();
    let output = p.output.display().to_string();
    let hash = match super::jobs::content_hash(&p.input) {
        Ok(h) => h,
        Err(e) => {
            let row = Row {
                path,
                hash: String::new(),
                status: Status::Failed,
                outcome: Status::Failed,
                exit_code: None,
                message: format!("cannot read: {e}"),
                samples: None,
                seconds: 0.0,
                output: String::new(),
                verdict: None,
            };
            return (entry(p, ctx, row, None), true);
        }
    };
    if let Some(done) = ctx
        .known
        .settled(&p.name, &hash, &ctx.command.words, ctx.retry_failed)
    {
        let mut row = done.row.clone();
        row.status = Status::SkippedDone;
        row.path = path;
        return (entry(p, ctx, row, done.pid), false);
    }
    let ended = child::run(ctx.exe, ctx.command, &p.input, &p.output, ctx.abort);
    let verdict = (ended.status == Status::Ok && ctx.command.command() == "calibrate")
        .then(|| calibration_verdict(&p.output))
        .flatten();
    let row = Row {
        path,
        hash,
        status: ended.status,
        outcome: ended.status,
        exit_code: ended.exit_code,
        message: ended.message,
        samples: ended.samples,
        seconds: ended.seconds,
        output: if ended.status == Status::Ok {
            output
        } else {
            String::new()
        },
        verdict,
    };
    (entry(p, ctx, row, ended.pid), true)
}

fn entry(p: &Planned, ctx: &Context<'_>, row: Row, pid: Option<u32>) -> Entry {
    Entry {
        name: p.name.clone(),
        command: ctx.command.words.clone(),
        row,
        pid,
    }
}

/// The verdict a calibration file records (`quality.verdict`), if it can be read.
fn calibration_verdict(output: &Path) -> Option<String> {
    let text = std::fs::read_to_string(output).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    json.get("quality")?
        .get("verdict")?
        .as_str()
        .map(str::to_string)
}
