//! The job list: the recordings a batch runs over (the files of its folders that end in one
//! of the extensions, and the lines of `--list`), each with the name its output takes under
//! the output folder, and the content hash that keys it in the journal.

use std::collections::HashSet;
use std::ffi::OsString;
use std::io::Read as _;
use std::path::{Component, Path, PathBuf};

use sha2::{Digest as _, Sha256};

use crate::io::{CliError, CliResult, InputPath};

/// One recording to run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// The input as the command is given it (the folder joined with the file, or the line
    /// of the list).
    pub input: PathBuf,
    /// The input's path relative to where it was found, which names its output.
    pub relative: PathBuf,
}

/// Where the recordings come from.
#[derive(Debug, Clone)]
pub struct Sources<'a> {
    /// Folders whose files are run.
    pub folders: &'a [PathBuf],
    /// A file with one path a line (`-`: standard input).
    pub list: Option<&'a Path>,
    /// Descend into sub-folders.
    pub recursive: bool,
    /// File name endings matched in the folders (without the dot, case ignored).
    pub extensions: &'a [String],
}

/// A path that is not run, and why.
pub type Skipped = (PathBuf, &'static str);

/// Why a path that is not a regular file is not run: a FIFO, a device or a socket would
/// block a worker in `open()` or never end.
const NOT_REGULAR: &str = "not a regular file (a FIFO, a device or a socket): not read";

/// The jobs of `sources`, sorted by input path, each file once (the same file reached twice,
/// through two folders or a list, is run once), and the paths left out with why.
pub fn collect(sources: &Sources<'_>) -> CliResult<(Vec<Job>, Vec<Skipped>)> {
    let mut skipped = Vec::new();
    let several = sources.folders.len() + usize::from(sources.list.is_some()) > 1;
    let mut jobs = Vec::new();
    for folder in sources.folders {
        let mut found = Vec::new();
        walk(folder, sources, &mut found, &mut skipped)?;
        for input in found {
            let inside = input.strip_prefix(folder).unwrap_or(&input).to_path_buf();
            // Alone, a folder's files are named from inside it; beside other sources, from
            // the folder as given, so that two folders' `a.csv` stay apart.
            let relative = if several { input.clone() } else { inside };
            jobs.push(Job { input, relative });
        }
    }
    if let Some(list) = sources.list {
        for line in read_list(list)? {
            let input = PathBuf::from(&line);
            if std::fs::metadata(&input).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
                skipped.push((input, NOT_REGULAR));
                continue;
            }
            jobs.push(Job {
                relative: input.clone(),
                input,
            });
        }
    }
    jobs.sort_by(|a, b| a.input.cmp(&b.input));
    let mut seen = HashSet::new();
    jobs.retain(|j| seen.insert(identity(&j.input)));
    Ok((jobs, skipped))
}

/// What makes two paths the same file: the canonical path where it exists, else its
/// folder's canonical path and its name (a file not written yet).
pub fn identity(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(dir), Some(name)) => {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            dir.canonicalize()
                .map_or_else(|_| path.to_path_buf(), |d| d.join(name))
        }
        _ => path.to_path_buf(),
    }
}

/// The files of `folder` (and its sub-folders with `--recursive`) that end in one of the
/// extensions; hidden files (a leading `.`, as the temporaries of unfinished outputs are)
/// are left out.
fn walk(
    folder: &Path,
    sources: &Sources<'_>,
    found: &mut Vec<PathBuf>,
    skipped: &mut Vec<Skipped>,
) -> CliResult {
    let entries = std::fs::read_dir(folder)
        .map_err(|e| CliError::file(folder, format!("cannot list the folder: {e}")))?;
    for entry in entries {
        let entry =
            entry.map_err(|e| CliError::file(folder, format!("cannot list the folder: {e}")))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            continue;
        };
        if name.starts_with('.') {
            continue;
        }
        let path = entry.path();
        // Through links: a linked recording or folder counts as what it points to.
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            if sources.recursive {
                walk(&path, sources, found, skipped)?;
            }
        } else if matches_extension(name, sources.extensions) {
            if meta.is_file() {
                found.push(path);
            } else {
                skipped.push((path, NOT_REGULAR));
            }
        }
    }
    Ok(())
}

