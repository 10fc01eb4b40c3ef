//! Flight and robot logs (PX4 ULog, ROS 2 MCAP) read into numpy arrays, stream by stream, in
//! the frames and units the `truenorth` command reads them in.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use truenorth_logs::{LogConfig, LogError, LogReader, Recording};

use crate::convert::{TruenorthError, array1, array2};

/// Reads a PX4 ULog (`.ulg`) or ROS 2 MCAP (`.mcap`) log, found by its magic number, into a
/// dict of numpy arrays, each stream at its own timestamps (seconds; PX4: since boot; MCAP:
/// since `time_origin_s`, Unix seconds), body axes x forward, y right, z down:
///
/// * `imu`: `t_s` (N), `gyr_rps` (N×3), `acc_mps2` (N×3, specific force), and `mag_uT`
///   (N×3) with each magnetometer reading on the first IMU row at or after it, NaN rows
///   between: the rows `truenorth orientation` reads (pass them to `update_array`);
/// * `mag`: `t_s` (M), `mag_uT` (M×3), the magnetometer at its own rate;
/// * `attitude`: `t_s` (K), `quaternion` (K×4, `qw,qx,qy,qz`, body → NED), the logger's own
///   estimate;
/// * `odometry`: `t_s` (J), `velocity_mps` (J×3, body axes), `yaw_rate_rps` (J, positive
///   turning right);
/// * `gnss`: `t_s` (F), `lat_deg`, `lon_deg` (F, WGS84), `sigma_m` (F, 1σ horizontal, NaN
///   where the receiver gives none), `speed_mps`, `course_deg` (F, over ground, NaN where it
///   gives none; an MCAP's from `gnss_velocity_topic`, by default a twist topic in the fixes'
///   frame): an MCAP's `sensor_msgs/msg/NavSatFix` fixes or a ULog's
///   `vehicle_gps_position`/`sensor_gps` (messages with no fix left out), ready for
///   `VehicleEstimator`'s `gnss=` (stacked as columns);
/// * `format` (`"PX4 ULog"` or `"MCAP"`), `complete`, `time_origin_s`, `topics` (a list of
///   dicts `name`, `kind`, `messages`) and `streams` (`role`, `topic`, `samples`,
///   `dropped`, `rate_hz`).
///
/// The topics are named as in the file (ULog `name:instance` for another instance;
/// `mag_topic="none"` reads no magnetometer); left out, the format's usual ones. A missing
/// topic, a corrupt file or (without `accept_incomplete`) a truncated one raises
/// `TruenorthError` with the reader's message (a missing topic's names the topics present).
#[pyfunction]
#[pyo3(signature = (path, imu_topic=None, mag_topic=None, attitude_topic=None, odometry_topic=None, accept_incomplete=false, gnss_topic=None, gnss_velocity_topic=None))]
#[allow(clippy::too_many_arguments)]
pub fn read_log<'py>(
    py: Python<'py>,
    path: PathBuf,
    imu_topic: Option<String>,
    mag_topic: Option<String>,
    attitude_topic: Option<String>,
    odometry_topic: Option<String>,
    accept_incomplete: bool,
    gnss_topic: Option<String>,
    gnss_velocity_topic: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let config = LogConfig {
        imu_topic,
        mag_topic,
        attitude_topic,
        odometry_topic,
        gnss_topic,
        gnss_velocity_topic,
        accept_incomplete,
    };
    let read = py.detach(|| LogReader::new(config)?.read_path(&path));
    let r = read.map_err(|e| match e {
        // The reader's own message names the path.
        LogError::Io { .. } => TruenorthError::new_err(e.to_string()),
        _ => TruenorthError::new_err(format!("{}: {e}", path.display())),
    })?;
    recording_dict(py, &r)
}

