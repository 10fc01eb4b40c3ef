//! Outputs that appear whole or not at all: written to a temporary file in the target's
//! folder, flushed to disk, then renamed over the target (a rename within one file system
//! replaces the name in one step, POSIX `rename(2)`), so a run that fails or is killed
//! leaves an existing output as it was. A symbolic link is followed: the file it points to
//! is replaced and the link stays. `-` (standard output), a device and a FIFO are written
//! into directly: they are not files to replace. Temporaries are `.NAME.tmp-PID`; how the
//! ones of a stopped run are removed is in [`temporaries`].

use std::fs::File;
use std::io::{BufWriter, ErrorKind, Write};
use std::path::{Path, PathBuf};

use super::output_target::OutputTarget;
use super::write_behind::WriteBehind;
use crate::io::console::end_on_closed_pipe;
use crate::io::reading::source::InputPath;
use crate::io::temporaries;
use crate::io::{CliError, CliResult};

/// The bytes' destination: standard output or an open file (a temporary, or a device or
/// FIFO written directly). Its reader closing the pipe ends the run quietly (see
/// [`console`](crate::io::console)). A temporary is synced behind its writes (see
/// [`write_behind`](super::write_behind)).
enum Dest {
    Stdout(std::io::Stdout),
    File(File),
    Temporary(WriteBehind),
}

impl Write for Dest {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let written = match self {
            Self::Stdout(s) => s.write(bytes),
            Self::File(f) => f.write(bytes),
            Self::Temporary(f) => f.write(bytes),
        };
        match written {
            Err(e) if e.kind() == ErrorKind::BrokenPipe => end_on_closed_pipe(),
            other => other,
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let flushed = match self {
            Self::Stdout(s) => s.flush(),
            Self::File(f) => f.flush(),
            Self::Temporary(f) => f.flush(),
        };
        match flushed {
            Err(e) if e.kind() == ErrorKind::BrokenPipe => end_on_closed_pipe(),
            other => other,
        }
    }
}

/// The (possibly compressing) writer over a [`Dest`].
enum Body {
    Plain(BufWriter<Dest>),
    Gzip(flate2::write::GzEncoder<BufWriter<Dest>>),
}

/// A streaming output: write to it, then [`AtomicOutput::commit`]. Dropped without a
/// commit (an error on the way, a panic), it removes its temporary file and the target is
/// untouched. A target named `*.gz` is gzip-compressed.
pub struct AtomicOutput {
    body: Option<Body>,
    /// The temporary and the file it replaces, for a target that is replaced.
    replace: Option<(PathBuf, PathBuf)>,
    name: PathBuf,
}

impl std::fmt::Debug for AtomicOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AtomicOutput")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

