//! A store for the readings of a batch fit that keeps the first of them in memory and the
//! rest in an anonymous temporary file, so that a calibration's memory stays bounded
//! whatever the length of the recording (as `sort(1)` spills to disk).
//!
//! The fits pass over the readings several times; the store replays them in the order they
//! came, in runs whose lengths are multiples of [`READINGS_RUN_MULTIPLE`], so the fit is the
//! same, bit for bit, as with every reading in memory (see
//! [`Readings`]). The file is created in the temporary directory
//! (`std::env::temp_dir()`: `TMPDIR` on Unix) under a fresh name and removed from the
//! directory at once: the open file lives on until the process ends, and nothing is left
//! behind however it ends (killed included). It is made only once the readings outgrow
//! the memory share, so a short recording never touches the disk.
//!
//! A write or a read that fails (a full disk, an unwritable directory) is one error line
//! naming the directory and saying to point `TMPDIR` at a disk with room: the store keeps
//! the first such failure in the [`ReadingSpill`] it came from, for the command to report
//! in place of the library's error, which the store hands the fit to stop it
//! ([`truenorth::core::Error::ReadingsUnavailable`]) and which cannot carry the I/O error's text.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use nalgebra::SVector;
use truenorth::calib::{READINGS_RUN_MULTIPLE, ReadingStore, Readings};
use truenorth::core::{Error, Result};

use super::CliError;

/// Memory the readings of one fit may take before the rest go to the temporary file.
pub const SPILL_MEMORY_BYTES: usize = 32 << 20;

/// Environment variable that overrides [`SPILL_MEMORY_BYTES`] (bytes), for tests that need a
/// recording to spill without writing a large file.
pub const SPILL_MEMORY_ENV: &str = "TRUENORTH_TEST_SPILL_MEMORY_BYTES";

/// The most one fit's readings may take on disk: 2 GiB, over a week of a 2-D compass at
/// 100 Hz — far beyond the minutes of turning a calibration needs, so a larger input (a
/// gzip bomb, a day-long log given whole) is refused rather than filling the disk.
pub const SPILL_DISK_BYTES: usize = 2 << 30;

/// Environment variable that overrides [`SPILL_DISK_BYTES`] (bytes), for tests.
pub const SPILL_DISK_ENV: &str = "TRUENORTH_TEST_SPILL_DISK_BYTES";

/// Readings per chunk of the file: written a chunk at a time and read back a chunk at a
/// time into a buffer of each replay (a multiple of [`READINGS_RUN_MULTIPLE`]).
const CHUNK_READINGS: usize = 1 << 15;

/// The reason the store gives the library when the disk fails it (the command reports the
/// failure kept in [`ReadingSpill`] instead).
const STOPPED: Error = Error::ReadingsUnavailable {
    reason: "they were kept in a temporary file; set TMPDIR to a directory on a disk with room",
};

/// Where the stores of one command spill, how much they keep in memory, and the first
/// failure any of them met.
#[derive(Debug, Clone)]
pub struct ReadingSpill {
    dir: PathBuf,
    memory_bytes: usize,
    disk_bytes: usize,
    failure: Arc<Mutex<Option<String>>>,
}

impl ReadingSpill {
    /// Spilling to the temporary directory past [`SPILL_MEMORY_BYTES`] (or the bytes in
    /// [`SPILL_MEMORY_ENV`], when set to a number).
    /// The disk takes at most [`SPILL_DISK_BYTES`] (or the bytes in [`SPILL_DISK_ENV`]).
    pub fn from_env() -> Self {
        let bytes = |name: &str, default: usize| {
            std::env::var(name)
                .ok()
                .and_then(|v| v.trim().parse().ok())
                .unwrap_or(default)
        };
        let mut spill = Self::new(
            std::env::temp_dir(),
            bytes(SPILL_MEMORY_ENV, SPILL_MEMORY_BYTES),
        );
        spill.disk_bytes = bytes(SPILL_DISK_ENV, SPILL_DISK_BYTES);
        spill
    }