/// The recording as the dict [`read_log`] documents.
fn recording_dict<'py>(py: Python<'py>, r: &Recording) -> PyResult<Bound<'py, PyDict>> {
    let xyz =
        |v: Option<truenorth::nalgebra::Vector3<f64>>| v.map_or([f64::NAN; 3], |v| [v.x, v.y, v.z]);
    let rows = r.imu_with_mag();
    let imu = PyDict::new(py);
    imu.set_item("t_s", array1(py, rows.iter().map(|s| s.t_s).collect()))?;
    imu.set_item(
        "gyr_rps",
        array2(
            py,
            rows.iter().flat_map(|s| xyz(s.gyr_rps.as_xyz())).collect(),
            3,
        )?,
    )?;
    imu.set_item(
        "acc_mps2",
        array2(
            py,
            rows.iter().flat_map(|s| xyz(s.acc_mps2.as_xyz())).collect(),
            3,
        )?,
    )?;
    imu.set_item(
        "mag_uT",
        array2(
            py,
            rows.iter().flat_map(|s| xyz(s.mag.as_xyz())).collect(),
            3,
        )?,
    )?;
    let mag = PyDict::new(py);
    mag.set_item("t_s", array1(py, r.mag.iter().map(|s| s.t_s).collect()))?;
    mag.set_item(
        "mag_uT",
        array2(py, r.mag.iter().flat_map(|s| xyz(Some(s.mag))).collect(), 3)?,
    )?;
    let attitude = PyDict::new(py);
    attitude.set_item(
        "t_s",
        array1(py, r.attitude.iter().map(|s| s.t_s).collect()),
    )?;
    attitude.set_item(
        "quaternion",
        array2(
            py,
            r.attitude
                .iter()
                .flat_map(|s| {
                    let q = s.attitude;
                    [q.w, q.i, q.j, q.k]
                })
                .collect(),
            4,
        )?,
    )?;
    let odometry = PyDict::new(py);
    odometry.set_item(
        "t_s",
        array1(py, r.odometry.iter().map(|s| s.t_s).collect()),
    )?;
    odometry.set_item(
        "velocity_mps",
        array2(
            py,
            r.odometry
                .iter()
                .flat_map(|s| xyz(Some(s.velocity_mps)))
                .collect(),
            3,
        )?,
    )?;
    odometry.set_item(
        "yaw_rate_rps",
        array1(py, r.odometry.iter().map(|s| s.yaw_rate_rps).collect()),
    )?;
    let gnss = PyDict::new(py);
    gnss.set_item("t_s", array1(py, r.gnss.iter().map(|s| s.t_s).collect()))?;
    gnss.set_item(
        "lat_deg",
        array1(py, r.gnss.iter().map(|s| s.lat_deg).collect()),
    )?;
    gnss.set_item(
        "lon_deg",
        array1(py, r.gnss.iter().map(|s| s.lon_deg).collect()),
    )?;
    gnss.set_item(
        "sigma_m",
        array1(
            py,
            r.gnss
                .iter()
                .map(|s| s.sigma_m.unwrap_or(f64::NAN))
                .collect(),
        ),
    )?;
    let velocity = |pick: fn((f64, f64)) -> f64| -> Vec<f64> {
        r.gnss
            .iter()
            .map(|s| s.velocity.map_or(f64::NAN, pick))
            .collect()
    };
    gnss.set_item("speed_mps", array1(py, velocity(|(v, _)| v)))?;
    gnss.set_item("course_deg", array1(py, velocity(|(_, c)| c)))?;
    let topics = PyList::empty(py);
    for t in &r.topics {
        let d = PyDict::new(py);
        d.set_item("name", &t.name)?;
        d.set_item("kind", &t.kind)?;
        d.set_item("messages", t.messages)?;
        topics.append(d)?;
    }
    let streams = PyList::empty(py);
    for s in &r.streams {
        let d = PyDict::new(py);
        d.set_item("role", s.role)?;
        d.set_item("topic", &s.topic)?;
        d.set_item("samples", s.samples)?;
        d.set_item("dropped", s.dropped)?;
        d.set_item("rate_hz", s.rate_hz)?;
        streams.append(d)?;
    }
    let out = PyDict::new(py);
    out.set_item("format", r.format.to_string())?;
    out.set_item("complete", r.complete)?;
    out.set_item("time_origin_s", r.time_origin_s)?;
    out.set_item("topics", topics)?;
    out.set_item("streams", streams)?;
    out.set_item("imu", imu)?;
    out.set_item("mag", mag)?;
    out.set_item("attitude", attitude)?;
    out.set_item("odometry", odometry)?;
    out.set_item("gnss", gnss)?;
    Ok(out)
}
