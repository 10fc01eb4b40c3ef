//! PX4 ULog through the `px4-ulog` crate (PX4's own Rust reader): the crate parses the file
//! and hands over each data message with its flattened format; this module finds the fields
//! it needs by name and turns them into the library's samples. PX4 body axes are FRD and its
//! attitude refers to NED, the library's own frames, so nothing is rotated.
//!
//! Field names follow PX4's uORB messages: `sensor_combined` (`gyro_rad[3]` rad/s,
//! `accelerometer_m_s2[3]` m/s², and in older logs `magnetometer_ga[3]` gauss with
//! `magnetometer_timestamp_relative` µs), `vehicle_magnetometer` (`magnetometer_ga[3]`),
//! `sensor_mag` (`x`, `y`, `z` gauss), `vehicle_attitude` (`q[4]`, w first, FRD → NED) and the
//! satellite fixes of `vehicle_gps_position` or `sensor_gps` (`latitude_deg`/`longitude_deg`
//! in degrees, or in older logs `lat`/`lon` in 10⁻⁷ degrees; `eph` m; `fix_type`, 2 or more
//! for a fix; `vel_m_s` and `cog_rad`, the course over ground, unless `vel_ned_valid` is 0).
//! Times are `timestamp_sample` where the message has it (when the sensor sampled), else
//! `timestamp` (when the message was published), both µs since boot.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use px4_ulog::stream_parser::LogParser;
use px4_ulog::stream_parser::model::{DataMessage, FlattenedFieldType};
use truenorth_core::{ImuSample, Mag3Sample};

use crate::config::{LogConfig, NO_TOPIC, TopicSpec};
use crate::error::{LogError, LogFormat, Result};
use crate::recording::{
    AttitudeSample, GnssFix, Recording, StreamInfo, TopicInfo, keep_increasing, rate_hz,
};
use crate::ulog_fields::{
    Fields, GnssFields, ImuFields, MagFields, Num, attitude_fields, field, gnss_fields, imu_fields,
    mag_fields, read_all,
};

/// The first bytes of every ULog file: `ULog`, then 0x01 0x12 0x35.
pub(crate) const ULOG_MAGIC: &[u8] = b"ULog\x01\x12\x35";

/// Microtesla per gauss.
const UT_PER_GAUSS: f64 = 100.0;

/// PX4's marker for a relative timestamp that holds no reading (`RELATIVE_TIMESTAMP_INVALID`
/// in `sensor_combined.msg`).
const RELATIVE_TIMESTAMP_INVALID: i64 = i32::MAX as i64;

/// Bytes fed to the parser at a time until its header is read (the appended-data offsets are
/// in the header's flag bits, which must be known before the data is fed).
const HEADER_CHUNK: usize = 256;

/// Default magnetometer topics, in order of preference.
const MAG_DEFAULTS: [&str; 3] = ["sensor_combined", "vehicle_magnetometer", "sensor_mag"];

/// Default satellite-fix topics, in order of preference (PX4 renamed the receiver's topic
/// `vehicle_gps_position` → `sensor_gps` and kept the first for the selected receiver).
const GNSS_DEFAULTS: [&str; 2] = ["vehicle_gps_position", "sensor_gps"];

/// The least `fix_type` that is a position (PX4: 0–1 no fix, 2 a 2D fix, 3 a 3D fix, more
/// for differential and RTK).
const FIX_TYPE_2D: f64 = 2.0;

/// How to read one message format (one `msg_id`) for the roles its topic was selected for.
struct Decoder {
    timestamp: Option<Num>,
    timestamp_sample: Option<Num>,
    imu: Option<Fields<ImuFields>>,
    /// Index into the magnetometer candidates, and the fields.
    mag: Option<(usize, Fields<MagFields>)>,
    attitude: Option<Fields<[Num; 4]>>,
    /// Index into the satellite-fix candidates, and the fields.
    gnss: Option<(usize, Fields<GnssFields>)>,
}

/// What the parser's callback gathers.
struct Gathered {
    imu_spec: TopicSpec,
    mag_specs: Vec<TopicSpec>,
    attitude_spec: Option<TopicSpec>,
    decoders: HashMap<u16, Decoder>,
    counts: BTreeMap<(String, u8), usize>,
    messages: usize,
    imu: Vec<ImuSample>,
    imu_error: Option<String>,
    mags: Vec<Vec<Mag3Sample>>,
    mag_errors: Vec<Option<String>>,
    attitude: Vec<AttitudeSample>,
    attitude_error: Option<String>,
    gnss_specs: Vec<TopicSpec>,
    gnss: Vec<Vec<GnssFix>>,
    gnss_errors: Vec<Option<String>>,
    /// Readings left out for a non-finite value: imu, mag, attitude, fixes.
    non_finite: [usize; 4],
}

