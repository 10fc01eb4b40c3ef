//! Reading the JSON files the tools take (a compass calibration, a vehicle, a drive's
//! learned state) the same way: a byte-order mark is skipped as in a CSV, an unknown key is
//! named with the closest known one and where it stands, and the layout version is checked
//! with one rule.

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::io::closest_name::unknown_key;
use crate::io::reading::source::InputPath;
use crate::io::{CliError, CliResult};

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
/// key, names the known key closest to it and, below the top level, where it stands.
pub fn parse_json<T: DeserializeOwned>(value: Value, what: &str) -> Result<T, String> {
    serde_json::from_value(value.clone())
        .map_err(|e| format!("{what}: {}", explain(&e.to_string(), &value)))
}

/// [`parse_json`], and then no key that `T` does not read at any depth, refused with the
/// same message. A type that denies unknown keys refuses them itself; this catches them
/// in the types inside that do not (the library's serde types read other programs' files
/// and later versions', so they ignore unknown keys), by comparing the keys given with
/// those `T` writes back. `T` must write every key it reads.
pub fn parse_json_strict<T: DeserializeOwned + Serialize>(
    value: Value,
    what: &str,
) -> Result<T, String> {
    let parsed: T = parse_json(value.clone(), what)?;
    let known = serde_json::to_value(&parsed).map_err(|e| format!("{what}: {e}"))?;
    first_unknown_key(&value, &known, "").map_err(|m| format!("{what}: {m}"))?;
    Ok(parsed)
}

/// Parses the text into a JSON value (a syntax error says where). A key given twice in
/// one object is refused: a JSON value keeps the last, and the first would be dropped
/// without a word.
pub fn parse_value(text: &str, what: &str) -> Result<Value, String> {
    serde_json::from_str::<NoDuplicateKeys>(text).map_err(|e| format!("{what}: {e}"))?;
    serde_json::from_str(text).map_err(|e| format!("{what}: {e}"))
}

/// A JSON document walked only to refuse a key given twice in one object, at any depth.
struct NoDuplicateKeys;

impl<'de> serde::Deserialize<'de> for NoDuplicateKeys {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NoDuplicateKeys)
    }
}

impl<'de> serde::de::Visitor<'de> for NoDuplicateKeys {
    type Value = Self;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self, A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if !seen.insert(key.clone()) {
                return Err(serde::de::Error::custom(format!(
                    "the key `{key}` is given twice in one object (only one of them would be used); give it once"
                )));
            }
            map.next_value::<NoDuplicateKeys>()?;
        }
        Ok(self)
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self, A::Error> {
        while seq.next_element::<NoDuplicateKeys>()?.is_some() {}
        Ok(self)
    }

    fn visit_bool<E>(self, _: bool) -> Result<Self, E> {
        Ok(self)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Self, E> {
        Ok(self)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Self, E> {
        Ok(self)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Self, E> {
        Ok(self)
    }
    fn visit_str<E>(self, _: &str) -> Result<Self, E> {
        Ok(self)
    }
    fn visit_unit<E>(self) -> Result<Self, E> {
        Ok(self)
    }
}

/// serde's message, with the closest known key after an unknown one, and where in `value`
/// the object with that key stands.
fn explain(message: &str, value: &Value) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_string();
    };
    let Some((key, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    let known: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    if known.is_empty() {
        return message.to_string();
    }
    at(
        path_of_object(value, key, &known, "").as_deref(),
        unknown_key(key, &known),
    )
}

/// `message`, prefixed with where it applies unless that is the top level.
fn at(path: Option<&str>, message: String) -> String {
    match path {
        Some(path) if !path.is_empty() => format!("in `{path}`, {message}"),
        _ => message,
    }
}

/// The path (`compass.quality`) of the first object in `value` that holds `key` and
/// otherwise only keys of `known`: the object serde refused `key` in.
fn path_of_object(value: &Value, key: &str, known: &[&str], path: &str) -> Option<String> {
    match value {
        Value::Object(map) => {
            if map.contains_key(key) && map.keys().all(|k| k == key || known.contains(&k.as_str()))
            {
                return Some(path.to_string());
            }
            map.iter()
                .find_map(|(k, v)| path_of_object(v, key, known, &join(path, k)))
        }
        Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, v)| path_of_object(v, key, known, &format!("{path}[{i}]"))),
        _ => None,
    }
}

