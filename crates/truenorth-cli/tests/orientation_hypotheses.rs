//! `orientation` when no unit fits the physics: a gyro in mrad/s, a time column running at
//! half speed, an accelerometer with gravity removed. None of them is a known mistake the
//! checks name a unit for; each is refused as what it is — the factor by which the gyro's
//! turns miss, or an accelerometer that reads no gravity — and `inspect` says the same.

mod common;

use std::path::{Path, PathBuf};

use common::ScratchDir;

fn dir(tag: &str) -> ScratchDir {
    common::scratch("cli_orientation_hypotheses", tag)
}

/// Two minutes of simulated hand-held motion, every row's cells passed through `change`
/// (with every row's cells as simulated, for a filter).
fn recording(dir: &Path, change: impl Fn(usize, &mut [f64; 10], &[[f64; 10]])) -> PathBuf {
    common::handheld_csv(dir, 120.0, 9, change)
}

/// `orientation` refuses `input` with no output; its message, which `inspect` says too.
fn refused(dir: &Path, input: &Path) -> String {
    let output = dir.join("attitude.csv");
    let run = common::orientation(input, &output, &[]);
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(!output.exists());
    let inspect = common::ok(&["inspect", common::p(input)]);
    let report = String::from_utf8_lossy(&inspect.stdout);
    let line = report
        .lines()
        .find(|l| l.starts_with("found: "))
        .unwrap_or_else(|| panic!("inspect does not say it: {report}"));
    let evidence = line["found: ".len()..].split(';').next().unwrap();
    assert!(stderr.contains(evidence), "{stderr} / {line}");
    stderr
}

#[test]
fn a_gyro_in_mrad_per_s_fits_no_unit() {
    let dir = dir("mrad");
    let input = recording(&dir, |_, c, _| {
        c[1..4].iter_mut().for_each(|g| *g *= 1000.0)
    });
    let says = refused(&dir, &input);
    assert!(
        says.contains("fit no unit") && says.contains("mrad/s"),
        "{says}"
    );
    assert!(says.contains("times 0.00"), "{says}");
    assert!(!says.contains("--gyro-unit"), "{says}");
}

#[test]
fn a_clock_at_half_speed_fits_no_unit() {
    let dir = dir("clock");
    let input = recording(&dir, |_, c, _| c[0] *= 0.5);
    let says = refused(&dir, &input);
    assert!(
        says.contains("fit no unit") && says.contains("t_s is in seconds"),
        "{says}"
    );
}

#[test]
fn an_accelerometer_without_gravity_fits_no_unit() {
    let dir = dir("linear");
    // Each reading less its 2-second mean: what a phone's "linear acceleration" gives.
    let input = recording(&dir, |k, c, acc| {
        let window = &acc[k.saturating_sub(100)..(k + 100).min(acc.len())];
        for i in 0..3 {
            let mean = window.iter().map(|a| a[4 + i]).sum::<f64>() / window.len() as f64;
            c[4 + i] -= mean;
        }
    });
    let says = refused(&dir, &input);
    assert!(says.contains("gravity removed"), "{says}");
    assert!(says.contains("linear acceleration"), "{says}");
}

/// The same recording as published runs (no finding where the physics fits).
#[test]
fn the_recording_as_made_runs() {
    let dir = dir("clean");
    let input = recording(&dir, |_, _, _| {});
    common::succeeded(common::orientation(&input, &dir.join("a.csv"), &[]));
}

/// A real car's IMU (comma2k19): its specific force tilts as it brakes and accelerates while
/// its gyro hardly turns in pitch and roll, so gravity's spans alone turn many times what the
/// gyro integrates. Those spans weigh no factor (the rates predict no turn there): it runs.
#[test]
fn a_cars_imu_is_not_taken_for_a_wrong_scale() {
    let Some(data) = truenorth_sim::shared_data::folder("vehicle_comma2k19_example").unwrap()
    else {
        return;
    };
    let dir = dir("car");
    let columns = "t_s=t_boot_s,acc_x=acc_f_mps2,acc_y=acc_r_mps2,acc_z=acc_d_mps2,gyr_x=gyr_f_rps,gyr_y=gyr_r_rps,gyr_z=gyr_d_rps";
    let input = data.join("imu.csv");
    let output = dir.join("attitude.csv");
    common::succeeded(common::orientation(
        &input,
        &output,
        &["--no-mag", "--column", columns],
    ));
    let inspect = common::ok(&["inspect", common::p(&input), "--column", columns]);
    let report = String::from_utf8_lossy(&inspect.stdout);
    assert!(!report.contains("found: "), "{report}");
}
