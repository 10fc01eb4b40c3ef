//! `truenorth inspect` in bounded memory: a recording of any length is summarised row by
//! row, and only its first rows are kept for the judgements of units and axes, so the
//! memory it takes stops growing with the rows (it held every row, about 75 bytes each).

mod common;

use std::io::Write as _;
use std::process::{Child, Stdio};

use common::binary;

/// The peak resident memory of a running process, kB (Linux's `VmHWM`).
fn peak_kb(child: &Child) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Streams `rows` rows of a yaw gyro and two wheel distances into `inspect -` and returns
/// its peak memory once every row has gone in, kB, and what it printed.
fn inspect_peak(rows: usize) -> (u64, String) {
    let mut child = binary()
        .args(["inspect", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the truenorth binary runs");
    let mut pipe = child.stdin.take().unwrap();
    pipe.write_all(b"t_s,gyr_z,dist_l_m,dist_r_m\n").unwrap();
    let mut chunk = String::new();
    for k in 0..rows {
        let t = k as f64 * 0.01;
        chunk.push_str(&format!("{t:.2},0.0{},{:.3},{:.3}\n", k % 10, t, t * 1.01));
        if chunk.len() > 1 << 16 {
            pipe.write_all(chunk.as_bytes()).unwrap();
            chunk.clear();
        }
    }
    pipe.write_all(chunk.as_bytes()).unwrap();
    pipe.flush().unwrap();
    // Every row is in the pipe or read: the peak so far is the reading's.
    std::thread::sleep(std::time::Duration::from_millis(200));
    let peak = peak_kb(&child);
    drop(pipe);
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    (peak.expect("/proc/<pid>/status has VmHWM"), text)
}

/// Twice the rows beyond the judged ones take the same memory (within 16 MB, a few
/// allocator arenas); holding every row would add about 60 MB for the extra 1.5 million.
/// The report counts every row and says which were judged.
#[test]
#[cfg(target_os = "linux")]
fn memory_stops_growing_with_the_rows() {
    let (small, small_text) = inspect_peak(1_500_000);
    let (large, large_text) = inspect_peak(3_000_000);
    eprintln!("inspect peak memory: 1.5e6 rows {small} kB, 3e6 rows {large} kB");
    assert!(small_text.starts_with("-: 1500000 rows") || small_text.contains(": 1500000 rows"));
    assert!(large_text.contains(": 3000000 rows"), "{large_text}");
    assert!(
        large_text.contains("judged on the first 524288 rows of 3000000"),
        "{large_text}"
    );
    assert!(
        large_text.contains("gyr_z") && large_text.contains(" 3000000 "),
        "{large_text}"
    );
    assert!(
        large < small + 16_384,
        "peak {large} kB at 3e6 rows against {small} kB at 1.5e6"
    );
}