impl AtomicOutput {
    /// Starts writing `path` (`-`: standard output; a device or FIFO: into it; a link: the
    /// file it points to). Leftover temporaries of `path` from runs that were killed are
    /// removed first.
    pub fn create(path: &Path) -> CliResult<Self> {
        let cannot_create = |e: std::io::Error| CliError::file(path, format!("cannot create: {e}"));
        let (dest, replace, name) = match OutputTarget::of(path)? {
            OutputTarget::Stdout => (
                Dest::Stdout(std::io::stdout()),
                None,
                PathBuf::from("<stdout>"),
            ),
            OutputTarget::Direct(target) => {
                // No create, no truncate: the device or FIFO is there and has no length.
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&target)
                    .map_err(cannot_create)?;
                (Dest::File(file), None, path.to_path_buf())
            }
            OutputTarget::Replace(target) => {
                let temp = temporaries::name_for(&target)
                    .ok_or_else(|| CliError::file(path, "not a file name"))?;
                temporaries::remove_stale(&target);
                let file = temporaries::create(&temp).map_err(cannot_create)?;
                // The replacement keeps the permissions of the file it replaces.
                if let Ok(m) = std::fs::metadata(&target) {
                    let _ = file.set_permissions(m.permissions());
                }
                (
                    Dest::Temporary(WriteBehind::new(file)),
                    Some((temp, target)),
                    path.to_path_buf(),
                )
            }
        };
        let writer = BufWriter::with_capacity(1 << 16, dest);
        let gz = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
        let body = if gz {
            Body::Gzip(flate2::write::GzEncoder::new(
                writer,
                flate2::Compression::default(),
            ))
        } else {
            Body::Plain(writer)
        };
        Ok(Self {
            body: Some(body),
            replace,
            name,
        })
    }

    /// The output's name for messages (`<stdout>` for standard output).
    pub fn name(&self) -> &Path {
        &self.name
    }

    fn writer(&mut self) -> &mut dyn Write {
        match self.body.as_mut() {
            Some(Body::Plain(w)) => w,
            Some(Body::Gzip(encoder)) => encoder,
            None => unreachable!("a committed output is consumed"),
        }
    }

    /// Writes `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> CliResult {
        // The name is borrowed only on an error: this runs once a row.
        let written = self.writer().write_all(bytes);
        written.map_err(|e| CliError::file(&self.name, format!("cannot write: {e}")))
    }

    /// Finishes the output. A replaced file is flushed, synced to disk and renamed over
    /// the target (whose folder is then synced too, so the new name survives a power cut);
    /// standard output, a device or a FIFO is flushed.
    pub fn commit(mut self) -> CliResult {
        let name = self.name.clone();
        let err = |e: std::io::Error| CliError::file(&name, format!("cannot write: {e}"));
        let writer = match self.body.take() {
            Some(Body::Plain(w)) => w,
            Some(Body::Gzip(encoder)) => encoder.finish().map_err(err)?,
            None => return Ok(()),
        };
        let dest = writer.into_inner().map_err(|e| err(e.into_error()))?;
        let Some((temp, target)) = self.replace.take() else {
            let mut dest = dest;
            return dest.flush().map_err(err);
        };
        // From here on the temporary is this function's to remove on failure.
        let synced = match dest {
            Dest::Temporary(f) => f.finish().and_then(|f| f.sync_all()),
            Dest::File(f) => f.sync_all(),
            Dest::Stdout(_) => Ok(()),
        };
        if let Err(e) = synced {
            temporaries::discard(&temp);
            return Err(err(e));
        }
        temporaries::publish(&temp, &target)
            .map_err(|e| CliError::file(&name, format!("cannot replace: {e}")))?;
        // Best effort: not every platform can open a folder to sync it.
        if let Some(dir) = target.parent() {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            if let Ok(d) = File::open(dir) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }
}

impl Drop for AtomicOutput {
    fn drop(&mut self) {
        // Close the file before removing its name.
        drop(self.body.take());
        if let Some((temp, _)) = self.replace.take() {
            temporaries::discard(&temp);
        }
    }
}

/// Writes `path` through `fill`, whole or not at all (see `AtomicOutput`).
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error>>,
) -> CliResult {
    let mut out = AtomicOutput::create(path)?;
    let name = out.name().to_path_buf();
    fill(out.writer()).map_err(|e| CliError::file(&name, format!("cannot write: {e}")))?;
    out.commit()
}

