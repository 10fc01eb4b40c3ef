//! The journal that makes a batch resumable: one JSON line per finished file in the output
//! folder, appended and synced to disk as each file finishes, keyed by the file's output
//! name, the SHA-256 of its bytes and the command line. A rerun skips a file whose key and
//! last line match; a kill can tear at most the line being written, which the reader
//! ignores (and the next line starts on a line of its own).

use std::collections::HashMap;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read as _, Seek as _, SeekFrom, Write as _};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::results::{Row, Status};
use crate::io::{CliError, CliResult};

/// The journal's name in the output folder (hidden; no output name starts with `.`).
pub const JOURNAL_NAME: &str = ".truenorth-batch-journal.jsonl";

/// The exit code of a command that ended normally with its one-line error.
pub const COMMAND_ERROR_CODE: i32 = 1;

/// One line of the journal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The output's name under the output folder (the key's first part).
    pub name: String,
    /// The command and its options as given after `--` (the key's last part).
    pub command: Vec<String>,
    /// The row of the run (its `hash` is the key's middle part).
    #[serde(flatten)]
    pub row: Row,
    /// The process id of the run, so that a run can be told from another in the journal.
    pub pid: Option<u32>,
}

impl Entry {
    /// What the journal looks entries up by (the hash is compared on the entry found).
    fn key(&self) -> (String, Vec<String>) {
        (self.name.clone(), self.command.clone())
    }

    /// Whether the run settled the file: it succeeded, or the command itself declined it
    /// (refused, or failed with its own message). A run ended by a signal, a crash or that
    /// never started is tried again; so is any failure with `retry_failed`.
    pub fn settled(&self, retry_failed: bool) -> bool {
        match self.row.status {
            Status::Ok | Status::Refused => true,
            Status::Failed => !retry_failed && self.row.exit_code == Some(COMMAND_ERROR_CODE),
            Status::SkippedDone => false,
        }
    }
}

/// The last entry of every name and command in the journal, to look runs up in.
#[derive(Debug, Clone, Default)]
pub struct Known {
    last: HashMap<(String, Vec<String>), Entry>,
}

impl Known {
    /// The entry that settles `name` for these bytes and this command, if any.
    pub fn settled(
        &self,
        name: &str,
        hash: &str,
        command: &[String],
        retry_failed: bool,
    ) -> Option<&Entry> {
        self.last
            .get(&(name.to_string(), command.to_vec()))
            .filter(|e| e.row.hash == hash && e.settled(retry_failed))
    }
}

/// The journal open for appending, with the last entry of every name read from it.
#[derive(Debug)]
pub struct Journal {
    file: File,
    path: PathBuf,
    known: Known,
}

impl Journal {
    /// Opens (or creates) the journal in `dir` and reads what it holds.
    pub fn open(dir: &Path) -> CliResult<Self> {
        let path = dir.join(JOURNAL_NAME);
        let err =
            |e: std::io::Error| CliError::file(&path, format!("cannot open the journal: {e}"));
        let mut file = OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(&path)
            .map_err(err)?;
        // One batch per folder: a second would interleave its journal lines with the first's,
        // write the same outputs twice and leave whichever results table ends last. The
        // lock goes with the process, however it ends. A file system without locks (some
        // network ones) runs unlocked, as before.
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(CliError::file(
                    &path,
                    "another `truenorth batch` is writing into this folder: wait for it to \
                     end, or give this one another --out",
                ));
            }
            Err(TryLockError::Error(e)) if e.kind() == std::io::ErrorKind::Unsupported => {}
            Err(TryLockError::Error(e)) => return Err(err(e)),
        }
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(err)?;
        let mut last = HashMap::new();
        for line in bytes.split(|&b| b == b'\n') {
            // A torn line (a kill mid-write) does not parse and is skipped.
            if let Ok(entry) = serde_json::from_slice::<Entry>(line) {
                last.insert(entry.key(), entry);
            }
        }
        if bytes.last().is_some_and(|&b| b != b'\n') {
            file.seek(SeekFrom::End(0)).map_err(err)?;
            file.write_all(b"\n").map_err(err)?;
        }
        Ok(Self {
            file,
            path,
            known: Known { last },
        })
    }

    /// What the journal holds.
    pub fn known(&self) -> &Known {
        &self.known
    }

    /// Appends `entry` as one line and syncs it to disk before returning.
    pub fn append(&mut self, entry: Entry) -> CliResult {
        let mut line = serde_json::to_vec(&entry)
            .map_err(|e| CliError::file(&self.path, format!("cannot write the journal: {e}")))?;
        line.push(b'\n');
        self.file
            .write_all(&line)
            .and_then(|()| self.file.sync_data())
            .map_err(|e| CliError::file(&self.path, format!("cannot write the journal: {e}")))?;
        self.known.last.insert(entry.key(), entry);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(name: &str, status: Status, code: Option<i32>) -> Entry {
        Entry {
            name: name.into(),
            command: vec!["calibrate".into()],
            row: Row {
                path: name.into(),
                hash: "h".into(),
                status,
                outcome: status,
                exit_code: code,
                message: String::new(),
                samples: Some(3),
                seconds: 0.5,
                output: String::new(),
                verdict: None,
            },
            pid: Some(1),
        }
    }

    #[test]
    fn a_second_batch_on_one_folder_is_refused_while_the_first_runs() {
        let d = std::env::temp_dir().join(format!("truenorth-journal-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let first = Journal::open(&d).unwrap();
        let second = Journal::open(&d).unwrap_err().to_string();
        assert!(second.contains("another `truenorth batch`"), "{second}");
        drop(first);
        assert!(
            Journal::open(&d).is_ok(),
            "the lock ends with the first batch"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_torn_line_is_skipped_and_the_next_starts_afresh() {
        let d = std::env::temp_dir().join(format!("truenorth-journal-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let mut j = Journal::open(&d).unwrap();
        j.append(entry("a", Status::Ok, Some(0))).unwrap();
        drop(j);
        let mut f = OpenOptions::new()
            .append(true)
            .open(d.join(JOURNAL_NAME))
            .unwrap();
        f.write_all(b"{\"name\":\"b\",\"comm").unwrap();
        drop(f);
        let mut j = Journal::open(&d).unwrap();
        let cmd = vec!["calibrate".to_string()];
        assert!(j.known().settled("a", "h", &cmd, false).is_some());
        assert!(
            j.known().settled("a", "other", &cmd, false).is_none(),
            "new bytes"
        );
        assert!(
            j.known().settled("a", "h", &[], false).is_none(),
            "another command"
        );
        assert!(j.known().settled("b", "h", &cmd, false).is_none());
        j.append(entry("b", Status::Failed, None)).unwrap();
        drop(j);
        let j = Journal::open(&d).unwrap();
        assert!(
            j.known().last.contains_key(&("b".into(), cmd.clone())),
            "the line after a torn one reads"
        );
        assert!(
            j.known().settled("b", "h", &cmd, false).is_none(),
            "a crash is retried"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn failures_the_command_reported_are_settled_unless_retried() {
        let e = entry("a", Status::Failed, Some(COMMAND_ERROR_CODE));
        assert!(e.settled(false));
        assert!(!e.settled(true));
        assert!(entry("a", Status::Refused, Some(1)).settled(true));
    }
}
