//! `truenorth orientation` streams: the units are checked on the first
//! [`CHECKED_ROWS`] rows, the rows are written as they are estimated, and a recording longer
//! than that is neither held whole nor passed unchecked.

mod common;

use common::{ok, p, scratch, truenorth};
use truenorth_cli::commands::orientation::CHECKED_ROWS;

/// A sensor lying still and level for `rows` rows at 100 Hz (gravity on z, a constant
/// field), with the accelerometer in `acc_scale` times m/s² and a slow yaw rate from row
/// `turn_from` on (so that the gyro has something to do).
fn still(rows: usize, acc_scale: f64, turn_from: usize) -> String {
    let mut s = String::with_capacity(rows * 48);
    s += "t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n";
    for k in 0..rows {
        let r = if k >= turn_from { 0.01 } else { 0.0 };
        s += &format!(
            "{},0,0,{r},0,0,{},20,0,45\n",
            k as f64 * 0.01,
            -9.81 * acc_scale
        );
    }
    s
}

fn lines(path: &std::path::Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn rows_are_written_as_estimated_whatever_follows() {
    let d = scratch("orientation-streaming", "prefix");
    let (whole, part) = (d.join("whole.csv"), d.join("part.csv"));
    std::fs::write(&whole, still(5000, 1.0, 2000)).unwrap();
    std::fs::write(&part, still(1200, 1.0, 2000)).unwrap();
    let (a, b) = (d.join("a.csv"), d.join("b.csv"));
    for (i, o) in [(&whole, &a), (&part, &b)] {
        ok(&["orientation", "--input", p(i), "--output", p(o), "--status"]);
    }
    let (a, b) = (lines(&a), lines(&b));
    assert_eq!(a.len(), 5001);
    // The filter is causal: the rows of the first part are the same, bit for bit.
    assert_eq!(a[..b.len()], b[..]);
}

#[test]
fn a_long_recording_is_checked_on_its_first_part_and_never_passed_silently() {
    // The command's help quotes the figure.
    assert_eq!(CHECKED_ROWS, 131_072);
    let d = scratch("orientation-streaming", "long");
    let rows = CHECKED_ROWS + 2000;
    // Still throughout: no turns near rest to judge the gyro by, so a warning says the
    // units and axes went unchecked.
    let input = d.join("still.csv");
    std::fs::write(&input, still(rows, 1.0, usize::MAX)).unwrap();
    let (out, plot) = (d.join("att.csv"), d.join("att.svg"));
    let o = ok(&[
        "orientation",
        "--input",
        p(&input),
        "--output",
        p(&out),
        "--plot",
        p(&plot),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("the first {CHECKED_ROWS} rows hold too few")),
        "{err}"
    );
    assert_eq!(lines(&out).len(), rows + 1);
    // The plot is drawn from bounded buckets, not every row.
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.len() < 400_000, "{}", svg.len());
    // The same recording in g declared as m/s²: the first part shows the wrong unit, and
    // the run is refused before anything is written.
    let wrong = d.join("in_g.csv");
    std::fs::write(&wrong, still(rows, 1.0 / 9.81, usize::MAX)).unwrap();
    let o = truenorth(&[
        "orientation",
        "--input",
        p(&wrong),
        "--output",
        p(&d.join("wrong.csv")),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--acc-unit g"), "{err}");
    assert!(!d.join("wrong.csv").exists());
}

#[test]
fn a_recording_within_the_checked_part_is_judged_whole_without_a_warning() {
    let d = scratch("orientation-streaming", "short");
    let input = d.join("still.csv");
    std::fs::write(&input, still(3000, 1.0, usize::MAX)).unwrap();
    let o = ok(&[
        "orientation",
        "--input",
        p(&input),
        "--output",
        p(&d.join("att.csv")),
    ]);
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
