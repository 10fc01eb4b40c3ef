//! `truenorth batch`: the results table and its statuses, the journal that makes a rerun skip
//! what is done and redo what changed, resuming after repeated SIGKILLs, the same table
//! whatever the number of workers, the passthrough command checked, and output names that
//! never collide nor leave the output folder.

mod common;

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use truenorth_cli::commands::batch::output_name;

use common::scratch;

const JOURNAL: &str = ".truenorth-batch-journal.jsonl";

/// A 2-D compass turned through a full circle about an offset centre: `ellipse` fits it.
fn circle(rows: usize, phase: f64) -> String {
    let mut s = String::from("t_s,mag_x,mag_y\n");
    for i in 0..rows {
        let a = std::f64::consts::TAU * i as f64 / rows as f64 + phase;
        let wobble = 0.01 * (7.0 * i as f64).sin();
        s += &format!(
            "{:.2},{:.5},{:.5}\n",
            0.1 * i as f64,
            0.3 + 20.0 * a.cos() + wobble,
            -5.0 + 18.0 * a.sin()
        );
    }
    s
}

/// A quarter-radian arc: too little turn, which `calibrate` refuses.
fn arc() -> String {
    let mut s = String::from("t_s,mag_x,mag_y\n");
    for i in 0..100 {
        let a = 0.5 * i as f64 / 100.0;
        s += &format!(
            "{:.1},{:.4},{:.4}\n",
            0.1 * i as f64,
            20.0 * a.cos(),
            18.0 * a.sin()
        );
    }
    s
}

/// The fleet: three good circles (one in a sub-folder), a refused arc, a corrupt file, an
/// empty file, and a file the extensions leave out.
fn fleet(dir: &Path) {
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("a.csv"), circle(200, 0.0)).unwrap();
    std::fs::write(dir.join("b c.csv"), circle(150, 1.0)).unwrap();
    std::fs::write(dir.join("sub").join("d.csv"), circle(120, 2.0)).unwrap();
    std::fs::write(dir.join("arc.csv"), arc()).unwrap();
    std::fs::write(
        dir.join("corrupt.csv"),
        "t_s,mag_x,mag_y\n0,1,2\n0.1,abc,2\n",
    )
    .unwrap();
    std::fs::write(dir.join("empty.csv"), "").unwrap();
    std::fs::write(dir.join("notes.txt"), "not a recording").unwrap();
}

/// Runs a batch; its exit code and stdout.
fn batch(args: &[&str]) -> (Option<i32>, String, String) {
    let argv: Vec<&str> = std::iter::once("batch")
        .chain(args.iter().copied())
        .collect();
    let out = common::truenorth(&argv);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A CSV line split into cells, quotes undone (RFC 4180).
fn cells(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                cells.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(String::new()),
            c => cells.last_mut().unwrap().push(c),
        }
    }
    cells
}

/// The results table: rows by the input's file name, each a map from column to cell.
fn table(path: &Path) -> BTreeMap<String, BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = cells(lines.next().unwrap());
    let mut rows = BTreeMap::new();
    for line in lines {
        let row: BTreeMap<String, String> = header.iter().cloned().zip(cells(line)).collect();
        let name = Path::new(&row["path"])
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        assert!(rows.insert(name, row).is_none(), "a file twice: {line}");
    }
    rows
}

fn journal_lines(out: &Path) -> usize {
    std::fs::read_to_string(out.join(JOURNAL))
        .unwrap_or_default()
        .lines()
        .count()
}

/// The files the journal names (in lines that parse: a kill may tear the last).
fn journal_names(out: &Path) -> std::collections::BTreeSet<String> {
    let text = std::fs::read_to_string(out.join(JOURNAL)).unwrap_or_default();
    text.lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .map(|v| v["name"].as_str().unwrap().to_string())
        .collect()
}

/// Files under `dir` whose names mark them as temporaries of unfinished outputs.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            found.extend(temporaries(&p));
        } else if p.to_string_lossy().contains(".tmp-") {
            found.push(p);
        }
    }
    found
}

const CALIBRATE: [&str; 4] = ["--", "calibrate", "--method", "ellipse"];

