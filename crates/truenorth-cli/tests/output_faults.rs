//! Outputs under faults, run as a user would meet them: the writer killed mid-write
//! (SIGKILL, SIGTERM) again and again, a full disk, a reader that closes the pipe, and
//! outputs that are not plain files (a device, a FIFO, a symbolic link, a link to an input).

#![cfg(unix)]

mod common;

use std::io::{BufRead as _, BufReader, Read as _};
use std::os::unix::fs::FileTypeExt as _;
use std::os::unix::process::ExitStatusExt as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use common::{TURN_HEADER, ok, p, truenorth};

/// The status of a run that stopped because its reader closed the pipe (128 + SIGPIPE).
const CLOSED_PIPE: i32 = 141;

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_output_faults", name)
}

/// A calibration (from a full generated turn) and two long recordings whose headings
/// differ, so that the output of one run is told apart from the other's.
struct Setup {
    calibration: PathBuf,
    inputs: [PathBuf; 2],
}

fn setup(dir: &Path, rows: usize) -> Setup {
    let turn = common::turn_rows(360, 0.05, 20.0, [12.0, -7.0], 0.0);
    let (_, calibration) =
        common::ellipse_calibration(dir, &(TURN_HEADER.to_string() + &turn), &[]);
    let inputs = [0.0, 1.0].map(|offset: f64| {
        let mut csv = String::with_capacity(rows * 24);
        csv += "t_s,mag_x,mag_y\n";
        for k in 0..rows {
            let a = k as f64 * 1e-3 + offset;
            csv += &format!(
                "{:.2},{:.4},{:.4}\n",
                k as f64 * 0.01,
                12.0 + 20.0 * a.cos(),
                -7.0 - 20.0 * a.sin()
            );
        }
        let path = dir.join(format!("drive{offset}.csv"));
        std::fs::write(&path, csv).unwrap();
        path
    });
    Setup {
        calibration,
        inputs,
    }
}

fn heading_args<'a>(s: &'a Setup, input: usize, output: &'a str) -> Vec<&'a str> {
    vec![
        "heading",
        "--calibration",
        p(&s.calibration),
        "--input",
        p(&s.inputs[input]),
        "--output",
        output,
    ]
}

fn spawn(args: &[&str]) -> std::process::Child {
    common::binary()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        // Piped, to show a failed run's message (one line: it never fills the pipe).
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// The number of the signal `kill -NAME` sends (the same on every Unix).
fn signal_number(name: &str) -> i32 {
    match name {
        "INT" => 2,
        "KILL" => 9,
        "TERM" => 15,
        _ => unreachable!("a signal these tests send: {name}"),
    }
}

/// The `.NAME.tmp-PID` temporaries in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect()
}

/// A small deterministic generator for the kill delays (xorshift64*).
struct Delays(u64);

