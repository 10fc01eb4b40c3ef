//! Reading the JSON files the tools take (a compass calibration, a vehicle, a drive's
//! learned state) the same way: a byte-order mark is skipped as in a CSV, an unknown key is
//! named with the closest known one, and the layout version is checked with one rule.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use super::source::InputPath;
use super::{CliError, CliResult};

/// The UTF-8 byte-order mark some editors put at the start of a file.
const BOM: char = '\u{feff}';

/// The text of a JSON input (`-`: standard input, gzip or not) without a byte-order mark,
/// and the name to use for it in messages.
pub fn read_json_text(path: &Path) -> CliResult<(String, PathBuf)> {
    let input = InputPath::new(path);
    let name = input.display_path();
    let mut text = String::new();
    std::io::Read::read_to_string(&mut input.open()?, &mut text)
        .map_err(|e| CliError::file(&name, format!("cannot read: {e}")))?;
    let text = match text.strip_prefix(BOM) {
        Some(rest) => rest.to_string(),
        None => text,
    };
    Ok((text, name))
}

/// Parses `value` as `T`; a failure is one line that starts with `what` and, for an unknown
/// key, names the known key closest to it.
pub fn parse_json<T: DeserializeOwned>(value: serde_json::Value, what: &str) -> Result<T, String> {
    serde_json::from_value(value).map_err(|e| format!("{what}: {}", explain(&e.to_string())))
}

/// Parses the text into a JSON value (a syntax error says where).
pub fn parse_value(text: &str, what: &str) -> Result<serde_json::Value, String> {
    serde_json::from_str(text).map_err(|e| format!("{what}: {e}"))
}

/// serde's message, with the closest known key after an unknown one.
fn explain(message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_string();
    };
    let Some((key, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    let known: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    match closest(key, &known) {
        Some(k) => format!(
            "unknown key `{key}` (did you mean `{k}`?); the keys are {}",
            {
                let quoted: Vec<String> = known.iter().map(|k| format!("`{k}`")).collect();
                quoted.join(", ")
            }
        ),
        None => message.to_string(),
    }
}

/// The entry of `known` nearest to `key` in edit distance (case ignored).
pub fn closest<'a>(key: &str, known: &[&'a str]) -> Option<&'a str> {
    let key = key.to_ascii_lowercase();
    known
        .iter()
        .map(|k| (edit_distance(&key, &k.to_ascii_lowercase()), *k))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

/// Levenshtein distance between two strings, by characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

/// The `version` key of a JSON object, checked: `None` when the file has
/// none (a layout from before versions, which the caller may accept), an error naming the
/// versions this build reads when it is not a whole number or is not one of `readable`.
pub fn version_of(
    value: &serde_json::Value,
    readable: &[u32],
    kind: &str,
) -> Result<Option<u32>, String> {
    let serde_json::Value::Object(map) = value else {
        return Err(format!("not a {kind}: the file must hold one JSON object"));
    };
    let Some(v) = map.get("version") else {
        return Ok(None);
    };
    let newest = readable.iter().copied().max().unwrap_or(0);
    let version = v
        .as_u64()
        .and_then(|v| u32::try_from(v).ok())
        .filter(|v| *v > 0)
        .ok_or_else(|| {
            format!("`version` is {v}, must be a layout version (this build reads {readable:?})")
        })?;
    if version > newest {
        return Err(format!(
            "{kind} layout version {version} is newer than this build reads (versions {readable:?}): it was written by a later truenorth; use that one or write the file again with this one"
        ));
    }
    if !readable.contains(&version) {
        return Err(format!(
            "{kind} layout version {version} is not one this build reads (versions {readable:?})"
        ));
    }
    Ok(Some(version))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_key_is_named_with_the_closest_known_one() {
        #[derive(Debug, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct V {
            track_m: f64,
            odometer_wheels: String,
        }
        let v = serde_json::json!({"trak_m": 1.5, "odometer_wheels": "rear"});
        let e = parse_json::<V>(v, "not a vehicle file").unwrap_err();
        assert!(e.contains("`trak_m` (did you mean `track_m`?)"), "{e}");
        assert_eq!(
            closest("Odometer_Wheel", &["track_m", "odometer_wheels"]),
            Some("odometer_wheels")
        );
    }

    #[test]
    fn versions_missing_newer_and_odd_are_told_apart() {
        let v = serde_json::json!({"a": 1});
        assert_eq!(version_of(&v, &[1, 2], "x"), Ok(None));
        let v = serde_json::json!({"version": 2, "a": 1});
        assert_eq!(version_of(&v, &[1, 2], "x"), Ok(Some(2)));
        let v = serde_json::json!({"version": 99});
        assert!(version_of(&v, &[1, 2], "x").unwrap_err().contains("newer"));
        let v = serde_json::json!({"version": "2"});
        assert!(
            version_of(&v, &[1, 2], "x")
                .unwrap_err()
                .contains("must be")
        );
        let v = serde_json::json!([1]);
        assert!(version_of(&v, &[1, 2], "x").is_err());
    }
}
