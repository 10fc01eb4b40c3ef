//! Real files as users have them: gzip, standard input and output, headers in any case,
//! other delimiters, a column mapping, a sensor mounted with other axes, and the refusals
//! that keep a recording safe (a duplicated column, an output that is an input, a failed
//! run that must leave the old output as it was).

mod common;

use std::f64::consts::TAU;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Stdio;

use common::{gzip, p};

fn scratch(name: &str) -> common::ScratchDir {
    common::scratch("cli_input_files", name)
}

/// The one line on stderr of a run that failed with status 1.
fn failed(out: std::process::Output) -> String {
    assert_eq!(out.status.code(), Some(1), "should fail");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "one line on stderr: {err:?}");
    err
}

/// A level compass turning clockwise through a full circle in a field of 20 with hard
/// iron (4, −3): `(header, rows)` with columns t, x, y.
fn turn(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|k| {
            let h = TAU * k as f64 / n as f64;
            [0.1 * k as f64, 4.0 + 20.0 * h.cos(), -3.0 - 20.0 * h.sin()]
        })
        .collect()
}

fn csv(header: &str, delim: &str, rows: &[[f64; 3]]) -> String {
    let mut s = format!("{header}\n");
    for r in rows {
        s += &format!("{}{delim}{}{delim}{}\n", r[0], r[1], r[2]);
    }
    s
}

fn headings(text: &str) -> Vec<f64> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

/// The same turn as a plain file, a `.gz` file, gzip on standard input, and semicolon
/// separated with headers in capitals: one calibration, the same headings.
#[test]
fn gzip_stdin_case_and_delimiters_read_the_same() {
    let dir = scratch("formats");
    let rows = turn(90);
    let plain = dir.join("turn.csv");
    std::fs::write(&plain, csv("t_s,mag_x,mag_y", ",", &rows)).unwrap();
    let cal = dir.join("cal.json");
    let out = common::succeeded(common::calibrate("ellipse", &plain, &cal, &[]));
    // One summary line on success.
    let summary = String::from_utf8(out.stderr).unwrap();
    assert_eq!(summary.lines().count(), 1, "{summary:?}");
    let reference = common::succeeded(common::heading(&cal, &plain, Path::new("-"), &[]));
    let reference = headings(&String::from_utf8(reference.stdout).unwrap());
    assert_eq!(reference.len(), 90);

    let gz = dir.join("turn.csv.gz");
    std::fs::write(&gz, gzip(csv("t_s,mag_x,mag_y", ",", &rows).as_bytes())).unwrap();
    let semicolons = csv("T_S;MAG_X;Mag_Y", ";", &rows);
    type Case<'a> = (&'a str, Option<Vec<u8>>, &'a [&'a str]);
    let cases: [Case; 3] = [
        (p(&gz), None, &[]),
        (
            "-",
            Some(gzip(csv("t_s,mag_x,mag_y", ",", &rows).as_bytes())),
            &[],
        ),
        ("-", Some(semicolons.into_bytes()), &["--delimiter", ";"]),
    ];
    for (input, stdin, extra) in cases {
        let mut args = vec![
            "heading",
            "--calibration",
            p(&cal),
            "--input",
            input,
            "--output",
            "-",
        ];
        args.extend_from_slice(extra);
        let out = common::ok_with(&args, stdin.as_deref());
        assert_eq!(
            headings(&String::from_utf8(out.stdout).unwrap()),
            reference,
            "{args:?}"
        );
    }
}

/// Columns named otherwise, one negated, and time not given: calibrate reads them through
/// the mapping (the batch fit does not need time).
#[test]
fn column_mapping_negation_and_no_time() {
    let dir = scratch("mapping");
    let rows = turn(120);
    let mut text = String::from("mx,my_inverted,temperature\n");
    for r in &rows {
        text += &format!("{},{},21.5\n", r[1], -r[2]);
    }
    let (input, cal) =
        common::ellipse_calibration(&dir, &text, &["--column", "mag_x=MX,mag_y=-my_inverted"]);
    let json = common::read_json(&cal);
    let hard: Vec<f64> = serde_json::from_value(json["hard_iron"].clone()).unwrap();
    assert!(
        (hard[0] - 4.0).abs() < 1e-6 && (hard[1] + 3.0).abs() < 1e-6,
        "{hard:?}"
    );
    let e = failed(common::calibrate(
        "ellipse",
        &input,
        &cal,
        &["--column", "mag_x=nothing"],
    ));
    assert!(
        e.contains("no column `nothing`") && e.contains("row 1"),
        "{e}"
    );
}

