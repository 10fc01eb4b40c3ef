//! `--precision`: the numbers of heading's output rounded to N significant digits, each
//! within half a unit of its last digit of the default (shortest round-trip) output.

mod common;

use common::{TURN_HEADER, column};

#[test]
fn heading_precision_rounds_to_significant_digits() {
    let dir = common::scratch("cli_output_precision", "heading");
    let text = common::turn_rows(90, 0.1, 20.0, [4.0, -3.0], 0.0123);
    let (input, cal) = common::ellipse_calibration(&dir, &format!("{TURN_HEADER}{text}"), &[]);
    let run = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        common::succeeded(common::heading(&cal, &input, &out, extra));
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
    // Every column is rounded but the time, which is written exactly (0.1 · 3 =
    // 0.30000000000000004 in the input): rows stay as distinct as the input's.
    assert_eq!(column(&short, 0)[3], column(&full, 0)[3]);
    assert_eq!(column(&short, 0)[3], "0.30000000000000004");
    let bad = common::heading(&cal, &input, &dir.join("x.csv"), &["--precision", "0"]);
    assert_eq!(bad.status.code(), Some(2), "clap refuses a precision of 0");
}

/// Epoch timestamps (1.7·10⁹ s, 10 ms apart) stay distinct at any precision: the time column
/// is written exactly.
#[test]
fn precision_keeps_epoch_timestamps_distinct() {
    let dir = common::scratch("cli_output_precision", "epoch");
    let text = common::turn_rows(200, 0.01, 20.0, [4.0, -3.0], 0.0123);
    let epoch: String = text
        .lines()
        .map(|l| {
            let (t, rest) = l.split_once(',').unwrap();
            format!("{},{rest}\n", 1.7e9 + t.parse::<f64>().unwrap())
        })
        .collect();
    let (input, cal) = common::ellipse_calibration(&dir, &format!("{TURN_HEADER}{epoch}"), &[]);
    let out = dir.join("out.csv");
    common::succeeded(common::heading(&cal, &input, &out, &["--precision", "3"]));
    let text = std::fs::read_to_string(&out).unwrap();
    let times = column(&text, 0);
    let mut distinct = times.clone();
    distinct.dedup();
    assert_eq!(distinct.len(), times.len(), "every row keeps its own time");
}