fn matches(spec: &TopicSpec, name: &str, instance: u8) -> bool {
    spec.name == name && spec.instance == instance
}

impl Gathered {
    fn decoder(&self, msg: &DataMessage) -> Decoder {
        let format = msg.flattened_format;
        let (name, instance) = (format.message_name(), msg.multi_id.value());
        Decoder {
            timestamp: field(format, "timestamp", &[FlattenedFieldType::UInt64]),
            timestamp_sample: field(format, "timestamp_sample", &[FlattenedFieldType::UInt64]),
            imu: matches(&self.imu_spec, name, instance).then(|| imu_fields(format)),
            mag: self
                .mag_specs
                .iter()
                .position(|s| matches(s, name, instance))
                .map(|k| (k, mag_fields(format))),
            attitude: self
                .attitude_spec
                .as_ref()
                .filter(|s| matches(s, name, instance))
                .map(|_| attitude_fields(format)),
            gnss: self
                .gnss_specs
                .iter()
                .position(|s| matches(s, name, instance))
                .map(|k| (k, gnss_fields(format))),
        }
    }

    fn take(&mut self, msg: &DataMessage) {
        self.messages += 1;
        let key = (
            msg.flattened_format.message_name().to_string(),
            msg.multi_id.value(),
        );
        *self.counts.entry(key).or_default() += 1;
        if !self.decoders.contains_key(&msg.msg_id) {
            let d = self.decoder(msg);
            self.decoders.insert(msg.msg_id, d);
        }
        let Some(d) = self.decoders.get(&msg.msg_id) else {
            return;
        };
        let data = msg.data;
        let published_us = d.timestamp.and_then(|f| f.read(data));
        let sampled_us = d
            .timestamp_sample
            .and_then(|f| f.read(data))
            .or(published_us);
        match &d.imu {
            Some(Ok(f)) => {
                if let (Some(t), Some(g), Some(a)) =
                    (published_us, read_all(&f.gyr, data), read_all(&f.acc, data))
                {
                    let s = ImuSample::new_6d(t * 1e-6, Vector3::from(g), Vector3::from(a));
                    if s.check_finite().is_ok() {
                        self.imu.push(s);
                    } else {
                        self.non_finite[0] += 1;
                    }
                }
            }
            Some(Err(e)) => {
                self.imu_error.get_or_insert_with(|| e.clone());
            }
            None => {}
        }
        match &d.mag {
            Some((k, Ok(f))) => {
                let relative_us = match f.relative.map(|r| r.read(data)) {
                    None => Some(0.0),
                    Some(Some(r)) if r as i64 != RELATIVE_TIMESTAMP_INVALID => Some(r),
                    Some(_) => None,
                };
                let t_us = match f.relative {
                    Some(_) => published_us.zip(relative_us).map(|(t, r)| t + r),
                    None => sampled_us,
                };
                if let (Some(t), Some(m)) = (t_us, read_all(&f.field, data)) {
                    let v = Vector3::from(m) * UT_PER_GAUSS;
                    if v.iter().all(|x| x.is_finite()) {
                        self.mags[*k].push(Mag3Sample::new(t * 1e-6, v.x, v.y, v.z));
                    } else {
                        self.non_finite[1] += 1;
                    }
                }
            }
            Some((k, Err(e))) => {
                self.mag_errors[*k].get_or_insert_with(|| e.clone());
            }
            None => {}
        }
        match &d.attitude {
            Some(Ok(f)) => {
                if let (Some(t), Some([w, x, y, z])) = (sampled_us, read_all(f, data)) {
                    let q = Quaternion::new(w, x, y, z);
                    if q.coords.iter().all(|c| c.is_finite()) && q.norm() > 0.5 {
                        let attitude = UnitQuaternion::from_quaternion(q);
                        self.attitude.push(AttitudeSample {
                            t_s: t * 1e-6,
                            attitude,
                        });
                    } else {
                        self.non_finite[2] += 1;
                    }
                }
            }
            Some(Err(e)) => {
                self.attitude_error.get_or_insert_with(|| e.clone());
            }
            None => {}
        }
        match &d.gnss {
            Some((k, Ok(f))) => {
                let fix_type = f.fix_type.and_then(|n| n.read(data));
                if fix_type.is_some_and(|t| t < FIX_TYPE_2D) {
                    return;
                }
                if let (Some(t), Some([lat, lon])) = (sampled_us, read_all(&f.lat_lon, data)) {
                    let (lat_deg, lon_deg) = (lat * f.deg_per_unit, lon * f.deg_per_unit);
                    let eph = f.eph.and_then(|n| n.read(data));
                    let valid = f.velocity_valid.and_then(|n| n.read(data)) != Some(0.0);
                    let velocity = f
                        .velocity
                        .and_then(|v| read_all(&v, data))
                        .filter(|[v, c]| valid && v.is_finite() && *v >= 0.0 && c.is_finite())
                        .map(|[v, c]| (v, c.to_degrees().rem_euclid(360.0)));
                    if lat_deg.abs() <= 90.0 && lon_deg.abs() <= 180.0 {
                        self.gnss[*k].push(GnssFix {
                            t_s: t * 1e-6,
                            lat_deg,
                            lon_deg,
                            sigma_m: eph.filter(|e| e.is_finite() && *e > 0.0),
                            velocity,
                        });
                    } else {
                        self.non_finite[3] += 1;
                    }
                }
            }
            Some((k, Err(e))) => {
                self.gnss_errors[*k].get_or_insert_with(|| e.clone());
            }
            None => {}
        }
    }
}

