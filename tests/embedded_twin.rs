//! The host twin of the Cortex-M4F example in `examples/embedded/`: the same computation
//! (`examples/embedded/src/shared_run.rs`, included here, not copied) run on the host, and
//! the test that produced and still checks the recording slice compiled into the example.
//!
//! `.ci/embedded` compares the QEMU run's lines with the lines [`host_twin`] writes to
//! `$TRUENORTH_EMBEDDED_TWIN_OUT`.

#[path = "../examples/embedded/src/shared_run.rs"]
mod shared_run;

use std::io::Read as _;
use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use shared_run::{HEADER_VALUES, SAMPLE_VALUES, TURN_FIELD_UT, TURN_HARD_IRON_UT, UpdateMeter};
use truenorth_calib::{EllipsoidConfig, fit_ellipsoid};
use truenorth_core::angle_diff;

/// The host has no instruction counter: the update just runs.
struct NoMeter;

impl UpdateMeter for NoMeter {
    fn measure<T>(&mut self, update: impl FnOnce() -> T) -> T {
        update()
    }
}

/// The trial the slice is cut from, and where in it: 150 samples (0.5 s) of rest before the
/// movement phase starts, then 450 of motion, 600 in all (21.6 kB as `f32`).
const TRIAL: &str = "01_undisturbed_slow_rotation_A.csv.gz";
const REST_BEFORE_MOTION: usize = 150;
const SLICE_LEN: usize = 600;

/// The recording file compiled into the example.
fn recording_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/embedded/data/broad_01_slice.bin")
}

/// One trial's rows: the 15 numeric columns of BROAD's CSV, in file order
/// (`t_s, gyr ×3, acc ×3, mag ×3, qw, qx, qy, qz, movement`).
fn read_trial(path: &Path) -> Vec<[f64; 15]> {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut text = String::new();
    flate2::read::GzDecoder::new(file)
        .read_to_string(&mut text)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().expect("a header row");
    assert!(
        header.starts_with(
            "t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z,qw,qx,qy,qz,movement"
        ),
        "unexpected BROAD columns: {header}"
    );
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let mut row = [0.0; 15];
            for (v, cell) in row.iter_mut().zip(l.split(',')) {
                *v = cell.trim().parse().unwrap_or(f64::NAN);
            }
            row
        })
        .collect()
}

/// What the example's recording should hold, from the BROAD trial: the slice's samples and
/// a compass calibration fitted (ellipsoid) to every magnetometer reading of the trial.
fn expected_recording(trial: &[[f64; 15]]) -> (Vec<f32>, Vec<f64>) {
    let motion = trial
        .iter()
        .position(|r| r[14] > 0.5)
        .expect("the trial has a movement phase");
    let first = motion - REST_BEFORE_MOTION;
    let mags: Vec<Vector3<f64>> = trial
        .iter()
        .map(|r| Vector3::new(r[7], r[8], r[9]))
        .collect();
    let cal = fit_ellipsoid(&mags, &EllipsoidConfig::default())
        .expect("the trial's magnetometer readings support an ellipsoid fit")
        .params;
    let last = &trial[first + SLICE_LEN - 1];
    let mut header = vec![first as f64];
    header.extend(cal.hard_iron.iter());
    header.extend(cal.soft_iron.transpose().iter()); // row-major
    header.extend(&last[10..14]);
    assert_eq!(header.len(), HEADER_VALUES);
    let mut samples = Vec::with_capacity(SLICE_LEN * SAMPLE_VALUES);
    for r in &trial[first..first + SLICE_LEN] {
        samples.extend(r[1..10].iter().map(|&v| v as f32));
    }
    (samples, header)
}

