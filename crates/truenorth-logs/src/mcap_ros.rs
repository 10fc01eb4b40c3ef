//! ROS 2 bags in MCAP through the `mcap` crate (Foxglove's reader, which also decompresses
//! zstd chunks, rosbag2's usual compression). Messages must be CDR-encoded ROS 2 messages;
//! they are decoded by [`crate::ros_msgs`] and turned from REP-103 axes (body FLU, world
//! ENU) into the library's (FRD, NED) by [`crate::frames`].

use std::collections::BTreeMap;

use mcap::sans_io::{LinearReaderOptions, MessageReadEvent, MessageReader};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use truenorth_core::{ImuSample, Mag3Sample};

use crate::config::{LogConfig, NO_TOPIC};
use crate::error::{LogError, LogFormat, Result};
use crate::frames::{enu_flu_to_ned_frd, flu_vector_to_frd};
use crate::recording::{
    AttitudeSample, GnssFix, OdometrySample, Recording, StreamInfo, TopicInfo, keep_increasing,
    rate_hz,
};
use crate::ros_msgs::{self, Quat};

/// The first bytes of every MCAP file (MCAP specification, "Magic").
pub(crate) const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Largest uncompressed chunk accepted, bytes. MCAP writers default to chunks of about 1 MiB
/// (rosbag2 and the `mcap` libraries alike); a damaged chunk header can declare exabytes, which
/// the reader would try to reserve before decompressing, so the size is checked first.
const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Microtesla per tesla.
const UT_PER_TESLA: f64 = 1e6;

/// The message types read, by the schema names rosbag2 writes (and the ROS 1 style names
/// some converters write).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Imu,
    MagneticField,
    Odometry,
    NavSatFix,
}

impl Kind {
    fn of(schema: &str) -> Option<Self> {
        match schema {
            "sensor_msgs/msg/Imu" | "sensor_msgs/Imu" => Some(Self::Imu),
            "sensor_msgs/msg/MagneticField" | "sensor_msgs/MagneticField" => {
                Some(Self::MagneticField)
            }
            "nav_msgs/msg/Odometry" | "nav_msgs/Odometry" => Some(Self::Odometry),
            "sensor_msgs/msg/NavSatFix" | "sensor_msgs/NavSatFix" => Some(Self::NavSatFix),
            _ => None,
        }
    }

    fn schema(self) -> &'static str {
        match self {
            Self::Imu => "sensor_msgs/msg/Imu",
            Self::MagneticField => "sensor_msgs/msg/MagneticField",
            Self::Odometry => "nav_msgs/msg/Odometry",
            Self::NavSatFix => "sensor_msgs/msg/NavSatFix",
        }
    }
}

/// One topic as read: its type, encoding, count and, for the types read, its samples in
/// absolute time.
#[derive(Default)]
struct Topic {
    schema: String,
    encoding: String,
    messages: usize,
    imu: Vec<ImuSample>,
    mag: Vec<Mag3Sample>,
    odometry: Vec<OdometrySample>,
    gnss: Vec<GnssFix>,
    attitude: Vec<AttitudeSample>,
    non_finite: usize,
    decode_error: Option<(usize, String)>,
}

fn vec3(v: &ros_msgs::Vec3) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// A REP-103 orientation as a body FRD → NED attitude, if it is a rotation at all.
fn attitude(q: &Quat) -> Option<UnitQuaternion<f64>> {
    let q = Quaternion::new(q.w, q.x, q.y, q.z);
    (q.coords.iter().all(|c| c.is_finite()) && q.norm() > 0.5)
        .then(|| enu_flu_to_ned_frd(&UnitQuaternion::from_quaternion(q)))
}

/// The message's stamp, or the bag's log time when the publisher left the stamp at zero,
/// in nanoseconds.
fn stamp_ns(stamp: &ros_msgs::Time, log_time_ns: u64) -> i128 {
    if stamp.sec == 0 && stamp.nanosec == 0 {
        i128::from(log_time_ns)
    } else {
        i128::from(stamp.sec) * 1_000_000_000 + i128::from(stamp.nanosec)
    }
}