/// How the byte stream ended.
enum Ending {
    Complete,
    Truncated,
    Damaged(String),
}

/// Feeds the file to the parser: the header in small pieces until the appended-data offsets
/// are known, then the main data section up to the first appended section, then each
/// appended section from its offset (ULog spec, "Appended data"). Offsets beyond the file
/// are clamped to its end.
fn feed(parser: &mut LogParser, bytes: &[u8]) -> Result<Ending> {
    let corrupt = |detail: String| LogError::Corrupt {
        format: LogFormat::Ulog,
        detail,
    };
    let mut pos = 0;
    while !parser.header_complete() && pos < bytes.len() {
        let end = (pos + HEADER_CHUNK).min(bytes.len());
        parser
            .consume_bytes(&bytes[pos..end])
            .map_err(|e| corrupt(e.to_string()))?;
        pos = end;
    }
    let clamp = |o: u64| usize::try_from(o).unwrap_or(usize::MAX).min(bytes.len());
    let appended: Vec<usize> = parser
        .appended_offsets()
        .iter()
        .filter(|&&o| o != 0)
        .map(|&o| clamp(o))
        .collect();
    let mut sections = vec![(
        pos,
        appended.first().copied().unwrap_or(bytes.len()).max(pos),
    )];
    for (k, &start) in appended.iter().enumerate() {
        let end = appended
            .get(k + 1)
            .copied()
            .unwrap_or(bytes.len())
            .max(start);
        sections.push((start, end));
    }
    for (k, (start, end)) in sections.into_iter().enumerate() {
        if k > 0 {
            parser.clear_leftover();
        }
        if let Err(e) = parser.consume_bytes(&bytes[start..end]) {
            return if parser.in_data() {
                Ok(Ending::Damaged(e.to_string()))
            } else {
                Err(corrupt(e.to_string()))
            };
        }
    }
    if !parser.in_data() {
        return Err(corrupt("the file ends before its data section".to_string()));
    }
    Ok(if parser.has_leftover() {
        Ending::Truncated
    } else {
        Ending::Complete
    })
}

/// Bytes of the ULog file header before the first record (magic, version, timestamp).
const FILE_HEADER_BYTES: usize = 16;

