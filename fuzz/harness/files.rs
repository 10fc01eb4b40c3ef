//! The CLI's file readers over arbitrary bytes: the CSV reader, the calibration, vehicle and
//! learned-state JSON, each followed by what the commands do with what they read.

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use truenorth::core::MagneticHeading;
use truenorth::fusion::vehicle::VehicleCalibration;
use truenorth::fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth::nalgebra::{Vector2, Vector3};
use truenorth_cli::io::{
    CalibrationFile, InputOptions, InputPath, ReadSpec, RowReader, Table, VehicleFile,
};
use truenorth_cli::registry::{VehicleMethod, VehicleRun};

use super::input::Bytes;

/// A file holding `bytes`, removed when dropped (the readers take paths, as the commands do).
struct TempFile(PathBuf);

impl TempFile {
    fn new(bytes: &[u8], ext: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("truenorth-fuzz-{}-{n}.{ext}", std::process::id()));
        std::fs::write(&path, bytes).expect("the temporary directory is writable");
        Self(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// The column names a request picks from.
const NAMES: [&str; 12] = [
    "t_s", "mag_x", "mag_y", "mag_z", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z",
    "dist_l_m", "dist_r_m",
];

/// The CSV reader (streaming and whole-table) over arbitrary bytes and an arbitrary request:
/// the first bytes choose the delimiter, the header mode, the required and optional columns,
/// a mapping and the increasing column; the rest is the file.
pub fn csv_reader(data: &[u8]) {
    let mut b = Bytes::new(data);
    let flags = b.byte();
    let required_mask = b.u16();
    let optional_mask = b.u16();
    let mapping = b.byte();
    let delimiter = ["auto", ",", ";", "tab", "whitespace", "|"][usize::from(flags % 6)];
    let axes = ["frd", "flu", "rfu", "frd"][usize::from((flags >> 3) % 4)];
    let mut opts = InputOptions {
        delimiter: delimiter.parse().expect("a listed delimiter"),
        no_header: flags & 0x20 != 0,
        axes: axes.parse().expect("a listed convention"),
        ..InputOptions::default()
    };
    if mapping & 1 != 0 {
        let name = NAMES[usize::from(mapping >> 1) % NAMES.len()];
        let header = if opts.no_header { "2" } else { "-X" };
        if let Ok(m) = format!("{name}={header}").parse() {
            opts.columns.push(m);
        }
    }
    let pick = |mask: u16| -> Vec<&str> {
        NAMES
            .iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, n)| *n)
            .collect()
    };
    let required = pick(required_mask);
    let optional: Vec<&str> = pick(optional_mask & !required_mask);
    let mut spec = ReadSpec::new(&required).optional(&optional);
    if flags & 0x40 != 0 {
        spec = spec.increasing("t_s");
    }
    let file = TempFile::new(b.rest(), if flags & 0x80 != 0 { "csv.gz" } else { "csv" });
    let input = InputPath::new(&file.0);
    if let Ok(mut reader) = RowReader::open(&input, &opts, &spec) {
        let width = reader.names().count();
        while let Ok(Some(row)) = reader.next_row() {
            assert_eq!(
                row.values.len(),
                width,
                "a row has one value per column read"
            );
        }
    }
    if let Ok(table) = Table::read_with(&input, &opts, &spec) {
        let _ = table.require_rows();
        let _ = table.check_increasing_time();
        for name in required.iter().chain(&optional) {
            if let Some(col) = table.col(name) {
                assert_eq!(col.len(), table.len());
            }
        }
    }
}

/// A calibration file read as `heading` and `drive` read it, then applied as `heading`
/// applies it: the bytes up to the first NUL are the file, the rest the readings.
pub fn calibration_json(data: &[u8]) {
    let split = data.iter().position(|&c| c == 0).unwrap_or(data.len());
    let file = TempFile::new(&data[..split], "json");
    let Ok((_, cal)) = CalibrationFile::read(&file.0) else {
        return;
    };
    let mut b = Bytes::new(data.get(split + 1..).unwrap_or_default());
    while !b.is_empty() {
        let mag = Vector3::new(b.f64(50.0), b.f64(50.0), b.f64(50.0));
        let acc = (b.byte() & 1 != 0).then(|| Vector3::new(b.f64(10.0), b.f64(10.0), b.f64(10.0)));
        let _: Option<MagneticHeading> = cal.heading(&mag, acc.as_ref()).ok().map(|(h, _)| h);
    }
}

/// A vehicle file read as `drive` reads it, and every vehicle method built from it.
pub fn vehicle_json(data: &[u8]) {
    let file = TempFile::new(data, "json");
    let Ok(vehicle) = VehicleFile::read(&file.0) else {
        return;
    };
    let Ok(wheels) = vehicle.wheels(&file.0) else {
        return;
    };
    let mut priors = SensorPriors::for_wheels(&wheels);
    if let Some(r) = vehicle.wheel_resolution_m {
        priors.wheel_resolution_m = r;
    }
    let config = VehicleConfig {
        wheels,
        priors: Some(priors),
        ..VehicleConfig::default()
    };
    let Ok(fused) = VehicleEstimator::new(config) else {
        return;
    };
    for method in [
        VehicleMethod::Fused,
        VehicleMethod::SeedOdometerCompass,
        VehicleMethod::SeedGyroCompass,
    ] {
        if let Ok(mut run) = method.runner(wheels, fused.clone(), false) {
            let s = truenorth::core::VehicleSample::at(0.0).with_wheels(0.0, 0.0);
            let _ = run.push(&s, &mut |_, _| {});
            let _ = run.push(&s.with_gyro(0.0), &mut |_, _| {});
            let _ = run.finish(&mut |_, _| {});
        }
    }
}

/// The learned state of `drive` (`--calibration-in`) read as `drive` reads it, then a
/// short drive continued from it.
pub fn drive_state_json(data: &[u8]) {
    let Ok(learned) = serde_json::from_slice::<VehicleCalibration>(data) else {
        return;
    };
    let Ok(mut est) = VehicleEstimator::with_calibration(VehicleConfig::default(), &learned) else {
        return;
    };
    let mut run: &mut dyn VehicleRun = &mut est;
    for k in 0..50 {
        let t = f64::from(k) * 0.1;
        let s = truenorth::core::VehicleSample::at(t)
            .with_wheels(t, t * 1.01)
            .with_gyro(0.01)
            .with_mag(Vector2::new(20.0, -5.0));
        let _ = run.push(&s, &mut |_, _| {});
    }
    let _ = run.calibration();
    run = &mut est;
    let _ = run.finish(&mut |_, _| {});
}
