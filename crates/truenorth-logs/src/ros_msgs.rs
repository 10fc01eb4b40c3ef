//! The ROS 2 messages this crate reads, laid out field for field as their `.msg` definitions
//! (`sensor_msgs/msg/Imu`, `sensor_msgs/msg/MagneticField`, `nav_msgs/msg/Odometry`,
//! `sensor_msgs/msg/NavSatFix`, `geometry_msgs/msg/TwistStamped`,
//! `geometry_msgs/msg/TwistWithCovarianceStamped` and the `std_msgs` / `geometry_msgs` types
//! inside them), and their CDR decoding through the
//! `cdr-encoding` crate. A serialized ROS 2 message is a 4-byte encapsulation header (its
//! second byte 0 for big-endian, 1 for little-endian plain CDR; OMG DDS-XTypes 1.3, 7.6.3.1.2)
//! followed by the CDR body, aligned from the body's first byte.

use byteorder::{BigEndian, LittleEndian};
use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds (Unix time for wall-clock stamps).
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

impl Time {
    /// Seconds as `f64`.
    pub fn seconds(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// When the data were taken.
    pub stamp: Time,
    /// The frame the data are expressed in.
    pub frame_id: String,
}

/// `geometry_msgs/msg/Vector3` (also the layout of `geometry_msgs/msg/Point`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vec3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion` (vector part first, scalar last).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Quat {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w (the scalar part).
    pub w: f64,
}

/// `sensor_msgs/msg/Imu`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu {
    /// Stamp and frame.
    pub header: Header,
    /// Orientation, body FLU → ENU (REP-103); meaningless when `orientation_covariance[0]`
    /// is −1.
    pub orientation: Quat,
    /// Row-major 3×3 covariance; −1 first means "no orientation".
    pub orientation_covariance: [f64; 9],
    /// Angular velocity, rad/s, body axes.
    pub angular_velocity: Vec3,
    /// Row-major 3×3 covariance.
    pub angular_velocity_covariance: [f64; 9],
    /// Specific force, m/s², body axes.
    pub linear_acceleration: Vec3,
    /// Row-major 3×3 covariance.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/msg/MagneticField`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MagneticField {
    /// Stamp and frame.
    pub header: Header,
    /// Field, tesla, body axes.
    pub magnetic_field: Vec3,
    /// Row-major 3×3 covariance.
    pub magnetic_field_covariance: [f64; 9],
}

/// `sensor_msgs/msg/NavSatStatus`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatStatus {
    /// −1 no fix, 0 fix, 1 with satellite augmentation, 2 with ground augmentation.
    pub status: i8,
    /// The constellations used (bit field).
    pub service: u16,
}

/// `sensor_msgs/msg/NavSatFix`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatFix {
    /// Stamp and frame.
    pub header: Header,
    /// Whether there is a fix.
    pub status: NavSatStatus,
    /// Latitude, degrees (WGS84), north positive.
    pub latitude: f64,
    /// Longitude, degrees (WGS84), east positive.
    pub longitude: f64,
    /// Altitude above the WGS84 ellipsoid, m.
    pub altitude: f64,
    /// Row-major 3×3 covariance of the position in east, north, up, m².
    pub position_covariance: [f64; 9],
    /// 0 unknown, 1 approximated, 2 diagonal known, 3 known.
    pub position_covariance_type: u8,
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position (`geometry_msgs/msg/Point`).
    pub position: Vec3,
    /// Orientation.
    pub orientation: Quat,
}

/// `geometry_msgs/msg/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity, m/s.
    pub linear: Vec3,
    /// Angular velocity, rad/s.
    pub angular: Vec3,
}

/// A row-major 6×6 covariance (serde derives arrays up to 32 elements, so six rows of six).
pub type Covariance6 = [[f64; 6]; 6];

/// `geometry_msgs/msg/PoseWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance.
    pub covariance: Covariance6,
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Its covariance.
    pub covariance: Covariance6,
}

/// `geometry_msgs/msg/TwistStamped` (a GNSS driver's velocity, e.g. `nmea_navsat_driver`'s
/// `vel`, east and north in `linear.x`, `linear.y`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The twist.
    pub twist: Twist,
}

/// `geometry_msgs/msg/TwistWithCovarianceStamped` (a GNSS driver's velocity, e.g.
/// `ublox_gps`'s `fix_velocity`, east and north in `twist.twist.linear.x`, `.y`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovarianceStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The twist and its covariance.
    pub twist: TwistWithCovariance,
}

/// `nav_msgs/msg/Odometry`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// Stamp and the pose's frame.
    pub header: Header,
    /// The frame of the twist (the body).
    pub child_frame_id: String,
    /// Pose of the body in `header.frame_id` (FLU → ENU for a REP-103 world frame).
    pub pose: PoseWithCovariance,
    /// Velocity of the body in `child_frame_id`.
    pub twist: TwistWithCovariance,
}

/// Decodes one serialized ROS 2 message (encapsulation header + plain CDR body).
pub fn decode<'de, T: Deserialize<'de>>(data: &'de [u8]) -> Result<T, String> {
    let (header, body) = match data {
        [a, b, _, _, body @ ..] => ([*a, *b], body),
        _ => return Err(format!("{} bytes, shorter than the CDR header", data.len())),
    };
    let decoded = match header {
        [0, 0] => cdr_encoding::from_bytes::<T, BigEndian>(body),
        [0, 1] => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        _ => {
            return Err(format!(
                "representation {:#04x}{:02x} is not plain CDR",
                header[0], header[1]
            ));
        }
    };
    decoded.map(|(m, _)| m).map_err(|e| e.to_string())
}

/// Serializes a message as ROS 2 does: little-endian plain CDR after its header.
pub fn encode<T: Serialize>(message: &T) -> Result<Vec<u8>, String> {
    let body = cdr_encoding::to_vec::<T, LittleEndian>(message).map_err(|e| e.to_string())?;
    let mut out = vec![0, 1, 0, 0];
    out.extend_from_slice(&body);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-laid `MagneticField`: the string `"m"` (length 2 with its NUL), padding to the
    /// 8-byte alignment of the doubles, counted from the body's start.
    #[test]
    fn decodes_a_known_layout() {
        let mut bytes = vec![0u8, 1, 0, 0];
        bytes.extend_from_slice(&7i32.to_le_bytes());
        bytes.extend_from_slice(&5u32.to_le_bytes());
        bytes.extend_from_slice(&2u32.to_le_bytes());
        bytes.extend_from_slice(b"m\0");
        bytes.extend_from_slice(&[0; 2]); // body offset 14 → 16
        for v in [1.5f64, -2.0, 3.25].iter().chain(&[0.0; 9]) {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let m: MagneticField = decode(&bytes).unwrap();
        assert_eq!(m.header.stamp, Time { sec: 7, nanosec: 5 });
        assert_eq!(m.header.frame_id, "m");
        assert_eq!(
            m.magnetic_field,
            Vec3 {
                x: 1.5,
                y: -2.0,
                z: 3.25
            }
        );
        assert_eq!(encode(&m).unwrap(), bytes);
    }

    #[test]
    fn refuses_other_representations_and_short_input() {
        assert!(decode::<Imu>(&[0, 1]).is_err());
        assert!(decode::<Imu>(&[0, 7, 0, 0, 1, 2, 3]).is_err());
        assert!(decode::<Imu>(&[0, 1, 0, 0, 1, 2, 3]).is_err());
    }
}