impl Delays {
    fn next_fraction(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// What the kills found.
#[derive(Debug, Default)]
struct KillOutcomes {
    kills: usize,
    /// Kills sent while the temporary was being written (at a random share of its size).
    sent_mid_write: usize,
    /// Kills sent at a random time before the writing began.
    sent_early: usize,
    /// Runs that ended (and were reaped) while the test waited for their temporary to
    /// grow, before their signal could be sent: these must have succeeded.
    ended_before_the_signal: usize,
    stopped_by_the_signal: usize,
    finished_first: usize,
    previous_output_kept: usize,
    new_output_complete: usize,
    temporaries_left: usize,
}

/// How waiting for a temporary to grow ended.
enum Waited {
    /// The temporary holds the bytes asked for.
    Reached,
    /// The run ended first, with this status: it is reaped, and its process id may
    /// already be another process's, so no signal may be sent to it.
    Ended(ExitStatus),
    /// Neither within a minute.
    TimedOut,
}

/// Waits until `temp` holds at least `bytes`, or the run ends first.
fn wait_for_size(temp: &Path, bytes: u64, child: &mut std::process::Child) -> Waited {
    let deadline = Instant::now() + Duration::from_secs(60);
    while Instant::now() < deadline {
        if std::fs::metadata(temp).is_ok_and(|m| m.len() >= bytes) {
            return Waited::Reached;
        }
        if let Some(status) = child.try_wait().unwrap() {
            return Waited::Ended(status);
        }
        std::thread::sleep(Duration::from_micros(500));
    }
    Waited::TimedOut
}

/// Runs `heading` `kills` times, each time on the input whose output is not there yet, and stops each run with `signal`:
/// one in five at a random time before its writing begins, the others once its temporary
/// holds a random share of the output (one in ten: all of it, as it is synced and renamed). After each: the output is the previous one byte for
/// byte or the complete new one; after SIGTERM no temporary is left.
fn kill_repeatedly(name: &str, signal: &str, kills: usize, seed: u64) -> KillOutcomes {
    let dir = scratch(name);
    let s = setup(&dir, 300_000);
    let output = dir.join("out.csv");
    let out = p(&output);
    // The complete output of each input, and how long starting a run takes.
    let mut complete = Vec::new();
    for input in [1, 0] {
        ok(&heading_args(&s, input, out));
        complete.push(std::fs::read(&output).unwrap());
    }
    complete.reverse();
    assert_ne!(
        complete[0], complete[1],
        "the two inputs give different outputs"
    );
    let started = Instant::now();
    ok(&["field", "--lat", "0", "--lon", "0", "--date", "2026"]);
    let start_up = started.elapsed();
    let mut delays = Delays(seed);
    let mut found = KillOutcomes::default();
    for k in 0..kills {
        // The input whose output differs from what is there, so the two are told apart.
        let previous = std::fs::read(&output).unwrap();
        let input = usize::from(previous == complete[0]);
        let mut child = spawn(&heading_args(&s, input, out));
        let temp = dir.join(format!(".out.csv.tmp-{}", child.id()));
        let share = delays.next_fraction();
        let mut ended_first = None;
        if share < 0.2 {
            std::thread::sleep(start_up.mul_f64(share * 5.0));
            found.sent_early += 1;
        } else {
            // One in ten waits for the whole output: the kill lands while it is synced
            // and renamed, or just after.
            let whole = complete[input].len() as f64;
            let bytes = (whole * ((share - 0.2) / 0.7).min(1.0)) as u64;
            match wait_for_size(&temp, bytes.max(1), &mut child) {
                Waited::Reached => found.sent_mid_write += 1,
                Waited::Ended(status) => ended_first = Some(status),
                Waited::TimedOut => {}
            }
        }
        let status = match ended_first {
            Some(status) => {
                found.ended_before_the_signal += 1;
                status
            }
            None => {
                if signal == "KILL" {
                    let _ = child.kill();
                } else {
                    // The run is not reaped yet (a zombie at worst), so its id is still its own.
                    let sent = Command::new("kill")
                        .args([format!("-{signal}"), child.id().to_string()])
                        .status()
                        .unwrap();
                    assert!(sent.success(), "run {k}: kill -{signal} failed: {sent}");
                }
                child.wait().unwrap()
            }
        };
        let mut stderr = String::new();
        if let Some(mut pipe) = child.stderr.take() {
            let _ = pipe.read_to_string(&mut stderr);
        }
        found.kills += 1;
        let now = std::fs::read(&output).unwrap();
        // The two endings the contract allows: stopped by the signal sent (it arrived before
        // the handler was installed and the default action ended the run, or the handler
        // removed the temporary and raised it again), or success (the run ended before its
        // signal was sent, or renamed its output into place and ended before the handler
        // acted: either way the output is the new one). An exit status is a failure of the
        // run itself, shown with its message.
        if status.signal() == Some(signal_number(signal)) {
            found.stopped_by_the_signal += 1;
        } else if status.success() {
            assert!(
                now == complete[input],
                "run {k} (SIG{signal}): a successful run left {} bytes, not its complete output ({})",
                now.len(),
                complete[input].len()
            );
            found.finished_first += 1;
        } else {
            panic!(
                "run {k} (SIG{signal}): ended with {status}, neither stopped by the signal nor successful; its stderr: {stderr:?}"
            );
        }
        if now == complete[input] {
            found.new_output_complete += 1;
        } else {
            assert!(
                now == previous,
                "run {k} ({signal}): the output is neither the previous one nor the complete new one ({} bytes; previous {}, complete {})",
                now.len(),
                previous.len(),
                complete[input].len()
            );
            found.previous_output_kept += 1;
        }
        let left = temporaries(&dir);
        if signal != "KILL" {
            assert!(left.is_empty(), "run {k}: SIG{signal} left {left:?}");
        }
        assert!(
            left.len() <= 1,
            "run {k}: each run cleans the one before: {left:?}"
        );
        found.temporaries_left += left.len();
    }
    // The next run cleans what the last kill left.
    ok(&heading_args(&s, 0, out));
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
    assert_eq!(std::fs::read(&output).unwrap(), complete[0]);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("SIG{signal}: {found:?}");
    assert!(
        found.sent_mid_write * 2 >= kills,
        "most kills land while the output is written: {found:?}"
    );
    found
}

#[test]
fn sigkill_mid_write_never_truncates_and_the_next_run_cleans_up() {
    let found = kill_repeatedly("sigkill", "KILL", 20, 0x5EED_0001);
    assert_eq!(found.kills, 20);
}

#[test]
fn sigterm_mid_write_never_truncates_and_leaves_no_temporary() {
    let kill_works = Command::new("kill")
        .args(["-0", &std::process::id().to_string()])
        .status()
        .is_ok_and(|s| s.success());
    if !kill_works {
        eprintln!("SKIPPED: no `kill` program to send SIGTERM with");
        return;
    }
    let found = kill_repeatedly("sigterm", "TERM", 20, 0x5EED_0002);
    assert_eq!(found.kills, 20);
}

/// Whether this process was started with SIGINT ignored (as a background job of a script
/// is): its children then rightly keep ignoring it.
fn sigint_ignored() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("SigIgn:"))
                .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        })
        .is_some_and(|mask| mask & 0b10 != 0)
}

