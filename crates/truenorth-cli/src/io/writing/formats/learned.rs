//! The file of what a drive learned about its sensors (`truenorth drive --calibration-out`,
//! read back by `--calibration-in`): the estimator's learned state behind a format tag and
//! a layout version, checked with the same rules as a compass calibration file.

use std::path::Path;

use truenorth::checks::compass::check_compass;
use truenorth::core::Validate;
use truenorth::fusion::vehicle::VehicleCalibration;

use super::json::{parse_json_strict, parse_value, read_json_text, version_of};
use crate::io::writing::atomic_write::write_atomically;
use crate::io::{CliError, CliResult};

/// The `format` tag of a learned-state file.
pub const LEARNED_FORMAT: &str = "truenorth-drive-calibration";

/// The layout version written: 2 adds the `format` tag and this version to the estimator's
/// state, which version 1 files (written before files were versioned) hold alone.
pub const LEARNED_VERSION: u32 = 2;

/// The layout versions this build reads.
const READABLE: [u32; 2] = [1, LEARNED_VERSION];

/// Writes `learned` with its format tag and version (whole or not at all).
pub fn write_learned(path: &Path, learned: &VehicleCalibration) -> CliResult {
    let encode = |e: serde_json::Error| {
        CliError::file(path, format!("cannot encode the drive calibration: {e}"))
    };
    let mut map = serde_json::Map::new();
    map.insert("format".into(), LEARNED_FORMAT.into());
    map.insert("version".into(), LEARNED_VERSION.into());
    if let serde_json::Value::Object(state) = serde_json::to_value(learned).map_err(encode)? {
        map.extend(state);
    }
    let json = serde_json::to_string_pretty(&serde_json::Value::Object(map)).map_err(encode)?;
    write_atomically(path, |w| Ok(w.write_all((json + "\n").as_bytes())?))
}

/// Reads and checks a learned-state file: a byte-order mark skipped, the format and
/// version checked (a file with neither is a version-1 file), no unknown key at any depth
/// (the library's types inside, such as the compass's quality report, ignore unknown keys
/// for their other readers; this file is the CLI's own, and a misspelt key in it would
/// silently drop what was learned), and the values against physics (`check_learned`).
pub fn read_learned(path: &Path) -> CliResult<VehicleCalibration> {
    let (text, name) = read_json_text(path)?;
    let what = "not a drive calibration (write one with `truenorth drive --calibration-out`)";
    let fail = |m: String| CliError::file(&name, m);
    let mut value = parse_value(&text, what).map_err(fail)?;
    let version = version_of(&value, &READABLE, "drive calibration").map_err(fail)?;
    let serde_json::Value::Object(map) = &mut value else {
        return Err(fail(format!("{what}: the file must hold one JSON object")));
    };
    let format = map.remove("format");
    map.remove("version");
    match (&format, version) {
        (Some(f), _) if f.as_str() != Some(LEARNED_FORMAT) => {
            return Err(fail(format!(
                "`format` is {f}, expected \"{LEARNED_FORMAT}\""
            )));
        }
        (Some(_), None) => {
            return Err(fail(format!(
                "it has no `version` (a file with `format` carries one; this build reads versions {READABLE:?})"
            )));
        }
        _ => {}
    }
    let learned: VehicleCalibration = parse_json_strict(value, what).map_err(fail)?;
    check_learned(&learned).map_err(fail)?;
    Ok(learned)
}

/// The checks of a learned state, wherever one is read: the estimator's own (every value
/// finite, gains and scales within their physical ranges) and the compass part's as for a
/// calibration file.
pub fn check_learned(learned: &VehicleCalibration) -> Result<(), String> {
    learned.validate().map_err(|e| e.to_string())?;
    if let Some(c) = &learned.compass {
        let s = c.calibration.soft_iron;
        let hard: Vec<f64> = c.calibration.hard_iron.iter().copied().collect();
        check_compass(
            &hard,
            s.determinant(),
            s.singular_values().as_slice(),
            c.quality.field_magnitude,
        )
        .map_err(|m| format!("the learned compass: {m}"))?;
    }
    Ok(())
}
