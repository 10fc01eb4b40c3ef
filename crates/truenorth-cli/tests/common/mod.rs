//! What the command-line tests share: a scratch folder per test that is removed when the
//! test ends (also when it fails), running the binary, the usual inputs (a level compass
//! turn, a vehicle file, an IMU recording) and reading what the binary wrote.

// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

pub mod tables;

use std::io::Write as _;
use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A scratch folder that removes itself, with everything in it, when dropped: at the end of
/// the test, and also while a failed test unwinds.
pub struct ScratchDir(tempfile::TempDir);

impl Deref for ScratchDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

/// A fresh scratch folder for one test, named `truenorth-group-name-XXXX` inside Cargo's
/// temporary folder for tests; removed when the returned guard is dropped.
pub fn scratch(group: &str, name: &str) -> ScratchDir {
    let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let dir = tempfile::Builder::new()
        .prefix(&format!("truenorth-{group}-{name}-"))
        .tempdir_in(base)
        .expect("a scratch folder in the target folder");
    ScratchDir(dir)
}

/// The binary, to be given arguments.
pub fn binary() -> Command {
    Command::new(env!("CARGO_BIN_EXE_truenorth"))
}

/// Runs the binary with `args`, feeding `stdin` (if any) to its standard input.
pub fn run(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let mut child = binary()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the truenorth binary runs");
    let mut pipe = child.stdin.take().unwrap();
    if let Some(bytes) = stdin {
        pipe.write_all(bytes).unwrap();
    }
    drop(pipe);
    child.wait_with_output().unwrap()
}

/// Runs the binary with no input.
pub fn truenorth(args: &[&str]) -> Output {
    run(args, None)
}

/// Runs the binary and asserts that it succeeded, showing the arguments and stderr if not.
pub fn ok(args: &[&str]) -> Output {
    ok_with(args, None)
}