    /// Spilling to `dir` past `memory_bytes` of readings, up to [`SPILL_DISK_BYTES`].
    pub fn new(dir: PathBuf, memory_bytes: usize) -> Self {
        Self {
            dir,
            memory_bytes,
            disk_bytes: SPILL_DISK_BYTES,
            failure: Arc::new(Mutex::new(None)),
        }
    }

    /// An empty store of `D`-dimensional readings.
    pub fn store<const D: usize>(&self) -> SpillStore<D> {
        let per_reading = D * size_of::<f64>();
        let fit = self.memory_bytes / per_reading.max(1);
        SpillStore {
            spill: self.clone(),
            memory: Vec::new(),
            memory_readings: fit - fit % READINGS_RUN_MULTIPLE,
            file: None,
            on_disk: 0,
            pending: Vec::new(),
            read_buffers: Mutex::new(Vec::new()),
        }
    }

    /// The first failure of a store, as the command's error line (taken: a second call
    /// gives `None`).
    pub fn take_failure(&self) -> Option<CliError> {
        self.failure
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
            .map(CliError::msg)
    }

    /// Keeps the first failure, `doing` what on which error.
    fn fail(&self, doing: &str, e: &io::Error) -> Error {
        self.keep(format!(
            "cannot {doing} the readings kept for the fit in a temporary file in {}: {e}; set TMPDIR to a directory on a disk with room",
            self.dir.display()
        ))
    }

    /// Keeps `failure` if it is the first.
    fn keep(&self, message: String) -> Error {
        let mut failure = self.failure.lock().unwrap_or_else(PoisonError::into_inner);
        if failure.is_none() {
            *failure = Some(message);
        }
        STOPPED
    }
}

/// Readings in memory up to a share, the rest in an anonymous temporary file (see the
/// module documentation).
#[derive(Debug)]
pub struct SpillStore<const D: usize> {
    spill: ReadingSpill,
    /// The first readings (at most `memory_readings`).
    memory: Vec<SVector<f64, D>>,
    /// How many readings stay in memory: a multiple of [`READINGS_RUN_MULTIPLE`].
    memory_readings: usize,
    /// The file, once the memory share is full.
    file: Option<File>,
    /// Readings written to the file (whole chunks).
    on_disk: usize,
    /// Readings after the memory share not yet written (less than a chunk).
    pending: Vec<SVector<f64, D>>,
    /// Buffers to read chunks back into, kept between replays (a fresh chunk-sized
    /// buffer would be fresh pages from the system for every range every pass); one per
    /// replay running at once.
    read_buffers: Mutex<Vec<Vec<SVector<f64, D>>>>,
}

impl<const D: usize> SpillStore<D> {
    /// Whether the readings went beyond memory.
    pub fn spilled(&self) -> bool {
        self.on_disk > 0 || !self.pending.is_empty()
    }

    /// Writes the pending chunk to the file (made on the first chunk).
    fn write_pending(&mut self) -> io::Result<()> {
        let file = match &mut self.file {
            Some(f) => f,
            None => self.file.insert(anonymous_file(&self.spill.dir)?),
        };
        // The readings' own bytes: the same process reads them back.
        file.write_all(bytemuck::cast_slice(&self.pending))?;
        self.on_disk += self.pending.len();
        self.pending.clear();
        Ok(())
    }

    /// Reads back the readings `from..to` of the file into `chunk`.
    fn read_back(
        &self,
        from: usize,
        to: usize,
        chunk: &mut Vec<SVector<f64, D>>,
    ) -> io::Result<()> {
        let Some(file) = &self.file else {
            return Err(io::Error::other("the temporary file is missing"));
        };
        chunk.clear();
        chunk.resize(to - from, SVector::zeros());
        let offset = (from * size_of::<SVector<f64, D>>()) as u64;
        read_exact_at(file, bytemuck::cast_slice_mut(chunk), offset)
    }
}