/// Seconds after `origin_ns`, which is the first stamp met: a Unix time as `f64` keeps
/// only a quarter microsecond, the difference keeps the nanoseconds.
fn since(origin_ns: &mut Option<i128>, ns: i128) -> f64 {
    let origin = *origin_ns.get_or_insert(ns);
    (ns - origin) as f64 * 1e-9
}

impl Topic {
    fn take(&mut self, kind: Kind, data: &[u8], log_time_ns: u64, origin: &mut Option<i128>) {
        let index = self.messages - 1;
        let result = match kind {
            Kind::Imu => ros_msgs::decode::<ros_msgs::Imu>(data).map(|m| {
                let t_s = since(origin, stamp_ns(&m.header.stamp, log_time_ns));
                let s = ImuSample::new_6d(
                    t_s,
                    flu_vector_to_frd(&vec3(&m.angular_velocity)),
                    flu_vector_to_frd(&vec3(&m.linear_acceleration)),
                );
                if s.check_finite().is_ok() {
                    self.imu.push(s);
                } else {
                    self.non_finite += 1;
                }
                if m.orientation_covariance[0] != -1.0
                    && let Some(attitude) = attitude(&m.orientation)
                {
                    self.attitude.push(AttitudeSample { t_s, attitude });
                }
            }),
            Kind::MagneticField => ros_msgs::decode::<ros_msgs::MagneticField>(data).map(|m| {
                let v = flu_vector_to_frd(&vec3(&m.magnetic_field)) * UT_PER_TESLA;
                if v.iter().all(|x| x.is_finite()) {
                    let t_s = since(origin, stamp_ns(&m.header.stamp, log_time_ns));
                    self.mag.push(Mag3Sample::new(t_s, v.x, v.y, v.z));
                } else {
                    self.non_finite += 1;
                }
            }),
            Kind::Odometry => ros_msgs::decode::<ros_msgs::Odometry>(data).map(|m| {
                let t_s = since(origin, stamp_ns(&m.header.stamp, log_time_ns));
                let velocity_mps = flu_vector_to_frd(&vec3(&m.twist.twist.linear));
                let yaw_rate_rps = flu_vector_to_frd(&vec3(&m.twist.twist.angular)).z;
                if velocity_mps.iter().all(|x| x.is_finite()) && yaw_rate_rps.is_finite() {
                    self.odometry.push(OdometrySample {
                        t_s,
                        velocity_mps,
                        yaw_rate_rps,
                    });
                } else {
                    self.non_finite += 1;
                }
                if let Some(attitude) = attitude(&m.pose.pose.orientation) {
                    self.attitude.push(AttitudeSample { t_s, attitude });
                }
            }),
            Kind::NavSatFix => ros_msgs::decode::<ros_msgs::NavSatFix>(data).map(|m| {
                // Status −1: no fix (the numbers are whatever the driver left).
                if m.status.status < 0 {
                    return;
                }
                let (lat_deg, lon_deg) = (m.latitude, m.longitude);
                if lat_deg.is_finite() && lon_deg.is_finite() {
                    let t_s = since(origin, stamp_ns(&m.header.stamp, log_time_ns));
                    self.gnss.push(GnssFix {
                        t_s,
                        lat_deg,
                        lon_deg,
                        sigma_m: horizontal_sigma_m(&m),
                        velocity: None,
                    });
                } else {
                    self.non_finite += 1;
                }
            }),
        };
        if let Err(e) = result {
            self.decode_error.get_or_insert((index, e));
        }
    }
}

/// The 1σ horizontal error of a fix: the root of the mean of its east and north variances,
/// when the receiver gives a covariance (type not 0, "unknown") that is usable.
fn horizontal_sigma_m(m: &ros_msgs::NavSatFix) -> Option<f64> {
    let c = &m.position_covariance;
    let variance = 0.5 * (c[0] + c[4]);
    (m.position_covariance_type != 0 && variance.is_finite() && variance > 0.0)
        .then(|| variance.sqrt())
}

