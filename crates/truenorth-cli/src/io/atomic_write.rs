//! Outputs that appear whole or not at all: written to a temporary file in the target's
//! folder, flushed to disk, then renamed over the target (a rename within one file system
//! replaces the name in one step, POSIX `rename(2)`), so a run that fails or is killed
//! leaves an existing output as it was. `-` writes to standard output instead.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::number_format::Precision;
use super::source::{InputPath, STDIO};
use super::{CliError, CliResult};

/// Where the bytes go while an [`AtomicOutput`] is open.
enum Sink {
    Stdout(BufWriter<std::io::Stdout>),
    Temp {
        file: BufWriter<File>,
        temp: PathBuf,
        target: PathBuf,
    },
    Gzip {
        encoder: flate2::write::GzEncoder<BufWriter<File>>,
        temp: PathBuf,
        target: PathBuf,
    },
}

/// A streaming output: write to it, then [`AtomicOutput::commit`]. Dropped without a
/// commit (an error on the way, a panic), it removes its temporary file and the target is
/// untouched. A target named `*.gz` is gzip-compressed.
pub struct AtomicOutput {
    sink: Option<Sink>,
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
    /// Starts writing `path` (`-`: standard output).
    pub fn create(path: &Path) -> CliResult<Self> {
        if path.as_os_str() == STDIO {
            return Ok(Self {
                sink: Some(Sink::Stdout(BufWriter::new(std::io::stdout()))),
                name: PathBuf::from("<stdout>"),
            });
        }
        let name = path
            .file_name()
            .ok_or_else(|| CliError::file(path, "not a file name"))?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".tmp-{}", std::process::id()));
        let temp = path.with_file_name(tmp_name);
        let file =
            File::create(&temp).map_err(|e| CliError::file(path, format!("cannot create: {e}")))?;
        let file = BufWriter::with_capacity(1 << 16, file);
        let gz = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
        let sink = if gz {
            Sink::Gzip {
                encoder: flate2::write::GzEncoder::new(file, flate2::Compression::default()),
                temp,
                target: path.to_path_buf(),
            }
        } else {
            Sink::Temp {
                file,
                temp,
                target: path.to_path_buf(),
            }
        };
        Ok(Self {
            sink: Some(sink),
            name: path.to_path_buf(),
        })
    }

    /// The output's name for messages (`<stdout>` for standard output).
    pub fn name(&self) -> &Path {
        &self.name
    }

    fn writer(&mut self) -> &mut dyn Write {
        match self.sink.as_mut() {
            Some(Sink::Stdout(w)) => w,
            Some(Sink::Temp { file, .. }) => file,
            Some(Sink::Gzip { encoder, .. }) => encoder,
            None => unreachable!("a committed output is consumed"),
        }
    }

    /// Writes `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> CliResult {
        let name = self.name.clone();
        self.writer()
            .write_all(bytes)
            .map_err(|e| CliError::file(&name, format!("cannot write: {e}")))
    }

    /// Finishes the output: flushed, synced to disk and renamed over the target (whose
    /// folder is then synced too, so the new name survives a power cut).
    pub fn commit(mut self) -> CliResult {
        let name = self.name.clone();
        let err = |e: std::io::Error| CliError::file(&name, format!("cannot write: {e}"));
        let (file, temp, target) = match self.sink.take() {
            Some(Sink::Stdout(mut w)) => return w.flush().map_err(err),
            Some(Sink::Temp { file, temp, target }) => (file, temp, target),
            Some(Sink::Gzip {
                encoder,
                temp,
                target,
            }) => {
                let file = encoder.finish().map_err(|e| {
                    let _ = std::fs::remove_file(&temp);
                    err(e)
                })?;
                (file, temp, target)
            }
            None => return Ok(()),
        };
        let synced = file
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all());
        if let Err(e) = synced {
            let _ = std::fs::remove_file(&temp);
            return Err(err(e));
        }
        if let Err(e) = std::fs::rename(&temp, &target) {
            let _ = std::fs::remove_file(&temp);
            return Err(CliError::file(&name, format!("cannot replace: {e}")));
        }
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
        if let Some(Sink::Temp { temp, .. } | Sink::Gzip { temp, .. }) = self.sink.take() {
            let _ = std::fs::remove_file(temp);
        }
    }
}

/// Writes `path` through `fill`, whole or not at all (see [`AtomicOutput`]).
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> Result<(), Box<dyn std::error::Error>>,
) -> CliResult {
    let mut out = AtomicOutput::create(path)?;
    let name = out.name().to_path_buf();
    fill(out.writer()).map_err(|e| CliError::file(&name, format!("cannot write: {e}")))?;
    out.commit()
}

/// A CSV written row by row into an [`AtomicOutput`]: numbers in Rust's shortest form that
/// reads back to the same `f64`.
pub struct CsvOutput {
    out: AtomicOutput,
    line: String,
}

impl std::fmt::Debug for CsvOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvOutput")
            .field("out", &self.out)
            .finish_non_exhaustive()
    }
}

impl CsvOutput {
    /// Starts `path` (`-`: standard output) with its header row.
    pub fn create(path: &Path, header: &[&str]) -> CliResult<Self> {
        let mut out = AtomicOutput::create(path)?;
        out.write_all((header.join(",") + "\n").as_bytes())?;
        Ok(Self {
            out,
            line: String::new(),
        })
    }

    /// Appends one row, the numbers written at `precision` (see [`Precision`]); a NaN is
    /// written as an empty cell (no value, as an empty cell reads on input).
    pub fn row(&mut self, values: &[f64], precision: Precision) -> CliResult {
        self.line.clear();
        for (k, &v) in values.iter().enumerate() {
            if k > 0 {
                self.line.push(',');
            }
            precision.write(&mut self.line, v);
        }
        self.line.push('\n');
        self.out.write_all(self.line.as_bytes())
    }

    /// Finishes the file (see [`AtomicOutput::commit`]).
    pub fn commit(self) -> CliResult {
        self.out.commit()
    }
}

/// Writes a CSV with a header row and rows of numbers, whole or not at all.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
    precision: Precision,
) -> CliResult {
    let mut out = CsvOutput::create(path, header)?;
    for r in rows {
        out.row(&r, precision)?;
    }
    out.commit()
}

/// Refuses an output path that names one of the inputs (it would destroy the recording),
/// before anything is read: the same path, the same file through a link, or the same file
/// under another name (same device and inode). Standard input and output never clash.
pub fn check_distinct(output: &Path, inputs: &[&Path]) -> CliResult {
    if output.as_os_str() == STDIO {
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

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("truenorth-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
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
        let d = dir("abandon");
        let target = d.join("out.csv");
        std::fs::write(&target, "old\n").unwrap();
        {
            let mut out = CsvOutput::create(&target, &["a"]).unwrap();
            out.row(&[1.0], Precision::default()).unwrap();
            // Dropped without commit, as on an error half way.
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert!(leftovers(&d).is_empty(), "{:?}", leftovers(&d));
        let failed = write_atomically(&target, |w| {
            w.write_all(b"partial")?;
            Err("stopped".into())
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert!(leftovers(&d).is_empty());
        write_csv(
            &target,
            &["a", "b"],
            [vec![1.5, -2.0]],
            Precision::default(),
        )
        .unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "a,b\n1.5,-2\n");
        assert!(leftovers(&d).is_empty());
    }

    #[test]
    fn gz_outputs_are_compressed_and_read_back() {
        let d = dir("gz");
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
        let d = dir("distinct");
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
