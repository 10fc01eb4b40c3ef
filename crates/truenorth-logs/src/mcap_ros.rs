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
    TwistStamped,
    TwistWithCovarianceStamped,
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
            "geometry_msgs/msg/TwistStamped" | "geometry_msgs/TwistStamped" => {
                Some(Self::TwistStamped)
            }
            "geometry_msgs/msg/TwistWithCovarianceStamped"
            | "geometry_msgs/TwistWithCovarianceStamped" => Some(Self::TwistWithCovarianceStamped),
            _ => None,
        }
    }

    fn schema(self) -> &'static str {
        match self {
            Self::Imu => "sensor_msgs/msg/Imu",
            Self::MagneticField => "sensor_msgs/msg/MagneticField",
            Self::Odometry => "nav_msgs/msg/Odometry",
            Self::NavSatFix => "sensor_msgs/msg/NavSatFix",
            Self::TwistStamped => "geometry_msgs/msg/TwistStamped",
            Self::TwistWithCovarianceStamped => "geometry_msgs/msg/TwistWithCovarianceStamped",
        }
    }
}

/// The types a receiver's velocity comes in.
const VELOCITY_KINDS: [Kind; 2] = [Kind::TwistWithCovarianceStamped, Kind::TwistStamped];

/// Longest time between a fix and the velocity it takes, s: a receiver stamps both from one
/// solution (`ublox_gps`), an NMEA driver from sentences of one epoch a few hundred
/// milliseconds apart at 4800 baud.
const MAX_VELOCITY_SKEW_S: f64 = 0.5;

/// A receiver's velocity over ground (ENU as REP-103 and the GNSS drivers give it).
#[derive(Debug, Clone, Copy, PartialEq)]
struct GroundVelocity {
    t_s: f64,
    east_mps: f64,
    north_mps: f64,
}

/// One topic as read: its type, encoding, count, the frame of its first stamped message and,
/// for the types read, its samples in absolute time.
#[derive(Default)]
struct Topic {
    schema: String,
    encoding: String,
    messages: usize,
    frame_id: Option<String>,
    velocity: Vec<GroundVelocity>,
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
                self.frame_id.get_or_insert(m.header.frame_id.clone());
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
            Kind::TwistStamped => ros_msgs::decode::<ros_msgs::TwistStamped>(data)
                .map(|m| self.take_velocity(&m.header, &m.twist, log_time_ns, origin)),
            Kind::TwistWithCovarianceStamped => {
                ros_msgs::decode::<ros_msgs::TwistWithCovarianceStamped>(data)
                    .map(|m| self.take_velocity(&m.header, &m.twist.twist, log_time_ns, origin))
            }
        };
        if let Err(e) = result {
            self.decode_error.get_or_insert((index, e));
        }
    }
}

impl Topic {
    fn take_velocity(
        &mut self,
        header: &ros_msgs::Header,
        twist: &ros_msgs::Twist,
        log_time_ns: u64,
        origin: &mut Option<i128>,
    ) {
        self.frame_id.get_or_insert(header.frame_id.clone());
        let (east_mps, north_mps) = (twist.linear.x, twist.linear.y);
        if east_mps.is_finite() && north_mps.is_finite() {
            let t_s = since(origin, stamp_ns(&header.stamp, log_time_ns));
            self.velocity.push(GroundVelocity {
                t_s,
                east_mps,
                north_mps,
            });
        } else {
            self.non_finite += 1;
        }
    }
}

