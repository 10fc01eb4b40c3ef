//! The temporary files of outputs being written: named `.NAME.tmp-PID` beside their target,
//! known to the process while it writes them, removed when it stops early.
//!
//! * An error or a panic drops the output, which removes its temporary.
//! * SIGINT, SIGTERM and SIGHUP (Ctrl-C, `kill`, a closed terminal) remove every live
//!   temporary, then end the process as the signal would have (a thread waits for them,
//!   started when the first temporary is made; a signal the process was started with
//!   ignored, as `nohup` does, stays ignored).
//! * SIGKILL cannot be caught: it leaves the temporary, and the next run writing the same
//!   output removes every `.NAME.tmp-PID` whose process is gone (never one of a live
//!   concurrent run).

use std::ffi::OsString;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once};

/// The temporaries this process is writing.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The signal thread, started once.
static HANDLER: Once = Once::new();

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    // A panic while holding the list leaves it usable: it is a plain list of names.
    LIVE.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// What the temporary of `target` is named in this process: `.NAME.tmp-PID` beside it.
pub(super) fn name_for(target: &Path) -> Option<PathBuf> {
    let name = target.file_name()?;
    let mut tmp = OsString::from(".");
    tmp.push(name);
    tmp.push(format!(".tmp-{}", std::process::id()));
    Some(target.with_file_name(tmp))
}

/// Creates `temp` (truncating it) and records it as live, both under the list's lock, and
/// makes sure the signals remove it: a signal handled at the same moment either comes
/// first, and then holds the lock until the process ends so the file is never made, or
/// finds it made and listed. (Listed first and created outside the lock, a file made just
/// after the signal emptied the list would outlive the process.)
pub(super) fn create(temp: &Path) -> std::io::Result<File> {
    install_handler();
    let mut list = live();
    let file = File::create(temp)?;
    list.push(temp.to_path_buf());
    Ok(file)
}

/// Removes `temp` from the disk and from the live list.
pub(super) fn discard(temp: &Path) {
    let mut list = live();
    let _ = std::fs::remove_file(temp);
    list.retain(|p| p != temp);
}

/// Renames `temp` over `target` and forgets it, under the list's lock so that a signal
/// handled at the same moment either finds the temporary whole or finds it renamed.
pub(super) fn publish(temp: &Path, target: &Path) -> std::io::Result<()> {
    let mut list = live();
    let renamed = std::fs::rename(temp, target);
    if renamed.is_err() {
        let _ = std::fs::remove_file(temp);
    }
    list.retain(|p| p != temp);
    renamed
}

/// Removes every live temporary; the lock is held until the process ends, so nothing is
/// renamed or started after it. For a run that stops at once (a signal, a closed pipe).
pub(super) fn remove_all_live() -> MutexGuard<'static, Vec<PathBuf>> {
    let list = live();
    for p in list.iter() {
        let _ = std::fs::remove_file(p);
    }
    list
}

/// Removes the temporaries of `target` left by processes that no longer run (killed by
/// SIGKILL, a power cut). A process is known to be gone when `/proc` is there and has no
/// entry for it; without `/proc` nothing is removed.
pub(super) fn remove_stale(target: &Path) {
    let Some(name) = target.file_name() else {
        return;
    };
    let mut prefix = OsString::from(".");
    prefix.push(name);
    prefix.push(".tmp-");
    let prefix = prefix.as_encoded_bytes();
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let proc_fs = Path::new("/proc");
    if !proc_fs.join("self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let me = std::process::id();
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(pid) = file_name
            .as_encoded_bytes()
            .strip_prefix(prefix)
            .and_then(|rest| std::str::from_utf8(rest).ok())
            .filter(|rest| rest.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|rest| rest.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != me && !proc_fs.join(pid.to_string()).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Starts the thread that turns SIGINT, SIGTERM and SIGHUP into "remove the temporaries,
/// then end as the signal would".
fn install_handler() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    HANDLER.call_once(|| {
        let ignored = ignored_signals();
        let wanted: Vec<i32> = [SIGINT, SIGTERM, SIGHUP]
            .into_iter()
            .filter(|s| !ignored.contains(s))
            .collect();
        let Ok(mut signals) = signal_hook::iterator::Signals::new(&wanted) else {
            return;
        };
        let started = std::thread::Builder::new()
            .name("truenorth-signals".into())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    let _held = remove_all_live();
                    // The default action of these three ends the process; the exit below
                    // is only for a platform where it did not.
                    let _ = signal_hook::low_level::emulate_default_handler(signal);
                    std::process::exit(128 + signal);
                }
            });
        drop(started);
    });
}

/// The signals this process was started with ignored (Linux: `SigIgn` in
/// `/proc/self/status`, a hexadecimal mask with bit `n - 1` for signal `n`); none where that
/// cannot be read.
fn ignored_signals() -> Vec<i32> {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return Vec::new();
    };
    let Some(mask) = status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
    else {
        return Vec::new();
    };
    (1..=64).filter(|&n| mask & (1 << (n - 1)) != 0).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporaries_of_gone_processes_are_removed_and_live_ones_kept() {
        let scratch = crate::io::scratch::scratch_dir("stale");
        let d = scratch.path();
        let target = d.join("out.csv");
        // Above any pid_max Linux allows (2^22): no process has it.
        let gone = d.join(".out.csv.tmp-4294967");
        let mine = d.join(format!(".out.csv.tmp-{}", std::process::id()));
        let other_output = d.join(".other.csv.tmp-4294967");
        let not_a_pid = d.join(".out.csv.tmp-12ab");
        for p in [&gone, &mine, &other_output, &not_a_pid] {
            std::fs::write(p, "x").unwrap();
        }
        remove_stale(&target);
        if Path::new("/proc/self").exists() {
            assert!(!gone.exists(), "a dead process's temporary is removed");
        }
        assert!(mine.exists(), "a live process's temporary is kept");
        assert!(
            other_output.exists(),
            "another output's temporary is not touched"
        );
        assert!(not_a_pid.exists(), "a name that is not ours is not touched");
    }

    #[test]
    fn ignored_signals_are_read_from_the_status_mask() {
        // Rust's runtime ignores SIGPIPE (13) before main on Unix.
        if Path::new("/proc/self/status").exists() {
            assert!(ignored_signals().contains(&13));
        }
    }
}