fn args<'a>(head: &[&'a str], tail: &[&'a str]) -> Vec<&'a str> {
    head.iter().chain(tail).copied().collect()
}

#[test]
fn the_table_gives_each_file_its_status_and_a_rerun_runs_only_what_changed() {
    let d = scratch("batch", "statuses");
    let logs = d.join("logs");
    let out = d.join("out");
    fleet(&logs);
    let (l, o) = (logs.to_str().unwrap(), out.to_str().unwrap());
    let (code, stdout, stderr) = batch(&args(
        &[l, "--recursive", "--out", o, "-j", "2"],
        &CALIBRATE,
    ));
    assert_eq!(code, Some(3), "a file failed: {stdout}{stderr}");
    assert!(
        stdout.contains("3 ok, 1 refused, 2 failed, 0 skipped-done"),
        "{stdout}"
    );
    let rows = table(&out.join("results.csv"));
    assert_eq!(rows.len(), 6, "notes.txt is no recording: {rows:?}");
    let status = |n: &str| rows[n]["status"].clone();
    for good in ["a.csv", "b c.csv", "d.csv"] {
        assert_eq!(status(good), "ok", "{:?}", rows[good]);
        assert_eq!(rows[good]["verdict"], "good");
        assert_eq!(rows[good]["exit_code"], "0");
        assert!(Path::new(&rows[good]["output"]).is_file());
        assert_eq!(rows[good]["hash"].len(), 64);
    }
    assert_eq!(rows["a.csv"]["samples"], "200");
    assert_eq!(rows["b c.csv"]["samples"], "150");
    assert_eq!(
        PathBuf::from(&rows["d.csv"]["output"]),
        out.join("sub").join("d.csv.json"),
        "the output mirrors the input's place in its folder"
    );
    assert_eq!(
        PathBuf::from(&rows["b c.csv"]["output"]),
        out.join("b%20c.csv.json")
    );
    assert_eq!(status("arc.csv"), "refused");
    assert!(
        rows["arc.csv"]["message"].contains("cannot calibrate"),
        "{:?}",
        rows["arc.csv"]
    );
    assert_eq!(rows["arc.csv"]["samples"], "100");
    assert_eq!(rows["arc.csv"]["output"], "");
    assert_eq!(status("corrupt.csv"), "failed");
    assert!(
        rows["corrupt.csv"]["message"].contains("row 3"),
        "{:?}",
        rows["corrupt.csv"]
    );
    assert_eq!(rows["corrupt.csv"]["exit_code"], "1");
    assert_eq!(status("empty.csv"), "failed");
    assert!(
        rows["empty.csv"]["message"].contains("empty"),
        "{:?}",
        rows["empty.csv"]
    );
    assert_eq!(journal_lines(&out), 6, "one line per finished file");

    // A rerun runs nothing: every row skipped as done, and no line added to the journal
    // (each run of a command appends one); the two failures still stand, and its exit
    // status says so.
    let before = std::fs::read_to_string(out.join(JOURNAL)).unwrap();
    let (code, stdout, _) = batch(&args(&[l, "--recursive", "--out", o], &CALIBRATE));
    assert_eq!(code, Some(3), "earlier failures still stand: {stdout}");
    assert!(
        stdout.contains("(2 of them failed in an earlier run: --retry-failed runs them again)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("0 ok, 0 refused, 0 failed, 6 skipped-done"),
        "{stdout}"
    );
    assert_eq!(std::fs::read_to_string(out.join(JOURNAL)).unwrap(), before);
    let again = table(&out.join("results.csv"));
    for (name, row) in &again {
        assert_eq!(row["status"], "skipped-done", "{name}");
        assert_eq!(row["outcome"], rows[name]["status"], "{name}");
        assert_eq!(row["hash"], rows[name]["hash"], "{name}");
    }

    // One file changed: only it runs again.
    std::fs::write(logs.join("b c.csv"), circle(160, 0.5)).unwrap();
    let (code, stdout, _) = batch(&args(&[l, "--recursive", "--out", o], &CALIBRATE));
    assert_eq!(code, Some(3), "the earlier failures still stand: {stdout}");
    assert!(
        stdout.contains("1 ok, 0 refused, 0 failed, 5 skipped-done"),
        "{stdout}"
    );
    assert_eq!(journal_lines(&out), 7);
    let changed = table(&out.join("results.csv"));
    assert_eq!(changed["b c.csv"]["status"], "ok");
    assert_eq!(changed["b c.csv"]["samples"], "160");
    assert_ne!(changed["b c.csv"]["hash"], rows["b c.csv"]["hash"]);

    // Another command line is another key: everything runs again.
    let (_, stdout, _) = batch(&[
        l,
        "--recursive",
        "--out",
        o,
        "--",
        "calibrate",
        "--method",
        "ellipse",
        "--accept-poor",
    ]);
    assert!(stdout.contains("0 skipped-done"), "{stdout}");
    // --retry-failed reruns the failures the command reported, and only them.
    let (_, stdout, _) = batch(&args(
        &[l, "--recursive", "--out", o, "--retry-failed"],
        &CALIBRATE,
    ));
    assert!(
        stdout.contains("0 ok, 0 refused, 2 failed, 4 skipped-done"),
        "{stdout}"
    );
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}

#[test]
fn one_worker_and_two_give_the_same_table_apart_from_timings() {
    let d = scratch("batch", "workers");
    let logs = d.join("logs");
    fleet(&logs);
    let l = logs.to_str().unwrap();
    let mut tables = Vec::new();
    for jobs in ["1", "2"] {
        let out = d.join(format!("out{jobs}"));
        let o = out.to_str().unwrap();
        let (code, ..) = batch(&args(
            &[
                l,
                "--out",
                o,
                "--jobs",
                jobs,
                "--results",
                &format!("{o}/r.csv"),
            ],
            &CALIBRATE,
        ));
        assert_eq!(code, Some(3));
        let mut t = table(&out.join("r.csv"));
        for row in t.values_mut() {
            row.remove("seconds");
            let output = row["output"].replace(o, "OUT");
            row.insert("output".into(), output);
        }
        tables.push(t);
    }
    assert_eq!(tables[0], tables[1]);
    // The same rows as JSON.
    let out = d.join("json");
    let o = out.to_str().unwrap();
    batch(&args(
        &[l, "--out", o, "--results", &format!("{o}/r.json")],
        &CALIBRATE,
    ));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("r.json")).unwrap()).unwrap();
    let rows = json.as_array().unwrap();
    assert_eq!(rows.len(), 5);
    assert!(
        rows.iter()
            .any(|r| r["status"] == "refused" && r["exit_code"] == 1)
    );
}