/// Reads an MCAP file's bytes.
pub(crate) fn read(bytes: &[u8], config: &LogConfig) -> Result<Recording> {
    let corrupt = |detail: String| LogError::Corrupt {
        format: LogFormat::Mcap,
        detail,
    };
    check_chunk_sizes(bytes).map_err(corrupt)?;
    // The sans-io message reader with a record length limit: `MessageStream` sets none, and
    // a damaged record length inside a chunk would be reserved whole before it is read.
    let options = LinearReaderOptions::default().with_record_length_limit(MAX_CHUNK_BYTES as usize);
    let mut reader = MessageReader::new_with_options(options);
    let mut rest = bytes;
    let mut topics: BTreeMap<String, Topic> = BTreeMap::new();
    let mut messages = 0usize;
    let mut complete = true;
    let mut origin_ns = None;
    while let Some(event) = reader.next_event() {
        let message = match event {
            Ok(MessageReadEvent::ReadRequest(need)) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
                continue;
            }
            Ok(MessageReadEvent::Message(m)) => m,
            Err(e) if messages == 0 => return Err(corrupt(e.to_string())),
            Err(_) if config.accept_incomplete => {
                complete = false;
                break;
            }
            Err(e) => {
                return Err(LogError::Incomplete {
                    format: LogFormat::Mcap,
                    messages,
                    detail: e.to_string(),
                });
            }
        };
        messages += 1;
        let channel = &message.channel;
        let schema = channel
            .schema
            .as_ref()
            .map(|s| s.name.as_str())
            .unwrap_or("");
        let topic = topics.entry(channel.topic.clone()).or_default();
        if topic.messages == 0 {
            topic.schema = schema.to_string();
            topic.encoding = channel.message_encoding.clone();
        }
        topic.messages += 1;
        if let Some(kind) = Kind::of(schema).filter(|_| channel.message_encoding == "cdr") {
            topic.take(kind, &message.data, message.log_time, &mut origin_ns);
        }
    }
    let origin_s = origin_ns.map_or(0.0, |ns| ns as f64 * 1e-9);
    select(topics, config, complete, origin_s)
}

/// Refuses a chunk whose declared uncompressed size is beyond [`MAX_CHUNK_BYTES`]; the
/// records are scanned without decompressing. A structural error is left for the message
/// stream to report with its count of good messages.
fn check_chunk_sizes(bytes: &[u8]) -> core::result::Result<(), String> {
    // A damaged or missing end is the message stream's to report: scan up to it.
    let options = mcap::read::Options::IgnoreEndMagic.into();
    let Ok(records) = mcap::read::LinearReader::new_with_options(bytes, options) else {
        return Ok(());
    };
    for record in records {
        match record {
            Ok(mcap::records::Record::Chunk { header, .. })
                if header.uncompressed_size > MAX_CHUNK_BYTES =>
            {
                return Err(format!(
                    "a chunk declares {} bytes uncompressed, beyond the {MAX_CHUNK_BYTES} any \
                     writer produces: its header is damaged",
                    header.uncompressed_size
                ));
            }
            Ok(_) => {}
            Err(_) => break,
        }
    }
    Ok(())
}