/// The first key of `given`, at any depth, that `known` (the same value as its type writes
/// it back) does not have, as the message of [`unknown_key`] with where it stands.
fn first_unknown_key(given: &Value, known: &Value, path: &str) -> Result<(), String> {
    match (given, known) {
        (Value::Object(given), Value::Object(known)) => {
            given.iter().try_for_each(|(k, v)| match known.get(k) {
                Some(w) => first_unknown_key(v, w, &join(path, k)),
                None => {
                    let names: Vec<&str> = known.keys().map(String::as_str).collect();
                    Err(at(Some(path), unknown_key(k, &names)))
                }
            })
        }
        (Value::Array(given), Value::Array(known)) => given
            .iter()
            .zip(known)
            .enumerate()
            .try_for_each(|(i, (g, w))| first_unknown_key(g, w, &format!("{path}[{i}]"))),
        _ => Ok(()),
    }
}

/// `path.key`, or `key` at the top level.
fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The `version` key of a JSON object, checked: `None` when the file has
/// none (a layout from before versions, which the caller may accept), an error naming the
/// versions this build reads when it is not a whole number or is not one of `readable`.
pub fn version_of(value: &Value, readable: &[u32], kind: &str) -> Result<Option<u32>, String> {
    let Value::Object(map) = value else {
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
    fn a_key_given_twice_is_refused_at_any_depth() {
        for text in [
            r#"{"track_m": 1.5, "track_m": 1.6}"#,
            r#"{"a": [{"b": 1, "c": {"d": 2, "d": 3}}]}"#,
        ] {
            let e = parse_value(text, "vehicle file").unwrap_err();
            assert!(e.contains("given twice"), "{e}");
        }
        let fine = r#"{"a": [{"b": 1}, {"b": 2}], "c": null, "d": -1, "e": 1e300, "f": true}"#;
        assert!(parse_value(fine, "x").is_ok());
    }

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
        assert!(!e.contains("in `"), "at the top level: {e}");
    }

    #[derive(Debug, serde::Deserialize, serde::Serialize)]
    struct Inner {
        points: usize,
    }

    #[derive(Debug, serde::Deserialize, serde::Serialize)]
    #[serde(deny_unknown_fields)]
    struct Outer {
        fit: Inner,
        list: Vec<Inner>,
    }

    #[test]
    fn an_unknown_key_inside_is_refused_with_where_it_stands() {
        let v = serde_json::json!({"fit": {"points": 1, "pointz": 2}, "list": []});
        assert!(
            parse_json::<Outer>(v.clone(), "x").is_ok(),
            "serde alone ignores it"
        );
        let e = parse_json_strict::<Outer>(v, "x").unwrap_err();
        assert_eq!(
            e,
            "x: in `fit`, unknown key `pointz` (did you mean `points`?); the keys are `points`"
        );
        let v = serde_json::json!({"fit": {"points": 1}, "list": [{"points": 1}, {"point": 2, "points": 3}]});
        let e = parse_json_strict::<Outer>(v, "x").unwrap_err();
        assert!(e.contains("in `list[1]`, unknown key `point`"), "{e}");
        let v = serde_json::json!({"fit": {"points": 1}, "list": [], "lists": 1});
        let e = parse_json_strict::<Outer>(v, "x").unwrap_err();
        assert!(
            e.starts_with("x: unknown key `lists` (did you mean `list`?)"),
            "{e}"
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
