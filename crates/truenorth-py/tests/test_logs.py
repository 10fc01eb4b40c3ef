"""`read_log`: PX4 ULog and ROS 2 MCAP read into arrays, in the command's frames and units,
and the quaternion filter over them agreeing with `truenorth orientation` on the same log."""

import csv
import subprocess

import numpy as np
import pytest

import truenorth as tn
from conftest import REPO, missing

MCAP = REPO / "crates" / "truenorth-logs" / "tests" / "data" / "ros2_small.mcap"


@pytest.fixture
def sample_ulg(data):
    path = data / "px4_ulog_samples" / "sample.ulg"
    if not path.is_file():
        missing(f"no {path}")
    return path


def test_sample_ulg_streams_counts_and_units(sample_ulg):
    log = tn.read_log(sample_ulg)
    assert log["format"] == "PX4 ULog" and log["complete"]
    streams = {s["role"]: s for s in log["streams"]}
    assert (streams["imu"]["topic"], streams["imu"]["samples"]) == ("sensor_combined:0", 17070)
    assert streams["mag"]["samples"] == 6759 and streams["attitude"]["samples"] == 6461
    assert any(t["name"] == "vehicle_attitude" for t in log["topics"])
    imu, mag = log["imu"], log["mag"]
    assert imu["gyr_rps"].shape == (17070, 3) and imu["mag_uT"].shape == (17070, 3)
    assert mag["mag_uT"].shape == (6759, 3) and log["attitude"]["quaternion"].shape == (6461, 4)
    assert np.all(np.diff(imu["t_s"]) > 0)
    # On the pad: one gravity up the -z axis (FRD), an Earth field in µT.
    assert abs(np.linalg.norm(imu["acc_mps2"][0]) - 9.81) < 0.5 and imu["acc_mps2"][0, 2] < -9
    assert 25 < np.linalg.norm(mag["mag_uT"][0]) < 65
    # Each magnetometer reading sits on one IMU row at or after it.
    with_mag = ~np.isnan(imu["mag_uT"][:, 0])
    assert 0 < with_mag.sum() <= len(mag["t_s"])


def test_orientation_from_read_log_is_the_commands(sample_ulg, cli, tmp_path):
    out = tmp_path / "attitude.csv"
    subprocess.run([cli, "orientation", "--input", str(sample_ulg), "--output", str(out)],
                   check=True)
    with open(out) as f:
        rows = np.array([[float(v) for v in r] for r in list(csv.reader(f))[1:]])
    imu = tn.read_log(sample_ulg)["imu"]
    got = tn.QuaternionFilter().update_array(
        imu["t_s"], imu["gyr_rps"], imu["acc_mps2"], imu["mag_uT"])
    assert np.array_equal(rows[:, 0], got["t_s"])
    assert np.array_equal(rows[:, 1:5], got["quaternion"])


def test_mcap_fixture_streams_and_frames():
    log = tn.read_log(MCAP)
    assert log["format"] == "MCAP" and log["time_origin_s"] > 1.6e9
    assert len(log["imu"]["t_s"]) == 200 and len(log["mag"]["t_s"]) == 50
    assert len(log["odometry"]["t_s"]) == 20 and len(log["attitude"]["t_s"]) == 0
    # The robot turns left (REP-103 +z) at 0.5 rad/s: negative about z down.
    assert np.allclose(log["imu"]["gyr_rps"][:, 2], -0.5)
    assert np.allclose(log["odometry"]["yaw_rate_rps"], -0.5)
    assert np.allclose(log["imu"]["acc_mps2"][:, 2], -9.81)
    without = tn.read_log(MCAP, mag_topic="none")
    assert len(without["mag"]["t_s"]) == 0 and np.isnan(without["imu"]["mag_uT"]).all()


def test_log_errors_are_the_packages_exception(tmp_path):
    with pytest.raises(tn.TruenorthError, match="topics present: /chatter"):
        tn.read_log(MCAP, imu_topic="/nope")
    # A receiver's velocity topic is checked for its type like any other.
    with pytest.raises(tn.TruenorthError, match="cannot serve as gnss_velocity"):
        tn.read_log(MCAP, gnss_velocity_topic="/chatter")
    text = tmp_path / "x.csv"
    text.write_text("t_s,gyr_x\n0,1\n")
    with pytest.raises(tn.TruenorthError, match="not a PX4 ULog or MCAP"):
        tn.read_log(text)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(MCAP.read_bytes()[: MCAP.stat().st_size // 2])
    with pytest.raises(tn.TruenorthError):
        tn.read_log(cut)
    with pytest.raises(tn.TruenorthError, match="x.ulg"):
        tn.read_log(tmp_path / "x.ulg")


def test_check_gnss_delay_finds_fixes_stamped_late():
    # A car at 12 m/s weaving, its gyro in deg/s with a bias; fixes at 5 Hz carry the
    # course of the epoch 2 s before their stamp.
    t = np.arange(0.0, 300.0, 0.02)
    heading = -0.2 / 0.21 * np.cos(0.21 * t) - 0.1 / 0.67 * np.cos(0.67 * t + 1.0)
    rate = 0.2 * np.sin(0.21 * t) + 0.1 * np.sin(0.67 * t + 1.0)
    gyr = np.degrees(rate) + 1.0
    fix = (np.arange(len(t)) % 10 == 0) & (t >= 2.0)
    lat = np.where(fix, 52.5, np.nan)
    lon = np.where(fix, 13.4, np.nan)
    speed = np.where(fix, 12.0, np.nan)
    course = np.where(fix, np.degrees(np.interp(t - 2.0, t, heading)) % 360.0, np.nan)
    found = tn.check_gnss_delay(t, gyr, lat, lon, speed, course)
    assert abs(found["lag_s"] - 2.0) < 3 * found["sigma_s"] and found["sigma_s"] < 0.1
    assert found["excess_at_assumed"] > 25
    on_time = np.where(fix, np.degrees(heading) % 360.0, np.nan)
    found = tn.check_gnss_delay(t, gyr, lat, lon, speed, on_time)
    assert abs(found["lag_s"]) < 0.1 and found["excess_at_assumed"] < 9
    assert tn.check_gnss_delay(t[:100], gyr[:100], lat[:100], lon[:100]) is None
    with pytest.raises(ValueError, match="together"):
        tn.check_gnss_delay(t, gyr, lat, lon, speed)
