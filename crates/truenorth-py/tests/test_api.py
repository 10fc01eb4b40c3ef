"""The package's API on its own: shapes, per-sample and array paths, reports, errors."""

import math

import numpy as np
import pytest

import truenorth as tn
from conftest import load_csv


def circle(n=720, hard=(8.0, -3.0), field=20.0, turns=2.0):
    psi = np.linspace(0.0, 2 * math.pi * turns, n, endpoint=False)
    mag = np.column_stack([hard[0] + field * np.cos(psi), hard[1] - field * np.sin(psi)])
    return np.arange(n) * 0.1, mag, psi


def test_errors_are_one_value_error_with_the_librarys_message():
    assert issubclass(tn.TruenorthError, ValueError)
    with pytest.raises(tn.TruenorthError, match="too few points"):
        tn.calibrate("ellipse", np.zeros((3, 2)))
    with pytest.raises(ValueError, match="unknown calibration method `nope`"):
        tn.Calibrator("nope")
    with pytest.raises(tn.TruenorthError, match="columns"):
        tn.calibrate("ellipsoid", np.zeros((10, 2)))
    with pytest.raises(tn.TruenorthError, match="invalid configuration"):
        tn.QuaternionFilter({"no_such_field": 1})
    with pytest.raises(tn.TruenorthError, match="row 1"):
        tn.QuaternionFilter().update_array(
            np.array([0.0, 0.0]), np.zeros((2, 3)), np.tile([0.0, 0.0, -9.81], (2, 1)))
    with pytest.raises(tn.TruenorthError):
        tn.field(51.5, -0.13, 2040.0)


def test_a_circle_calibrates_with_its_hard_iron_and_a_good_verdict():
    t, mag, psi = circle()
    cal = tn.calibrate("ellipse", mag, t_s=t)
    assert cal.dimensions == 2 and cal.method == "ellipse"
    assert np.allclose(cal.hard_iron, [8.0, -3.0], atol=1e-9)
    assert cal.soft_iron.shape == (2, 2)
    assert cal.field == pytest.approx(20.0, rel=1e-9)
    assert cal.verdict.grade == "good" and cal.verdict.reason
    q = cal.quality
    assert q.points == len(t) and q.coverage > 0.99
    assert q.uncertainty.dilution == pytest.approx(2.0, rel=0.05)
    d = cal.to_dict()
    assert d["quality"]["verdict"]["grade"] == "good"
    assert d["soft_iron"] == cal.soft_iron.tolist()
    # Heading: psi clockwise from north, in [0, 360).
    h = cal.heading(mag)
    err = (h - np.degrees(psi) + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(err)) < 1e-6
    assert h.min() >= 0.0 and h.max() < 360.0


def test_per_sample_push_equals_the_array_push():
    t, mag, _ = circle()
    one = tn.Calibrator("online-ellipse")
    for k in range(len(t)):
        assert one.push(t[k], mag[k].tolist()) in ("ignored", "accepted", "new_estimate")
    many = tn.Calibrator("online-ellipse")
    assert many.push_array(mag, t_s=t) > 0
    a, b = one.estimate(), many.estimate()
    assert a is not None and b is not None
    assert a.to_dict() == b.to_dict()
    assert many.progress()["ready"]
    many.reset()
    assert many.progress()["samples"] == 0
    assert tn.Calibrator("ellipse").estimate() is None


@pytest.mark.parametrize("method", ["binned-ellipse", "merit-circle", "turn"])
def test_the_seed_methods_run(method):
    t, mag, _ = circle(n=1440, turns=4.0)
    cal = tn.calibrate(method, mag, t_s=t)
    assert np.allclose(cal.hard_iron, [8.0, -3.0], atol=0.5)


def test_configuration_dicts_reach_the_library():
    t, mag, _ = circle()
    cal = tn.calibrate("ellipse", mag, t_s=t, config={"expected_field": 40.0})
    assert cal.quality.field_ratio_to_expected == pytest.approx(0.5, rel=1e-6)


