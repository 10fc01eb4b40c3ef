//! Whatever the bytes, reading them returns a recording or a typed error, never a panic or
//! an abort: random bytes, random bytes behind each format's magic, and real files damaged at
//! random. (A panic inside a reader crate comes back as `LogError::ReaderFault`.)

use proptest::prelude::*;
use truenorth_logs::{LogConfig, LogReader};

fn readers() -> [LogReader; 2] {
    [false, true].map(|accept_incomplete| {
        LogReader::new(LogConfig {
            accept_incomplete,
            ..LogConfig::default()
        })
        .unwrap()
    })
}

const ULOG_MAGIC: &[u8] = b"ULog\x01\x12\x35";
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn fixture() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/ros2_small.mcap"
    ))
    .unwrap()
}

/// The first 64 kB of `sample_log_small.ulg` (header, definitions, first data), if present.
fn ulog_head() -> Option<Vec<u8>> {
    let dir = truenorth_sim::shared_data::folder("px4_ulog_samples").unwrap()?;
    let mut b = std::fs::read(dir.join("sample_log_small.ulg")).unwrap();
    b.truncate(65_536);
    Some(b)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        for r in readers() {
            let _ = r.read_bytes(&bytes);
        }
    }

    #[test]
    fn random_bytes_after_either_magic_never_panic(
        tail in prop::collection::vec(any::<u8>(), 0..2048), mcap in any::<bool>(),
    ) {
        let mut bytes = if mcap { MCAP_MAGIC.to_vec() } else { ULOG_MAGIC.to_vec() };
        bytes.extend_from_slice(&tail);
        for r in readers() {
            let _ = r.read_bytes(&bytes);
        }
    }

    /// Real files with a few bytes overwritten and cut at a random length.
    #[test]
    fn damaged_real_files_never_panic(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        keep in any::<prop::sample::Index>(), ulog in any::<bool>(),
    ) {
        let Some(mut bytes) = (if ulog { ulog_head() } else { Some(fixture()) }) else {
            return Ok(());
        };
        for (at, value) in edits {
            let k = at.index(bytes.len());
            bytes[k] = value;
        }
        bytes.truncate(keep.index(bytes.len() + 1));
        for r in readers() {
            let _ = r.read_bytes(&bytes);
        }
    }
}