impl<const D: usize> Readings<D> for SpillStore<D> {
    fn len(&self) -> usize {
        self.memory.len() + self.on_disk + self.pending.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[SVector<f64, D>])) -> Result<()> {
        self.replay_range(0, Readings::len(self), run)
    }

    /// The readings `start..end` from memory, the file and the pending chunk, in runs cut
    /// where those meet and at the file's chunks, each but the last a multiple of
    /// [`READINGS_RUN_MULTIPLE`] (`start`, the memory share and the chunks are). Each call
    /// reads through buffers of its own, so threads may replay ranges at once.
    fn replay_range(
        &self,
        start: usize,
        end: usize,
        run: &mut dyn FnMut(&[SVector<f64, D>]),
    ) -> Result<()> {
        let end = end.min(Readings::len(self));
        let (memory, disk_end) = (self.memory.len(), self.memory.len() + self.on_disk);
        if start < end.min(memory) {
            run(&self.memory[start..end.min(memory)]);
        }
        let (mut at, to) = (start.max(memory), end.min(disk_end));
        if at < to {
            let mut pool = self
                .read_buffers
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            let mut chunk = pool.pop().unwrap_or_default();
            drop(pool);
            while at < to {
                // Up to the end of the chunk `at` is in, or of the range.
                let from = at - memory;
                let next = (from / CHUNK_READINGS + 1) * CHUNK_READINGS;
                let upto = (to - memory).min(next);
                let read = self.read_back(from, upto, &mut chunk);
                if let Err(e) = read {
                    return Err(self.spill.fail("read back", &e));
                }
                run(&chunk);
                at = memory + upto;
            }
            self.read_buffers
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push(chunk);
        }
        let at = start.max(disk_end);
        if at < end {
            run(&self.pending[at - disk_end..end - disk_end]);
        }
        Ok(())
    }

    fn shared(&self) -> Option<&(dyn Readings<D> + Sync)> {
        Some(self)
    }
}

impl<const D: usize> ReadingStore<D> for SpillStore<D> {
    fn push(&mut self, reading: SVector<f64, D>) -> Result<()> {
        if self.memory.len() < self.memory_readings {
            if self.memory.len() == self.memory.capacity() {
                // Grow by doubling, but never past the share (a plain `push` could
                // reserve up to twice it).
                let want = (2 * self.memory.len()).max(64).min(self.memory_readings);
                self.memory.reserve_exact(want - self.memory.len());
            }
            self.memory.push(reading);
            return Ok(());
        }
        if self.pending.capacity() == 0 {
            self.pending.reserve_exact(CHUNK_READINGS);
        }
        self.pending.push(reading);
        if self.pending.len() == CHUNK_READINGS {
            let on_disk = (self.on_disk + CHUNK_READINGS) * size_of::<SVector<f64, D>>();
            if on_disk > self.spill.disk_bytes {
                return Err(self.spill.keep(format!(
                    "more than {} readings for one fit ({} MB beyond memory): a calibration needs minutes of turning, not this much; give it the stretch of the recording with the turns",
                    Readings::len(self),
                    self.spill.disk_bytes >> 20
                )));
            }
            self.write_pending()
                .map_err(|e| self.spill.fail("write", &e))?;
        }
        Ok(())
    }

    fn clear(&mut self) {
        self.memory = Vec::new();
        self.pending = Vec::new();
        // A new file for the next readings; this one goes with its handle.
        self.file = None;
        self.on_disk = 0;
        self.read_buffers
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
            .clear();
    }
}

