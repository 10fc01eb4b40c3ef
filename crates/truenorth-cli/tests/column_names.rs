//! `--column NAME=HEADER` as a careless user gives it: a NAME no command reads is refused
//! with the closest one this command does, one this command does not read is said (both
//! were silently ignored), and a NAME given twice is said, the last being the one used (as a
//! fix appended to the options given).

mod common;

use common::{TURN_HEADER, ellipse_calibration, outcome, scratch, turn_rows};

#[test]
fn a_misspelt_column_name_is_refused_with_the_closest() {
    let dir = scratch("column_names", "misspelt");
    let csv = format!(
        "{TURN_HEADER}{}",
        turn_rows(360, 0.1, 30.0, [5.0, -3.0], 0.0)
    );
    let (input, cal) = ellipse_calibration(&dir, &csv, &[]);
    let (ok, err) = outcome(&common::heading(
        &cal,
        &input,
        &dir.join("h.csv"),
        &["--column", "magx=mag_x"],
    ));
    assert!(!ok, "{err}");
    assert!(
        err.contains("`magx` is not a column this command reads"),
        "{err}"
    );
    assert!(err.contains("did you mean `mag_x`?"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    // A column another command reads (a script's mapping shared by several) is said, and the
    // run goes on.
    let (ok, err) = outcome(&common::heading(
        &cal,
        &input,
        &dir.join("h.csv"),
        &["--column", "mag_z=mz"],
    ));
    assert!(ok, "{err}");
    assert!(err.contains("this command does not read `mag_z`"), "{err}");
}

#[test]
fn a_column_given_twice_is_said_and_the_last_used() {
    let dir = scratch("column_names", "twice");
    let text = format!("t_s,mx,my\n{}", turn_rows(360, 0.1, 30.0, [5.0, -3.0], 0.0));
    let input = dir.join("turn.csv");
    std::fs::write(&input, text).unwrap();
    let cal = dir.join("cal.json");
    let (ok, err) = outcome(&common::calibrate(
        "ellipse",
        &input,
        &cal,
        &["--column", "mag_x=my,mag_y=my", "--column", "mag_x=mx"],
    ));
    assert!(ok, "{err}");
    assert!(
        err.contains("--column gives `mag_x` twice, from `my` and from `mx`: the last is used"),
        "{err}"
    );
}

/// Magnetometer columns given but never used — every cell empty, or one of the three
/// missing — are said: the heading is then relative to the start, which the output's
/// columns do not show.
#[test]
fn magnetometer_columns_that_give_no_reading_are_said() {
    let dir = scratch("column_names", "empty_mag");
    let rows: String = (0..3000)
        .map(|k| {
            let t = k as f64 * 0.01;
            format!("{t},0.001,0.002,{},0.01,0.02,-9.81,,,\n", 0.3 * t.sin())
        })
        .collect();
    let empty = dir.join("empty.csv");
    std::fs::write(
        &empty,
        format!("t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n{rows}"),
    )
    .unwrap();
    let (ok, err) = outcome(&common::orientation(&empty, &dir.join("a.csv"), &[]));
    assert!(ok, "{err}");
    assert!(err.contains("present but empty on every row"), "{err}");
    assert!(err.contains("relative to the start heading"), "{err}");
    let two: String = rows
        .lines()
        .map(|l| format!("{}\n", &l[..l.len() - 1]))
        .collect();
    let partial = dir.join("partial.csv");
    std::fs::write(
        &partial,
        format!("t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y\n{two}"),
    )
    .unwrap();
    let (ok, err) = outcome(&common::orientation(&partial, &dir.join("b.csv"), &[]));
    assert!(ok, "{err}");
    assert!(err.contains("only 2 of mag_x, mag_y, mag_z"), "{err}");
    let (_, err) = outcome(&common::orientation(
        &empty,
        &dir.join("c.csv"),
        &["--no-mag"],
    ));
    assert!(!err.contains("magnetometer"), "{err}");
}
