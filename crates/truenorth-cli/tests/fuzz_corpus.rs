//! The fuzz targets' saved corpus and crash artefacts, replayed through the same code as the
//! targets (`fuzz/harness/`): what the fuzzer once found stays fixed, and CI checks it
//! without running the fuzzer. Each file must return without a panic.

use std::path::{Path, PathBuf};

#[path = "../../../fuzz/harness/mod.rs"]
mod harness;

/// The `fuzz/` folder at the top of the repository.
fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// The files of `dir`, sorted; none when it does not exist.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.retain(|p| p.is_file());
    v.sort();
    v
}

#[test]
fn every_saved_input_runs_through_its_target_without_a_panic() {
    let mut total = 0;
    for (name, target) in harness::TARGETS {
        let corpus = files(&fuzz_dir().join("corpus").join(name));
        assert!(
            !corpus.is_empty(),
            "fuzz/corpus/{name} holds no input: every target keeps a corpus"
        );
        let artefacts = files(&fuzz_dir().join("artifacts").join(name));
        for path in corpus.iter().chain(&artefacts) {
            // A running fuzzer replaces corpus files as it shortens them: one gone since
            // the listing is skipped (in CI nothing runs beside the test).
            let Ok(data) = std::fs::read(path) else {
                continue;
            };
            let run = std::panic::catch_unwind(|| target(&data));
            assert!(run.is_ok(), "{name} panicked on {}", path.display());
            total += 1;
        }
    }
    println!("{total} saved fuzz inputs replayed");
}

#[test]
fn empty_and_tiny_inputs_run_through_every_target() {
    for (_, target) in harness::TARGETS {
        for data in [&b""[..], b"\0", b"\xff\xff\xff\xff", b"t_s,mag_x\n1,2\n"] {
            target(data);
        }
    }
}

/// The inputs under `fuzz/findings/<target>/` are failures the fuzzer found that the library
/// does not handle yet (each named in fuzz/README.md): replayed by hand until fixed, when
/// they move to `fuzz/artifacts/<target>/` and the test above holds them.
#[test]
#[ignore = "open fuzz findings: run with --ignored to reproduce them"]
fn open_findings_still_fail() {
    for (name, target) in harness::TARGETS {
        for path in files(&fuzz_dir().join("findings").join(name)) {
            let data = std::fs::read(&path).expect("a readable finding");
            let run = std::panic::catch_unwind(|| target(&data));
            assert!(run.is_ok(), "{name} panicked on {}", path.display());
        }
    }
}
