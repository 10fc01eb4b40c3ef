//! Removing the temporaries that killed runs left in the output folder. A run killed by
//! SIGKILL (with its batch, by a power cut, by the out-of-memory killer) leaves its output's
//! `.NAME.tmp-PID`; the next run writing that output removes it, but a file finished by
//! another run in the meantime is never written again. So a batch sweeps its folder when it
//! starts and when it ends, removing the temporaries whose process is gone or a zombie (a
//! killed process whose parent died is one until the system reaps it).

use std::path::Path;

/// Removes the temporaries under `dir` (and its sub-folders) of processes that no longer run.
/// Without `/proc` nothing is removed: there is no telling a live process from a gone one.
pub fn remove_stale_temporaries(dir: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    sweep(dir);
}

fn sweep(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() {
            sweep(&entry.path());
            continue;
        }
        let name = entry.file_name();
        let Some(pid) = temporary_pid(&name.to_string_lossy()) else {
            continue;
        };
        if pid != std::process::id() && !running(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The process id of a temporary's name, `.NAME.tmp-PID`.
pub fn temporary_pid(name: &str) -> Option<u32> {
    let (stem, pid) = name.strip_prefix('.')?.rsplit_once(".tmp-")?;
    if stem.is_empty() || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// Whether process `pid` runs: it has an entry in `/proc` whose state (the field after the
/// parenthesised command name in `/proc/PID/stat`, proc(5)) is not `Z`, a zombie.
fn running(pid: u32) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return false;
    };
    let state = stat
        .rsplit_once(')')
        .and_then(|(_, rest)| rest.split_whitespace().next());
    state != Some("Z")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_are_told_by_their_names() {
        assert_eq!(temporary_pid(".a.csv.json.tmp-123"), Some(123));
        assert_eq!(temporary_pid("a.csv.json.tmp-123"), None);
        assert_eq!(temporary_pid(".a.tmp-12x"), None);
        assert_eq!(temporary_pid(".tmp-12"), None);
    }

    #[test]
    fn a_gone_process_s_temporary_goes_and_a_live_one_s_stays() {
        let d = std::env::temp_dir().join(format!("truenorth-sweep-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("sub")).unwrap();
        // Above any pid_max Linux allows (2^22): no process has it.
        let gone = d.join("sub").join(".a.json.tmp-4294967");
        let mine = d.join(format!(".b.json.tmp-{}", std::process::id()));
        let output = d.join("a.json");
        for p in [&gone, &mine, &output] {
            std::fs::write(p, "x").unwrap();
        }
        remove_stale_temporaries(&d);
        if Path::new("/proc/self").exists() {
            assert!(!gone.exists());
        }
        assert!(mine.exists() && output.exists());
        let _ = std::fs::remove_dir_all(&d);
    }
}