/// Refuses a format definition whose array length no message can hold. A ULog record's
/// size is a `u16` (ULog spec, "Message Header"), so no array has more than 65 535
/// elements; a damaged digit can make one declare billions, which the reader would lay out
/// element by element before it looks at any data. Only the record framing (`u16` size,
/// `u8` type) and the text of the `F` records are looked at, up to the first record of the
/// data section (`A`, `D`).
fn check_array_lengths(bytes: &[u8]) -> core::result::Result<(), String> {
    let mut at = FILE_HEADER_BYTES;
    while let Some(&[lo, hi, kind]) = bytes
        .get(at..at + 3)
        .and_then(|h| <&[u8; 3]>::try_from(h).ok())
    {
        let size = usize::from(u16::from_le_bytes([lo, hi]));
        match kind {
            b'A' | b'D' => return Ok(()),
            b'F' => {
                let end = (at + 3 + size).min(bytes.len());
                let text = &bytes[at + 3..end];
                for part in text.split(|&b| b == b'[').skip(1) {
                    let digits = part.iter().take_while(|b| b.is_ascii_digit()).count();
                    let n = std::str::from_utf8(&part[..digits])
                        .ok()
                        .and_then(|d| d.parse::<u32>().ok());
                    if digits > 0 && n.is_none_or(|n| n > u32::from(u16::MAX)) {
                        return Err(format!(
                            "a format definition declares an array of {} elements, more than any \
                             ULog message holds: the definitions are damaged",
                            String::from_utf8_lossy(&part[..digits])
                        ));
                    }
                }
            }
            _ => {}
        }
        at += 3 + size;
    }
    Ok(())
}

/// Reads a ULog file's bytes.
pub(crate) fn read(bytes: &[u8], config: &LogConfig) -> Result<Recording> {
    if config.odometry_topic.is_some() {
        return Err(LogError::InvalidConfig {
            field: "odometry_topic",
            reason: "is read from MCAP logs only (a PX4 ULog's odometry is not read); leave it out"
                .to_string(),
        });
    }
    if config.gnss_velocity_topic.is_some() {
        return Err(LogError::InvalidConfig {
            field: "gnss_velocity_topic",
            reason: "is read from MCAP logs only (a PX4 ULog's fixes carry their own velocity, \
                     `vel_m_s` and `cog_rad`); leave it out"
                .to_string(),
        });
    }
    check_array_lengths(bytes).map_err(|detail| LogError::Corrupt {
        format: LogFormat::Ulog,
        detail,
    })?;
    let imu_spec = TopicSpec::parse(config.imu_topic.as_deref().unwrap_or("sensor_combined"));
    let mag_specs: Vec<TopicSpec> = match config.mag_topic.as_deref() {
        Some(NO_TOPIC) => Vec::new(),
        Some(name) => vec![TopicSpec::parse(name)],
        None => MAG_DEFAULTS.iter().map(|n| TopicSpec::plain(n)).collect(),
    };
    let attitude_spec = match config.attitude_topic.as_deref() {
        Some(NO_TOPIC) => None,
        Some(name) => Some(TopicSpec::parse(name)),
        None => Some(TopicSpec::plain("vehicle_attitude")),
    };
    let gnss_specs: Vec<TopicSpec> = match config.gnss_topic.as_deref() {
        Some(NO_TOPIC) => Vec::new(),
        Some(name) => vec![TopicSpec::parse(name)],
        None => GNSS_DEFAULTS.iter().map(|n| TopicSpec::plain(n)).collect(),
    };
    let mut g = Gathered {
        imu_spec,
        mags: vec![Vec::new(); mag_specs.len()],
        mag_errors: vec![None; mag_specs.len()],
        mag_specs,
        attitude_spec,
        decoders: HashMap::new(),
        counts: BTreeMap::new(),
        messages: 0,
        imu: Vec::new(),
        imu_error: None,
        attitude: Vec::new(),
        attitude_error: None,
        gnss: vec![Vec::new(); gnss_specs.len()],
        gnss_errors: vec![None; gnss_specs.len()],
        gnss_specs,
        non_finite: [0; 4],
    };
    let ending = {
        let mut callback = |msg: &DataMessage| g.take(msg);
        let mut parser = LogParser::default();
        parser.set_data_message_callback(&mut callback);
        feed(&mut parser, bytes)?
    };
    let complete = match ending {
        Ending::Complete => true,
        _ if config.accept_incomplete => false,
        Ending::Truncated => {
            return Err(incomplete(
                g.messages,
                "the file ends inside a record".to_string(),
            ));
        }
        Ending::Damaged(detail) => return Err(incomplete(g.messages, detail)),
    };
    finish(g, config, complete)
}

fn incomplete(messages: usize, detail: String) -> LogError {
    LogError::Incomplete {
        format: LogFormat::Ulog,
        messages,
        detail,
    }
}

fn spec_name(s: &TopicSpec) -> String {
    format!("{}:{}", s.name, s.instance)
}

/// The candidate topics of one role, in order of preference, and what each gave.
struct Candidates<'a, T> {
    role: &'static str,
    specs: &'a [TopicSpec],
    samples: &'a mut [Vec<T>],
    errors: &'a mut [Option<String>],
    /// Readings left out for a non-finite value.
    non_finite: usize,
}