/// The little-endian `f32`s of a file.
fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The recording in the example is the BROAD slice described at [`TRIAL`], with the
/// calibration the ellipsoid fit gives. With `TRUENORTH_WRITE_EMBEDDED_DATA=1` it (re)writes
/// the file instead. The samples must match to the bit; the calibration, fitted anew by the
/// library, within 1e-5 (relative to the field for the hard iron), far below what moves a
/// heading (1e-5 rad ≈ 0.0006°), so that a change in the fit's last digits does not fail
/// here while a different fit does.
#[test]
fn embedded_data_is_the_broad_slice() {
    let Some(broad) = truenorth_sim::shared_data::folder("broad").unwrap_or_else(|e| panic!("{e}"))
    else {
        return;
    };
    let trial = read_trial(&broad.join("trials").join(TRIAL));
    let (samples, header) = expected_recording(&trial);
    let path = recording_path();
    if std::env::var_os("TRUENORTH_WRITE_EMBEDDED_DATA").is_some() {
        let mut bytes = Vec::new();
        for v in header
            .iter()
            .map(|&v| v as f32)
            .chain(samples.iter().copied())
        {
            bytes.extend(v.to_le_bytes());
        }
        std::fs::write(&path, bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("wrote {}", path.display());
        return;
    }
    let stored = f32s(&std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())));
    assert_eq!(
        stored.len(),
        HEADER_VALUES + samples.len(),
        "recording length"
    );
    let (stored_header, stored_samples) = stored.split_at(HEADER_VALUES);
    assert!(
        stored_samples == samples.as_slice(),
        "the samples differ from the trial's"
    );
    assert_eq!(f64::from(stored_header[0]), header[0], "first sample index");
    let field = 45.0; // µT, a round figure above the field in this recording (about 41 µT)
    for (k, (&s, &e)) in stored_header.iter().zip(&header).enumerate().skip(1) {
        let scale = if k < 4 { field } else { 1.0 };
        assert!(
            (f64::from(s) - e).abs() <= 1e-5 * scale,
            "header value {k}: stored {s}, fitted {e}"
        );
    }
}

/// The output's blocks, one per float type, in order: the float's name (`f32`, `f64`) and
/// the block's lines, its `float ...` line first.
fn blocks(out: &str) -> Vec<(&str, Vec<&str>)> {
    let mut blocks: Vec<(&str, Vec<&str>)> = Vec::new();
    for l in out.lines() {
        if let Some(rest) = l.strip_prefix("float ") {
            let name = rest.split(':').next().expect("split yields a first part");
            blocks.push((name, Vec::new()));
        }
        blocks
            .last_mut()
            .unwrap_or_else(|| panic!("a line before the first `float` line: {l}"))
            .1
            .push(l);
    }
    blocks
}

/// The numbers of the line `name ...` in a block's lines.
fn numbers(lines: &[&str], name: &str) -> Vec<f64> {
    let l = lines
        .iter()
        .find(|l| l.starts_with(&format!("{name} ")))
        .unwrap_or_else(|| panic!("no `{name}` line in:\n{}", lines.join("\n")));
    l.split_whitespace()
        .skip(1)
        .map(|v| v.parse().expect("a number"))
        .collect()
}

/// How far the final attitude of the `f32` run may be from the `f64` run's, degrees.
/// Single precision rounds each operation by up to 2⁻²⁴ ≈ 6·10⁻⁸ relative; one update's
/// rotation and correction, a few roundings deep, move the attitude by a few 10⁻⁷ rad. Summed
/// with the same sign over all 600 updates, with no cancellation and no pull-back by the
/// corrections, that is at most 600 × 4·10⁻⁷ = 2.4·10⁻⁴ rad ≈ 0.014°; 0.02° covers it. A
/// broken `f32` path (a wrong cast, a lost reading) misses by degrees. Over whole BROAD
/// trials the `f32` filter's RMSE stays within 0.0013° of the `f64` one's
/// (`crates/truenorth-fusion/tests/broad_f32.rs`).
const F32_VS_F64_DEG: f64 = 0.02;

/// How far the online ellipse calibrator's hard iron may be from the simulated compass's,
/// relative to the field. The simulated readings carry a second-harmonic wobble of 0.2 % of
/// the field, which the ellipse absorbs partly into its centre (measured 0.18 %); 0.5 % is
/// that wobble's size with room, a wrong centre (axes swapped, a lost reading) misses by
/// tens of percent.
const ELLIPSE_HARD_IRON_REL: f64 = 5e-3;

/// How far the heading through the learned calibration may be from the simulated heading,
/// degrees: the wobble's 0.2 % of the field is 0.11° of heading at most, and the centre's
/// error adds as much again (measured 0.16°); 0.5° leaves room for both.
const ELLIPSE_HEADING_DEG: f64 = 0.5;

/// How far the `f32` calibrator's hard iron may be from the `f64` one's, relative to the
/// field: its sums are single precision (the fit runs in `f64` in both), each off by at
/// most `(n + 4)·2⁻²⁴` of its terms (Higham 2002, §4.2) = 2.2·10⁻⁵ for 360 readings, times
/// the conditioning of the fit, a few units here (`online_precision.rs` in
/// truenorth-calib measures both); 10⁻⁴ holds it (measured 4.5·10⁻⁷).
const ELLIPSE_F32_VS_F64_REL: f64 = 1e-4;

