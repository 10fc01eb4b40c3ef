//! `truenorth batch`: one command over a fleet of recordings, on every core, resumable.
//!
//! The parts, one file each: [`jobs`] (which files, their output names, their content
//! hash), [`passthrough`] (the command after `--`), [`child`] (one file's run as a child
//! process), [`pool`] (the workers), [`journal`] (what makes a rerun skip what is done),
//! [`results`] (the table), [`progress`] (the line on a terminal), [`summary`] (the
//! counts, the throughput and the exit code) and [`sweep`] (what killed runs left behind).

pub mod child;
pub mod jobs;
pub mod journal;
pub mod passthrough;
pub mod pool;
pub mod progress;
pub mod results;
pub mod summary;
pub mod sweep;

use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::Instant;

pub use jobs::output_name;

use crate::io::{CliError, CliResult, errln, outln};
use journal::Journal;
use passthrough::Passthrough;
use pool::{Context, Planned};
use results::Row;
use summary::Counts;

/// The long help of the command (after the options).
const AFTER_HELP: &str = "\
Runs one command on every recording of the folders (the files ending in --ext, not in \
sub-folders unless --recursive; hidden files left out) and of --list, each as its own \
process: a file that fails, or even crashes, is one failed row. The command and its options \
follow `--`; batch gives each file `--input` and `--output` (or, for inspect, the file, its \
report written to the output), so they are refused after `--`, as are --plot and \
--calibration-out, which every file would write over. Only calibrate, heading, orientation, \
drive and inspect run per file.

Outputs: under --out, at the input's path inside its folder (with several folders or a list, \
the path as given), each part escaped (bytes other than letters, digits and _-+=@,. as %XX, \
a leading dot too), with .json (calibrate, inspect --json), .txt (inspect) or .csv appended: \
never outside --out, never two files to one output.

Results: one row per file (path, sha256, status, outcome, exit_code, message, samples, \
seconds, output, verdict), CSV or JSON by --results' extension, written whole at the end. \
status: ok; refused (the command declined the data, with its reason: a calibration too poor, \
a unit or field that does not match); failed (the file could not be read or used, the \
command crashed or was killed); skipped-done (settled by an earlier batch; outcome says how).

Resuming: a journal in --out (.truenorth-batch-journal.jsonl) gets one synced line per \
finished file, keyed by the output name, the SHA-256 of the input's bytes and the command \
line. A rerun skips a file whose bytes and command are unchanged and whose run settled it \
(ok, refused, or failed with the command's own message; a crash or a signal is retried; \
--retry-failed retries every failure), and reruns a changed one. One batch at a time per \
--out: the journal is locked while a batch runs, and a second is refused (exit 1).

Stopping: Ctrl-C or SIGTERM stops handing out files and lets the running ones finish; a \
second one stops them too (SIGTERM, so each removes its unfinished output). The journal \
holds every finished file either way; rerun to go on.

Exit codes: 0 every file ok, refused or skipped-done; 1 the batch could not run (one line on \
stderr); 2 wrong arguments; 3 at least one file failed; 128+N stopped by signal N.

Example: `truenorth batch logs/ --out results/ -- calibrate --method ellipsoid`.";

/// Arguments of `truenorth batch`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct Args {
    /// Folders of recordings.
    pub folders: Vec<PathBuf>,
    /// A file naming one recording a line (`-`: standard input; empty lines and lines
    /// starting with `#` skipped).
    #[arg(long, value_name = "FILE")]
    pub list: Option<PathBuf>,
    /// Also the recordings in the folders' sub-folders.
    #[arg(long)]
    pub recursive: bool,
    /// File name endings run in the folders, comma-separated.
    #[arg(
        long,
        value_name = "EXT",
        value_delimiter = ',',
        default_value = "csv,csv.gz,ulg,mcap"
    )]
    pub ext: Vec<String>,
    /// Output folder: one output per file, the journal, and the results table.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Results table, `.csv` or `.json` [default: DIR/results.csv].
    #[arg(long, value_name = "FILE")]
    pub results: Option<PathBuf>,
    /// Files run at once [default: the number of cores].
    #[arg(long, short = 'j', value_name = "N")]
    pub jobs: Option<NonZeroUsize>,
    /// No progress line (it shows only on a terminal anyway).
    #[arg(long)]
    pub quiet: bool,
    /// Rerun files that failed before even when unchanged.
    #[arg(long)]
    pub retry_failed: bool,
    /// The command and its options, after `--`.
    #[arg(last = true, value_name = "COMMAND")]
    pub command: Vec<String>,
}

