//! Hostile and careless CSV input: each case ends in one clear line on stderr naming the
//! file, the row where there is one, and the problem, with exit status 1, never a panic or
//! an abort; the harmless variants (byte-order mark, CRLF, quotes, a last line without a
//! line break, a FIFO) are read as the plain file is.

mod common;

use std::path::{Path, PathBuf};

use common::{ScratchDir, TURN_HEADER, p, run};

fn scratch(name: &str) -> ScratchDir {
    common::scratch("cli_hostile_input", name)
}

/// A level compass turning through a full circle: `t_s,mag_x,mag_y` rows.
fn turn_rows(n: usize) -> String {
    common::turn_rows(n, 0.1, 20.0, [4.0, -3.0], 0.0)
}

/// A 2-D calibration in `dir`, fitted to a clean turn.
fn calibration(dir: &Path) -> PathBuf {
    common::ellipse_calibration(dir, &format!("{TURN_HEADER}{}", turn_rows(72)), &[]).1
}

/// Runs `heading` on `input`; the output file is in the same folder.
fn heading(dir: &Path, cal: &Path, input: &str) -> std::process::Output {
    common::heading(cal, Path::new(input), &dir.join("out.csv"), &[])
}

/// Asserts one line on stderr, exit status 1, the file named, and every part in `expect`.
fn refused(out: &std::process::Output, file: &str, expect: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "exit status, stderr {err:?}");
    assert_eq!(err.lines().count(), 1, "one line: {err:?}");
    assert!(err.len() < 400, "a short line: {} bytes", err.len());
    assert!(err.contains(file), "names {file}: {err}");
    for e in expect {
        assert!(err.contains(e), "says `{e}`: {err}");
    }
    err
}

/// The headings a successful run wrote.
fn headings(dir: &Path) -> Vec<f64> {
    common::headings(&std::fs::read_to_string(dir.join("out.csv")).unwrap())
}

/// Each malformed file: its bytes and what the one line must say.
#[test]
fn malformed_files_get_one_line_naming_the_row() {
    let dir = scratch("malformed");
    let cal = calibration(&dir);
    let good = turn_rows(4);
    let cases: Vec<(&str, Vec<u8>, Vec<&str>)> = vec![
        ("empty", vec![], vec!["row 1", "empty file"]),
        (
            "comments_only",
            b"# nothing\n\n".to_vec(),
            vec!["empty file"],
        ),
        (
            "header_only",
            b"t_s,mag_x,mag_y\n".to_vec(),
            vec!["row 2", "no data rows"],
        ),
        (
            "missing",
            b"t_s,mag_x\n0,1\n".to_vec(),
            vec!["row 1", "missing column `mag_y`"],
        ),
        (
            "misspelled",
            b"t_s,mag_x,mag_yy\n0,1,2\n".to_vec(),
            vec!["row 1", "mag_y"],
        ),
        (
            "duplicated",
            b"t_s,mag_x,mag_y,MAG_Y\n0,1,2,3\n".to_vec(),
            vec!["row 1", "2 times"],
        ),
        (
            "text",
            b"t_s,mag_x,mag_y\n0,1,2\n1,abc,2\n".to_vec(),
            vec!["row 3", "`abc` is not a number"],
        ),
        (
            "nan",
            b"t_s,mag_x,mag_y\n0,NaN,2\n".to_vec(),
            vec!["row 2", "not finite"],
        ),
        (
            "inf",
            b"t_s,mag_x,mag_y\n0,1,-inf\n".to_vec(),
            vec!["row 2", "not finite"],
        ),
        (
            "overflow",
            b"t_s,mag_x,mag_y\n0,1e309,2\n".to_vec(),
            vec!["row 2", "not finite"],
        ),
        (
            "huge",
            b"t_s,mag_x,mag_y\n0,1,2\n0.1,1e308,2\n".to_vec(),
            vec!["row 3", "`1e308` is beyond ±2^53"],
        ),
        (
            "decimal_comma",
            b"t_s,mag_x,mag_y\n0,1.5,2\n1,1,5,2\n".to_vec(),
            vec!["row 3", "has 4 fields, the header 3", "decimal comma"],
        ),
        (
            "truncated",
            format!("t_s,mag_x,mag_y\n{good}9.9,1.2").into_bytes(),
            vec!["row 6", "truncated"],
        ),
        (
            "duplicated_time",
            b"t_s,mag_x,mag_y\n0,1,2\n0,1,2\n".to_vec(),
            vec!["row 3", "does not come after"],
        ),
        (
            "decreasing_time",
            b"t_s,mag_x,mag_y\n1,1,2\n0.5,1,2\n".to_vec(),
            vec!["row 3", "does not come after"],
        ),
        (
            "garbage",
            (0..2000u32).map(|k| (k * 7919 % 251) as u8).collect(),
            vec!["row"],
        ),
        (
            "short_row",
            b"t_s,mag_x,mag_y\n0,1\n".to_vec(),
            vec!["row 2", "no value for `mag_y`"],
        ),
    ];
    for (name, bytes, expect) in cases {
        let f = dir.join(format!("{name}.csv"));
        std::fs::write(&f, &bytes).unwrap();
        let out = heading(&dir, &cal, p(&f));
        refused(&out, &format!("{name}.csv"), &expect);
        // calibrate reads through the same reader, and says the same.
        let c = common::calibrate("ellipse", &f, &dir.join("c.json"), &[]);
        refused(&c, &format!("{name}.csv"), &expect);
    }
}