/// Refuses an output path that names one of the inputs (it would destroy the recording),
/// before anything is read: the same path, the same file through a link, or the same file
/// under another name (same device and inode). Standard input and output never clash, nor
/// does an output that is not a file (a device or FIFO is written into, never replaced).
pub fn check_distinct(output: &Path, inputs: &[&Path]) -> CliResult {
    if matches!(
        OutputTarget::of(output),
        Ok(OutputTarget::Stdout | OutputTarget::Direct(_))
    ) {
        return Ok(());
    }
    for input in inputs {
        let InputPath::File(input) = InputPath::new(input) else {
            continue;
        };
        if same_file(output, &input) {
            return Err(CliError::file(
                output,
                format!(
                    "the output would overwrite the input {}; choose another output path",
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(ca), Ok(cb)) = (a.canonicalize(), b.canonicalize()) {
        if ca == cb {
            return true;
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt as _;
            if let (Ok(ma), Ok(mb)) = (std::fs::metadata(&ca), std::fs::metadata(&cb)) {
                return ma.dev() == mb.dev() && ma.ino() == mb.ino();
            }
        }
        return false;
    }
    // The output does not exist yet: compare what the names say.
    let abs = |p: &Path| {
        std::path::absolute(p)
            .map(|p| p.components().collect::<PathBuf>())
            .unwrap_or_else(|_| p.to_path_buf())
    };
    abs(a) == abs(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{CsvOutput, Precision, write_csv};

    fn dir(tag: &str) -> tempfile::TempDir {
        crate::io::scratch::scratch_dir(&format!("atomic-{tag}"))
    }

    fn leftovers(d: &Path) -> Vec<String> {
        std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp-"))
            .collect()
    }

    #[test]
    fn an_abandoned_output_leaves_the_old_file_and_no_temporary() {
        let scratch = dir("abandon");
        let d = scratch.path();
        let target = d.join("out.csv");
        std::fs::write(&target, "old\n").unwrap();
        {
            let mut out = CsvOutput::create(&target, &["a"]).unwrap();
            out.row(&[1.0], Precision::default()).unwrap();
            // Dropped without commit, as on an error half way.
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert!(leftovers(d).is_empty(), "{:?}", leftovers(d));
        let failed = write_atomically(&target, |w| {
            w.write_all(b"partial")?;
            Err("stopped".into())
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert!(leftovers(d).is_empty());
        write_csv(
            &target,
            &["a", "b"],
            [vec![1.5, -2.0]],
            Precision::default(),
        )
        .unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "a,b\n1.5,-2\n");
        assert!(leftovers(d).is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_followed_a_device_written_into_and_permissions_kept() {
        use std::os::unix::fs::PermissionsExt as _;
        let scratch = dir("kinds");
        let d = scratch.path();
        let real = d.join("real.csv");
        std::fs::write(&real, "old\n").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.csv");
        std::os::unix::fs::symlink("real.csv", &link).unwrap();
        write_csv(&link, &["a"], [vec![2.0]], Precision::default()).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "a\n2\n");
        let mode = std::fs::metadata(&real).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640, "{mode:o}");
        assert!(leftovers(d).is_empty());
        write_csv(
            Path::new("/dev/null"),
            &["a"],
            [vec![1.0]],
            Precision::default(),
        )
        .unwrap();
        use std::os::unix::fs::FileTypeExt as _;
        let null = std::fs::metadata("/dev/null").unwrap();
        assert!(null.file_type().is_char_device());
        assert!(
            check_distinct(Path::new("/dev/null"), &[Path::new("/dev/null")]).is_ok(),
            "writing into a device destroys no input"
        );
    }

    #[test]
    fn gz_outputs_are_compressed_and_read_back() {
        let scratch = dir("gz");
        let d = scratch.path();
        let target = d.join("out.csv.gz");
        write_csv(&target, &["t_s"], [vec![0.25]], Precision::default()).unwrap();
        let mut text = String::new();
        use std::io::Read as _;
        InputPath::new(&target)
            .open()
            .unwrap()
            .read_to_string(&mut text)
            .unwrap();
        assert_eq!(text, "t_s\n0.25\n");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let scratch = dir("distinct");
        let d = scratch.path();
        let input = d.join("in.csv");
        std::fs::write(&input, "x\n").unwrap();
        let e = check_distinct(&input, &[&input]).unwrap_err().to_string();
        assert!(e.contains("would overwrite the input"), "{e}");
        let dotted = d.join(".").join("in.csv");
        assert!(check_distinct(&dotted, &[&input]).is_err());
        #[cfg(unix)]
        {
            let link = d.join("hard.csv");
            std::fs::hard_link(&input, &link).unwrap();
            assert!(
                check_distinct(&link, &[&input]).is_err(),
                "a hard link is the same file"
            );
        }
        assert!(check_distinct(&d.join("new.csv"), &[&input]).is_ok());
        assert!(check_distinct(Path::new("-"), &[Path::new("-")]).is_ok());
        assert!(
            check_distinct(&d.join("a.csv"), &[&d.join("a.csv")]).is_err(),
            "even before it exists"
        );
    }
}