/// Gives each fix the speed and course over ground (degrees clockwise from true north in
/// [0, 360)) of the velocity stamped nearest to it, within half the time to its neighbouring
/// fixes and [`MAX_VELOCITY_SKEW_S`]; a fix without one keeps none. Both are in time order.
/// Returns how many of the velocities were taken.
fn attach_velocity(fixes: &mut [GnssFix], velocity: &[GroundVelocity]) -> usize {
    let times: Vec<f64> = fixes.iter().map(|f| f.t_s).collect();
    let (mut taken, mut last_taken) = (0, None);
    for (i, fix) in fixes.iter_mut().enumerate() {
        let gap = |j: Option<usize>| j.and_then(|j| times.get(j)).map(|t| (t - fix.t_s).abs());
        let window = [gap(i.checked_sub(1)), gap(Some(i + 1))]
            .into_iter()
            .flatten()
            .fold(2.0 * MAX_VELOCITY_SKEW_S, f64::min)
            * 0.5;
        let at = velocity.partition_point(|v| v.t_s < fix.t_s);
        let skew = |j: &usize| (velocity[*j].t_s - fix.t_s).abs();
        let nearest = [at.checked_sub(1), Some(at)]
            .into_iter()
            .flatten()
            .filter(|&j| j < velocity.len())
            .min_by(|a, b| skew(a).total_cmp(&skew(b)));
        let finite =
            |j: &usize| velocity[*j].east_mps.is_finite() && velocity[*j].north_mps.is_finite();
        if let Some(j) = nearest.filter(|j| skew(j) <= window && finite(j)) {
            let v = velocity[j];
            let course_deg = v.east_mps.atan2(v.north_mps).to_degrees().rem_euclid(360.0);
            let course_deg = if course_deg < 360.0 { course_deg } else { 0.0 };
            fix.velocity = Some((v.east_mps.hypot(v.north_mps), course_deg));
            if last_taken != Some(j) {
                (taken, last_taken) = (taken + 1, Some(j));
            }
        }
    }
    taken
}

