//! One file's run: the current executable started on it as a child process, so a file that
//! fails, panics or is killed is one failed row and never the end of the batch; its exit,
//! its last message and the rows it read make the row.

use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use super::journal::COMMAND_ERROR_CODE;
use super::passthrough::Passthrough;
use super::results::Status;
use crate::io::{CliError, CliResult, ErrorKind, write_atomically};

/// Set in a child's environment: the child then reports the rows it read on its last line
/// of standard error, after [`STATS_PREFIX`].
pub const CHILD_ENV: &str = "TRUENORTH_BATCH_CHILD";

/// What starts the line on which a child reports the rows it read.
pub const STATS_PREFIX: &str = "truenorth-batch: rows read ";

/// What starts the line on which a child that ended with an error reports its kind
/// ([`ErrorKind::name`]: the data refused, or a failure), where the error carries one. A
/// line of its own on standard error, which the batch reads and the user never sees, so that
/// the exit codes and messages scripts rely on stay as they are.
pub const KIND_PREFIX: &str = "truenorth-batch: error kind ";

/// How often a running child is checked for its end and for an abort.
const POLL: Duration = Duration::from_millis(2);

/// How long a child stopped with SIGTERM has to remove its temporaries before SIGKILL.
const GRACE: Duration = Duration::from_secs(2);

/// The end of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Ended {
    /// ok, refused or failed.
    pub status: Status,
    /// The exit code (none: a signal, or not started).
    pub exit_code: Option<i32>,
    /// The one-line reason when not ok.
    pub message: String,
    /// Rows the child read, as it reported them.
    pub samples: Option<u64>,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The child's process id.
    pub pid: Option<u32>,
}

/// Runs `exe` with `command` on `input`, writing `output`; `abort` set while it runs stops
/// it (SIGTERM, then SIGKILL after a grace period).
pub fn run(
    exe: &Path,
    command: &Passthrough,
    input: &Path,
    output: &Path,
    abort: &AtomicBool,
) -> Ended {
    let start = Instant::now();
    let mut cmd = Command::new(exe);
    cmd.args(command.arguments(input, output))
        .env(CHILD_ENV, "1")
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .stdout(if command.writes_stdout() {
            Stdio::piped()
        } else {
            Stdio::null()
        });
    #[cfg(unix)]
    {
        // Its own process group: a Ctrl-C at the terminal reaches the batch, which decides
        // whether the running files finish, not each child.
        use std::os::unix::process::CommandExt as _;
        cmd.process_group(0);
    }
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            return Ended {
                status: Status::Failed,
                exit_code: None,
                message: format!("could not start {}: {e}", exe.display()),
                samples: None,
                seconds: start.elapsed().as_secs_f64(),
                pid: None,
            };
        }
    };
    let pid = child.id();
    let stderr = child.stderr.take();
    let stdout = child.stdout.take();
    let (status, err_text, out_bytes) = std::thread::scope(|s| {
        let err_reader = s.spawn(move || read_all(stderr));
        let out_reader = s.spawn(move || read_all(stdout));
        let status = wait(&mut child, abort);
        let err_text = String::from_utf8_lossy(&err_reader.join().unwrap_or_default()).into_owned();
        (status, err_text, out_reader.join().unwrap_or_default())
    });
    let seconds = start.elapsed().as_secs_f64();
    let mut ended = judge(status, &err_text);
    ended.seconds = seconds;
    ended.pid = Some(pid);
    if ended.status == Status::Ok
        && command.writes_stdout()
        && let Err(e) = write_atomically(output, |w| Ok(w.write_all(&out_bytes)?))
    {
        ended.status = Status::Failed;
        ended.message = e.to_string();
    }
    ended
}

/// Everything a pipe gives until its end (nothing for no pipe).
fn read_all(pipe: Option<impl std::io::Read>) -> Vec<u8> {
    let mut bytes = Vec::new();
    if let Some(mut p) = pipe {
        let _ = p.read_to_end(&mut bytes);
    }
    bytes
}

/// Waits for the child, stopping it if `abort` is set meanwhile.
fn wait(child: &mut std::process::Child, abort: &AtomicBool) -> Option<ExitStatus> {
    let mut term_sent: Option<Instant> = None;
    loop {
        match child.try_wait() {
            Ok(Some(s)) => return Some(s),
            Ok(None) => {}
            Err(_) => return child.wait().ok(),
        }
        if abort.load(Ordering::Relaxed) {
            match term_sent {
                None => {
                    if terminate(child.id()).is_err() {
                        let _ = child.kill();
                    }
                    term_sent = Some(Instant::now());
                }
                Some(t) if t.elapsed() > GRACE => {
                    let _ = child.kill();
                }
                Some(_) => {}
            }
        }
        std::thread::sleep(POLL);
    }
}

/// Sends SIGTERM (the child removes its temporaries and ends), through `kill(1)`: the
/// workspace has no unsafe code to call `kill(2)`. The child is not yet reaped, so its
/// process id is still its own.
fn terminate(pid: u32) -> CliResult {
    let status = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| CliError::msg(e.to_string()))?;
    if status.success() {
        Ok(())
    } else {
        Err(CliError::msg("kill failed"))
    }
}