/// A new file in `dir`, open for reading and writing, already removed from the directory.
fn anonymous_file(dir: &std::path::Path) -> io::Result<File> {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    for _ in 0..16 {
        let name = format!(
            ".truenorth-readings-{}-{nanos:08x}-{}",
            std::process::id(),
            COUNT.fetch_add(1, Ordering::Relaxed)
        );
        let path = dir.join(name);
        let mut options = OpenOptions::new();
        options.read(true).write(true).create_new(true);
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
        match options.open(&path) {
            Ok(file) => {
                // Gone from the directory at once; the open handle keeps the data (on
                // systems that refuse to remove an open file, it stays until the end).
                let _ = std::fs::remove_file(&path);
                return Ok(file);
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::AlreadyExists,
        "no free temporary file name",
    ))
}

/// Reads `buf.len()` bytes of `file` at `offset`, without moving its cursor.
#[cfg(unix)]
fn read_exact_at(file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
}

/// Reads `buf.len()` bytes of `file` at `offset`.
#[cfg(windows)]
fn read_exact_at(file: &File, mut buf: &mut [u8], mut offset: u64) -> io::Result<()> {
    while !buf.is_empty() {
        match std::os::windows::fs::FileExt::seek_read(file, buf, offset) {
            Ok(0) => return Err(io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => {
                buf = &mut buf[n..];
                offset += n as u64;
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]

        /// Any range of readings comes back, in order, in runs that are multiples of the
        /// run length but the last, whether it starts or ends in memory, in the file or in
        /// the pending chunk; and the store offers itself to threads.
        #[test]
        fn replays_any_range(
            n in 0usize..100_000,
            memory in prop_oneof![0usize..2_000, 0usize..200_000],
            start in 0usize..4_000,
            len in 0usize..100_000,
        ) {
            let spill = ReadingSpill::new(std::env::temp_dir(), memory);
            let mut store = spill.store::<2>();
            for k in 0..n {
                store.push(SVector::<f64, 2>::new(k as f64, -(k as f64))).unwrap();
            }
            prop_assert!(store.shared().is_some());
            let start = (start * READINGS_RUN_MULTIPLE).min(n - n % READINGS_RUN_MULTIPLE);
            let end = (start + len).min(n);
            let mut next = start;
            let mut last_short = false;
            store
                .replay_range(start, end, &mut |run| {
                    assert!(!last_short, "a short run before the last");
                    assert!(!run.is_empty(), "an empty run");
                    last_short = run.len() % READINGS_RUN_MULTIPLE != 0;
                    for p in run {
                        assert_eq!(p.x, next as f64);
                        next += 1;
                    }
                })
                .unwrap();
            prop_assert_eq!(next, end.max(start));
        }

        /// Every reading comes back, in order, in runs that are multiples of the run
        /// length but the last, whatever the memory share.
        #[test]
        fn replays_in_order(n in 0usize..100_000, memory in prop_oneof![0usize..2_000, 0usize..200_000]) {
            let spill = ReadingSpill::new(std::env::temp_dir(), memory);
            let mut store = spill.store::<3>();
            for k in 0..n {
                let x = k as f64;
                store.push(Vector3::new(x, -x, 0.5 * x)).unwrap();
            }
            prop_assert_eq!(Readings::len(&store), n);
            // The memory held is bounded whatever `n`: the share (at least one block of
            // 64 readings) and one chunk of the file, never more.
            let per_reading = size_of::<Vector3<f64>>();
            prop_assert!(store.memory.capacity() <= (memory / per_reading).max(64));
            prop_assert!(store.pending.capacity() <= CHUNK_READINGS);
            let mut seen = 0usize;
            let mut last_short = false;
            store
                .replay(&mut |run| {
                    assert!(!last_short, "a short run before the last");
                    last_short = run.len() % READINGS_RUN_MULTIPLE != 0;
                    for p in run {
                        let x = seen as f64;
                        assert_eq!(*p, Vector3::new(x, -x, 0.5 * x));
                        seen += 1;
                    }
                })
                .unwrap();
            prop_assert_eq!(seen, n);
            prop_assert!(spill.take_failure().is_none());
        }
    }

    #[test]
    fn an_unwritable_directory_is_one_error_naming_it() {
        let dir = std::env::temp_dir().join("truenorth-no-such-directory-for-readings");
        let spill = ReadingSpill::new(dir.clone(), 0);
        let mut store = spill.store::<2>();
        let mut result = Ok(());
        for _ in 0..CHUNK_READINGS {
            result = store.push(SVector::<f64, 2>::new(1.0, 2.0));
            if result.is_err() {
                break;
            }
        }
        assert_eq!(result, Err(STOPPED));
        let e = spill.take_failure().unwrap().to_string();
        assert!(e.contains(&dir.display().to_string()), "{e}");
        assert!(e.contains("TMPDIR"), "{e}");
    }
}
