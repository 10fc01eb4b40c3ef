//! The real recordings in `shared/data/` beside the checkout, for tests and benches.
//!
//! Tests that need a recording ask [`folder`] for it. Where the recordings are absent the
//! answer depends on who is asking: on a developer's machine the test prints why it skips
//! and passes; under CI (the `CI` environment variable set), which always has the
//! recordings, absence is an error, so a green CI run can never be one that skipped.

use std::path::PathBuf;

/// Environment variable that points at the shared recordings instead of
/// `<workspace>/../shared/data`.
pub const DATA_DIR_VAR: &str = "TRUENORTH_SHARED_DATA";

/// A recording folder that is absent where it must be present.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "shared recording folder {path} is missing and CI is set (CI always has ../shared/data); set {DATA_DIR_VAR} or restore the folder"
)]
pub struct MissingData {
    /// The folder looked for.
    pub path: String,
}

/// Where the shared recordings live: `$TRUENORTH_SHARED_DATA` if set, otherwise
/// `shared/data` beside the workspace root.
pub fn root() -> PathBuf {
    match std::env::var_os(DATA_DIR_VAR) {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
}

/// The recording folder `name` (e.g. `"broad"`), if present. Absent: `Ok(None)` after
/// printing a visible skip reason on stderr, or [`MissingData`] when `CI` is set.
pub fn folder(name: &str) -> Result<Option<PathBuf>, MissingData> {
    folder_in(root(), name, std::env::var_os("CI").is_some())
}

fn folder_in(root: PathBuf, name: &str, ci: bool) -> Result<Option<PathBuf>, MissingData> {
    let path = root.join(name);
    if path.is_dir() {
        return Ok(Some(path));
    }
    if ci {
        return Err(MissingData {
            path: path.display().to_string(),
        });
    }
    eprintln!(
        "SKIPPED: shared recording folder {} is absent (tests that need it pass without running; under CI they fail)",
        path.display()
    );
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absence_skips_locally_and_fails_under_ci() {
        let nowhere = std::env::temp_dir().join("truenorth-no-such-shared-data");
        assert_eq!(folder_in(nowhere.clone(), "broad", false), Ok(None));
        assert!(folder_in(nowhere, "broad", true).is_err());
    }

    #[test]
    fn a_present_folder_is_found_either_way() {
        let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        for ci in [false, true] {
            assert_eq!(
                folder_in(here.clone(), "src", ci),
                Ok(Some(here.join("src")))
            );
        }
    }
}