/// The shared computation on the host, in `f32` and then in `f64`: the lines it prints are
/// the lines the QEMU run must print (`.ci/embedded` compares them). Held here, in both
/// blocks: the attitude stays a unit quaternion (within 10⁻¹² for f64, within 10⁻⁶, about
/// 8 ulp, for f32: the filter normalises in its own float), the filter's final yaw is within
/// 5° of the motion-capture reference, and the calibrated compass's tilt-compensated
/// heading within 5° of the filter's yaw (measured 0.04° and 0.10° in f64). 5° is 2.7 times
/// this filter's mean total RMSE on BROAD (1.86°, the README's `broad` figure): a single
/// instant of one trial may exceed the RMSE, a broken run (wrong axes, frame or
/// calibration) misses by tens of degrees. And the two final attitudes agree within
/// [`F32_VS_F64_DEG`].
#[test]
fn host_twin() {
    let mut out = String::new();
    shared_run::run::<f32>(&mut out, &mut NoMeter).unwrap_or_else(|e| panic!("{e}"));
    shared_run::calibrate::<f32>(&mut out, &mut NoMeter).unwrap_or_else(|e| panic!("{e}"));
    shared_run::run::<f64>(&mut out, &mut NoMeter).unwrap_or_else(|e| panic!("{e}"));
    shared_run::calibrate::<f64>(&mut out, &mut NoMeter).unwrap_or_else(|e| panic!("{e}"));
    print!("{out}");
    if let Some(path) = std::env::var_os("TRUENORTH_EMBEDDED_TWIN_OUT") {
        std::fs::write(&path, &out).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    }
    let blocks = blocks(&out);
    let names: Vec<&str> = blocks.iter().map(|b| b.0).collect();
    assert_eq!(names, ["f32", "f64"], "the blocks' floats");
    let diff = |a: f64, b: f64| {
        angle_diff(a.to_radians(), b.to_radians())
            .abs()
            .to_degrees()
    };
    let mut finals = Vec::new();
    let mut hard_irons = Vec::new();
    for (float, lines) in &blocks {
        let hard = numbers(lines, "ellipse_hard_iron_ut");
        let off = ((hard[0] - TURN_HARD_IRON_UT[0]).powi(2)
            + (hard[1] - TURN_HARD_IRON_UT[1]).powi(2))
        .sqrt()
            / TURN_FIELD_UT;
        let heading = numbers(lines, "ellipse_heading_deg");
        assert!(
            off < ELLIPSE_HARD_IRON_REL,
            "{float}: hard iron {hard:?}, {off} of the field off"
        );
        assert!(
            diff(heading[0], heading[1]) < ELLIPSE_HEADING_DEG,
            "{float}: calibrated heading {}° for {}°",
            heading[0],
            heading[1]
        );
        hard_irons.push(hard);
        let q = numbers(lines, "final_q");
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let norm_tol = if *float == "f32" { 1e-6 } else { 1e-12 };
        assert!((norm - 1.0).abs() < norm_tol, "{float}: |q| = {norm}");
        let yaw = numbers(lines, "filter_yaw_pitch_roll_deg")[0];
        let compass = numbers(lines, "compass_heading_deg")[0];
        let reference = numbers(lines, "reference_yaw_deg")[0];
        assert!(
            diff(yaw, reference) < 5.0,
            "{float}: filter {yaw}° vs reference {reference}°"
        );
        assert!(
            diff(compass, yaw) < 5.0,
            "{float}: compass {compass}° vs filter {yaw}°"
        );
        finals.push(UnitQuaternion::from_quaternion(Quaternion::new(
            q[0], q[1], q[2], q[3],
        )));
    }
    let hard_apart = ((hard_irons[0][0] - hard_irons[1][0]).powi(2)
        + (hard_irons[0][1] - hard_irons[1][1]).powi(2))
    .sqrt()
        / TURN_FIELD_UT;
    println!("f32 vs f64 online ellipse hard iron: {hard_apart:e} of the field");
    assert!(
        hard_apart < ELLIPSE_F32_VS_F64_REL,
        "the f32 and f64 hard irons are {hard_apart} of the field apart"
    );
    let apart_deg = finals[0].angle_to(&finals[1]).to_degrees();
    println!("f32 vs f64 final attitude: {apart_deg:e}°");
    assert!(
        apart_deg < F32_VS_F64_DEG,
        "the f32 and f64 final attitudes are {apart_deg}° apart"
    );
}