/// The processes whose command line mentions `dir` (the batch and its children).
fn processes_on(dir: &Path) -> Vec<u32> {
    let needle = dir.to_string_lossy().into_owned();
    let mut pids = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        if let Ok(cmd) = std::fs::read(entry.path().join("cmdline"))
            && String::from_utf8_lossy(&cmd).contains(&needle)
        {
            pids.push(pid);
        }
    }
    pids
}

fn sigkill(pid: u32) {
    let _ = Command::new("kill")
        .args(["-KILL", &pid.to_string()])
        .stderr(Stdio::null())
        .status();
}

#[cfg(target_os = "linux")]
#[test]
fn a_batch_killed_again_and_again_resumes_with_every_file_once_and_no_temporaries() {
    let d = scratch("batch", "killed");
    let logs = d.join("logs");
    let out = d.join("out");
    std::fs::create_dir_all(&logs).unwrap();
    let files = 40;
    for k in 0..files {
        std::fs::write(
            logs.join(format!("log{k:02}.csv")),
            circle(400 + k, k as f64),
        )
        .unwrap();
    }
    std::fs::write(logs.join("zz-arc.csv"), arc()).unwrap();
    let (l, o) = (logs.to_str().unwrap(), out.to_str().unwrap());
    let argv = args(&[l, "--out", o, "-j", "2"], &CALIBRATE);
    let mut killed_mid_way = 0;
    for round in 0..5u64 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_truenorth"))
            .arg("batch")
            .args(&argv)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(60 + 70 * round));
        let finished = child.try_wait().unwrap().is_some();
        if round % 2 == 0 {
            // The whole job dies at once (the batch and its running files, as a power cut
            // or an out-of-memory kill would): the files' temporaries stay behind.
            for pid in processes_on(&out) {
                sigkill(pid);
            }
        }
        sigkill(child.id());
        let _ = child.wait();
        killed_mid_way += usize::from(!finished);
        // Files left running by a killed batch finish on their own.
        let t = Instant::now();
        while !processes_on(&out).is_empty() && t.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    assert!(killed_mid_way > 0, "no batch was killed before its end");
    let settled_before = journal_names(&out).len();
    let (code, stdout, stderr) = batch(&argv);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let rows = table(&out.join("results.csv"));
    assert_eq!(rows.len(), files + 1, "every file once: {stdout}");
    for (name, row) in &rows {
        let want = if name.contains("arc") {
            "refused"
        } else {
            "ok"
        };
        assert_eq!(row["outcome"], want, "{name}: {row:?}");
        if row["outcome"] == "ok" {
            assert!(Path::new(&row["output"]).is_file(), "{name}");
        }
    }
    assert!(
        stdout.contains(&format!("{settled_before} skipped-done")),
        "the files the killed batches finished are not run again: {stdout}"
    );
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
    assert_eq!(journal_names(&out).len(), files + 1);
}

