//! A small program that depends on the facade alone (`tests/downstream/`) builds and runs:
//! the public API a user sees through `truenorth` is enough for a calibration with its
//! verdict and a one-line swap of orientation estimators.
//!
//! It is built in a temporary copy, against this checkout, offline (the workspace's own
//! build has fetched every crate it needs), with the workspace's lock file so that it uses
//! the same versions, into `target/downstream` so that later runs reuse the build.

use std::path::{Path, PathBuf};
use std::process::Command;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

#[test]
fn a_program_using_the_facade_alone_builds_and_runs() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    // Removed when dropped, also when the test fails.
    let scratch = tempfile::Builder::new()
        .prefix("truenorth-downstream-")
        .tempdir()
        .unwrap();
    let work = scratch.path().join("downstream");
    copy_dir(&root.join("tests/downstream"), &work);
    let manifest = std::fs::read_to_string(work.join("Cargo.toml.in"))
        .unwrap()
        .replace("@TRUENORTH@", &root.display().to_string());
    std::fs::write(work.join("Cargo.toml"), manifest).unwrap();
    std::fs::remove_file(work.join("Cargo.toml.in")).unwrap();
    std::fs::copy(root.join("Cargo.lock"), work.join("Cargo.lock")).unwrap();
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| root.join("target"), PathBuf::from)
        .join("downstream");
    let out = Command::new(env!("CARGO"))
        .args(["run", "--quiet", "--offline", "--manifest-path"])
        .arg(work.join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", &target)
        .output()
        .expect("cargo runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stdout.contains("downstream: ok"),
        "the downstream program failed\n--- stdout\n{stdout}\n--- stderr\n{stderr}"
    );
    println!("{stdout}");
}
