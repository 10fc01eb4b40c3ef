//! Where an input comes from: a file or standard input (`-`), gzip-compressed or not.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use crate::io::{CliError, CliResult};

/// The name standing for standard input (as an input) or standard output (as an output).
pub const STDIO: &str = "-";

/// The two bytes every gzip member starts with (RFC 1952, §2.3.1).
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// An input named on the command line: a file, or standard input when the name is `-`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputPath {
    /// Standard input.
    Stdin,
    /// A file.
    File(PathBuf),
}

impl InputPath {
    /// `-` is standard input; anything else a file.
    pub fn new(path: &Path) -> Self {
        if path.as_os_str() == STDIO {
            Self::Stdin
        } else {
            Self::File(path.to_path_buf())
        }
    }

    /// The name used in error messages: the path, or `<stdin>`.
    pub fn display_path(&self) -> PathBuf {
        match self {
            Self::Stdin => PathBuf::from("<stdin>"),
            Self::File(p) => p.clone(),
        }
    }

    /// The file, if this is one.
    pub fn file(&self) -> Option<&Path> {
        match self {
            Self::Stdin => None,
            Self::File(p) => Some(p),
        }
    }

    /// Opens the input for buffered reading, decompressing gzip transparently: a stream
    /// that starts with the gzip magic bytes is decompressed whatever its name, and a file
    /// named `*.gz` that does not start with them is refused.
    pub fn open(&self) -> CliResult<Box<dyn BufRead + Send>> {
        let name = self.display_path();
        let raw: Box<dyn Read + Send> = match self {
            Self::Stdin => Box::new(std::io::stdin()),
            Self::File(p) => Box::new(
                File::open(p).map_err(|e| CliError::file(&name, format!("cannot open: {e}")))?,
            ),
        };
        let mut buffered = BufReader::with_capacity(1 << 16, raw);
        let head = buffered
            .fill_buf()
            .map_err(|e| CliError::file(&name, format!("cannot read: {e}")))?;
        let gzip = head.starts_with(&GZIP_MAGIC);
        let named_gz = self
            .file()
            .and_then(Path::extension)
            .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
        if named_gz && !gzip && !head.is_empty() {
            return Err(CliError::file(
                &name,
                "named .gz but is not gzip-compressed (it does not start with the gzip magic bytes)",
            ));
        }
        if !gzip && let Some(what) = not_text(head, false) {
            return Err(CliError::file(&name, what));
        }
        if !gzip {
            return Ok(Box::new(buffered));
        }
        let mut decoded =
            BufReader::with_capacity(1 << 16, flate2::bufread::MultiGzDecoder::new(buffered));
        let inner = decoded
            .fill_buf()
            .map_err(|e| CliError::file(&name, format!("cannot decompress: {e}")))?;
        if let Some(what) = not_text(inner, true) {
            return Err(CliError::file(&name, what));
        }
        Ok(Box::new(decoded))
    }
}

/// What a stream that starts with `head` is when it is not text a CSV reader can read
/// (by the formats' magic bytes), with what to do; `gunzipped`: `head` is what a gzip
/// layer held.
fn not_text(head: &[u8], gunzipped: bool) -> Option<String> {
    let kinds: [(&[u8], &str); 7] = [
        (
            &GZIP_MAGIC,
            "gzip-compressed twice: decompress it once (`gunzip`)",
        ),
        (
            b"BZh",
            "bzip2-compressed: decompress it (`bunzip2`) or give it gzip-compressed",
        ),
        (
            &[0xfd, b'7', b'z', b'X', b'Z', 0x00],
            "xz-compressed: decompress it (`unxz`) or give it gzip-compressed",
        ),
        (
            &[0x28, 0xb5, 0x2f, 0xfd],
            "zstd-compressed: decompress it (`unzstd`) or give it gzip-compressed",
        ),
        (b"PK\x03\x04", "a zip archive: extract the CSV from it"),
        (&[0xff, 0xfe], "UTF-16 text: save it as UTF-8 (or ASCII)"),
        (&[0xfe, 0xff], "UTF-16 text: save it as UTF-8 (or ASCII)"),
    ];
    let (_, what) = kinds.iter().find(|(magic, _)| head.starts_with(magic))?;
    if !gunzipped && what.starts_with("gzip") {
        return None;
    }
    Some(if gunzipped && !what.starts_with("gzip") {
        format!("is gzip-compressed, and what it holds is {what}")
    } else {
        format!("is {what}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write as _;

    #[test]
    fn gzip_is_found_by_its_magic_bytes_whatever_the_name() {
        let scratch = crate::io::scratch::scratch_dir("src");
        let dir = scratch.path();
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(b"a,b\n1,2\n").unwrap();
        let bytes = gz.finish().unwrap();
        for name in ["x.csv.gz", "x.csv"] {
            let p = dir.join(name);
            std::fs::write(&p, &bytes).unwrap();
            let mut text = String::new();
            InputPath::new(&p)
                .open()
                .unwrap()
                .read_to_string(&mut text)
                .unwrap();
            assert_eq!(text, "a,b\n1,2\n", "{name}");
        }
        let fake = dir.join("plain.gz");
        std::fs::write(&fake, b"a,b\n").unwrap();
        let e = InputPath::new(&fake).open().err().unwrap().to_string();
        assert!(e.contains("not gzip"), "{e}");
        let missing = InputPath::new(&dir.join("none.csv")).open().err().unwrap();
        assert!(missing.to_string().contains("cannot open"), "{missing}");
    }

    #[test]
    fn compressed_and_utf16_inputs_are_named_for_what_they_are() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(&str, Vec<u8>, &str); 5] = [
            ("b.csv", b"BZh91AY&SY".to_vec(), "bzip2"),
            ("x.csv", vec![0xfd, b'7', b'z', b'X', b'Z', 0x00, 1], "xz"),
            ("z.csv", vec![0x28, 0xb5, 0x2f, 0xfd, 0], "zstd"),
            ("u.csv", vec![0xff, 0xfe, b't', 0], "UTF-16"),
            (
                "twice.csv",
                gzip(&gzip(b"t_s\n1\n")),
                "gzip-compressed twice",
            ),
        ];
        for (name, bytes, what) in cases {
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            let e = InputPath::new(&path).open().err().unwrap().to_string();
            assert!(e.contains(what), "{name}: {e}");
        }
        let plain = dir.path().join("ok.csv");
        std::fs::write(&plain, gzip(b"t_s,mag_x\n1,2\n")).unwrap();
        assert!(InputPath::new(&plain).open().is_ok());
    }

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn dash_is_standard_input() {
        assert_eq!(InputPath::new(Path::new("-")), InputPath::Stdin);
        assert_eq!(InputPath::Stdin.display_path(), PathBuf::from("<stdin>"));
        assert!(InputPath::new(Path::new("./-")).file().is_some());
    }
}
