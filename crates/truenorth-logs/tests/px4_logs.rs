//! The three real PX4 logs in `../shared/data/px4_ulog_samples/` (pyulog's own test logs):
//! what each holds, at which rates, and the quaternion filter run on `sample.ulg` against
//! PX4's own attitude estimate. Absent logs skip visibly; under CI they fail.

mod common;

use std::path::PathBuf;

use truenorth_core::{OrientationEstimator, angle_diff, rad_to_deg};
use truenorth_fusion::{AttitudeError, QuaternionFilter, QuaternionFilterConfig};
use truenorth_logs::{LogConfig, LogError, LogReader, Recording};

fn folder() -> Option<PathBuf> {
    truenorth_sim::shared_data::folder("px4_ulog_samples").unwrap()
}

fn read(name: &str) -> Option<Recording> {
    let path = folder()?.join(name);
    Some(
        LogReader::new(LogConfig::default())
            .unwrap()
            .read_path(path)
            .unwrap(),
    )
}

/// (role, topic, samples, rate Hz) per selected stream. The counts are the file's; the rates
/// are one over the median timestamp step, to 0.5 %.
fn check_streams(r: &Recording, expected: &[(&str, &str, usize, f64)]) {
    assert!(r.complete);
    for &(role, topic, samples, rate_hz) in expected {
        let s = r.stream(role).unwrap_or_else(|| panic!("no {role} stream"));
        assert_eq!((s.topic.as_str(), s.samples), (topic, samples), "{role}");
        assert!(
            (s.rate_hz / rate_hz - 1.0).abs() < 5e-3,
            "{role}: {} Hz",
            s.rate_hz
        );
        eprintln!(
            "{role}: {topic}, {samples} samples, {:.2} Hz, {} left out",
            s.rate_hz, s.dropped
        );
    }
    assert_eq!(r.streams.len(), expected.len(), "{:?}", r.streams);
    let rows = r.imu_with_mag();
    let with_mag = rows.iter().filter(|s| !s.mag.is_empty()).count();
    assert!(with_mag > 0 && with_mag <= r.mag.len());
}

#[test]
fn sample_ulg_older_layout_with_the_magnetometer_in_sensor_combined() {
    let Some(r) = read("sample.ulg") else { return };
    check_streams(
        &r,
        &[
            ("imu", "sensor_combined:0", 17070, 250.0),
            ("mag", "sensor_combined:0", 6759, 96.47),
            ("attitude", "vehicle_attitude:0", 6461, 83.34),
        ],
    );
    // At rest on the pad before take-off: one gravity, z down (FRD), and an Earth field
    // (25–65 µT) from gauss × 100.
    let a = r.imu[0].acc_mps2.as_xyz().unwrap();
    assert!((a.norm() - 9.81).abs() < 0.5 && a.z < -9.0, "{a:?}");
    let b = r.mag[0].mag.norm();
    assert!((25.0..65.0).contains(&b), "{b} µT");
}

#[test]
fn sample_log_small_newer_layout_with_vehicle_magnetometer() {
    let Some(r) = read("sample_log_small.ulg") else {
        return;
    };
    check_streams(
        &r,
        &[
            ("imu", "sensor_combined:0", 1298, 204.58),
            ("mag", "vehicle_magnetometer:0", 319, 50.0),
            ("attitude", "vehicle_attitude:0", 1298, 204.58),
            ("gnss", "vehicle_gps_position:0", 32, 5.0),
        ],
    );
    // The older integer layout (`lat`, `lon` in 10⁻⁷ degrees), as pyulog 1.2 reads the
    // first and last messages: lat 634170622, lon 104082151, eph 3.26 m at 20.471648 s;
    // lat 634170457, lon 104082271, eph 2.507 m at 26.658637 s.
    let (first, last) = (r.gnss[0], r.gnss[r.gnss.len() - 1]);
    assert_eq!((first.t_s, last.t_s), (20.471648, 26.658637));
    for (fix, lat, lon, eph) in [
        (first, 63.4170622, 10.4082151, 3.26),
        (last, 63.4170457, 10.4082271, 2.507),
    ] {
        assert!((fix.lat_deg - lat).abs() < 1e-9 && (fix.lon_deg - lon).abs() < 1e-9);
        assert!((fix.sigma_m.unwrap() - eph).abs() < 1e-5);
    }
    // `vel_m_s` 0.076 and `cog_rad` 0.57123244 (f32) on the first.
    let (speed, course) = first.velocity.unwrap();
    assert!((speed - 0.076).abs() < 1e-6, "{speed}");
    assert!(
        (course - 0.571_232_44f64.to_degrees()).abs() < 1e-4,
        "{course}"
    );
    let none = LogReader::new(LogConfig {
        gnss_topic: Some("none".into()),
        ..LogConfig::default()
    })
    .unwrap()
    .read_path(folder().unwrap().join("sample_log_small.ulg"))
    .unwrap();
    assert!(none.gnss.is_empty() && none.stream("gnss").is_none());
    // Topic selection by name and instance, and the error listing what is there.
    let dir = folder().unwrap();
    let with = |mag: &str| {
        LogReader::new(LogConfig {
            mag_topic: Some(mag.into()),
            ..LogConfig::default()
        })
        .unwrap()
        .read_path(dir.join("sample_log_small.ulg"))
    };
    let second = with("sensor_mag:1").unwrap();
    assert_eq!(second.stream("mag").unwrap().topic, "sensor_mag:1");
    assert_eq!(second.mag.len(), 6);
    let err = with("sensor_mag:2").unwrap_err();
    assert!(matches!(err, LogError::MissingTopic { role: "mag", .. }));
    let text = err.to_string();
    assert!(
        text.contains("sensor_mag (instance 1, 6 messages)"),
        "{text}"
    );
    let wrong = with("vehicle_attitude").unwrap_err();
    assert!(
        matches!(wrong, LogError::WrongTopicType { role: "mag", .. }),
        "{wrong}"
    );
}

