//! The parallel read against chunk boundaries: whatever the chunk size and the number of
//! parsing threads, the rows, their numbers and the first error are those of a read of the
//! whole file as one chunk on one thread.

use std::path::PathBuf;

use super::options::InputOptions;
use super::reader::{ReadSpec, RowReader};

/// A row as its number and the bits of its values (so that NaN equals NaN and the
/// comparison is bit for bit).
#[derive(Debug, PartialEq)]
struct Bits {
    number: usize,
    values: Vec<u64>,
}

impl Bits {
    fn value(&self, i: usize) -> f64 {
        f64::from_bits(self.values[i])
    }
}
use super::source::InputPath;

fn file(tag: &str, text: &[u8]) -> PathBuf {
    let p = std::env::temp_dir().join(format!(
        "truenorth-chunks-{tag}-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::write(&p, text).unwrap();
    p
}

/// The rows (or the error's text) of `path` read in chunks of `lines` lines by `workers`.
fn read(
    path: &std::path::Path,
    opts: &InputOptions,
    spec: &ReadSpec<'_>,
    lines: usize,
    workers: usize,
) -> Result<Vec<Bits>, String> {
    let mut reader =
        RowReader::open_chunked(&InputPath::new(path), opts, spec, lines, Some(workers))
            .map_err(|e| e.to_string())?;
    let mut rows = Vec::new();
    while let Some(r) = reader.next_row().map_err(|e| e.to_string())? {
        rows.push(Bits {
            number: r.number,
            values: r.values.iter().map(|v| v.to_bits()).collect(),
        });
    }
    Ok(rows)
}

/// Reads `text` in every chunk size of `sizes` on one and two threads and checks that all
/// agree with one chunk on one thread; returns that read.
fn same_in_any_chunks(
    tag: &str,
    text: &[u8],
    opts: &InputOptions,
    spec: &ReadSpec<'_>,
    sizes: &[usize],
) -> Result<Vec<Bits>, String> {
    let p = file(tag, text);
    let whole = read(&p, opts, spec, usize::MAX, 1);
    for &lines in sizes {
        for workers in [1, 2, 3] {
            let got = read(&p, opts, spec, lines, workers);
            assert_eq!(
                got, whole,
                "{tag}: chunks of {lines} lines, {workers} threads"
            );
        }
    }
    std::fs::remove_file(&p).ok();
    whole
}

const SIZES: &[usize] = &[1, 2, 3, 4, 7];

fn spec() -> ReadSpec<'static> {
    ReadSpec::new(&["t_s", "mag_x"])
        .optional(&["mag_z"])
        .increasing("t_s")
}

#[test]
fn a_decreasing_time_in_the_first_row_of_a_chunk_is_found_at_its_row() {
    let o = InputOptions::default();
    // Rows on lines 2..=9; with chunks of one, two or four lines, line 6 starts a chunk.
    for bad in [2, 3, 5, 6, 9] {
        let mut text = String::from("t_s,mag_x\n");
        for line in 2..=9 {
            let t = if line == bad { 0.5 } else { line as f64 };
            text.push_str(&format!("{t},{line}\n"));
        }
        let got = same_in_any_chunks("dec", text.as_bytes(), &o, &spec(), SIZES);
        if bad == 2 {
            assert_eq!(got.unwrap().len(), 8);
        } else {
            let e = got.unwrap_err();
            assert!(
                e.contains(&format!("row {bad}:")) && e.contains("does not come after"),
                "{e}"
            );
        }
    }
    // An equal time, and a NaN time after numbers (an optional increasing column), at a
    // chunk's first row.
    let e = same_in_any_chunks("eq", b"t_s,mag_x\n1,1\n2,1\n2,1\n", &o, &spec(), SIZES);
    assert!(e.unwrap_err().contains("row 4:"));
    let spec_opt = ReadSpec::new(&["mag_x"])
        .optional(&["t_s"])
        .increasing("t_s");
    let text = b"t_s,mag_x\n,1\n,1\n1,1\n2,1\n,1\n3,1\n";
    let e = same_in_any_chunks("nan", text, &o, &spec_opt, SIZES).unwrap_err();
    assert!(e.contains("row 6:") && e.contains("t_s = NaN"), "{e}");
    // Leading NaNs carry no time: the first number is checked against nothing.
    let rows = same_in_any_chunks(
        "nan0",
        b"t_s,mag_x\n,1\n,2\n5,3\n6,4\n",
        &o,
        &spec_opt,
        SIZES,
    );
    assert_eq!(rows.unwrap().len(), 4);
}

#[test]
fn an_error_in_the_first_row_of_a_chunk_comes_after_every_row_before_it() {
    let o = InputOptions::default();
    let text = b"t_s,mag_x\n1,1\n# note\n\n2,2\n3,x\n4,4\n5,y\n";
    let e = same_in_any_chunks("err", text, &o, &spec(), SIZES).unwrap_err();
    assert!(
        e.contains("row 6:") && e.contains("`x` is not a number"),
        "{e}"
    );
    // A wide row, a truncated last line, a line too long.
    let e = same_in_any_chunks("wide", b"t_s,mag_x\n1,1\n2,2,2\n", &o, &spec(), SIZES);
    assert!(e.unwrap_err().contains("row 3: has 3 fields"));
    let e = same_in_any_chunks("cut", b"t_s,mag_x\n1,1\n2,2\n3", &o, &spec(), SIZES);
    assert!(e.unwrap_err().contains("row 4: the last line has 1 fields"));
    let mut text = b"t_s,mag_x\n1,1\n2,2\n".to_vec();
    text.extend(std::iter::repeat_n(b'#', 70 * 1024));
    text.extend(b"\n3,3\n");
    let e = same_in_any_chunks("long", &text, &o, &spec(), SIZES).unwrap_err();
    assert!(e.contains("row 4: malformed CSV: line longer"), "{e}");
}

#[test]
fn lines_straddling_buffer_refills_and_chunks_read_whole() {
    // Rows of varied length across several read buffers (1 MiB) and chunks (128 KiB), with
    // quotes, CRLF, comments and blank lines among them.
    let mut text = String::from("\u{feff}t_s;mag_x;mag_z\r\n");
    let mut want = Vec::new();
    let mut line = 1;
    for k in 0..60_000usize {
        let t = k as f64 * 0.01;
        let x = (k as f64 * 0.7).sin() * 10f64.powi((k % 7) as i32 - 3);
        let row = match k % 5 {
            0 => format!("{t};{x:e};\r\n"),
            1 => format!("\"{t}\";\"{x}\";  {}\n", k % 13),
            2 => format!("# comment {k}\n\n{t};{x};1e-3\n"),
            _ => format!("{t};{x};{}\n", "0".repeat(k % 40)),
        };
        line += row.matches('\n').count();
        let z = match k % 5 {
            0 => f64::NAN,
            1 => (k % 13) as f64,
            2 => 1e-3,
            _ => 0.0,
        };
        want.push((line, t, x, z));
        text.push_str(&row);
    }
    let spec = ReadSpec::new(&["t_s", "mag_x"])
        .optional(&["mag_z"])
        .increasing("t_s");
    let rows = same_in_any_chunks(
        "straddle",
        text.as_bytes(),
        &InputOptions::default(),
        &spec,
        &[1000, 8192],
    )
    .unwrap();
    assert_eq!(rows.len(), want.len());
    for (r, &(line, t, x, z)) in rows.iter().zip(&want) {
        assert_eq!(r.number, line);
        assert_eq!((r.value(0), r.value(1)), (t, x), "row {line}");
        assert_eq!(r.value(2).to_bits(), z.to_bits(), "row {line}");
    }
}

#[test]
fn without_a_header_the_first_record_is_read_again() {
    let opts = InputOptions {
        no_header: true,
        columns: ["t_s=1", "mag_x=2"]
            .iter()
            .map(|c| c.parse().unwrap())
            .collect(),
        ..InputOptions::default()
    };
    let text = b"# logger\n\n\xef\xbb\xbf1 10\n2 20\n3 30";
    let rows = same_in_any_chunks("nohdr", text, &opts, &spec(), SIZES).unwrap();
    let got: Vec<(usize, f64)> = rows.iter().map(|r| (r.number, r.value(1))).collect();
    assert_eq!(got, vec![(3, 10.0), (4, 20.0), (5, 30.0)]);
}
