//! What the log readers' tests share: reading a cut log both ways.

use truenorth_logs::{LogConfig, LogError, LogReader, Recording};

/// A reader that keeps what a cut log holds up to the cut.
pub fn lenient() -> LogReader {
    LogReader::new(LogConfig {
        accept_incomplete: true,
        ..LogConfig::default()
    })
    .unwrap()
}

/// `cut` (a log cut short after its definitions) read both ways: refused as incomplete by
/// default, and its prefix kept with `accept_incomplete`, which is returned.
pub fn refused_or_prefix_kept(cut: &[u8]) -> Recording {
    let strict = LogReader::new(LogConfig::default())
        .unwrap()
        .read_bytes(cut);
    assert!(
        matches!(strict, Err(LogError::Incomplete { .. })),
        "{strict:?}"
    );
    lenient().read_bytes(cut).unwrap()
}
