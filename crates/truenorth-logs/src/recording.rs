//! What a log yields: the selected streams as the library's sample types, each at its own
//! timestamps, and a summary of every topic in the file.

use nalgebra::{UnitQuaternion, Vector3};
use truenorth_core::{Axes, ImuSample, Mag3Sample};

use crate::error::LogFormat;

/// The logger's own attitude at one instant, body FRD → NED.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeSample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Hamilton quaternion rotating body vectors into NED.
    pub attitude: UnitQuaternion<f64>,
}

/// The body's motion from a wheel or visual odometer, on FRD axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometrySample {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// Velocity along the body axes (x forward, y right, z down), m/s.
    pub velocity_mps: Vector3<f64>,
    /// Yaw rate about the body z axis (down), rad/s: positive turning right.
    pub yaw_rate_rps: f64,
}

/// A satellite fix, as a receiver gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssFix {
    /// Time, s, on the recording's clock.
    pub t_s: f64,
    /// Latitude, degrees (WGS84).
    pub lat_deg: f64,
    /// Longitude, degrees (WGS84).
    pub lon_deg: f64,
    /// 1σ horizontal error the receiver gives, m, when it gives one.
    pub sigma_m: Option<f64>,
    /// Speed over ground, m/s, and course over ground, degrees clockwise from true north,
    /// when the receiver gives both (PX4's `vel_m_s` and `cog_rad`; for a NavSatFix, the
    /// receiver's velocity topic nearest in time, [`crate::LogConfig::gnss_velocity_topic`]).
    pub velocity: Option<(f64, f64)>,
}

/// One topic of the file: its name, instance (ULog) or message type (MCAP), and message count.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    /// Topic name.
    pub name: String,
    /// ULog: `instance N`; MCAP: the schema name (`sensor_msgs/msg/Imu`).
    pub kind: String,
    /// Messages in the file.
    pub messages: usize,
}

impl core::fmt::Display for TopicInfo {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} ({}, {} messages)",
            self.name, self.kind, self.messages
        )
    }
}

/// A selected stream: where it came from and its rate.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamInfo {
    /// The role: `imu`, `mag`, `attitude`, `odometry` or `gnss`.
    pub role: &'static str,
    /// The topic it was read from (ULog `name:instance`).
    pub topic: String,
    /// Samples kept.
    pub samples: usize,
    /// Messages left out: a reading whose time does not increase (the repeats of a slow
    /// sensor carried on a faster topic, as PX4's older `sensor_combined` carries the
    /// magnetometer) or that holds a non-finite value.
    pub dropped: usize,
    /// One over the median step of the timestamps, Hz (0 with fewer than two samples).
    pub rate_hz: f64,
}

/// A log read into the library's types. Every stream keeps its own timestamps (seconds; PX4:
/// since boot; MCAP: since `time_origin_s`), strictly increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// The file's format.
    pub format: LogFormat,
    /// Seconds added back to every `t_s` for the logger's own clock (MCAP: Unix time of the
    /// first selected sample; PX4: 0, its timestamps being time since boot).
    pub time_origin_s: f64,
    /// Whether the file ended cleanly (always `true` unless `accept_incomplete` kept the part
    /// before a damaged tail).
    pub complete: bool,
    /// Every topic in the file.
    pub topics: Vec<TopicInfo>,
    /// The selected streams (those present): ULog imu, mag, attitude, gnss; MCAP imu, mag,
    /// odometry, gnss, gnss_velocity, attitude.
    pub streams: Vec<StreamInfo>,
    /// Gyro (rad/s) and accelerometer (m/s², specific force) readings, FRD body axes, no
    /// magnetometer: one per message of the IMU topic.
    pub imu: Vec<ImuSample>,
    /// Magnetometer readings, FRD body axes, microtesla (PX4's gauss × 100, ROS's tesla × 10⁶).
    pub mag: Vec<Mag3Sample>,
    /// The logger's own attitude estimate, body FRD → NED.
    pub attitude: Vec<AttitudeSample>,
    /// Body velocity and yaw rate (MCAP odometry).
    pub odometry: Vec<OdometrySample>,
    /// Satellite fixes (MCAP `sensor_msgs/msg/NavSatFix`, ULog `vehicle_gps_position` or
    /// `sensor_gps`, each with a fix), if a topic has them.
    pub gnss: Vec<GnssFix>,
}