#[test]
fn sample_appended_multiple_reads_its_appended_sections() {
    let Some(r) = read("sample_appended_multiple.ulg") else {
        return;
    };
    check_streams(
        &r,
        &[
            ("imu", "sensor_combined:0", 2373, 250.0),
            ("mag", "sensor_combined:0", 444, 45.83),
            ("attitude", "vehicle_attitude:0", 306, 31.26),
        ],
    );
}

#[test]
fn a_cut_log_is_refused_or_its_prefix_kept() {
    let Some(dir) = folder() else { return };
    let bytes = std::fs::read(dir.join("sample.ulg")).unwrap();
    let cut = &bytes[..bytes.len() / 2 + 7];
    let lenient = common::refused_or_prefix_kept(cut);
    assert!(!lenient.complete);
    assert!(
        lenient.imu.len() > 5000 && lenient.imu.len() < 17070,
        "{}",
        lenient.imu.len()
    );
    // Cut inside the definitions: nothing is usable.
    let header_only = &bytes[..2000];
    let err = common::lenient().read_bytes(header_only).unwrap_err();
    assert!(
        matches!(
            err,
            LogError::Corrupt { .. } | LogError::MissingTopic { .. }
        ),
        "{err}"
    );
}

/// RMS of the inclination and heading differences between the quaternion filter and PX4's
/// `vehicle_attitude` over `sample.ulg`, after the filter's first `settle_s` seconds, and
/// the mean heading offset (PX4 refers heading to true north once it knows its position,
/// the filter to magnetic north: the offset holds the declination).
struct Comparison {
    inclination_rms_deg: f64,
    heading_rms_deg: f64,
    heading_offset_deg: f64,
    heading_rms_about_offset_deg: f64,
    /// RMS over the same instants of the filter's own inclination σ, √(σ_north² + σ_east²).
    inclination_sigma_rms_deg: f64,
    compared: usize,
}

fn compare(r: &Recording, settle_s: f64) -> Comparison {
    let mut filter = QuaternionFilter::new(QuaternionFilterConfig::default()).unwrap();
    let rows = r.imu_with_mag();
    let start = rows[0].t_s + settle_s;
    let mut estimates = Vec::with_capacity(rows.len());
    for s in &rows {
        let e = filter.update(s).unwrap();
        let sigma = e.sigma_rad.unwrap();
        estimates.push((s.t_s, e.attitude, sigma.x.hypot(sigma.y)));
    }
    let (mut incl2, mut head2, mut sigma2, mut heads) = (0.0, 0.0, 0.0, Vec::new());
    for px4 in r.attitude.iter().filter(|a| a.t_s >= start) {
        // The filter's estimate at the last IMU row at or before PX4's timestamp.
        let k = estimates.partition_point(|(t, _, _)| *t <= px4.t_s);
        if k == 0 {
            continue;
        }
        let e = AttitudeError::between(&estimates[k - 1].1, &px4.attitude);
        incl2 += e.inclination_rad.powi(2);
        sigma2 += estimates[k - 1].2.powi(2);
        head2 += e.heading_rad.powi(2);
        // Signed heading difference: the twist of the error about the vertical.
        let q = (estimates[k - 1].1 * px4.attitude.inverse()).into_inner();
        heads.push(angle_diff(2.0 * (q.k / q.w).atan(), 0.0));
    }
    let n = heads.len() as f64;
    let mean = heads.iter().sum::<f64>() / n;
    let about = (heads.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
    Comparison {
        inclination_rms_deg: rad_to_deg((incl2 / n).sqrt()),
        heading_rms_deg: rad_to_deg((head2 / n).sqrt()),
        heading_offset_deg: rad_to_deg(mean),
        heading_rms_about_offset_deg: rad_to_deg(about),
        inclination_sigma_rms_deg: rad_to_deg((sigma2 / n).sqrt()),
        compared: heads.len(),
    }
}

#[test]
fn quaternion_filter_against_px4_attitude_on_sample_ulg() {
    let Some(r) = read("sample.ulg") else { return };
    let c = compare(&r, 10.0);
    eprintln!(
        "quaternion filter vs PX4 vehicle_attitude on sample.ulg ({} instants after 10 s): \
         inclination RMS {:.3}°, heading RMS {:.3}° (mean offset {:+.3}°, RMS about it {:.3}°)",
        c.compared,
        c.inclination_rms_deg,
        c.heading_rms_deg,
        c.heading_offset_deg,
        c.heading_rms_about_offset_deg
    );
    eprintln!(
        "the filter's own inclination σ (RMS): {:.3}°",
        c.inclination_sigma_rms_deg
    );
    assert!(c.compared > 5000);
    // PX4's estimate is not ground truth but another estimate from the same accelerometer
    // and gyro; were its error as large as the filter's own σ and independent of it, the
    // difference's RMS would be √2 σ. Twice the filter's σ bounds the difference.
    assert!(
        c.inclination_rms_deg <= 2.0 * c.inclination_sigma_rms_deg,
        "inclination differs from PX4's by {:.3}° RMS, beyond twice the filter's own σ {:.3}°",
        c.inclination_rms_deg,
        c.inclination_sigma_rms_deg
    );
}
