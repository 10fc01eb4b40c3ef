//! Which topics to read and how strictly: the validated configuration of [`crate::LogReader`].

use serde::{Deserialize, Serialize};

use crate::error::{LogError, Result};

/// What to read from a log. Every topic is optional: left out, the reader takes the format's
/// usual topic (see each field). Unknown fields are refused so that a misspelt option is not
/// silently ignored.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LogConfig {
    /// The gyro + accelerometer topic. ULog: a topic with `gyro_rad[3]` and
    /// `accelerometer_m_s2[3]` (default `sensor_combined`); MCAP: a `sensor_msgs/msg/Imu`
    /// topic (default: the one with the most messages). A ULog topic logged in several
    /// instances is named `topic:N` (default instance 0).
    pub imu_topic: Option<String>,
    /// The magnetometer topic. ULog: `sensor_combined` (older logs carry `magnetometer_ga`
    /// there), `vehicle_magnetometer` or `sensor_mag`, the first of them present by default;
    /// MCAP: a `sensor_msgs/msg/MagneticField` topic (default: the one with the most
    /// messages). `none` reads no magnetometer.
    pub mag_topic: Option<String>,
    /// The topic with the logger's own attitude estimate, kept for comparison. ULog:
    /// `vehicle_attitude` (`q[4]`) by default; MCAP: none by default (a
    /// `sensor_msgs/msg/Imu` topic's orientation or a `nav_msgs/msg/Odometry` pose when named).
    pub attitude_topic: Option<String>,
    /// MCAP only: the `nav_msgs/msg/Odometry` topic for the body's forward speed and yaw rate
    /// (default: the one with the most messages, if any).
    pub odometry_topic: Option<String>,
    /// The satellite fixes. ULog: a topic with `latitude_deg`/`longitude_deg` or `lat`/`lon`
    /// (`vehicle_gps_position`, else `sensor_gps`, by default); MCAP: a
    /// `sensor_msgs/msg/NavSatFix` topic (default: the one with the most messages, if any).
    /// `none` reads no fixes.
    pub gnss_topic: Option<String>,
    /// MCAP only: the receiver's velocity, a `geometry_msgs/msg/TwistWithCovarianceStamped` or
    /// `geometry_msgs/msg/TwistStamped` topic with east and north in its linear x and y (ENU,
    /// as `ublox_gps`'s `fix_velocity` and `nmea_navsat_driver`'s `vel` publish it). Each fix
    /// takes the velocity stamped nearest to it, within half the time to its neighbouring
    /// fixes and at most 0.5 s, as its speed and course over ground. Default: of the topics
    /// of those types whose frame (`header.frame_id`) is the fixes' own, the one with the
    /// most messages, if any; a twist in another frame (a body's `cmd_vel`) is never taken
    /// unless named. `none` reads no velocity. A ULog's fixes carry their velocity.
    pub gnss_velocity_topic: Option<String>,
    /// Keep the messages before a truncated or damaged tail instead of refusing the file
    /// (default `false`: a log cut off by a power loss is reported, not read silently).
    pub accept_incomplete: bool,
}

/// A topic asked for: its name and, for ULog, its instance (multi id).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct TopicSpec {
    pub name: String,
    pub instance: u8,
}

impl TopicSpec {
    /// Splits `name:N` (ULog instances); a name without a numeric suffix is instance 0.
    pub(crate) fn parse(spec: &str) -> Self {
        if let Some((name, n)) = spec.rsplit_once(':')
            && let Ok(instance) = n.parse::<u8>()
        {
            return Self {
                name: name.to_string(),
                instance,
            };
        }
        Self {
            name: spec.to_string(),
            instance: 0,
        }
    }

    pub(crate) fn plain(name: &str) -> Self {
        Self {
            name: name.to_string(),
            instance: 0,
        }
    }
}

/// The magnetometer's topic choice.
pub(crate) const NO_TOPIC: &str = "none";

impl LogConfig {
    /// Checks every named topic: not empty, no control characters or surrounding spaces
    /// (a topic name pasted with a newline would never match).
    pub fn validate(&self) -> Result<()> {
        for (field, value) in [
            ("imu_topic", &self.imu_topic),
            ("mag_topic", &self.mag_topic),
            ("attitude_topic", &self.attitude_topic),
            ("odometry_topic", &self.odometry_topic),
            ("gnss_topic", &self.gnss_topic),
            ("gnss_velocity_topic", &self.gnss_velocity_topic),
        ] {
            if let Some(name) = value {
                if name.is_empty() {
                    return Err(LogError::InvalidConfig {
                        field,
                        reason: "is empty; leave it out for the default topic".to_string(),
                    });
                }
                if name.trim() != name || name.chars().any(char::is_control) {
                    return Err(LogError::InvalidConfig {
                        field,
                        reason: format!(
                            "{name:?} has surrounding spaces or control characters; give the \
                             topic name exactly"
                        ),
                    });
                }
            }
        }
        if self.imu_topic.as_deref() == Some(NO_TOPIC) {
            return Err(LogError::InvalidConfig {
                field: "imu_topic",
                reason: "cannot be `none`: every reading needs the gyro".to_string(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_spec_reads_instances_and_plain_names() {
        assert_eq!(
            TopicSpec::parse("sensor_mag:1"),
            TopicSpec {
                name: "sensor_mag".into(),
                instance: 1
            }
        );
        assert_eq!(TopicSpec::parse("/imu/data"), TopicSpec::plain("/imu/data"));
        assert_eq!(TopicSpec::parse("a:b"), TopicSpec::plain("a:b"));
    }

    #[test]
    fn validation_refuses_empty_and_padded_names() {
        assert!(LogConfig::default().validate().is_ok());
        let empty = LogConfig {
            imu_topic: Some(String::new()),
            ..LogConfig::default()
        };
        assert!(matches!(
            empty.validate(),
            Err(LogError::InvalidConfig {
                field: "imu_topic",
                ..
            })
        ));
        let padded = LogConfig {
            mag_topic: Some("/mag\n".into()),
            ..LogConfig::default()
        };
        assert!(padded.validate().is_err());
        let none = LogConfig {
            imu_topic: Some("none".into()),
            ..LogConfig::default()
        };
        assert!(none.validate().is_err());
        let json: std::result::Result<LogConfig, _> = serde_json::from_str(r#"{"imu_topik": "x"}"#);
        assert!(json.is_err(), "a misspelt field is refused");
    }
}
