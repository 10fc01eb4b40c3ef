//! Text for the person at the terminal, on standard output and standard error, written so
//! that a failed write never panics:
//! * a closed pipe (the reader went away, as `truenorth … | head -1` does) ends the run at
//!   once, without a message, with status 141 (128 + SIGPIPE, what a shell reports for a
//!   program the closed pipe killed, so `set -o pipefail` scripts see the same as with
//!   `yes | head -1`); any unfinished output's temporary is removed first;
//! * any other failure on standard output (a full disk, `>/dev/full`) is an error that the
//!   command returns: one line on stderr and a non-zero exit;
//! * a failure on standard error other than a closed pipe is ignored: there is nowhere left
//!   to report it.
//!
//! Use [`outln!`](crate::io::outln) / [`out!`](crate::io::out) where `println!` / `print!`
//! would panic, and [`errln!`](crate::io::errln) for `eprintln!`.

use std::fmt;
use std::io::{ErrorKind, Write};

use super::{CliError, CliResult, temporaries};

/// The exit status of a run whose output pipe was closed by its reader: 128 + SIGPIPE.
pub const CLOSED_PIPE_STATUS: i32 = 141;

/// Writes `args` to standard output (flushed, so that a failure shows now, not at exit).
pub fn write_stdout(args: fmt::Arguments<'_>) -> CliResult {
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => end_on_closed_pipe(),
        Err(e) => Err(CliError::msg(format!("standard output: cannot write: {e}"))),
    }
}

/// Writes `args` to standard error; a closed pipe ends the run (see the module), any other
/// failure is ignored.
pub fn write_stderr(args: fmt::Arguments<'_>) {
    let mut err = std::io::stderr().lock();
    if let Err(e) = err.write_fmt(args).and_then(|()| err.flush())
        && e.kind() == ErrorKind::BrokenPipe
    {
        end_on_closed_pipe();
    }
}

/// Ends the run because its reader closed the pipe: removes the temporaries of unfinished
/// outputs, then exits with [`CLOSED_PIPE_STATUS`] and no message.
pub fn end_on_closed_pipe() -> ! {
    let _held = temporaries::remove_all_live();
    std::process::exit(CLOSED_PIPE_STATUS)
}

/// `println!` on standard output that returns a [`CliResult`] instead of panicking.
macro_rules! outln {
    () => {
        $crate::io::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::io::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` on standard output that returns a [`CliResult`] instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::io::write_stdout(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics (see the module for what a failure does).
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::io::write_stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {errln, out, outln};