/// The row's status, exit code, message and samples from how the child ended and what it
/// wrote on standard error.
pub fn judge(status: Option<ExitStatus>, stderr: &str) -> Ended {
    let samples = stderr
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix(STATS_PREFIX))
        .and_then(|n| n.trim().parse().ok());
    let kind = stderr
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix(KIND_PREFIX))
        .and_then(ErrorKind::from_name);
    let said = stderr
        .lines()
        .rev()
        .filter(|l| !l.starts_with(STATS_PREFIX) && !l.starts_with(KIND_PREFIX))
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
        .trim();
    let base = Ended {
        status: Status::Failed,
        exit_code: status.and_then(|s| s.code()),
        message: String::new(),
        samples,
        seconds: 0.0,
        pid: None,
    };
    let Some(status) = status else {
        return Ended {
            message: "lost track of the run".into(),
            ..base
        };
    };
    match status.code() {
        Some(0) => Ended {
            status: Status::Ok,
            ..base
        },
        Some(COMMAND_ERROR_CODE) => {
            let message = said.strip_prefix("truenorth: ").unwrap_or(said).to_string();
            // The kind the child reported; today's reading of the words only for a child
            // that reported none.
            let refused = match kind {
                Some(kind) => kind == ErrorKind::Refusal,
                None => is_refusal(&message),
            };
            Ended {
                status: if refused {
                    Status::Refused
                } else {
                    Status::Failed
                },
                message,
                ..base
            }
        }
        Some(code) => {
            // A panic's first line says where; anything else is shown as the last line.
            let panic = stderr.lines().find(|l| l.contains("panicked at"));
            Ended {
                message: format!(
                    "ended with exit code {code}{}",
                    panic
                        .or(Some(said).filter(|s| !s.is_empty()))
                        .map_or(String::new(), |l| format!(": {}", l.trim()))
                ),
                ..base
            }
        }
        None => Ended {
            message: signal_message(status),
            ..base
        },
    }
}

#[cfg(unix)]
fn signal_message(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt as _;
    status
        .signal()
        .map_or("ended without an exit code".into(), |s| {
            format!("killed by signal {s}")
        })
}

#[cfg(not(unix))]
fn signal_message(_status: ExitStatus) -> String {
    "ended without an exit code".into()
}

/// Whether a command's message is a verdict on the data rather than a file it could not
/// read, for a child that reported no kind ([`KIND_PREFIX`]): the commands word a refusal as
/// one they `refuse`/`cannot calibrate`, or with the option that would accept it anyway
/// (`--accept-…`, "… anyway").
pub fn is_refusal(message: &str) -> bool {
    let m = message.to_ascii_lowercase();
    ["refused", "cannot calibrate", "anyway", "--accept-"]
        .iter()
        .any(|k| m.contains(k))
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt as _;

    #[test]
    fn exits_are_judged_by_code_signal_and_message() {
        let ok = judge(
            Some(ExitStatus::from_raw(0)),
            "truenorth: calibrate: ...\ntruenorth-batch: rows read 42\n",
        );
        assert_eq!((ok.status, ok.samples), (Status::Ok, Some(42)));
        let refused = judge(
            Some(ExitStatus::from_raw(1 << 8)),
            "truenorth: a.csv: cannot calibrate with method `ellipsoid`: too little turn\ntruenorth-batch: rows read 7\n",
        );
        assert_eq!(refused.status, Status::Refused);
        assert_eq!(refused.exit_code, Some(1));
        assert!(
            refused.message.starts_with("a.csv: cannot"),
            "{}",
            refused.message
        );
        let corrupt = judge(
            Some(ExitStatus::from_raw(1 << 8)),
            "truenorth: a.csv: row 3: column `x`: `?` is not a number\n",
        );
        assert_eq!(corrupt.status, Status::Failed);
        let panic = judge(
            Some(ExitStatus::from_raw(101 << 8)),
            "thread 'main' panicked at src/x.rs:1:1:\nboom\n",
        );
        assert_eq!(panic.status, Status::Failed);
        assert!(panic.message.contains("exit code 101"), "{}", panic.message);
        // A refusal worded with none of the words above is still a refusal when the child
        // says so, and a failure that happens to contain them is still a failure.
        let refused = judge(
            Some(ExitStatus::from_raw(1 << 8)),
            "truenorth-batch: rows read 9\ntruenorth-batch: error kind refusal\ntruenorth: a.csv: the turn covered only 90°, need at least 360°; drive a complete circle\n",
        );
        assert_eq!(refused.status, Status::Refused);
        assert!(
            refused.message.starts_with("a.csv: the turn"),
            "{}",
            refused.message
        );
        assert_eq!(refused.samples, Some(9));
        let failed = judge(
            Some(ExitStatus::from_raw(1 << 8)),
            "truenorth-batch: rows read 0\ntruenorth-batch: error kind failure\ntruenorth: a.csv: cannot open: refused by the file system\n",
        );
        assert_eq!(failed.status, Status::Failed);
        assert_eq!(
            failed.message,
            "a.csv: cannot open: refused by the file system"
        );
        let killed = judge(Some(ExitStatus::from_raw(9)), "");
        assert_eq!((killed.status, killed.exit_code), (Status::Failed, None));
        assert_eq!(killed.message, "killed by signal 9");
    }
}