#[cfg(target_os = "linux")]
#[test]
fn a_terminate_signal_lets_the_running_files_finish_and_a_rerun_completes() {
    let d = scratch("batch", "sigterm");
    let logs = d.join("logs");
    let out = d.join("out");
    std::fs::create_dir_all(&logs).unwrap();
    for k in 0..80 {
        std::fs::write(logs.join(format!("log{k:02}.csv")), circle(300, k as f64)).unwrap();
    }
    let (l, o) = (logs.to_str().unwrap(), out.to_str().unwrap());
    let argv = args(&[l, "--out", o, "-j", "2"], &CALIBRATE);
    let child = Command::new(env!("CARGO_BIN_EXE_truenorth"))
        .arg("batch")
        .args(&argv)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(60));
    let _ = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let done = child.wait_with_output().unwrap();
    let code = done.status.code();
    if code == Some(0) {
        eprintln!("skipped: the batch finished before the signal came");
        return;
    }
    assert_eq!(
        code,
        Some(128 + 15),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let rows = table(&out.join("results.csv"));
    assert!(
        rows.values().all(|r| r["status"] == "ok"),
        "the running files finished: {rows:?}"
    );
    assert_eq!(journal_lines(&out), rows.len());
    let (code, stdout, _) = batch(&argv);
    assert_eq!(code, Some(0));
    assert!(
        stdout.contains(&format!("{} skipped-done", rows.len())),
        "{stdout}"
    );
    assert_eq!(table(&out.join("results.csv")).len(), 80);
    assert!(temporaries(&out).is_empty());
}

