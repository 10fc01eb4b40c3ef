//! `--precision`: the numbers of heading's output rounded to N significant digits, each
//! within half a unit of its last digit of the default (shortest round-trip) output.

mod common;

use std::f64::consts::TAU;

use common::{ok, p};

fn column(text: &str, k: usize) -> Vec<String> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(k).unwrap().to_string())
        .collect()
}

#[test]
fn heading_precision_rounds_to_significant_digits() {
    let dir = common::scratch("cli_output_precision", "heading");
    let input = dir.join("turn.csv");
    let mut text = String::from("t_s,mag_x,mag_y\n");
    for k in 0..90 {
        let h = TAU * k as f64 / 90.0 + 0.0123;
        text += &format!(
            "{},{},{}\n",
            0.1 * k as f64,
            4.0 + 20.0 * h.cos(),
            -3.0 - 20.0 * h.sin()
        );
    }
    std::fs::write(&input, text).unwrap();
    let cal = dir.join("cal.json");
    ok(&[
        "calibrate",
        "--method",
        "ellipse",
        "--input",
        p(&input),
        "--output",
        p(&cal),
    ]);
    let run = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec![
            "heading",
            "--calibration",
            p(&cal),
            "--input",
            p(&input),
            "--output",
            p(&out),
        ];
        args.extend(extra);
        ok(&args);
        std::fs::read_to_string(&out).unwrap()
    };
    let full = run("full.csv", &[]);
    let short = run("short.csv", &["--precision", "5"]);
    assert_eq!(full.lines().next(), short.lines().next(), "same header");
    for (f, s) in column(&full, 1).iter().zip(column(&short, 1)) {
        let digits = s
            .trim_start_matches(['-', '0', '.'])
            .chars()
            .filter(char::is_ascii_digit)
            .count();
        assert!(digits <= 5, "{s}: at most 5 significant digits");
        let (f, r): (f64, f64) = (f.parse().unwrap(), s.parse().unwrap());
        let half_unit = 0.5 * 10f64.powi(f.abs().log10().floor() as i32 - 4);
        assert!((f - r).abs() <= half_unit * (1.0 + 1e-9), "{f} -> {r}");
    }
    // Every column is rounded, the time too (0.1 · 3 = 0.30000000000000004 in the input).
    assert_eq!(column(&short, 0)[3], "0.3");
    let bad = common::run(
        &[
            "heading",
            "--calibration",
            p(&cal),
            "--input",
            p(&input),
            "--output",
            p(&dir.join("x.csv")),
            "--precision",
            "0",
        ],
        None,
    );
    assert_eq!(bad.status.code(), Some(2), "clap refuses a precision of 0");
}