/// The topic for a role: the one named, checked for its type; else the one of that type
/// with the most messages (the first by name among equals), if any.
fn choose(
    topics: &BTreeMap<String, Topic>,
    requested: Option<&str>,
    kinds: &[Kind],
    role: &'static str,
) -> Result<Option<String>> {
    let present = || {
        topics
            .iter()
            .map(|(name, t)| {
                TopicInfo {
                    name: name.clone(),
                    kind: t.schema.clone(),
                    messages: t.messages,
                }
                .to_string()
            })
            .collect()
    };
    match requested {
        Some(NO_TOPIC) => Ok(None),
        Some(name) => {
            let topic = topics.get(name).ok_or_else(|| LogError::MissingTopic {
                role,
                requested: name.to_string(),
                present: present(),
            })?;
            let wrong = |detail: String| LogError::WrongTopicType {
                topic: name.to_string(),
                role,
                detail,
            };
            if !Kind::of(&topic.schema).is_some_and(|k| kinds.contains(&k)) {
                let wanted: Vec<&str> = kinds.iter().map(|k| k.schema()).collect();
                return Err(wrong(format!(
                    "its type is `{}`, not {}",
                    topic.schema,
                    wanted.join(" or ")
                )));
            }
            if topic.encoding != "cdr" {
                return Err(wrong(format!(
                    "its messages are encoded as `{}`, not ROS 2 `cdr`",
                    topic.encoding
                )));
            }
            Ok(Some(name.to_string()))
        }
        None => Ok(topics
            .iter()
            .filter(|(_, t)| t.encoding == "cdr" && Kind::of(&t.schema) == Some(kinds[0]))
            .max_by(|a, b| a.1.messages.cmp(&b.1.messages).then(b.0.cmp(a.0)))
            .map(|(name, _)| name.clone())),
    }
}

fn select(
    mut topics: BTreeMap<String, Topic>,
    config: &LogConfig,
    complete: bool,
    stamp_origin_s: f64,
) -> Result<Recording> {
    let imu_name = choose(&topics, config.imu_topic.as_deref(), &[Kind::Imu], "imu")?;
    let Some(imu_name) = imu_name else {
        return Err(LogError::MissingTopic {
            role: "imu",
            requested: "any sensor_msgs/msg/Imu topic".to_string(),
            present: topics
                .iter()
                .map(|(name, t)| {
                    TopicInfo {
                        name: name.clone(),
                        kind: t.schema.clone(),
                        messages: t.messages,
                    }
                    .to_string()
                })
                .collect(),
        });
    };
    let mag_name = choose(
        &topics,
        config.mag_topic.as_deref(),
        &[Kind::MagneticField],
        "mag",
    )?;
    let odometry_name = choose(
        &topics,
        config.odometry_topic.as_deref(),
        &[Kind::Odometry],
        "odometry",
    )?;
    let gnss_name = choose(
        &topics,
        config.gnss_topic.as_deref(),
        &[Kind::NavSatFix],
        "gnss",
    )?;
    let attitude_name = match config.attitude_topic.as_deref() {
        None => None,
        requested => choose(&topics, requested, &[Kind::Imu, Kind::Odometry], "attitude")?,
    };
    let info: Vec<TopicInfo> = topics
        .iter()
        .map(|(name, t)| TopicInfo {
            name: name.clone(),
            kind: t.schema.clone(),
            messages: t.messages,
        })
        .collect();

    let mut streams = Vec::new();
    let mut take = |name: &Option<String>, role: &'static str| -> Result<Topic> {
        let Some(name) = name else {
            return Ok(Topic::default());
        };
        let mut topic = std::mem::take(topics.entry(name.clone()).or_default());
        if let Some((index, detail)) = topic.decode_error.take() {
            return Err(LogError::Decode {
                topic: name.clone(),
                index,
                detail,
            });
        }
        // Keep the attitude of a topic that is taken for another role as well.
        if let Some(t) = topics.get_mut(name) {
            t.attitude = topic.attitude.clone();
        }
        let (dropped, samples, rate) = match role {
            "imu" => {
                let d = keep_increasing(&mut topic.imu, |s| s.t_s);
                (d, topic.imu.len(), rate_hz(topic.imu.iter().map(|s| s.t_s)))
            }
            "mag" => {
                let d = keep_increasing(&mut topic.mag, |s| s.t_s);
                (d, topic.mag.len(), rate_hz(topic.mag.iter().map(|s| s.t_s)))
            }
            "gnss" => {
                let d = keep_increasing(&mut topic.gnss, |s| s.t_s);
                (
                    d,
                    topic.gnss.len(),
                    rate_hz(topic.gnss.iter().map(|s| s.t_s)),
                )
            }
            "odometry" => {
                let d = keep_increasing(&mut topic.odometry, |s| s.t_s);
                (
                    d,
                    topic.odometry.len(),
                    rate_hz(topic.odometry.iter().map(|s| s.t_s)),
                )
            }
            _ => {
                let d = keep_increasing(&mut topic.attitude, |s| s.t_s);
                (
                    d,
                    topic.attitude.len(),
                    rate_hz(topic.attitude.iter().map(|s| s.t_s)),
                )
            }
        };
        streams.push(StreamInfo {
            role,
            topic: name.clone(),
            samples,
            dropped: dropped + topic.non_finite,
            rate_hz: rate,
        });
        Ok(topic)
    };
    let imu = take(&Some(imu_name), "imu")?.imu;
    let mag = take(&mag_name, "mag")?.mag;
    let odometry = take(&odometry_name, "odometry")?.odometry;
    let gnss = take(&gnss_name, "gnss")?.gnss;
    let attitude = take(&attitude_name, "attitude")?.attitude;

    let time_origin_s = [
        imu.first().map(|s| s.t_s),
        mag.first().map(|s| s.t_s),
        odometry.first().map(|s| s.t_s),
        gnss.first().map(|s| s.t_s),
        attitude.first().map(|s| s.t_s),
    ]
    .into_iter()
    .flatten()
    .fold(f64::INFINITY, f64::min);
    let origin = if time_origin_s.is_finite() {
        time_origin_s
    } else {
        0.0
    };
    let mut recording = Recording {
        format: LogFormat::Mcap,
        time_origin_s: stamp_origin_s + origin,
        complete,
        topics: info,
        streams,
        imu,
        mag,
        attitude,
        odometry,
        gnss,
    };
    shift_times(&mut recording, origin);
    Ok(recording)
}