def test_orientation_per_sample_equals_the_array_call():
    n = 500
    t = np.arange(n) * 0.01
    gyr = np.column_stack([np.zeros(n), np.zeros(n), np.full(n, 0.3)])
    acc = np.tile([0.0, 0.0, -9.81], (n, 1))
    mag = np.tile([20.0, 0.0, 40.0], (n, 1))
    mag[::2] = np.nan  # a magnetometer at half the rate
    for cls in (tn.QuaternionFilter, tn.EulerDetector):
        arrays = cls().update_array(t, gyr, acc, mag)
        f = cls()
        for k in range(n):
            m = None if np.isnan(mag[k, 0]) else mag[k].tolist()
            a = f.update(t[k], gyr[k].tolist(), acc[k].tolist(), m)
        assert a.quaternion == tuple(arrays["quaternion"][-1])
        assert a.yaw_deg == arrays["euler_deg"][-1, 0]
        assert f.estimate().t_s == t[-1]
        assert arrays["quaternion"].shape == (n, 4) and arrays["at_rest"].dtype == bool
    # Level: the body's z axis stays down; pitch and roll near zero.
    assert np.max(np.abs(arrays["euler_deg"][:, 1:])) < 1.0


def test_6d_filter_and_enu_frame():
    n = 200
    t = np.arange(n) * 0.01
    r = tn.QuaternionFilter({"use_mag": False}).update_array(
        t, np.zeros((n, 3)), np.tile([0.0, 0.0, -9.81], (n, 1)), frame="enu")
    w, x, y, z = r["quaternion"][-1]
    # NED → ENU of a level body facing north: a half turn about the NE bisector.
    assert abs(w) < 1e-6 and abs(z) < 1e-6
    with pytest.raises(tn.TruenorthError, match="frame"):
        tn.QuaternionFilter().update_array(t, np.zeros((n, 3)), np.zeros((n, 3)), frame="xyz")


def test_vehicle_estimator_drives_straight_north_with_its_compass():
    n = 600
    t = np.arange(n) * 0.1
    dist = t * 10.0
    mag = np.tile([20.0, 0.0], (n, 1))
    v = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    r = v.update_array(t, dist_l_m=dist, dist_r_m=dist, gyr_z=np.zeros(n), mag=mag)
    assert r["north_m"][-1] == pytest.approx(dist[-1], rel=0.01)
    assert abs(r["east_m"][-1]) < 1.0
    one = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    for k in range(n):
        last = one.update(t[k], dist[k], dist[k], 0.0, (20.0, 0.0))
    assert last["north_m"] == r["north_m"][-1]
    assert isinstance(v.calibration(), dict)


def test_vehicle_priors_of_a_kind_go_into_the_configuration():
    skid = {"skid_steer": {"track_m": 0.57}}
    counted = tn.VehicleEstimator.priors(skid)
    speeds = tn.VehicleEstimator.priors(skid, speeds=True)
    assert counted["wheel_speed_quantum_mps"] == 0.0
    assert speeds["wheel_speed_quantum_mps"] == pytest.approx(0.001)
    assert speeds["compass_ground_tilt_deg"] == 6.0
    car = tn.VehicleEstimator.priors({"rear": {"track_m": 1.6}}, speeds=True)
    assert car["compass_ground_tilt_deg"] == 0.0
    tn.VehicleEstimator({"wheels": skid, "priors": speeds})
    with pytest.raises(tn.TruenorthError, match="invalid wheels"):
        tn.VehicleEstimator.priors({"tracked": {"track_m": 1.0}})