/// Whether `name` ends in `.EXT` for one of `extensions` (case ignored).
pub fn matches_extension(name: &str, extensions: &[String]) -> bool {
    let lower = name.to_ascii_lowercase();
    extensions.iter().any(|e| {
        let e = e.trim_start_matches('.').to_ascii_lowercase();
        lower.len() > e.len() + 1 && lower.ends_with(&e) && {
            let dot = lower.len() - e.len() - 1;
            lower.as_bytes()[dot] == b'.'
        }
    })
}

/// The paths of a list file: one a line, surrounding blanks trimmed, empty lines and lines
/// starting with `#` skipped.
fn read_list(list: &Path) -> CliResult<Vec<String>> {
    let mut text = String::new();
    InputPath::new(list)
        .open()?
        .read_to_string(&mut text)
        .map_err(|e| CliError::file(list, format!("cannot read the list: {e}")))?;
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_string)
        .collect())
}

/// The SHA-256 of the file's bytes as stored (a compressed file's compressed bytes), in
/// hexadecimal; read in 64 KiB pieces, so memory does not grow with the file.
pub fn content_hash(path: &Path) -> std::io::Result<String> {
    let mut file = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        hasher.update(&buf[..n]);
    }
    Ok(hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// The output's path under the output folder for an input at `relative`, with `suffix`
/// (`json`, `csv`, …) appended to its file name: the input's path, each component escaped.
///
/// Bytes other than ASCII letters, digits and `_-+=@,.` are written `%XX`, and so is a
/// leading `.` (so a name is never `.`, `..` or hidden, and never a temporary `.NAME.tmp-PID`
/// nor the journal); a root or a drive becomes a component of its own (`%2F`). Every
/// component is then an ordinary name: the path stays inside the folder, and two different
/// inputs never share an output (the escaping can be undone).
pub fn output_name(relative: &Path, suffix: &str) -> PathBuf {
    let mut parts: Vec<OsString> = Vec::new();
    for c in relative.components() {
        match c {
            Component::Prefix(p) => parts.push(escape(p.as_os_str().as_encoded_bytes())),
            Component::RootDir => parts.push("%2F".into()),
            Component::CurDir => {}
            Component::ParentDir => parts.push("%2E.".into()),
            Component::Normal(n) => parts.push(escape(n.as_encoded_bytes())),
        }
    }
    let Some(last) = parts.last_mut() else {
        // No component: an empty path, which no file has.
        return PathBuf::from(format!("%.{suffix}"));
    };
    last.push(".");
    last.push(suffix);
    parts.iter().collect()
}

/// One path component escaped (see [`output_name`]).
fn escape(bytes: &[u8]) -> OsString {
    let mut s = String::with_capacity(bytes.len());
    for (k, &b) in bytes.iter().enumerate() {
        let plain = b.is_ascii_alphanumeric()
            || matches!(b, b'_' | b'-' | b'+' | b'=' | b'@' | b',')
            || (b == b'.' && k > 0);
        if plain {
            s.push(char::from(b));
        } else {
            s.push_str(&format!("%{b:02X}"));
        }
    }
    OsString::from(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_match_whole_endings() {
        let e = ["csv".to_string(), "csv.gz".to_string(), ".ulg".to_string()];
        assert!(matches_extension("a.csv", &e));
        assert!(matches_extension("A.CSV.GZ", &e));
        assert!(matches_extension("log.ulg", &e));
        assert!(!matches_extension("acsv", &e));
        assert!(
            !matches_extension(".csv", &e),
            "a bare extension is no name"
        );
        assert!(!matches_extension("a.tsv", &e));
    }

    #[test]
    fn output_names_escape_and_stay_inside() {
        assert_eq!(
            output_name(Path::new("run 1/a.csv.gz"), "json"),
            PathBuf::from("run%201/a.csv.gz.json")
        );
        assert_eq!(
            output_name(Path::new("../.x/a.csv"), "csv"),
            PathBuf::from("%2E./%2Ex/a.csv.csv")
        );
        assert_eq!(
            output_name(Path::new("/data/a.csv"), "csv"),
            PathBuf::from("%2F/data/a.csv.csv")
        );
    }

    #[test]
    fn the_hash_is_sha256_of_the_bytes() {
        let d = std::env::temp_dir().join(format!("truenorth-hash-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("abc");
        std::fs::write(&f, "abc").unwrap();
        // FIPS 180-2, appendix B.1: SHA-256("abc").
        assert_eq!(
            content_hash(&f).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let _ = std::fs::remove_dir_all(&d);
    }
}