#[test]
fn commands_that_cannot_run_per_file_and_supplied_options_are_refused() {
    let d = scratch("batch", "refused");
    let logs = d.join("logs");
    fleet(&logs);
    let (l, o) = (logs.to_str().unwrap(), d.join("out"));
    let o = o.to_str().unwrap();
    for (tail, says) in [
        (&["--", "field", "--lat", "1"][..], "cannot run per file"),
        (
            &["--", "heading", "--output", "x.csv"][..],
            "drop `--output`",
        ),
        (
            &["--", "calibrate", "--input=a.csv", "--method", "ellipse"][..],
            "drop `--input`",
        ),
        (&["--", "orientation", "--plot", "p.svg"][..], "same file"),
        (&[][..], "after `--`"),
    ] {
        let (code, _, stderr) = batch(&args(&[l, "--out", o], tail));
        assert_eq!(code, Some(1), "{tail:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(says), "{tail:?}: {stderr}");
    }
}

#[test]
fn inspect_reports_are_written_per_file_and_a_list_names_files_anywhere() {
    let d = scratch("batch", "inspect");
    let logs = d.join("logs");
    fleet(&logs);
    let list = d.join("list.txt");
    std::fs::write(
        &list,
        format!(
            "# two files\n{}\n\n{}\n",
            logs.join("a.csv").display(),
            logs.join("arc.csv").display()
        ),
    )
    .unwrap();
    let out = d.join("out");
    let (code, stdout, stderr) = batch(&[
        "--list",
        list.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--",
        "inspect",
        "--json",
    ]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let rows = table(&out.join("results.csv"));
    assert_eq!(rows.len(), 2);
    let report = std::fs::read_to_string(&rows["a.csv"]["output"]).unwrap();
    assert!(
        serde_json::from_str::<serde_json::Value>(&report).is_ok(),
        "{report}"
    );
    assert!(Path::new(&rows["a.csv"]["output"]).starts_with(&out));
}

#[test]
fn real_recordings_run_with_their_verdicts() {
    let Some(dir) = truenorth_sim::shared_data::folder("magcal_sunsided_mpu6050_hmc5883l").unwrap()
    else {
        return;
    };
    let d = scratch("batch", "real");
    let logs = d.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    for name in [
        "full-sphere",
        "roll-and-tilt-at-45-90",
        "pan-along-x-pointing-forward",
    ] {
        std::fs::copy(
            dir.join(name).join("mag.csv.gz"),
            logs.join(format!("{name}.csv.gz")),
        )
        .unwrap();
    }
    // A gzip file cut short, and an empty one.
    let whole = std::fs::read(logs.join("full-sphere.csv.gz")).unwrap();
    std::fs::write(logs.join("cut.csv.gz"), &whole[..whole.len() / 3]).unwrap();
    std::fs::write(logs.join("empty.csv.gz"), b"").unwrap();
    let out = d.join("out");
    let (code, stdout, stderr) = batch(&[
        logs.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--",
        "calibrate",
        "--method",
        "ellipsoid",
        "--column",
        "mag_x=mag_x_gauss,mag_y=mag_y_gauss,mag_z=mag_z_gauss",
    ]);
    assert_eq!(code, Some(3), "{stdout}{stderr}");
    let rows = table(&out.join("results.csv"));
    let status = |n: &str| rows[n]["status"].as_str().to_string();
    assert_eq!(status("full-sphere.csv.gz"), "ok");
    assert_eq!(rows["full-sphere.csv.gz"]["verdict"], "good");
    assert_eq!(rows["full-sphere.csv.gz"]["samples"], "8190");
    assert_eq!(status("roll-and-tilt-at-45-90.csv.gz"), "ok");
    assert_eq!(status("pan-along-x-pointing-forward.csv.gz"), "refused");
    assert_eq!(status("cut.csv.gz"), "failed");
    assert_eq!(status("empty.csv.gz"), "failed");
}

/// A relative or absolute path of 1 to 5 parts drawn from names that include the awkward
/// ones (`.`, `..`, `%`, spaces, a leading dot, non-ASCII).
fn paths() -> impl Strategy<Value = PathBuf> {
    let part = prop_oneof![
        Just(".".to_string()),
        Just("..".to_string()),
        "[a-z%. _é-]{1,4}",
    ];
    (any::<bool>(), prop::collection::vec(part, 1..5)).prop_map(|(absolute, parts)| {
        let mut p = PathBuf::from(if absolute { "/" } else { "" });
        for part in parts {
            p.push(part);
        }
        p
    })
}

/// What a path names as far as its text goes (`.` parts dropped).
fn lexical(p: &Path) -> Vec<Component<'_>> {
    p.components().filter(|c| *c != Component::CurDir).collect()
}

proptest! {
    #[test]
    fn output_names_stay_inside_the_folder_and_never_collide(a in paths(), b in paths()) {
        for p in [&a, &b] {
            let name = output_name(p, "json");
            prop_assert!(!name.as_os_str().is_empty());
            for c in name.components() {
                let Component::Normal(part) = c else {
                    return Err(TestCaseError::fail(format!("{p:?} -> {name:?}: {c:?}")));
                };
                prop_assert!(!part.to_string_lossy().starts_with('.'), "{:?} -> {:?}", p, name);
            }
            let dir = Path::new("/out");
            prop_assert!(dir.join(&name).starts_with(dir));
        }
        if lexical(&a) != lexical(&b) && !lexical(&a).is_empty() && !lexical(&b).is_empty() {
            prop_assert_ne!(output_name(&a, "json"), output_name(&b, "json"));
        }
    }
}

/// Run as a batch's child, a command tells its parent that its error refused the data, in a
/// line of the batch protocol (a corrupt file is no refusal); run by hand, it prints no such
/// line.
#[test]
fn a_child_reports_the_kind_of_its_error() {
    use truenorth_cli::commands::batch::child::{CHILD_ENV, KIND_PREFIX};
    let dir = scratch("batch", "kind");
    std::fs::write(dir.join("arc.csv"), arc()).unwrap();
    std::fs::write(
        dir.join("corrupt.csv"),
        "t_s,mag_x,mag_y\n0,1,2\n0.1,abc,2\n",
    )
    .unwrap();
    let out = dir.join("o.json");
    let stderr = |input: &str, child: bool| {
        let mut c = common::binary();
        c.args(["calibrate", "--method", "ellipse", "--input"])
            .arg(dir.join(input))
            .arg("--output")
            .arg(&out)
            .env_remove(CHILD_ENV);
        if child {
            c.env(CHILD_ENV, "1");
        }
        let o = c.output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{input}");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    assert!(stderr("arc.csv", true).contains(&format!("{KIND_PREFIX}refusal")));
    assert!(!stderr("corrupt.csv", true).contains(&format!("{KIND_PREFIX}refusal")));
    for input in ["arc.csv", "corrupt.csv"] {
        let by_hand = stderr(input, false);
        assert!(!by_hand.contains(KIND_PREFIX), "{by_hand}");
        assert_eq!(by_hand.lines().count(), 1, "{by_hand}");
    }
}
