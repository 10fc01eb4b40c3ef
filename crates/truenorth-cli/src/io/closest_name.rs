//! The known name closest to one that is not known, for the "did you mean" of every input
//! check: an unknown key in a JSON file (at any depth) and a CSV column that is missing.

/// The message for `key`, which is not one of `known`: the closest known name, then all of
/// them, e.g. "unknown key `trak_m` (did you mean `track_m`?); the keys are `track_m`, …".
/// Without known names, only that the key is unknown.
pub fn unknown_key(key: &str, known: &[&str]) -> String {
    match closest(key, known) {
        Some(k) => format!(
            "unknown key `{key}` (did you mean `{k}`?); the keys are {}",
            quoted_list(known)
        ),
        None => format!("unknown key `{key}`; this object has no keys"),
    }
}

/// The entry of `known` nearest to `name` in edit distance (case ignored); `None` only when
/// `known` is empty.
pub fn closest<'a>(name: &str, known: &[&'a str]) -> Option<&'a str> {
    let name = name.to_ascii_lowercase();
    known
        .iter()
        .map(|k| (edit_distance(&name, &k.to_ascii_lowercase()), *k))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

/// The entry of `known` that `name` is a likely misspelling of: the closest one, when at
/// most a third of `name`'s characters (at least one) differ; a name further from every
/// entry is taken for another name, not a misspelling, and gets no suggestion.
pub fn likely_meant<'a>(name: &str, known: &[&'a str]) -> Option<&'a str> {
    let k = closest(name, known)?;
    let allowed = name.chars().count().div_ceil(3).max(1);
    (edit_distance(&name.to_ascii_lowercase(), &k.to_ascii_lowercase()) <= allowed).then_some(k)
}

/// `` `a`, `b`, `c` ``.
fn quoted_list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|k| format!("`{k}`")).collect();
    quoted.join(", ")
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_name_is_suggested_case_ignored() {
        assert_eq!(
            closest("Odometer_Wheel", &["track_m", "odometer_wheels"]),
            Some("odometer_wheels")
        );
        assert_eq!(closest("x", &[]), None);
        let m = unknown_key("trak_m", &["track_m", "odometer_wheels"]);
        assert_eq!(
            m,
            "unknown key `trak_m` (did you mean `track_m`?); the keys are `track_m`, `odometer_wheels`"
        );
    }

    #[test]
    fn only_a_misspelling_is_likely_meant() {
        let header = ["t_s", "mag_yy"];
        assert_eq!(likely_meant("mag_y", &header), Some("mag_yy"));
        assert_eq!(likely_meant("MAG_Y", &header), Some("mag_yy"));
        assert_eq!(likely_meant("gyr_z", &header), None);
        assert_eq!(likely_meant("t", &header), None);
    }
}