/// [`ok`] with `stdin` on standard input.
pub fn ok_with(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let out = run(args, stdin);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `out`, asserted to be a success, showing its stderr if not.
pub fn succeeded(out: Output) -> Output {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// (success, stderr) of a finished run.
pub fn outcome(out: &Output) -> (bool, String) {
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A path as an argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// `command leading… --input input --output output extra…`, as arguments.
pub fn command_args<'a>(
    command: &'a str,
    leading: &[&'a str],
    input: &'a Path,
    output: &'a Path,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec![command];
    args.extend_from_slice(leading);
    args.extend(["--input", p(input), "--output", p(output)]);
    args.extend_from_slice(extra);
    args
}

/// Runs `calibrate --method method` on `input`, writing `output`, with `extra` arguments.
pub fn calibrate(method: &str, input: &Path, output: &Path, extra: &[&str]) -> Output {
    truenorth(&command_args(
        "calibrate",
        &["--method", method],
        input,
        output,
        extra,
    ))
}

/// Runs `heading --calibration cal` on `input`, writing `output`, with `extra` arguments.
pub fn heading(cal: &Path, input: &Path, output: &Path, extra: &[&str]) -> Output {
    truenorth(&command_args(
        "heading",
        &["--calibration", p(cal)],
        input,
        output,
        extra,
    ))
}

/// Runs `drive --vehicle vehicle` on `input`, writing `output`, with `extra` arguments.
pub fn drive(vehicle: &Path, input: &Path, output: &Path, extra: &[&str]) -> Output {
    truenorth(&command_args(
        "drive",
        &["--vehicle", p(vehicle)],
        input,
        output,
        extra,
    ))
}

/// Runs `orientation` on `input`, writing `output`, with `extra` arguments.
pub fn orientation(input: &Path, output: &Path, extra: &[&str]) -> Output {
    truenorth(&command_args("orientation", &[], input, output, extra))
}

/// `n` rows `t_s,mag_x,mag_y` (no header) of a level compass turning clockwise through a
/// full circle, one row every `dt_s`: `hard_iron + field·(cos h, −sin h)` at heading
/// `h = 2π·k/n + phase_rad`.
pub fn turn_rows(n: usize, dt_s: f64, field: f64, hard_iron: [f64; 2], phase_rad: f64) -> String {
    (0..n)
        .map(|k| {
            let h = std::f64::consts::TAU * k as f64 / n as f64 + phase_rad;
            format!(
                "{},{},{}\n",
                dt_s * k as f64,
                hard_iron[0] + field * h.cos(),
                hard_iron[1] - field * h.sin()
            )
        })
        .collect()
}

/// The header of [`turn_rows`].
pub const TURN_HEADER: &str = "t_s,mag_x,mag_y\n";

/// Writes `csv` as `dir/turn.csv` and calibrates it with the ellipse fit (and `extra`
/// arguments) into `dir/cal.json`, which must succeed: (turn.csv, cal.json).
pub fn ellipse_calibration(dir: &Path, csv: &str, extra: &[&str]) -> (PathBuf, PathBuf) {
    let input = dir.join("turn.csv");
    std::fs::write(&input, csv).unwrap();
    let cal = dir.join("cal.json");
    succeeded(calibrate("ellipse", &input, &cal, extra));
    (input, cal)
}

/// Writes `dir/vehicle.json`: a vehicle of track `track_m` with odometers on the rear wheels.
pub fn rear_vehicle(dir: &Path, track_m: f64) -> PathBuf {
    vehicle_file(dir, "vehicle.json", track_m, "rear")
}

/// Writes `dir/name`: a vehicle of track `track_m` whose odometer wheels are `wheels`
/// (`rear`, `skid_steer` or `differential`).
pub fn vehicle_file(dir: &Path, name: &str, track_m: f64, wheels: &str) -> PathBuf {
    let vehicle = dir.join(name);
    let json = format!(r#"{{"track_m": {track_m}, "odometer_wheels": "{wheels}"}}"#);
    std::fs::write(&vehicle, json).unwrap();
    vehicle
}

/// A simulated 2 km drive as a log with a compass: `t_s,dist_l_m,dist_r_m,gyr_z,mag_x,mag_y`
/// in `dir/drive.csv`.
pub fn compass_drive_log(dir: &Path) -> PathBuf {
    use truenorth_sim::{DriveSpec, SimulatedDrive};
    let sim = SimulatedDrive::new(DriveSpec {
        length_m: 2000.0,
        ..DriveSpec::new(3)
    })
    .unwrap();
    let mut s = String::from("t_s,dist_l_m,dist_r_m,gyr_z,mag_x,mag_y\n");
    for x in &sim.samples {
        let (w, m) = (x.wheels.unwrap(), x.mag.unwrap());
        let cells = [
            x.t_s,
            w.dist_l_m,
            w.dist_r_m,
            x.gyr_z_rps.unwrap(),
            m.x,
            m.y,
        ];
        s += &csv_line(&cells, ",");
    }
    let log = dir.join("drive.csv");
    std::fs::write(&log, s).unwrap();
    log
}

/// `seconds` of simulated hand-held motion read by a typical consumer IMU (noise seed
/// `seed`), in the contract's columns, written to `dir/imu.csv`: each row's cells passed
/// first through `change` (its index, its cells, every row's cells as simulated).
pub fn handheld_csv(
    dir: &Path,
    seconds: f64,
    seed: u64,
    mut change: impl FnMut(usize, &mut [f64; 10], &[[f64; 10]]),
) -> PathBuf {
    use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};
    let truth = handheld_motion(&HandheldParams {
        duration_s: seconds,
        ..HandheldParams::default()
    })
    .unwrap();
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), seed).unwrap();
    let all: Vec<[f64; 10]> = samples.iter().map(imu_cells).collect();
    let mut csv = format!("{IMU_HEADER}\n");
    for (k, cells) in all.iter().enumerate() {
        let mut cells = *cells;
        change(k, &mut cells, &all);
        csv += &csv_line(&cells, ",");
    }
    let path = dir.join("imu.csv");
    std::fs::write(&path, csv).unwrap();
    path
}

/// The contract's IMU columns.
pub const IMU_HEADER: &str = "t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z";

/// The ten IMU cells of a simulated sample, in [`IMU_HEADER`]'s order (time as sampled).
pub fn imu_cells(s: &truenorth::core::ImuSample) -> [f64; 10] {
    let (g, a, m) = (
        s.gyr_rps.as_xyz().unwrap(),
        s.acc_mps2.as_xyz().unwrap(),
        s.mag.as_xyz().unwrap(),
    );
    [s.t_s, g.x, g.y, g.z, a.x, a.y, a.z, m.x, m.y, m.z]
}

/// Cells joined by `delim`.
pub fn csv_cells(cells: &[f64], delim: &str) -> String {
    cells
        .iter()
        .map(f64::to_string)
        .collect::<Vec<_>>()
        .join(delim)
}

/// Cells joined by `delim`, with a line break.
pub fn csv_line(cells: &[f64], delim: &str) -> String {
    csv_cells(cells, delim) + "\n"
}

/// `bytes` gzip-compressed.
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(bytes).unwrap();
    gz.finish().unwrap()
}

/// Column `k` of a CSV text, header skipped, as text.
pub fn column(text: &str, k: usize) -> Vec<String> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(k).unwrap().to_string())
        .collect()
}

/// Column 1 of a CSV text (heading's `heading_deg`), header skipped, as numbers.
pub fn headings(text: &str) -> Vec<f64> {
    column(text, 1).iter().map(|v| v.parse().unwrap()).collect()
}

/// A CSV output: its header cells and its rows of numbers; with `blanks_are_nan` an empty
/// cell reads as NaN, otherwise every cell must be a number.
pub fn table(path: &Path, blanks_are_nan: bool) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| {
                    if blanks_are_nan && v.is_empty() {
                        f64::NAN
                    } else {
                        v.parse().unwrap()
                    }
                })
                .collect()
        })
        .collect();
    (header, rows)
}

/// A JSON file the binary wrote.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The BROAD trials, sorted; `None` (skipped) without the shared data.
pub fn broad_trials() -> Option<Vec<PathBuf>> {
    let dir = truenorth_sim::shared_data::folder("broad").unwrap()?;
    let mut trials: Vec<PathBuf> = std::fs::read_dir(dir.join("trials"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    trials.sort();
    assert_eq!(trials.len(), 20);
    Some(trials)
}
