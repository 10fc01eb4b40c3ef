//! What the command-line tests share: a scratch folder per test, running the binary, and
//! paths as arguments.

// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A fresh scratch folder `group/name` for one test.
pub fn scratch(group: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the binary with `args`, feeding `stdin` (if any) to its standard input.
pub fn run(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_truenorth"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the truenorth binary runs");
    let mut pipe = child.stdin.take().unwrap();
    if let Some(bytes) = stdin {
        pipe.write_all(bytes).unwrap();
    }
    drop(pipe);
    child.wait_with_output().unwrap()
}

/// Runs the binary with no input.
pub fn truenorth(args: &[&str]) -> Output {
    run(args, None)
}

/// Runs the binary and asserts that it succeeded, showing the arguments and stderr if not.
pub fn ok(args: &[&str]) -> Output {
    ok_with(args, None)
}

/// [`ok`] with `stdin` on standard input.
pub fn ok_with(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let out = run(args, stdin);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A path as an argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// The BROAD trials, sorted; `None` (skipped) without the shared data.
pub fn broad_trials() -> Option<Vec<PathBuf>> {
    let dir = truenorth_sim::shared_data::folder("broad").unwrap()?;
    let mut trials: Vec<PathBuf> = std::fs::read_dir(dir.join("trials"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    trials.sort();
    assert_eq!(trials.len(), 20);
    Some(trials)
}
