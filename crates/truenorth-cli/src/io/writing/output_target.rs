//! What an output path names, and so how it is written: replaced whole (a regular file or a
//! new name, through any symbolic links) or written into (standard output, a device, a
//! FIFO, a socket: renaming a file over those would destroy them).

use std::path::{Path, PathBuf};

use crate::io::reading::source::STDIO;
use crate::io::{CliError, CliResult};

/// How many links are followed before giving up (Linux's own limit, `MAXSYMLINKS`).
const MAX_LINKS: usize = 40;

/// Where an output goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum OutputTarget {
    /// `-`: standard output.
    Stdout,
    /// Something that is not a file (a device, a FIFO, a socket): written into as it is.
    Direct(PathBuf),
    /// A regular file, existing or not, at the end of any links: replaced by renaming a
    /// temporary beside it.
    Replace(PathBuf),
}

impl OutputTarget {
    /// Looks `path` up (`-`: standard output).
    pub(super) fn of(path: &Path) -> CliResult<Self> {
        if path.as_os_str() == STDIO {
            return Ok(Self::Stdout);
        }
        let target = follow_links(path)?;
        match std::fs::metadata(&target) {
            Ok(m) if m.is_dir() => Err(CliError::file(
                path,
                "is a folder; give the output a file name",
            )),
            Ok(m) if m.is_file() => Ok(Self::Replace(target)),
            Ok(_) => Ok(Self::Direct(target)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Self::Replace(target)),
            Err(e) => Err(CliError::file(path, format!("cannot write: {e}"))),
        }
    }
}

/// The path at the end of the chain of symbolic links that `path` starts (itself if it is
/// none; a dangling link gives the name it points to, which is then created). Links in the
/// folders above are left as they are: a rename through them stays within one folder.
fn follow_links(path: &Path) -> CliResult<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&current) {
            Ok(m) if m.file_type().is_symlink() => {
                let points_to = std::fs::read_link(&current)
                    .map_err(|e| CliError::file(path, format!("cannot read the link: {e}")))?;
                current = match current.parent() {
                    Some(dir) if points_to.is_relative() => dir.join(points_to),
                    _ => points_to,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(CliError::file(
        path,
        format!("more than {MAX_LINKS} symbolic links in a row (a loop?)"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_of_path_is_recognised() {
        let scratch = crate::io::scratch::scratch_dir("target");
        let d = scratch.path();
        std::fs::create_dir_all(d.join("sub")).unwrap();
        assert_eq!(
            OutputTarget::of(Path::new("-")).unwrap(),
            OutputTarget::Stdout
        );
        let file = d.join("a.csv");
        assert_eq!(
            OutputTarget::of(&file).unwrap(),
            OutputTarget::Replace(file.clone()),
            "a new name"
        );
        std::fs::write(&file, "x").unwrap();
        assert_eq!(
            OutputTarget::of(&file).unwrap(),
            OutputTarget::Replace(file.clone())
        );
        assert!(OutputTarget::of(&d.join("sub")).is_err(), "a folder");
        #[cfg(unix)]
        {
            assert_eq!(
                OutputTarget::of(Path::new("/dev/null")).unwrap(),
                OutputTarget::Direct("/dev/null".into())
            );
            let link = d.join("sub").join("link.csv");
            std::os::unix::fs::symlink("../a.csv", &link).unwrap();
            assert_eq!(
                OutputTarget::of(&link).unwrap(),
                OutputTarget::Replace(d.join("sub").join("../a.csv"))
            );
            let dangling = d.join("dangling.csv");
            std::os::unix::fs::symlink("new.csv", &dangling).unwrap();
            assert_eq!(
                OutputTarget::of(&dangling).unwrap(),
                OutputTarget::Replace(d.join("new.csv"))
            );
            let looped = d.join("loop.csv");
            std::os::unix::fs::symlink("loop.csv", &looped).unwrap();
            let e = OutputTarget::of(&looped).unwrap_err().to_string();
            assert!(e.contains("symbolic links"), "{e}");
        }
    }
}