impl Recording {
    /// The IMU rows with each magnetometer reading placed on the first IMU row at or after
    /// its timestamp, as the `orientation` command's CSV rows carry them: a magnetometer at
    /// 50 Hz beside a gyro at 250 Hz is present on every fifth row and absent between. When
    /// two magnetometer readings fall before the same IMU row, the later one is kept.
    pub fn imu_with_mag(&self) -> Vec<ImuSample> {
        let mut out = self.imu.clone();
        let mut next_mag = 0;
        for row in &mut out {
            let mut latest = None;
            while let Some(m) = self.mag.get(next_mag) {
                if m.t_s > row.t_s {
                    break;
                }
                latest = Some(m.mag);
                next_mag += 1;
            }
            if let Some(m) = latest {
                row.mag = Axes::xyz(m);
            }
        }
        out
    }

    /// The summary of the stream read for `role`, if one was.
    pub fn stream(&self, role: &str) -> Option<&StreamInfo> {
        self.streams.iter().find(|s| s.role == role)
    }
}

/// One over the median step of increasing timestamps, Hz; 0 with fewer than two.
pub(crate) fn rate_hz(times_s: impl Iterator<Item = f64>) -> f64 {
    let t: Vec<f64> = times_s.collect();
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    if median > 0.0 { 1.0 / median } else { 0.0 }
}

/// Sorts by time (stably: a log's order is kept among equal times), then keeps only samples
/// whose time is finite and increases; returns how many were dropped.
pub(crate) fn keep_increasing<T>(samples: &mut Vec<T>, t_s: impl Fn(&T) -> f64) -> usize {
    let before = samples.len();
    samples.retain(|s| t_s(s).is_finite());
    samples.sort_by(|a, b| t_s(a).total_cmp(&t_s(b)));
    let mut last = f64::NEG_INFINITY;
    samples.retain(|s| {
        let t = t_s(s);
        let keep = t > last;
        if keep {
            last = t;
        }
        keep
    });
    before - samples.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn recording(imu_t: &[f64], mag_t: &[f64]) -> Recording {
        Recording {
            format: LogFormat::Ulog,
            time_origin_s: 0.0,
            complete: true,
            topics: Vec::new(),
            streams: Vec::new(),
            imu: imu_t
                .iter()
                .map(|&t| ImuSample::new_6d(t, Vector3::zeros(), Vector3::new(0.0, 0.0, -9.81)))
                .collect(),
            mag: mag_t
                .iter()
                .map(|&t| Mag3Sample::new(t, t, 0.0, 0.0))
                .collect(),
            attitude: Vec::new(),
            odometry: Vec::new(),
            gnss: Vec::new(),
        }
    }

    #[test]
    fn a_slow_magnetometer_lands_on_every_fifth_row() {
        let imu: Vec<f64> = (0..250).map(|k| k as f64 / 250.0).collect();
        let mag: Vec<f64> = (0..50).map(|k| k as f64 / 50.0 + 1e-4).collect();
        let rows = recording(&imu, &mag).imu_with_mag();
        let with_mag = rows.iter().filter(|r| !r.mag.is_empty()).count();
        assert_eq!(with_mag, 50, "every reading finds a row at or after it");
        assert!(rows[1].mag.x.is_some() && rows[2].mag.is_empty());
        assert!((rate_hz(imu.iter().copied()) - 250.0).abs() < 1e-6);
        assert!((rate_hz(mag.iter().copied()) - 50.0).abs() < 1e-6);
    }

    proptest! {
        /// No reading is placed before its time, none twice, and each row carries the
        /// latest reading not yet placed.
        #[test]
        fn mag_placement_never_looks_ahead(
            imu in prop::collection::vec(0.0f64..10.0, 0..60),
            mag in prop::collection::vec(0.0f64..10.0, 0..30),
        ) {
            let mut imu = imu;
            let mut mag = mag;
            keep_increasing(&mut imu, |t| *t);
            keep_increasing(&mut mag, |t| *t);
            let rows = recording(&imu, &mag).imu_with_mag();
            let mut used = Vec::new();
            for r in &rows {
                if let Some(x) = r.mag.x {
                    prop_assert!(x <= r.t_s);
                    used.push(x);
                }
            }
            prop_assert!(used.windows(2).all(|w| w[0] < w[1]));
        }

        #[test]
        fn kept_times_increase(t in prop::collection::vec(prop_oneof![any::<f64>(), -5.0f64..5.0], 0..50)) {
            let mut t = t;
            let n = t.len();
            let dropped = keep_increasing(&mut t, |x| *x);
            prop_assert_eq!(dropped + t.len(), n);
            prop_assert!(t.windows(2).all(|w| w[0] < w[1]));
            prop_assert!(t.iter().all(|x| x.is_finite()));
        }
    }
}