fn shift_times(r: &mut Recording, origin_s: f64) {
    r.imu.iter_mut().for_each(|s| s.t_s -= origin_s);
    r.mag.iter_mut().for_each(|s| s.t_s -= origin_s);
    r.attitude.iter_mut().for_each(|s| s.t_s -= origin_s);
    r.odometry.iter_mut().for_each(|s| s.t_s -= origin_s);
    r.gnss.iter_mut().for_each(|s| s.t_s -= origin_s);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(status: i8, lat: f64, covariance_type: u8, variance: f64) -> Vec<u8> {
        let mut c = [0.0; 9];
        (c[0], c[4], c[8]) = (variance, variance * 4.0, 9.0);
        ros_msgs::encode(&ros_msgs::NavSatFix {
            header: ros_msgs::Header {
                stamp: ros_msgs::Time {
                    sec: 1_700_000_000,
                    nanosec: 500_000_000,
                },
                frame_id: "gps".into(),
            },
            status: ros_msgs::NavSatStatus { status, service: 1 },
            latitude: lat,
            longitude: 13.4,
            altitude: 40.0,
            position_covariance: c,
            position_covariance_type: covariance_type,
        })
        .unwrap()
    }

    /// A fix is kept with the σ its covariance gives (the root of the mean of the east and
    /// north variances); "no fix" and non-finite positions are not; an unknown covariance
    /// gives no σ.
    #[test]
    fn fixes_are_read_with_their_sigma_and_no_fix_is_left_out() {
        let mut topic = Topic::default();
        let mut origin = None;
        for (status, lat, kind) in [(0, 52.5, 2), (-1, 52.5, 2), (0, f64::NAN, 2), (1, 52.6, 0)] {
            topic.messages += 1;
            topic.take(
                Kind::NavSatFix,
                &fix(status, lat, kind, 2.25),
                0,
                &mut origin,
            );
        }
        assert_eq!(topic.gnss.len(), 2);
        assert_eq!(topic.non_finite, 1);
        let sigma = topic.gnss[0].sigma_m.unwrap();
        assert!(
            (sigma - (0.5f64 * (2.25 + 9.0)).sqrt()).abs() < 1e-12,
            "{sigma}"
        );
        assert_eq!((topic.gnss[1].lat_deg, topic.gnss[1].sigma_m), (52.6, None));
        assert_eq!(Kind::of("sensor_msgs/msg/NavSatFix"), Some(Kind::NavSatFix));
    }
}