def test_vehicle_estimator_takes_one_vehicle_distance_with_a_yaw_rate():
    # A CAN bus's speed integrated (10 m/s) and a yaw rate of 0.05 rad/s for 20 s: an arc of
    # 200 m through 1 rad. The distance says nothing about turning: the gyro turns it.
    n = 201
    t = np.arange(n) * 0.1
    dist = t * 10.0
    v = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    r = v.update_array(t, gyr_z=np.full(n, 0.05), dist_m=dist)
    assert r["north_m"][-1] == pytest.approx(200.0 * math.sin(1.0), abs=1.0)
    assert r["east_m"][-1] == pytest.approx(200.0 * (1.0 - math.cos(1.0)), abs=1.0)
    one = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    for k in range(n):
        last = one.update(t[k], gyr_z=0.05, dist_m=dist[k])
    assert last["north_m"] == r["north_m"][-1]


def test_wmm_matches_the_official_test_values(data):
    """WMM2025_TEST_VALUES.txt: date, height km, lat, lon, X, Y, Z (nT), ..."""
    path = data / "wmm2025" / "WMM2025_TEST_VALUES.txt"
    rows = [l.split() for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    assert rows
    for r in rows:
        year, alt, lat, lon = map(float, r[:4])
        f = tn.field(lat, lon, year, alt_km=alt)
        # The file gives X, Y, Z to 0.1 nT.
        assert f.x_nt == pytest.approx(float(r[4]), abs=0.06)
        assert f.y_nt == pytest.approx(float(r[5]), abs=0.06)
        assert f.z_nt == pytest.approx(float(r[6]), abs=0.06)


def test_ellipsoid_accel_reports_its_joint_figures(data):
    _, rows = load_csv(data / "magcal_ck_explorer" / "acc_mag_log.csv")
    cal = tn.calibrate("ellipsoid-accel", rows[:, 3:6], acc=rows[:, 0:3])
    d = cal.to_dict()
    assert "joint" in d["quality"] and "dip_deg" in d
    assert np.array(d["mag_to_body"]).shape == (3, 3)
    h = cal.heading(rows[:100, 3:6], acc=rows[:100, 0:3])
    assert h.shape == (100,)
    with pytest.raises(tn.TruenorthError, match="needs `acc`"):
        tn.calibrate("ellipsoid-accel", rows[:, 3:6])


def rolling(rate_rps=0.8, seconds=20.0, hz=100.0):
    """A body turning at a constant rate about an axis off the vertical: its gyro, its
    specific force and the Earth's field in its axes."""
    n = int(seconds * hz)
    t = np.arange(n) / hz
    axis = np.array([0.6, 0.3, 0.74])
    axis /= np.linalg.norm(axis)
    w = rate_rps * axis
    up, field = np.array([0.0, 0.0, -9.80665]), np.array([18.0, 1.5, 45.0])
    acc, mag = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        # Body axes seen from the start: rotate the world vectors back by the turn so far.
        a = -rate_rps * t[k]
        c, s = math.cos(a), math.sin(a)
        kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        r = np.eye(3) + s * kx + (1 - c) * kx @ kx
        acc[k], mag[k] = r @ up, r @ field
    return t, np.tile(w, (n, 1)), acc, mag


def test_check_imu_names_the_unit_and_the_axes_that_read_the_data_right():
    t, gyr, acc, mag = rolling()
    assert tn.check_imu(t, gyr, acc, mag) == []
    found = tn.check_imu(t, np.degrees(gyr), acc, mag)
    assert found[0]["kind"] == "units" and found[0]["fix"] == {"gyro_unit": "deg/s"}
    assert tn.check_imu(t, np.degrees(gyr), acc, mag, gyro_unit="deg/s") == []
    found = tn.check_imu(t, gyr, acc / 9.80665, mag)
    assert found[0]["fix"] == {"acc_unit": "g"}
    swapped = gyr[:, [1, 0, 2]]
    found = tn.check_imu(t, swapped, acc, mag)
    assert found[0]["kind"] == "axes" and found[0]["fix"] == {"gyro_axes": "x=y,y=x,z=z"}
    # A magnetometer with x and y swapped: the gyro agrees with gravity, so it is the
    # magnetometer that is named, with the mapping that undoes a mirror or a turned mount.
    found = tn.check_imu(t, gyr, acc, mag[:, [1, 0, 2]])
    assert found[0]["kind"] == "axes"
    assert found[0]["fix"] == {"mag_axes": "x=y,y=x,z=z", "mag_axes_rotation": "x=-y,y=-x,z=-z"}
    # A gyro frozen on one reading for 300 rows where it otherwise changes every step.
    noisy = gyr + 1e-4 * np.sin(np.arange(len(t)) * 12.9898)[:, None]
    frozen = noisy.copy()
    frozen[500:800] = frozen[500]
    assert all(f["kind"] != "faults" for f in tn.check_imu(t, noisy, acc, mag))
    faults = [f for f in tn.check_imu(t, frozen, acc, mag) if f["kind"] == "faults"]
    assert faults and faults[0]["row"] == 500 and "stopped updating" in faults[0]["fix"]["advice"]
    with pytest.raises(tn.TruenorthError, match="gyro_unit"):
        tn.check_imu(t, gyr, acc, gyro_unit="rpm")


def test_vehicle_estimator_takes_satellite_fixes():
    # Due east at 10 m/s for 60 s from Berlin, fixes once a second with their course: the
    # track goes onto the tangent plane at the first fix and the heading onto true north.
    n = 601
    t = np.arange(n) * 0.1
    dist = t * 10.0
    lat0, lon0 = 52.5, 13.4
    metres_per_deg_lon = 111_320.0 * math.cos(math.radians(lat0))
    fixes = np.full((n, 3), np.nan)
    for k in range(0, n, 10):
        fixes[k] = (lat0, lon0 + dist[k] / metres_per_deg_lon, 2.0)
    v = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    r = v.update_array(t, gyr_z=np.zeros(n), dist_m=dist, gnss=fixes)
    assert r["gnss_frame"][-1]
    assert r["east_m"][-1] == pytest.approx(600.0, abs=5.0)
    assert abs(r["north_m"][-1]) < 5.0
    assert r["heading_deg"][-1] == pytest.approx(90.0, abs=2.0)
    one = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    for k in range(n):
        fix = None if np.isnan(fixes[k, 0]) else tuple(fixes[k])
        last = one.update(t[k], gyr_z=0.0, dist_m=dist[k], gnss=fix)
    assert last["gnss_frame"]
    assert last["east_m"] == r["east_m"][-1]


def test_vehicle_estimator_without_odometry_takes_the_fixes_course():
    # A gyro alone, due east at 10 m/s, fixes with speed and course once a second: the
    # heading goes onto true north, and there is no position without odometry.
    n = 601
    t = np.arange(n) * 0.1
    lat0, lon0 = 52.5, 13.4
    metres_per_deg_lon = 111_320.0 * math.cos(math.radians(lat0))
    fixes = np.full((n, 5), np.nan)
    for k in range(0, n, 10):
        fixes[k] = (lat0, lon0 + 10.0 * t[k] / metres_per_deg_lon, 2.0, 10.0, 90.0)
    v = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    r = v.update_array(t, gyr_z=np.zeros(n), gnss=fixes)
    assert r["gnss_frame"][-1]
    assert r["heading_deg"][-1] == pytest.approx(90.0, abs=2.0)
    assert np.isnan(r["north_m"][-1]) and np.isnan(r["east_m"][-1])
    one = tn.VehicleEstimator({"wheels": {"rear": {"track_m": 1.6}}})
    for k in range(n):
        fix = None if np.isnan(fixes[k, 0]) else tuple(fixes[k])
        last = one.update(t[k], gyr_z=0.0, gnss=fix)
    assert last["heading_deg"] == r["heading_deg"][-1]
    with pytest.raises(tn.TruenorthError, match="got 4 values"):
        one.update(61.0, gyr_z=0.0, gnss=(lat0, lon0, 2.0, 10.0))