/// A byte-order mark, CRLF line ends, quoted fields and a complete last line without a line
/// break read as the plain file does.
#[test]
fn harmless_variants_read_as_the_plain_file() {
    let dir = scratch("harmless");
    let cal = calibration(&dir);
    let rows = turn_rows(36);
    let plain = format!("{TURN_HEADER}{rows}");
    let f = dir.join("plain.csv");
    std::fs::write(&f, &plain).unwrap();
    common::succeeded(heading(&dir, &cal, p(&f)));
    let expected = headings(&dir);
    let quoted: String = rows
        .lines()
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            format!("\"{}\", \"{}\" ,{}\n", v[0], v[1], v[2])
        })
        .collect();
    let variants = [
        ("bom", format!("\u{feff}{plain}")),
        ("crlf", plain.replace('\n', "\r\n")),
        ("quoted", format!("\"t_s\",\"mag_x\",\"mag_y\"\n{quoted}")),
        ("no_final_newline", plain.trim_end().to_string()),
    ];
    for (name, text) in variants {
        let f = dir.join(format!("{name}.csv"));
        std::fs::write(&f, text).unwrap();
        let out = heading(&dir, &cal, p(&f));
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(headings(&dir), expected, "{name}");
    }
}

/// A line past the limit, a file that never ends a line, a directory and `/dev/zero`: one
/// line each, for every command that reads a CSV, with no allocation abort and no echo of
/// the huge cell.
#[test]
fn endless_lines_directories_and_devices_are_refused() {
    let dir = scratch("endless");
    let cal = calibration(&dir);
    let long = dir.join("long.csv");
    let mut text = b"t_s,mag_x,mag_y\n0,1,2\n1,".to_vec();
    text.extend(std::iter::repeat_n(b'9', 200_000));
    text.extend(b",2\n");
    std::fs::write(&long, &text).unwrap();
    refused(
        &heading(&dir, &cal, p(&long)),
        "long.csv",
        &["row 3", "longer than 64 KiB"],
    );
    // A cell under the limit but far too long to echo: cut, with its length.
    let wide = dir.join("wide.csv");
    let mut text = b"t_s,mag_x,mag_y\n0,".to_vec();
    text.extend(std::iter::repeat_n(b'x', 60_000));
    text.extend(b",2\n");
    std::fs::write(&wide, &text).unwrap();
    refused(
        &heading(&dir, &cal, p(&wide)),
        "wide.csv",
        &["row 2", "60000 bytes"],
    );
    refused(
        &heading(&dir, &cal, p(&dir)),
        "endless",
        &["Is a directory"],
    );
    let vehicle = dir.join("vehicle.json");
    std::fs::write(&vehicle, r#"{"track_m": 1.55, "odometer_wheels": "rear"}"#).unwrap();
    let out = p(&dir).to_string() + "/o.csv";
    let o2 = p(&dir).to_string() + "/o.json";
    let commands: Vec<Vec<&str>> = vec![
        vec!["heading", "--calibration", p(&cal), "--output", &out],
        vec!["calibrate", "--method", "online-ellipse", "--output", &o2],
        vec!["orientation", "--output", &out],
        vec!["drive", "--vehicle", p(&vehicle), "--output", &out],
    ];
    for c in commands {
        // orientation and drive refuse long.csv earlier, for its columns.
        let inputs = if matches!(c[0], "orientation" | "drive") {
            vec!["/dev/zero"]
        } else {
            vec!["/dev/zero", p(&long)]
        };
        for input in inputs {
            let mut args = c.clone();
            args.extend(["--input", input]);
            let o = run(&args, None);
            let err = refused(&o, input, &["row", "longer than 64 KiB"]);
            assert!(
                !err.contains("panicked") && !err.contains("memory allocation"),
                "{err}"
            );
        }
    }
}

/// A FIFO streams like a file.
#[cfg(unix)]
#[test]
fn a_fifo_is_read_as_a_stream() {
    let dir = scratch("fifo");
    let cal = calibration(&dir);
    let fifo = dir.join("in.fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("SKIPPED: mkfifo is not available");
        return;
    }
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            std::fs::write(&fifo, format!("{TURN_HEADER}{}", turn_rows(36))).unwrap();
        })
    };
    let out = heading(&dir, &cal, p(&fifo));
    writer.join().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(headings(&dir).len(), 36);
}
