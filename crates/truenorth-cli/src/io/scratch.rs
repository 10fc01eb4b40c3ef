//! Scratch folders for the unit tests: named `truenorth-TAG-…` in the system's temporary
//! folder and removed when dropped, also while a failed test unwinds.

/// A fresh scratch folder for one test.
pub(crate) fn scratch_dir(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("truenorth-{tag}-"))
        .tempdir()
        .expect("the temporary folder is writable")
}