/// A sensor with x forward, y left, z up turning clockwise seen from above: its raw y
/// and z have the opposite sign of frd's. Read with `--axes flu`, the heading rises as in
/// frd; read as frd, it runs backwards.
#[test]
fn axis_convention_turns_a_flu_sensor_into_frd() {
    let dir = scratch("axes");
    let rows = turn(72);
    let mut flu = String::from("t_s,mag_x,mag_y,mag_z\n");
    let mut frd = String::from("t_s,mag_x,mag_y,mag_z\n");
    let (h, v) = (20.0, 40.0);
    for (k, r) in rows.iter().enumerate() {
        let psi = TAU * k as f64 / 72.0;
        let (x, y, z) = (h * psi.cos(), -h * psi.sin(), v);
        frd += &format!("{},{x},{y},{z}\n", r[0]);
        flu += &format!("{},{x},{},{}\n", r[0], -y, -z);
    }
    let (frd_in, flu_in) = (dir.join("frd.csv"), dir.join("flu.csv"));
    std::fs::write(&frd_in, frd).unwrap();
    std::fs::write(&flu_in, flu).unwrap();
    let cal = dir.join("identity.json");
    std::fs::write(
        &cal,
        r#"{"format":"truenorth-compass-calibration","version":1,"method":"hand","dimensions":3,
            "hard_iron":[0,0,0],"soft_iron":[[1,0,0],[0,1,0],[0,0,1]],"field":44.7}"#,
    )
    .unwrap();
    let heading = |input: &Path, axes: &str| {
        let out = common::succeeded(common::heading(
            &cal,
            input,
            Path::new("-"),
            &["--axes", axes],
        ));
        headings(&String::from_utf8(out.stdout).unwrap())
    };
    let reference = heading(&frd_in, "frd");
    assert!((reference[18] - 90.0).abs() < 1e-9, "{}", reference[18]);
    assert_eq!(heading(&flu_in, "flu"), reference);
    let wrong = heading(&flu_in, "frd");
    assert!((wrong[18] - 270.0).abs() < 1e-9, "{}", wrong[18]);
}

/// A header that names a needed column twice is an error, whatever the case.
#[test]
fn duplicate_column_is_an_error() {
    let dir = scratch("duplicate");
    let input = dir.join("dup.csv");
    let mut text = String::from("t_s,mag_x,mag_y,MAG_X\n");
    for r in turn(40) {
        text += &format!("{},{},{},0\n", r[0], r[1], r[2]);
    }
    std::fs::write(&input, text).unwrap();
    let cal = dir.join("cal.json");
    let e = failed(common::calibrate("ellipse", &input, &cal, &[]));
    assert!(
        e.contains("mag_x") && e.contains("2 times") && e.contains("row 1"),
        "{e}"
    );
    assert!(!cal.exists());
}

/// An output that names an input is refused before anything is read or written: the
/// recording and the calibration stay byte for byte.
#[test]
fn output_naming_an_input_is_refused() {
    let dir = scratch("clobber");
    let input = dir.join("turn.csv");
    let text = csv("t_s,mag_x,mag_y", ",", &turn(60));
    std::fs::write(&input, &text).unwrap();
    let cal = dir.join("cal.json");
    common::succeeded(common::calibrate("ellipse", &input, &cal, &[]));
    let cal_text = std::fs::read_to_string(&cal).unwrap();
    let e = failed(common::calibrate("ellipse", &input, &input, &[]));
    assert!(e.contains("would overwrite the input"), "{e}");
    let dotted = dir.join(".").join("cal.json");
    for output in [&input, &dotted] {
        let e = failed(common::heading(&cal, &input, output, &[]));
        assert!(e.contains("would overwrite the input"), "{e}");
    }
    assert_eq!(std::fs::read_to_string(&input).unwrap(), text);
    assert_eq!(std::fs::read_to_string(&cal).unwrap(), cal_text);
}