/// Runs the subcommand; the exit code (see the long help) when the batch could run.
pub fn run(args: &Args) -> CliResult<u8> {
    let start = Instant::now();
    let command = Passthrough::new(&args.command)?;
    if args.folders.is_empty() && args.list.is_none() {
        return Err(CliError::msg(
            "batch: give one or more folders, or --list FILE",
        ));
    }
    if args
        .ext
        .iter()
        .any(|e| e.trim().trim_start_matches('.').is_empty())
    {
        return Err(CliError::msg(
            "batch: --ext has an empty extension, which matches no file; give the endings to run, e.g. --ext csv,csv.gz",
        ));
    }
    let (mut jobs, skipped) = jobs::collect(&jobs::Sources {
        folders: &args.folders,
        list: args.list.as_deref(),
        recursive: args.recursive,
        extensions: &args.ext,
    })?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| CliError::file(&args.out, format!("cannot create the folder: {e}")))?;
    let results_path = args
        .results
        .clone()
        .unwrap_or_else(|| args.out.join("results.csv"));
    for (path, why) in &skipped {
        errln!("batch: {}: {why}", path.display());
    }
    // A folder of inputs that holds --out would, on the next run, hand the batch its own
    // outputs (and results table) as inputs.
    let out_id = jobs::identity(&args.out);
    let before = jobs.len();
    jobs.retain(|j| !jobs::identity(&j.input).starts_with(&out_id));
    if jobs.len() < before {
        errln!(
            "batch: {} files under --out {} are this batch's own outputs and are not read as inputs",
            before - jobs.len(),
            args.out.display()
        );
    }
    check_results_path(&results_path, &args.out, &jobs)?;
    let plan = plan(&jobs, &command, &args.out, &results_path)?;
    let exe = std::env::current_exe()
        .map_err(|e| CliError::msg(format!("batch: cannot find its own executable: {e}")))?;
    // Locked first, so that a batch refused for another's folder touches nothing in it.
    let mut journal = Journal::open(&args.out)?;
    sweep::remove_stale_temporaries(&args.out);
    let known = journal.known().clone();
    let workers = args
        .jobs
        .map(NonZeroUsize::get)
        .or_else(|| {
            std::thread::available_parallelism()
                .ok()
                .map(NonZeroUsize::get)
        })
        .unwrap_or(1);

    let stop = AtomicBool::new(false);
    let abort = AtomicBool::new(false);
    let signal = AtomicI32::new(0);
    let ctx = Context {
        exe: &exe,
        command: &command,
        known: &known,
        retry_failed: args.retry_failed,
        stop: &stop,
        abort: &abort,
    };
    let mut progress = progress::Progress::new(plan.len(), args.quiet);
    let mut rows: Vec<Option<Row>> = vec![None; plan.len()];
    let ran = std::thread::scope(|s| {
        let signals = stop_on_signals(s, &stop, &abort, &signal);
        let ran = pool::run_all(&plan, &ctx, workers, |f| {
            if f.ran {
                journal.append(f.entry.clone())?;
            }
            progress.finished(f.entry.row.status == results::Status::Failed, f.ran);
            rows[f.index] = Some(f.entry.row);
            Ok(())
        });
        if let Some(handle) = signals {
            handle.close();
        }
        ran
    });
    progress.clear();
    ran?;
    let rows: Vec<Row> = rows.into_iter().flatten().collect();
    results::write(&results_path, &rows)?;
    sweep::remove_stale_temporaries(&args.out);
    let counts = Counts::of(&rows, plan.len());
    outln!(
        "{}; results: {}",
        counts.line(start.elapsed()),
        results_path.display()
    )?;
    match signal.load(Ordering::Relaxed) {
        0 => Ok(counts.exit_code()),
        s => Ok(u8::try_from(128 + s).unwrap_or(u8::MAX)),
    }
}

/// Refuses, before anything runs, a results table that would overwrite an input or the
/// journal (the rerun would then redo everything).
fn check_results_path(results: &Path, out: &Path, jobs: &[jobs::Job]) -> CliResult {
    let id = jobs::identity(results);
    if id == jobs::identity(&out.join(journal::JOURNAL_NAME)) {
        return Err(CliError::msg(format!(
            "batch: --results {} names the batch's journal, which says what is done; give another name",
            results.display()
        )));
    }
    if let Some(j) = jobs.iter().find(|j| jobs::identity(&j.input) == id) {
        return Err(CliError::msg(format!(
            "batch: --results {} names the input {}, which it would overwrite; give another name",
            results.display(),
            j.input.display()
        )));
    }
    Ok(())
}

/// Each job's output name and path, refusing an output that would be the results table.
fn plan(
    jobs: &[jobs::Job],
    command: &Passthrough,
    out: &Path,
    results_path: &Path,
) -> CliResult<Vec<Planned>> {
    let mut plan = Vec::with_capacity(jobs.len());
    for j in jobs {
        let name = output_name(&j.relative, command.output_suffix());
        let output = out.join(&name);
        if output == results_path {
            return Err(CliError::file(
                &j.input,
                format!(
                    "its output would be the results table {}; give --results another name",
                    results_path.display()
                ),
            ));
        }
        if let Some(dir) = output.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| CliError::file(dir, format!("cannot create the folder: {e}")))?;
        }
        plan.push(Planned {
            input: j.input.clone(),
            name: name.to_string_lossy().into_owned(),
            output,
        });
    }
    Ok(plan)
}

/// Turns SIGINT, SIGTERM and SIGHUP into a stop (the first) and an abort (the second),
/// on a thread of `scope`; the handle closes it.
fn stop_on_signals<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    stop: &'scope AtomicBool,
    abort: &'scope AtomicBool,
    signal: &'scope AtomicI32,
) -> Option<signal_hook::iterator::Handle> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]).ok()?;
    let handle = signals.handle();
    scope.spawn(move || {
        for s in signals.forever() {
            signal.store(s, Ordering::Relaxed);
            if stop.swap(true, Ordering::Relaxed) {
                abort.store(true, Ordering::Relaxed);
                errln!("batch: stopping the running files");
            } else {
                errln!("batch: stopping; the running files finish (again to stop them too)");
            }
        }
    });
    Some(handle)
}
