//! # truenorth-logs
//!
//! Flight and robot logs read as they come: PX4 ULog files (through PX4's `px4-ulog` crate)
//! and ROS 2 bags in MCAP (through Foxglove's `mcap` crate, CDR messages through
//! `cdr-encoding`) become the library's sample types in its frames and units: body axes
//! x forward, y right, z down, attitudes body → NED, gyro rad/s, specific force m/s²,
//! magnetic field µT, time in seconds. Each stream keeps its own timestamps, so a
//! magnetometer slower than the gyro stays so; [`Recording::imu_with_mag`] lays it on the
//! gyro's rows the way the `orientation` command reads them.
//!
//! Topics are chosen by name ([`LogConfig`]) or by the format's usual defaults
//! (`sensor_combined`, `vehicle_magnetometer`/`sensor_mag`, `vehicle_attitude` and
//! `vehicle_gps_position`/`sensor_gps` in ULog; the `sensor_msgs/msg/Imu`,
//! `sensor_msgs/msg/MagneticField` and `sensor_msgs/msg/NavSatFix` topics in MCAP, with the
//! receiver's velocity from a twist topic stamped in the fixes' frame); a topic asked for and
//! not present is an error that lists the topics the file has.
//!
//! ```
//! use truenorth_logs::{LogConfig, LogError, LogReader};
//!
//! let reader = LogReader::new(LogConfig::default())?;
//! // Bytes that are neither ULog nor MCAP are refused with a typed error, never a panic.
//! let err = reader.read_bytes(b"t_s,gyr_x\n0.0,0.1\n").unwrap_err();
//! assert!(matches!(err, LogError::UnknownFormat { .. }));
//!
//! // A missing topic names the topics the file has (here an MCAP file with none).
//! let mut empty = Vec::new();
//! mcap::Writer::new(std::io::Cursor::new(&mut empty))?.finish()?;
//! let err = reader.read_bytes(&empty).unwrap_err();
//! assert!(err.to_string().contains("topics present: none"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod config;
mod error;
pub mod frames;
mod mcap_ros;
mod recording;
pub mod ros_msgs;
mod ulog;
mod ulog_fields;

use std::panic::{AssertUnwindSafe, catch_unwind};

pub use config::LogConfig;
pub use error::{LogError, LogFormat, Result};
pub use recording::{AttitudeSample, GnssFix, OdometrySample, Recording, StreamInfo, TopicInfo};

/// Reads logs with one validated configuration.
#[derive(Debug, Clone)]
pub struct LogReader {
    config: LogConfig,
}

impl LogReader {
    /// A reader for `config`, validated once.
    pub fn new(config: LogConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self { config })
    }

    /// The configuration.
    pub fn config(&self) -> &LogConfig {
        &self.config
    }

    /// The format the bytes announce, from their magic number.
    pub fn detect(bytes: &[u8]) -> Result<LogFormat> {
        if bytes.starts_with(ulog::ULOG_MAGIC) {
            Ok(LogFormat::Ulog)
        } else if bytes.starts_with(mcap_ros::MCAP_MAGIC) {
            Ok(LogFormat::Mcap)
        } else {
            let found: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            Err(LogError::UnknownFormat {
                found: if found.is_empty() {
                    "nothing (empty)".to_string()
                } else {
                    found.join(" ")
                },
            })
        }
    }

    /// Reads a whole log held in memory (a file, standard input, a decompressed stream).
    pub fn read_bytes(&self, bytes: &[u8]) -> Result<Recording> {
        let format = Self::detect(bytes)?;
        // The readers promise not to panic on malformed input; should one break that
        // promise, the caller still gets an error naming the file as corrupt.
        let read = catch_unwind(AssertUnwindSafe(|| match format {
            LogFormat::Ulog => ulog::read(bytes, &self.config),
            LogFormat::Mcap => mcap_ros::read(bytes, &self.config),
        }));
        read.unwrap_or_else(|panic| {
            let detail = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "no message".to_string());
            Err(LogError::ReaderFault { format, detail })
        })
    }

    /// Reads the log at `path`.
    pub fn read_path(&self, path: impl AsRef<std::path::Path>) -> Result<Recording> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| LogError::Io {
            path: path.display().to_string(),
            source,
        })?;
        self.read_bytes(&bytes)
    }
}