#[test]
fn sigint_mid_write_never_truncates_and_leaves_no_temporary() {
    if sigint_ignored() {
        eprintln!("SKIPPED: started with SIGINT ignored, which the runs inherit and keep");
        return;
    }
    let found = kill_repeatedly("sigint", "INT", 10, 0x5EED_0003);
    assert_eq!(found.kills, 10);
}

#[test]
fn temporaries_of_gone_runs_are_removed_and_those_of_live_runs_kept() {
    let dir = scratch("stale");
    let s = setup(&dir, 100);
    let output = dir.join("out.csv");
    // Above Linux's largest process id (2^22): no process has it.
    let gone = dir.join(".out.csv.tmp-4294967");
    let live = dir.join(format!(".out.csv.tmp-{}", std::process::id()));
    std::fs::write(&gone, "left by a killed run").unwrap();
    std::fs::write(&live, "a concurrent run's").unwrap();
    ok(&heading_args(&s, 0, p(&output)));
    if Path::new("/proc/self").exists() {
        assert!(!gone.exists());
    }
    assert!(live.exists(), "a live process's temporary is not touched");
}

/// The one line on stderr, checked to be one line.
fn one_line(stderr: &[u8]) -> String {
    let text = String::from_utf8_lossy(stderr).into_owned();
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(!text.contains("panicked"), "{text}");
    text
}

fn dev_full() -> Option<std::fs::File> {
    std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .ok()
}