/// The receiver's velocity topic by default: of the velocity types, those stamped in the
/// fixes' own frame, the one with the most messages (the first by name among equals).
fn velocity_in_frame_of(topics: &BTreeMap<String, Topic>, fixes: &str) -> Option<String> {
    let frame = topics.get(fixes)?.frame_id.as_deref()?;
    topics
        .iter()
        .filter(|(_, t)| {
            t.encoding == "cdr"
                && Kind::of(&t.schema).is_some_and(|k| VELOCITY_KINDS.contains(&k))
                && t.frame_id.as_deref() == Some(frame)
        })
        .max_by(|a, b| a.1.messages.cmp(&b.1.messages).then(b.0.cmp(a.0)))
        .map(|(name, _)| name.clone())
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
    let velocity_name = match config.gnss_velocity_topic.as_deref() {
        None => gnss_name
            .as_deref()
            .and_then(|fixes| velocity_in_frame_of(&topics, fixes)),
        requested => choose(&topics, requested, &VELOCITY_KINDS, "gnss_velocity")?,
    };
    if velocity_name.is_some() && gnss_name.is_none() {
        return Err(LogError::InvalidConfig {
            field: "gnss_velocity_topic",
            reason: "names the receiver's velocity, and no fixes are read to carry it (it is \
                     taken as the fixes' speed and course over ground); name the fixes with \
                     `gnss_topic`, or leave it out"
                .to_string(),
        });
    }
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
            "gnss_velocity" => {
                let d = keep_increasing(&mut topic.velocity, |s| s.t_s);
                (
                    d,
                    topic.velocity.len(),
                    rate_hz(topic.velocity.iter().map(|s| s.t_s)),
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
    let mut gnss = take(&gnss_name, "gnss")?.gnss;
    let velocity = take(&velocity_name, "gnss_velocity")?.velocity;
    let attitude = take(&attitude_name, "attitude")?.attitude;
    if velocity_name.is_some() {
        let taken = attach_velocity(&mut gnss, &velocity);
        // The velocities no fix took are left out, as a stream's unreadable messages are.
        if let Some(s) = streams.iter_mut().find(|s| s.role == "gnss_velocity") {
            s.dropped += velocity.len() - taken;
        }
    }

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

    fn velocity(t_s: f64, east_mps: f64, north_mps: f64) -> GroundVelocity {
        GroundVelocity {
            t_s,
            east_mps,
            north_mps,
        }
    }

    /// Each fix takes the velocity nearest in time as speed and course over ground (clockwise
    /// from north), only within half the time to its neighbours: a velocity between two fixes
    /// a second apart is taken by neither when 0.6 s from both sides' nearest.
    #[test]
    fn each_fix_takes_the_nearest_velocity_within_its_epoch() {
        let mut fixes: Vec<GnssFix> = [0.0, 1.0, 2.0, 3.0]
            .map(|t_s| GnssFix {
                t_s,
                lat_deg: 52.5,
                lon_deg: 13.4,
                sigma_m: None,
                velocity: None,
            })
            .to_vec();
        let v = [
            velocity(0.02, 3.0, 4.0),
            velocity(0.4, 0.0, 9.0),
            velocity(1.6, -2.0, 0.0),
            velocity(2.9, 0.0, -1.0),
        ];
        assert_eq!(attach_velocity(&mut fixes, &v), 3);
        let (speed, course) = fixes[0].velocity.unwrap();
        assert!((speed - 5.0).abs() < 1e-12);
        assert!((course - 3f64.atan2(4.0).to_degrees()).abs() < 1e-12);
        assert_eq!(
            fixes[1].velocity, None,
            "0.4 s and 0.6 s away, beyond 0.5 s"
        );
        assert_eq!(fixes[2].velocity, Some((2.0, 270.0)));
        assert_eq!(fixes[3].velocity, Some((1.0, 180.0)));
        let mut none = fixes.clone();
        none.iter_mut().for_each(|f| f.velocity = None);
        assert_eq!(attach_velocity(&mut none, &[]), 0);
        assert!(none.iter().all(|f| f.velocity.is_none()));
    }

    /// By default only a twist stamped in the fixes' frame is their velocity: a busier
    /// `cmd_vel` in the body's frame is not taken.
    #[test]
    fn the_default_velocity_is_in_the_fixes_frame() {
        let topic = |schema: &str, frame: &str, messages: usize| Topic {
            schema: schema.into(),
            encoding: "cdr".into(),
            messages,
            frame_id: Some(frame.into()),
            ..Topic::default()
        };
        let mut topics = BTreeMap::new();
        topics.insert("/fix".into(), topic("sensor_msgs/msg/NavSatFix", "gps", 10));
        topics.insert(
            "/cmd_vel".into(),
            topic("geometry_msgs/msg/TwistStamped", "base_link", 500),
        );
        assert_eq!(velocity_in_frame_of(&topics, "/fix"), None);
        topics.insert(
            "/vel".into(),
            topic("geometry_msgs/TwistStamped", "gps", 10),
        );
        topics.insert(
            "/fix_velocity".into(),
            topic("geometry_msgs/msg/TwistWithCovarianceStamped", "gps", 10),
        );
        assert_eq!(
            velocity_in_frame_of(&topics, "/fix").as_deref(),
            Some("/fix_velocity")
        );
    }

    proptest::proptest! {
        /// Whatever the stamps and values (NaN and infinities included), a fix takes a
        /// velocity only from within 0.5 s and half the time to its neighbours, its speed is
        /// not negative and its course is in [0, 360); no more velocities are counted taken
        /// than there are.
        #[test]
        fn a_velocity_is_taken_only_near_its_fix(
            fix_steps in proptest::collection::vec(0.0f64..2.0, 0..12),
            samples in proptest::collection::vec(
                (-1.0f64..20.0, proptest::num::f64::ANY, proptest::num::f64::ANY),
                0..24,
            ),
        ) {
            let mut t = 0.0;
            let mut fixes: Vec<GnssFix> = fix_steps
                .iter()
                .map(|step| {
                    t += step + 0.01;
                    GnssFix { t_s: t, lat_deg: 0.0, lon_deg: 0.0, sigma_m: None, velocity: None }
                })
                .collect();
            let mut v: Vec<GroundVelocity> = samples
                .iter()
                .map(|&(t_s, e, n)| velocity(t_s, e, n))
                .collect();
            v.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
            let taken = attach_velocity(&mut fixes, &v);
            proptest::prop_assert!(taken <= v.len());
            for (i, fix) in fixes.iter().enumerate() {
                let Some((speed, course)) = fix.velocity else { continue };
                let near = v.iter().any(|s| {
                    let skew = (s.t_s - fix.t_s).abs();
                    let neighbours = [i.checked_sub(1), Some(i + 1)]
                        .into_iter()
                        .flatten()
                        .filter_map(|j| fixes.get(j))
                        .all(|f| skew <= 0.5 * (f.t_s - fix.t_s).abs() + 1e-12);
                    skew <= MAX_VELOCITY_SKEW_S && neighbours
                });
                proptest::prop_assert!(near, "fix {i} took a velocity from too far");
                proptest::prop_assert!(speed.is_finite() && speed >= 0.0, "speed {speed}");
                proptest::prop_assert!((0.0..360.0).contains(&course), "course {course}");
            }
        }
    }
}
