//! Write-behind: a file whose written bytes are flushed to the disk by another thread while
//! more are written, so that the sync that must precede the rename of a finished output
//! (see `atomic_write`) finds little left to flush.
//!
//! Without it, every byte of a large output waits in the page cache until that final sync,
//! which then writes them all while nothing else runs: a quarter of a second of `heading`'s
//! 0.85 s for 300 MB, measured with `scripts/io_speed.sh`. Syncing what is already written,
//! every [`SYNC_BYTES`], overlaps that device time with the computing of the rows after it.
//!
//! A sync is asked for, never waited on: a request made while the previous one still runs
//! is merged into the next, so the writer never blocks on the disk before the end. The
//! first error of a background sync is kept and returned by [`WriteBehind::finish`]: the
//! kernel reports a failed write-back once per open file, so the final sync on the same
//! file might not see it again.

use std::fs::File;
use std::io::Write;
use std::sync::mpsc::{SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

/// Bytes written between two requests to sync (32 MiB): large enough that a sync per
/// request costs the writer nothing beside the rows, small enough that what is left for the
/// final sync is a fraction of an output of hundreds of megabytes.
pub const SYNC_BYTES: u64 = 32 << 20;

/// A file being written whose data another thread syncs as it grows.
pub struct WriteBehind {
    /// `None` once [`WriteBehind::finish`] has taken it.
    file: Option<File>,
    /// Bytes written since the last request.
    unsynced: u64,
    /// The way to the syncing thread and the thread; `None` where it could not be started
    /// (the file is then synced at the end only).
    syncer: Option<(SyncSender<()>, JoinHandle<std::io::Result<()>>)>,
}

impl WriteBehind {
    /// Starts syncing `file` behind its writes; a file whose handle cannot be duplicated, or
    /// a thread that cannot be started, is written as it is and synced at the end only.
    pub fn new(file: File) -> Self {
        let syncer = file.try_clone().ok().and_then(|behind| {
            // One request waits while a sync runs; more are merged into it.
            let (requests, asked) = sync_channel::<()>(1);
            std::thread::Builder::new()
                .name("sync".into())
                .spawn(move || {
                    let mut first_error = Ok(());
                    while asked.recv().is_ok() {
                        if let Err(e) = behind.sync_data()
                            && first_error.is_ok()
                        {
                            first_error = Err(e);
                        }
                    }
                    first_error
                })
                .ok()
                .map(|thread| (requests, thread))
        });
        Self {
            file: Some(file),
            unsynced: 0,
            syncer,
        }
    }

    /// Stops the syncing thread (after the sync it is running) and returns the file, or the
    /// first error a background sync met.
    pub fn finish(mut self) -> std::io::Result<File> {
        self.stop()?;
        self.file
            .take()
            .ok_or_else(|| std::io::Error::other("finished twice"))
    }

    /// Closes the way to the syncing thread and waits for it to end.
    fn stop(&mut self) -> std::io::Result<()> {
        match self.syncer.take() {
            Some((requests, thread)) => {
                drop(requests);
                thread
                    .join()
                    .map_err(|_| std::io::Error::other("the syncing thread failed"))?
            }
            None => Ok(()),
        }
    }

    fn file(&mut self) -> std::io::Result<&mut File> {
        self.file
            .as_mut()
            .ok_or_else(|| std::io::Error::other("written after it was finished"))
    }
}

impl Write for WriteBehind {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let n = self.file()?.write(bytes)?;
        self.unsynced += n as u64;
        if self.unsynced >= SYNC_BYTES {
            self.unsynced = 0;
            if let Some((requests, _)) = &self.syncer
                && let Err(TrySendError::Disconnected(())) = requests.try_send(())
            {
                // The thread is gone (it cannot fail before the channel closes); the
                // final sync does all the work.
                self.syncer = None;
            }
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file()?.flush()
    }
}

impl Drop for WriteBehind {
    /// An abandoned output stops its syncing thread too (after the sync it is running), so
    /// that no thread outlives the file it syncs.
    fn drop(&mut self) {
        let _ = self.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn what_is_written_is_in_the_file_after_finish() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out");
        let mut w = WriteBehind::new(File::create(&path).unwrap());
        // Over two sync requests' worth, in pieces that do not divide it.
        let piece: Vec<u8> = (0..=250u8).collect();
        let pieces = (2 * SYNC_BYTES as usize) / piece.len() + 3;
        for _ in 0..pieces {
            w.write_all(&piece).unwrap();
        }
        let file = w.finish().unwrap();
        file.sync_all().unwrap();
        let mut back = Vec::new();
        File::open(&path).unwrap().read_to_end(&mut back).unwrap();
        assert_eq!(back.len(), pieces * piece.len());
        assert!(back.chunks(piece.len()).all(|c| c == piece.as_slice()));
    }
}
