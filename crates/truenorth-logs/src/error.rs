//! What can go wrong reading a log, each case saying what was found and what to do.

use thiserror::Error;

/// The log formats this crate reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum LogFormat {
    /// PX4 ULog (`.ulg`).
    Ulog,
    /// MCAP (`.mcap`) with ROS 2 messages in CDR.
    Mcap,
}

impl core::fmt::Display for LogFormat {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Ulog => "PX4 ULog",
            Self::Mcap => "MCAP",
        })
    }
}

/// An error reading a log.
#[derive(Debug, Error)]
pub enum LogError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path given.
        path: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The bytes start with neither the ULog nor the MCAP magic.
    #[error(
        "not a PX4 ULog or MCAP file (it starts with {found}); give a .ulg file from a PX4 \
         vehicle or a ROS 2 bag recorded with the MCAP storage plugin"
    )]
    UnknownFormat {
        /// The first bytes, in hex.
        found: String,
    },
    /// The header or the message definitions are damaged: nothing in the file is usable.
    #[error("{format} file is corrupt before its first sample: {detail}")]
    Corrupt {
        /// The format the magic announced.
        format: LogFormat,
        /// The reader's description of the fault.
        detail: String,
    },
    /// The data ends early or has a damaged record after `messages` good ones.
    #[error(
        "{format} file is incomplete after {messages} messages ({detail}); set \
         `accept_incomplete` to keep the messages before the damage"
    )]
    Incomplete {
        /// The format.
        format: LogFormat,
        /// Messages read before the damage.
        messages: usize,
        /// How the data ended.
        detail: String,
    },
    /// A requested topic (or, with none requested, the default) is not in the log.
    #[error(
        "no {role} topic `{requested}` in the log; topics present: {}",
        list(present)
    )]
    MissingTopic {
        /// What the topic was wanted for (`imu`, `mag`, `attitude`, `odometry`).
        role: &'static str,
        /// The name asked for (or the defaults tried).
        requested: String,
        /// Every topic in the log with its type and message count.
        present: Vec<String>,
    },
    /// A topic exists but does not carry what its role needs.
    #[error("topic `{topic}` cannot serve as {role}: {detail}")]
    WrongTopicType {
        /// The topic.
        topic: String,
        /// The role it was asked to fill.
        role: &'static str,
        /// What it lacks (fields, message type or encoding).
        detail: String,
    },
    /// One message of a selected topic could not be decoded.
    #[error("message {index} of topic `{topic}` cannot be decoded: {detail}")]
    Decode {
        /// The topic.
        topic: String,
        /// Zero-based index of the message within the topic.
        index: usize,
        /// The decoder's reason.
        detail: String,
    },
    /// The reader library failed in a way it should have reported as an error.
    #[error("the {format} reader failed on this file ({detail}); the file is likely corrupt")]
    ReaderFault {
        /// The format.
        format: LogFormat,
        /// What the reader said.
        detail: String,
    },
    /// A configuration field is invalid.
    #[error("invalid log configuration: {field} {reason}")]
    InvalidConfig {
        /// The field.
        field: &'static str,
        /// What is wrong with it and what it should be.
        reason: String,
    },
}

fn list(present: &[String]) -> String {
    if present.is_empty() {
        "none".to_string()
    } else {
        present.join(", ")
    }
}

/// Result with [`LogError`].
pub type Result<T> = core::result::Result<T, LogError>;