impl<T> Candidates<'_, T> {
    /// The first candidate that gave samples: its samples in increasing time and its
    /// summary (none without one). A topic `named` for the role (not `none`), the only
    /// candidate then, must be in the file and serve the role (`check`).
    fn select(
        self,
        named: Option<&str>,
        check: &impl Fn(&'static str, &TopicSpec, Option<String>) -> Result<()>,
        t_s: impl Fn(&T) -> f64,
    ) -> Result<(Vec<T>, Option<StreamInfo>)> {
        if named.is_some_and(|n| n != NO_TOPIC) {
            check(self.role, &self.specs[0], self.errors[0].take())?;
        }
        let Some(k) = self.samples.iter().position(|s| !s.is_empty()) else {
            return Ok((Vec::new(), None));
        };
        let mut samples = std::mem::take(&mut self.samples[k]);
        let dropped = keep_increasing(&mut samples, &t_s) + self.non_finite;
        let info = StreamInfo {
            role: self.role,
            topic: spec_name(&self.specs[k]),
            samples: samples.len(),
            dropped,
            rate_hz: rate_hz(samples.iter().map(&t_s)),
        };
        Ok((samples, Some(info)))
    }
}

/// Selects the streams from what was gathered and checks the requested topics exist.
fn finish(mut g: Gathered, config: &LogConfig, complete: bool) -> Result<Recording> {
    let topics: Vec<TopicInfo> = g
        .counts
        .iter()
        .map(|((name, instance), &messages)| TopicInfo {
            name: name.clone(),
            kind: format!("instance {instance}"),
            messages,
        })
        .collect();
    let present = || topics.iter().map(ToString::to_string).collect::<Vec<_>>();
    let has = |s: &TopicSpec| g.counts.contains_key(&(s.name.clone(), s.instance));
    let missing = |role, s: &TopicSpec| LogError::MissingTopic {
        role,
        requested: spec_name(s),
        present: present(),
    };
    let wrong = |role, s: &TopicSpec, detail: String| LogError::WrongTopicType {
        topic: spec_name(s),
        role,
        detail,
    };

    let check = |role, s: &TopicSpec, error: Option<String>| -> Result<()> {
        if !has(s) {
            return Err(missing(role, s));
        }
        error.map_or(Ok(()), |e| Err(wrong(role, s, e)))
    };
    check("imu", &g.imu_spec, g.imu_error.take())?;
    let mut streams = Vec::new();
    let dropped = keep_increasing(&mut g.imu, |s| s.t_s) + g.non_finite[0];
    streams.push(StreamInfo {
        role: "imu",
        topic: spec_name(&g.imu_spec),
        samples: g.imu.len(),
        dropped,
        rate_hz: rate_hz(g.imu.iter().map(|s| s.t_s)),
    });

    let (mag, info) = Candidates {
        role: "mag",
        specs: &g.mag_specs,
        samples: &mut g.mags,
        errors: &mut g.mag_errors,
        non_finite: g.non_finite[1],
    }
    .select(config.mag_topic.as_deref(), &check, |s| s.t_s)?;
    streams.extend(info);

    if let (Some(name), Some(spec)) = (config.attitude_topic.as_deref(), &g.attitude_spec)
        && name != NO_TOPIC
    {
        check("attitude", spec, g.attitude_error.take())?;
    }
    if let Some(spec) = g.attitude_spec.as_ref().filter(|_| !g.attitude.is_empty()) {
        let dropped = keep_increasing(&mut g.attitude, |s| s.t_s) + g.non_finite[2];
        streams.push(StreamInfo {
            role: "attitude",
            topic: spec_name(spec),
            samples: g.attitude.len(),
            dropped,
            rate_hz: rate_hz(g.attitude.iter().map(|s| s.t_s)),
        });
    }

    let (gnss, info) = Candidates {
        role: "gnss",
        specs: &g.gnss_specs,
        samples: &mut g.gnss,
        errors: &mut g.gnss_errors,
        non_finite: g.non_finite[3],
    }
    .select(config.gnss_topic.as_deref(), &check, |s| s.t_s)?;
    streams.extend(info);

    Ok(Recording {
        format: LogFormat::Ulog,
        time_origin_s: 0.0,
        complete,
        topics,
        streams,
        imu: g.imu,
        mag,
        attitude: g.attitude,
        odometry: Vec::new(),
        gnss,
    })
}
