//! `truenorth batch` arguments that would run nothing and say nothing, or lose a file:
//! refused before anything runs; inputs it cannot read, or its own outputs, left out with
//! a word.

mod common;

use common::p;

/// `--ext ""` (or an empty ending in a list) matches no file: the batch would run nothing
/// and exit 0. It is refused, saying what to give, and creates no output folder.
#[test]
fn an_empty_extension_is_refused() {
    let dir = common::scratch("batch_arguments", "ext");
    std::fs::write(dir.join("a.csv"), "t_s,mag_x,mag_y\n0,1,2\n").unwrap();
    let out = dir.join("out");
    for ext in ["", "csv,", "."] {
        let o = common::truenorth(&[
            "batch",
            p(&dir),
            "--ext",
            ext,
            "--out",
            p(&out),
            "--",
            "inspect",
        ]);
        let (ok, stderr) = common::outcome(&o);
        assert!(!ok, "--ext {ext:?} ran");
        assert!(stderr.contains("empty extension"), "{stderr}");
        assert!(!out.exists(), "nothing created");
    }
}

/// A folder of two inspectable files.
fn inputs(dir: &std::path::Path) -> std::path::PathBuf {
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    for name in ["a.csv", "b.csv"] {
        std::fs::write(logs.join(name), "t_s,mag_x,mag_y\n0,1,2\n0.1,2,1\n").unwrap();
    }
    logs
}

/// `--results` naming an input, or the journal, is refused before anything runs: the input
/// is left as it was, and the journal too.
#[test]
fn a_results_table_naming_an_input_or_the_journal_is_refused() {
    let dir = common::scratch("batch_arguments", "results");
    let logs = inputs(&dir);
    let out = dir.join("out");
    let a = logs.join("a.csv");
    let before = std::fs::read(&a).unwrap();
    let journal = out.join(".truenorth-batch-journal.jsonl");
    for (results, why) in [(&a, "names the input"), (&journal, "journal")] {
        let o = common::truenorth(&[
            "batch",
            p(&logs),
            "--out",
            p(&out),
            "--results",
            p(results),
            "--",
            "inspect",
        ]);
        let (ok, stderr) = common::outcome(&o);
        assert!(!ok && stderr.contains(why), "{stderr}");
        assert_eq!(std::fs::read(&a).unwrap(), before, "the input is untouched");
    }
}

/// A FIFO among the inputs is left out with its reason (opening it would block a worker for
/// good); with `--out` inside the input folder, a rerun does not take the batch's own
/// outputs and results table for inputs.
#[test]
fn a_fifo_and_the_batch_s_own_outputs_are_not_read() {
    let dir = common::scratch("batch_arguments", "fifo");
    let logs = inputs(&dir);
    let fifo = logs.join("pipe.csv");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let out = logs.join("out");
    let run = || {
        common::truenorth(&[
            "batch",
            p(&logs),
            "--recursive",
            "--out",
            p(&out),
            "--",
            "inspect",
        ])
    };
    let o = run();
    let (ok, stderr) = common::outcome(&o);
    assert!(ok, "{stderr}");
    if made.is_ok_and(|s| s.success()) {
        assert!(stderr.contains("pipe.csv: not a regular file"), "{stderr}");
    }
    let o = run();
    let (ok, stderr) = common::outcome(&o);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("this batch's own outputs"), "{stderr}");
    assert!(stdout.contains("2 skipped-done"), "{stdout}");
}
