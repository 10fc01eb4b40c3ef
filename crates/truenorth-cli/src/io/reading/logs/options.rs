//! The options that choose what a command reads from a PX4 ULog or ROS 2 MCAP log: its
//! topics, and whether a damaged end is read up to the damage.

use truenorth_logs::LogConfig;

use crate::io::{CliError, CliResult};

/// The options that choose what is read from a ULog or MCAP input (flattened into the
/// input options).
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct LogOptions {
    /// ULog/MCAP input: the gyro + accelerometer topic, as named in the file (ULog
    /// `NAME:INSTANCE` for another instance; default `sensor_combined`, or MCAP's
    /// `sensor_msgs/msg/Imu` topic with the most messages). `truenorth inspect` lists them.
    #[arg(long, value_name = "TOPIC")]
    pub imu_topic: Option<String>,
    /// ULog/MCAP input: the magnetometer topic, or `none` for no magnetometer (default:
    /// ULog `sensor_combined`, `vehicle_magnetometer` or `sensor_mag`, the first present;
    /// MCAP's `sensor_msgs/msg/MagneticField` topic with the most messages).
    #[arg(long, value_name = "TOPIC")]
    pub mag_topic: Option<String>,
    /// ULog/MCAP input: the logger's own attitude topic, listed by `inspect` (default ULog
    /// `vehicle_attitude`; MCAP none).
    #[arg(long, value_name = "TOPIC")]
    pub attitude_topic: Option<String>,
    /// MCAP input: the `nav_msgs/msg/Odometry` topic `drive` reads the speed and turn from
    /// (default: the one with the most messages).
    #[arg(long, value_name = "TOPIC")]
    pub odometry_topic: Option<String>,
    /// ULog/MCAP input: the satellite fixes' topic, listed by `inspect` (default ULog
    /// `vehicle_gps_position`, else `sensor_gps`; MCAP the `sensor_msgs/msg/NavSatFix` topic
    /// with the most messages, if any), or `none`.
    #[arg(long, value_name = "TOPIC")]
    pub gnss_topic: Option<String>,
    /// MCAP input: the receiver's velocity (`geometry_msgs/msg/TwistWithCovarianceStamped` or
    /// `TwistStamped`, east and north in linear x and y), taken as each fix's speed and course
    /// over ground (default: such a topic in the fixes' frame, if any), or `none`.
    #[arg(long, value_name = "TOPIC")]
    pub gnss_velocity_topic: Option<String>,
    /// ULog/MCAP input: read the messages before a truncated or damaged end (with a warning)
    /// instead of refusing the file.
    #[arg(long)]
    pub accept_incomplete: bool,
}

impl LogOptions {
    /// The log crate's configuration.
    pub fn config(&self) -> LogConfig {
        LogConfig {
            imu_topic: self.imu_topic.clone(),
            mag_topic: self.mag_topic.clone(),
            attitude_topic: self.attitude_topic.clone(),
            odometry_topic: self.odometry_topic.clone(),
            gnss_topic: self.gnss_topic.clone(),
            gnss_velocity_topic: self.gnss_velocity_topic.clone(),
            accept_incomplete: self.accept_incomplete,
        }
    }

    /// Refuses, in one line, any of these options given to `command`, which reads CSV files
    /// only (e.g. `eval broad`, whose trials are CSV).
    pub fn refuse_for_csv_only(&self, command: &str) -> CliResult {
        match self.given().first() {
            Some(flag) => Err(CliError::msg(format!(
                "{command} reads CSV files only, and {flag} applies to a PX4 ULog or MCAP log; leave it out"
            ))),
            None => Ok(()),
        }
    }

    /// The options given, by flag.
    pub fn given(&self) -> Vec<&'static str> {
        let mut given = Vec::new();
        for (flag, set) in [
            ("--imu-topic", self.imu_topic.is_some()),
            ("--mag-topic", self.mag_topic.is_some()),
            ("--attitude-topic", self.attitude_topic.is_some()),
            ("--odometry-topic", self.odometry_topic.is_some()),
            ("--gnss-topic", self.gnss_topic.is_some()),
            ("--gnss-velocity-topic", self.gnss_velocity_topic.is_some()),
            ("--accept-incomplete", self.accept_incomplete),
        ] {
            if set {
                given.push(flag);
            }
        }
        given
    }
}