#[test]
fn a_full_disk_is_one_line_and_a_failure() {
    let Some(_) = dev_full() else {
        eprintln!("SKIPPED: no /dev/full here");
        return;
    };
    let dir = scratch("full");
    let s = setup(&dir, 1000);
    // As the output file (as root this used to turn /dev/full into a regular file).
    let out = truenorth(&heading_args(&s, 0, "/dev/full"));
    assert_eq!(out.status.code(), Some(1));
    let line = one_line(&out.stderr);
    assert!(line.contains("No space left"), "{line}");
    let meta = std::fs::metadata("/dev/full").unwrap();
    assert!(
        meta.file_type().is_char_device(),
        "/dev/full is still a device"
    );
    // As standard output, for the commands that print.
    let demo_out = dir.join("demo");
    let commands: [Vec<&str>; 4] = [
        vec!["field", "--lat", "48", "--lon", "11", "--date", "2026.5"],
        vec!["demo", "--out", p(&demo_out)],
        vec!["inspect", p(&s.inputs[0])],
        heading_args(&s, 0, "-"),
    ];
    for args in commands {
        let out = common::binary()
            .args(&args)
            .stdin(Stdio::null())
            .stdout(dev_full().unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let line = one_line(&out.stderr);
        assert!(line.contains("No space left"), "{args:?}: {line}");
    }
}

#[test]
fn a_closed_pipe_ends_the_run_quietly() {
    let dir = scratch("pipe");
    let s = setup(&dir, 20_000);
    // `truenorth heading --output - | head -1`: read one line, close the pipe.
    let mut child = common::binary()
        .args(heading_args(&s, 0, "-"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "t_s,heading_deg\n");
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(CLOSED_PIPE), "{stderr}");
    assert!(stderr.is_empty(), "no message: {stderr}");
    assert!(temporaries(&dir).is_empty());
    // Commands that print to the terminal: closed before or while they print.
    let demo_out = dir.join("demo");
    let commands: [Vec<&str>; 2] = [
        vec!["field", "--lat", "48", "--lon", "11", "--date", "2026.5"],
        vec!["demo", "--out", p(&demo_out)],
    ];
    for args in commands {
        let mut child = common::binary()
            .args(&args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        // `field` may have printed its two lines before the pipe closed.
        assert!(
            matches!(out.status.code(), Some(0 | CLOSED_PIPE)),
            "{args:?}: {:?}",
            out.status
        );
        assert!(out.stderr.is_empty(), "{args:?}: {:?}", out.stderr);
    }
}

#[test]
fn devices_are_written_into_not_replaced() {
    let dir = scratch("device");
    let s = setup(&dir, 1000);
    ok(&heading_args(&s, 0, "/dev/null"));
    let meta = std::fs::metadata("/dev/null").unwrap();
    assert!(
        meta.file_type().is_char_device(),
        "/dev/null is still a device"
    );
    assert!(temporaries(Path::new("/dev")).is_empty());
}

#[test]
fn a_fifo_is_written_into_not_replaced() {
    let dir = scratch("fifo");
    let s = setup(&dir, 5000);
    let reference = dir.join("reference.csv");
    ok(&heading_args(&s, 0, p(&reference)));
    let fifo = dir.join("out.fifo");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|m| m.success()) {
        eprintln!("SKIPPED: mkfifo is not available");
        return;
    }
    let child = spawn(&heading_args(&s, 0, p(&fifo)));
    // Opening the reading end waits for the writer, as a reader of a FIFO does.
    let got = std::fs::read(&fifo).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert_eq!(got, std::fs::read(&reference).unwrap());
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(meta.file_type().is_fifo(), "the FIFO is still a FIFO");
    assert!(temporaries(&dir).is_empty());
}

#[test]
fn a_symbolic_link_is_followed_and_stays_a_link() {
    let dir = scratch("symlink");
    let s = setup(&dir, 1000);
    let reference = dir.join("reference.csv");
    ok(&heading_args(&s, 0, p(&reference)));
    let expected = std::fs::read(&reference).unwrap();
    std::fs::create_dir_all(dir.join("real")).unwrap();
    let real = dir.join("real").join("headings.csv");
    std::fs::write(&real, "old\n").unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink("real/headings.csv", &link).unwrap();
    ok(&heading_args(&s, 0, p(&link)));
    let meta = std::fs::symlink_metadata(&link).unwrap();
    assert!(meta.file_type().is_symlink(), "the link is still a link");
    assert_eq!(
        std::fs::read_link(&link).unwrap(),
        Path::new("real/headings.csv")
    );
    assert_eq!(std::fs::read(&real).unwrap(), expected);
    assert!(temporaries(&dir).is_empty() && temporaries(&dir.join("real")).is_empty());
    // A link to a file not there yet: the file is made where it points.
    let dangling = dir.join("dangling.csv");
    std::os::unix::fs::symlink("real/new.csv", &dangling).unwrap();
    ok(&heading_args(&s, 0, p(&dangling)));
    assert!(std::fs::symlink_metadata(&dangling).unwrap().is_symlink());
    assert_eq!(std::fs::read(dir.join("real/new.csv")).unwrap(), expected);
}

#[test]
fn an_output_linked_to_the_input_is_refused() {
    let dir = scratch("onto_input");
    let s = setup(&dir, 1000);
    let before = std::fs::read(&s.inputs[0]).unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&s.inputs[0], &link).unwrap();
    let hard = dir.join("hard.csv");
    std::fs::hard_link(&s.inputs[0], &hard).unwrap();
    for output in [&link, &hard] {
        let out = truenorth(&heading_args(&s, 0, p(output)));
        assert_eq!(out.status.code(), Some(1));
        let line = one_line(&out.stderr);
        assert!(line.contains("would overwrite the input"), "{line}");
    }
    assert_eq!(std::fs::read(&s.inputs[0]).unwrap(), before);
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
}
