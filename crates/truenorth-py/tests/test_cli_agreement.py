"""Python and the `truenorth` command give the same numbers on the same real recordings.

Both sides parse the same decimal text to the nearest double, run the same library code
(the package's Cargo.lock starts from the workspace's), and the command writes every float
in its shortest round-trip form, so the agreement asked for is bit-identical: `==`, no
tolerance."""

import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import truenorth as tn
from conftest import load_csv

SUNSIDED = "magcal_sunsided_mpu6050_hmc5883l"


def run_cli(cli: str, *args: str) -> None:
    r = subprocess.run([cli, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def same_number(a, b) -> bool:
    """Equal, or both absent / non-finite (the file writes a non-finite figure as null)."""
    if a is None or b is None:
        return (a is None or not math.isfinite(a)) and (b is None or not math.isfinite(b))
    return a == b


def compare_quality(py: dict, cli: dict) -> None:
    q = py["quality"]
    pairs = {
        "points": q["fit"]["points"],
        "coverage": q["fit"]["coverage"],
        "residual_rms_rel": q["fit"]["residual_rms_rel"],
        "condition": q["fit"]["condition"],
        "geometry_dilution": q["uncertainty"]["dilution"],
        "heading_error_bound_deg": q["heading_error_bound_deg"],
        "heading_error_3sigma_deg": q["heading_error_3sigma_deg"],
        "heading_error_systematic_deg": q["heading_error_systematic_deg"],
        "heading_noise_rms_deg": q["heading_noise_rms_deg"],
        "soft_iron_sigma_rel": q["uncertainty"]["soft_iron_sigma_rel"],
    }
    for key, value in pairs.items():
        assert same_number(value, cli["quality"].get(key)), (key, value, cli["quality"].get(key))
    assert q["verdict"]["grade"] == cli["quality"]["verdict"]


def calibrate_both(cli, tmp_path, method, path, columns, mag, t_s, acc=None):
    out = tmp_path / "cal.json"
    run_cli(cli, "calibrate", "--method", method, "--input", str(path), "--output", str(out),
            "--column", columns, "--accept-poor")
    py = tn.calibrate(method, mag, t_s=t_s, acc=acc).to_dict()
    return py, json.loads(out.read_text())


@pytest.mark.parametrize("method,folder,dims", [
    ("ellipse", "rotate-ccw-around-z-pointing-up", 2),
    ("online-ellipse", "rotate-ccw-around-z-pointing-up", 2),
    ("ellipsoid", "full-sphere", 3),
    ("online-ellipsoid", "full-sphere", 3),
])
def test_calibrate_is_bit_identical_to_the_cli(cli, data, tmp_path, method, folder, dims):
    path = data / SUNSIDED / folder / "mag.csv.gz"
    _, rows = load_csv(path)
    columns = "mag_x=mag_x_gauss,mag_y=mag_y_gauss,mag_z=mag_z_gauss"
    py, file = calibrate_both(cli, tmp_path, method, path, columns, rows[:, 1:1 + dims], rows[:, 0])
    assert file["dimensions"] == dims == py["dimensions"]
    assert py["hard_iron"] == file["hard_iron"]
    assert py["soft_iron"] == file["soft_iron"]
    assert py["field"] == file["field"]
    compare_quality(py, file)


def test_ellipsoid_accel_is_bit_identical_to_the_cli(cli, data, tmp_path):
    path = data / "magcal_ck_explorer" / "acc_mag_log.csv"
    names, rows = load_csv(path)
    assert names == ["ax", "ay", "az", "mx", "my", "mz"]
    columns = "acc_x=ax,acc_y=ay,acc_z=az,mag_x=mx,mag_y=my,mag_z=mz"
    py, file = calibrate_both(cli, tmp_path, "ellipsoid-accel", path, columns,
                              rows[:, 3:6], None, acc=rows[:, 0:3])
    for key in ("hard_iron", "soft_iron", "field", "mag_to_body", "dip_deg"):
        assert py[key] == file[key], key
    assert py["accelerometer"] == file["accelerometer"]
    compare_quality(py, file)


def test_heading_is_bit_identical_to_the_cli(cli, data, tmp_path):
    path = data / SUNSIDED / "full-sphere" / "mag.csv.gz"
    _, rows = load_csv(path)
    columns = "mag_x=mag_x_gauss,mag_y=mag_y_gauss,mag_z=mag_z_gauss"
    cal_file = tmp_path / "cal.json"
    run_cli(cli, "calibrate", "--method", "ellipsoid", "--input", str(path),
            "--output", str(cal_file), "--column", columns)
    out = tmp_path / "heading.csv"
    run_cli(cli, "heading", "--calibration", str(cal_file), "--input", str(path),
            "--output", str(out), "--column", columns)
    _, cli_rows = load_csv(out)
    cal = tn.calibrate("ellipsoid", rows[:, 1:4], t_s=rows[:, 0])
    heading = cal.heading(rows[:, 1:4])
    assert np.array_equal(heading, cli_rows[:, 1])


@pytest.mark.parametrize("method", ["quaternion", "euler-detector"])
def test_orientation_on_a_broad_trial_is_bit_identical_to_the_cli(cli, data, tmp_path, method):
    path = data / "broad" / "trials" / "01_undisturbed_slow_rotation_A.csv.gz"
    _, rows = load_csv(path)
    out = tmp_path / "att.csv"
    run_cli(cli, "orientation", "--method", method, "--input", str(path), "--output", str(out),
            "--frame", "enu", "--status")
    names, cli_rows = load_csv(out)
    est = tn.QuaternionFilter() if method == "quaternion" else tn.EulerDetector()
    r = est.update_array(rows[:, 0], rows[:, 1:4], rows[:, 4:7], rows[:, 7:10], frame="enu")
    col = {n: i for i, n in enumerate(names)}
    assert np.array_equal(r["quaternion"], cli_rows[:, [col[c] for c in ("qw", "qx", "qy", "qz")]])
    euler = cli_rows[:, [col["yaw_deg"], col["pitch_deg"], col["roll_deg"]]]
    assert np.array_equal(r["euler_deg"], euler)
    bias = cli_rows[:, [col["bias_x_rps"], col["bias_y_rps"], col["bias_z_rps"]]]
    assert np.array_equal(r["gyro_bias_rps"], bias)
    for flag in ("at_rest", "mag_used", "mag_disturbed", "mag_calibrating", "gap"):
        assert np.array_equal(r[flag], cli_rows[:, col[flag]] == 1.0), flag
    if "sigma_x_deg" in col:
        sigma = cli_rows[:, [col["sigma_x_deg"], col["sigma_y_deg"], col["sigma_z_deg"]]]
        assert np.array_equal(r["sigma_deg"], sigma)


def test_broad_metric_is_bit_identical_to_the_cli(cli, data, tmp_path):
    trials = sorted((data / "broad" / "trials").glob("*.csv.gz"))[:1]
    folder = tmp_path / "trials"
    folder.mkdir()
    (folder / trials[0].name).symlink_to(trials[0])
    r = subprocess.run([cli, "eval", "broad", str(folder), "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    _, rows = load_csv(trials[0])
    est = tn.QuaternionFilter().update_array(
        rows[:, 0], rows[:, 1:4], rows[:, 4:7], rows[:, 7:10], frame="enu")
    py = tn.broad_rmse(est["quaternion"], rows[:, 10:14], rows[:, 14] > 0.5)
    cli_trial = report["trials"][0]
    for key in ("total_deg", "heading_deg", "inclination_deg"):
        assert py[key] == cli_trial[key], key


def test_field_agrees_with_the_cli_to_its_printed_digits(cli):
    """`truenorth field` prints rounded figures (nT to 0.001, degrees to fixed decimals): the
    tolerance is half a unit of the last printed digit, the formatting's and nothing else."""
    r = subprocess.run([cli, "field", "--lat", "51.5", "--lon", "-0.13", "--alt-km", "0.1",
                        "--date", "2026.5"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    header, values = r.stdout.strip().splitlines()[-2:]
    f = tn.field(51.5, -0.13, 2026.5, alt_km=0.1).to_dict()
    for key, text in zip(header.split(","), values.split(",")):
        decimals = len(text.split(".")[1]) if "." in text else 0
        half_unit = 0.5 * 10.0 ** -decimals
        assert abs(f[key] - float(text)) <= half_unit * (1 + 1e-9), (key, f[key], text)