/// A folder with a calibration (`cal`) of a turn and the heading output (`out`) of that
/// turn: (folder, cal, out).
fn calibrated_with_output(name: &str) -> (common::ScratchDir, PathBuf, PathBuf) {
    let dir = scratch(name);
    let good = dir.join("turn.csv");
    std::fs::write(&good, csv("t_s,mag_x,mag_y", ",", &turn(60))).unwrap();
    let cal = dir.join("cal.json");
    common::succeeded(common::calibrate("ellipse", &good, &cal, &[]));
    let out = dir.join("heading.csv");
    common::succeeded(common::heading(&cal, &good, &out, &[]));
    (dir, cal, out)
}

/// A run that fails half way through the input (a bad row near the end) leaves the
/// existing output as it was, and no temporary file behind.
#[test]
fn a_failed_run_leaves_the_old_output() {
    let (dir, cal, out) = calibrated_with_output("failed_run");
    let before = std::fs::read_to_string(&out).unwrap();
    let bad = dir.join("bad.csv");
    let mut text = csv("t_s,mag_x,mag_y", ",", &turn(60));
    text += "99,oops,1\n";
    std::fs::write(&bad, text).unwrap();
    let e = failed(common::heading(&cal, &bad, &out, &[]));
    assert!(e.contains("row 62") && e.contains("not a number"), "{e}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), before);
    let stray: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}

/// A run killed while it writes (here: stopped half way through a recording streamed on
/// standard input) leaves the existing output exactly as it was: the new one was going to a
/// temporary file beside it.
#[test]
fn a_killed_run_leaves_the_old_output() {
    let (dir, cal, out) = calibrated_with_output("killed_run");
    let before = std::fs::read(&out).unwrap();
    let mut child = common::binary()
        .args([
            "heading",
            "--calibration",
            p(&cal),
            "--input",
            "-",
            "--output",
            p(&out),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // Enough rows to pass the output's buffer, then the stream stalls.
    let mut text = String::from("t_s,mag_x,mag_y\n");
    for k in 0..20_000 {
        text += &format!("{k},{},{}\n", 20.0 + (k % 7) as f64, -3.0 + (k % 5) as f64);
    }
    stdin.write_all(text.as_bytes()).unwrap();
    stdin.flush().unwrap();
    // Wait until the temporary output has data in it, then kill the run.
    let started = std::time::Instant::now();
    let temp_written = || {
        std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                e.file_name().to_string_lossy().contains(".tmp-")
                    && e.metadata().map(|m| m.len() > 0).unwrap_or(false)
            })
    };
    while !temp_written() && started.elapsed().as_secs() < 20 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(temp_written(), "the run was writing its temporary output");
    child.kill().unwrap();
    child.wait().unwrap();
    drop(stdin);
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the old output is untouched"
    );
}

/// Written to standard output, a run that stops at a bad row has written every row before
/// it (the rows are formatted on a writer thread, which gets them all before the run ends),
/// and the error names the row.
#[test]
fn standard_output_carries_every_row_before_an_error() {
    let dir = common::scratch("input_files", "stdout_error");
    let rows = common::turn_rows(10_000, 0.01, 25.0, [3.0, -2.0], 0.0);
    let (_, cal) =
        common::ellipse_calibration(&dir, &(common::TURN_HEADER.to_owned() + &rows), &[]);
    let good = 9_000;
    let mut text = common::TURN_HEADER.to_owned();
    text.extend(rows.lines().take(good).map(|l| format!("{l}\n")));
    text += "1e9,1,x\n";
    let input = dir.join("bad.csv");
    std::fs::write(&input, text).unwrap();
    let out = common::heading(&cal, &input, Path::new("-"), &[]);
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains(&format!("row {}", good + 2)), "{err}");
    assert_eq!(
        headings(&String::from_utf8(out.stdout).unwrap()).len(),
        good
    );
}
