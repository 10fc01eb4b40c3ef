//! A PX4 ULog's satellite fixes in both layouts PX4 has logged: `latitude_deg`/`longitude_deg`
//! as doubles (`sensor_gps`, PX4 1.14 on) and `lat`/`lon` in 10⁻⁷ degrees (older
//! `vehicle_gps_position`, held on a real log in `px4_logs.rs`). The files are written here,
//! record by record, as the ULog format specifies them: a 16-byte header, then records of a
//! `u16` size, a type byte and the payload.

use truenorth_logs::{LogConfig, LogError, LogReader};

fn record(out: &mut Vec<u8>, kind: u8, payload: &[u8]) {
    out.extend_from_slice(&u16::try_from(payload.len()).unwrap().to_le_bytes());
    out.push(kind);
    out.extend_from_slice(payload);
}

/// A log with an IMU topic and one fix topic of `format` (its fields after `timestamp`),
/// one data message per `payloads` entry (the bytes after `timestamp`), at 0.2 s steps.
fn ulog(gnss_format: &str, payloads: &[Vec<u8>]) -> Vec<u8> {
    let mut out = b"ULog\x01\x12\x35\x01".to_vec();
    out.extend_from_slice(&0u64.to_le_bytes());
    // Flag bits: no compatibility or incompatibility flags, no appended data.
    record(&mut out, b'B', &[0u8; 40]);
    record(
        &mut out,
        b'F',
        b"sensor_combined:uint64_t timestamp;float[3] gyro_rad;float[3] accelerometer_m_s2;",
    );
    record(&mut out, b'F', gnss_format.as_bytes());
    let subscribe = |out: &mut Vec<u8>, id: u16, name: &str| {
        let mut p = vec![0u8];
        p.extend_from_slice(&id.to_le_bytes());
        p.extend_from_slice(name.as_bytes());
        record(out, b'A', &p);
    };
    subscribe(&mut out, 0, "sensor_combined");
    let name = gnss_format.split(':').next().unwrap();
    subscribe(&mut out, 1, name);
    for (k, fix) in payloads.iter().enumerate() {
        let t_us = 1_000_000 + 200_000 * k as u64;
        let mut imu = 0u16.to_le_bytes().to_vec();
        imu.extend_from_slice(&t_us.to_le_bytes());
        for v in [0.0f32, 0.0, 0.0, 0.0, 0.0, -9.81] {
            imu.extend_from_slice(&v.to_le_bytes());
        }
        record(&mut out, b'D', &imu);
        let mut data = 1u16.to_le_bytes().to_vec();
        data.extend_from_slice(&t_us.to_le_bytes());
        data.extend_from_slice(fix);
        record(&mut out, b'D', &data);
    }
    out
}

/// A fix moving at 12.5 m/s on a course of −90° (west), its velocity valid or not.
fn double_fix(lat: f64, lon: f64, eph: f32, fix_type: u8, velocity_valid: bool) -> Vec<u8> {
    let mut p = lat.to_le_bytes().to_vec();
    p.extend_from_slice(&lon.to_le_bytes());
    p.extend_from_slice(&eph.to_le_bytes());
    p.push(fix_type);
    p.extend_from_slice(&12.5f32.to_le_bytes());
    p.extend_from_slice(&(-core::f32::consts::FRAC_PI_2).to_le_bytes());
    p.push(u8::from(velocity_valid));
    p
}

const DOUBLES: &str = "sensor_gps:uint64_t timestamp;double latitude_deg;double longitude_deg;float eph;uint8_t fix_type;float vel_m_s;float cog_rad;bool vel_ned_valid;";

#[test]
fn newer_layout_in_degrees_with_its_accuracy_and_no_fix_left_out() {
    let bytes = ulog(
        DOUBLES,
        &[
            double_fix(52.5123456789, 13.3987654321, 2.5, 3, true),
            double_fix(0.0, 0.0, 99.0, 1, true),
            double_fix(52.5123556789, 13.3987754321, 1.5, 6, false),
        ],
    );
    let r = LogReader::new(LogConfig::default())
        .unwrap()
        .read_bytes(&bytes)
        .unwrap();
    assert_eq!(r.imu.len(), 3);
    assert_eq!(
        r.gnss.len(),
        2,
        "the message without a fix (type 1) is left out"
    );
    assert_eq!(r.stream("gnss").unwrap().topic, "sensor_gps:0");
    assert_eq!(r.gnss[0].t_s, 1.0);
    assert_eq!(
        (r.gnss[0].lat_deg, r.gnss[0].lon_deg),
        (52.5123456789, 13.3987654321)
    );
    assert_eq!((r.gnss[1].t_s, r.gnss[1].sigma_m), (1.4, Some(1.5)));
    // The course clockwise from north in [0, 360); none where the receiver says the
    // velocity is not valid.
    let (speed, course) = r.gnss[0].velocity.unwrap();
    assert_eq!(speed, 12.5);
    assert!((course - 270.0).abs() < 1e-5, "{course}");
    assert_eq!(r.gnss[1].velocity, None);
}

#[test]
fn a_fix_topic_named_must_be_there_and_serve() {
    let bytes = ulog(DOUBLES, &[double_fix(52.5, 13.4, 2.5, 3, true)]);
    let read = |topic: &str| {
        LogReader::new(LogConfig {
            gnss_topic: Some(topic.into()),
            ..LogConfig::default()
        })
        .unwrap()
        .read_bytes(&bytes)
    };
    let missing = read("vehicle_gps_position").unwrap_err();
    assert!(
        matches!(missing, LogError::MissingTopic { role: "gnss", .. }),
        "{missing}"
    );
    let wrong = read("sensor_combined").unwrap_err();
    assert!(
        matches!(wrong, LogError::WrongTopicType { role: "gnss", .. }),
        "{wrong}"
    );
    assert!(read("none").unwrap().gnss.is_empty());
    let odometry = LogReader::new(LogConfig {
        odometry_topic: Some("vehicle_odometry".into()),
        ..LogConfig::default()
    })
    .unwrap()
    .read_bytes(&bytes)
    .unwrap_err();
    assert!(matches!(
        odometry,
        LogError::InvalidConfig {
            field: "odometry_topic",
            ..
        }
    ));
    // A ULog fix carries its own velocity: a velocity topic named is refused, not ignored.
    let velocity = LogReader::new(LogConfig {
        gnss_velocity_topic: Some("vehicle_gps_position".into()),
        ..LogConfig::default()
    })
    .unwrap()
    .read_bytes(&bytes)
    .unwrap_err();
    assert!(matches!(
        velocity,
        LogError::InvalidConfig {
            field: "gnss_velocity_topic",
            ..
        }
    ));
}
