#!/usr/bin/env python3
"""Every `truenorth` command's observable behaviour on a fixed set of inputs, as hashes, so that a
change meant to keep behaviour (a move, a split, a new reader underneath) can be shown to keep it.

    scripts/behaviour.py record OUT [--bin PATH] [--data DIR]
    scripts/behaviour.py compare BEFORE AFTER

`record` runs each case (about 300: every command, its help, simulated and real recordings, PX4
ULog and MCAP logs, gzip and standard input, refusals and errors) in a scratch folder under OUT,
and writes OUT/manifest.tsv: per case its exit status and the SHA-256 of its standard output,
standard error and every file it wrote; small texts are kept beside it for reading a difference.
Every run but `batch`'s has TRUENORTH_BATCH_CHILD=1, so the rows each command read and the kind
of its error are compared too. `compare` prints the cases that differ and exits 1 if any does.

Inputs: synthetic recordings made here (a level compass circle, a tumble, a turn with a yaw gyro,
an IMU in motion, a drive with wheels, gyro and compass; each with a seeded generator, so the
same bytes every time), the real recordings of ../shared/data (or --data, or
$TRUENORTH_SHARED_DATA) where present, and the MCAP fixture of truenorth-logs. The binary is
the test-profile build of this tree (`cargo build --profile test -p truenorth-cli`) unless --bin
names another. What differs between two runs of the same binary (batch's seconds, paths of the
scratch folder) is normalised before hashing.
"""

import csv
import gzip
import io
import hashlib
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KEEP_BYTES = 16384


# ---------------------------------------------------------------------------------------------
# Synthetic recordings


def num(v):
    """The shortest text of a float, as a logger with full precision would write it."""
    return repr(float(v))


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            f.write(",".join("" if v is None else num(v) for v in r) + "\n")


def rot_zyx(yaw, pitch, roll):
    """Body → NED rotation matrix of Z-Y-X angles."""
    cy, sy, cp, sp, cr, sr = (math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch),
                              math.cos(roll), math.sin(roll))
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def to_body(r, v):
    """R^T v: a NED vector in body axes."""
    return [sum(r[i][j] * v[i] for i in range(3)) for j in range(3)]


def mat_vec(m, v):
    return [sum(m[i][j] * v[j] for j in range(3)) for i in range(3)]


FIELD_NED = [18.0, 1.5, 45.0]  # µT, dip about 68°
SOFT = [[1.1, 0.08, 0.02], [0.08, 0.92, -0.03], [0.02, -0.03, 1.0]]
HARD = [8.0, -3.0, 5.0]


def raw_mag(body_field, rng, noise=0.15):
    m = mat_vec(SOFT, body_field)
    return [m[i] + HARD[i] + rng.gauss(0.0, noise) for i in range(3)]


def gen_circle(path, turned_deg, n, seed, gz=False):
    rng = random.Random(seed)
    rows = []
    for k in range(n):
        h = math.radians(turned_deg) * k / (n - 1) + 0.3
        b = to_body(rot_zyx(h, 0.0, 0.0), FIELD_NED)
        m = raw_mag(b, rng)
        rows.append([0.05 * k, m[0], m[1]])
    write_csv(path, ["t_s", "mag_x", "mag_y"], rows)
    if gz:
        with open(path, "rb") as f, gzip.GzipFile(str(path) + ".gz", "wb", mtime=0) as g:
            g.write(f.read())


def gen_tumble(path, seed):
    """Static shots in assorted orientations, a few samples each, then runs rolled about a
    target (magnetometer and accelerometer together)."""
    rng = random.Random(seed)
    rows, t = [], 0.0
    attitudes = [(rng.uniform(-math.pi, math.pi), rng.uniform(-1.3, 1.3),
                  rng.uniform(-math.pi, math.pi)) for _ in range(60)]
    for target in range(3):
        yaw, pitch = rng.uniform(-math.pi, math.pi), rng.uniform(-0.6, 0.6)
        for j in range(8):
            attitudes.append((yaw + rng.gauss(0, 0.01), pitch + rng.gauss(0, 0.01),
                              -math.pi + j * math.pi / 4))
    for (yaw, pitch, roll) in attitudes:
        r = rot_zyx(yaw, pitch, roll)
        for _ in range(5):
            m = raw_mag(to_body(r, FIELD_NED), rng)
            a = to_body(r, [0.0, 0.0, -9.80665])
            a = [1.02 * a[0] + 0.12 + rng.gauss(0, 0.02), 0.98 * a[1] - 0.05 + rng.gauss(0, 0.02),
                 1.01 * a[2] + 0.2 + rng.gauss(0, 0.02)]
            rows.append([t] + m + a)
            t += 0.1
    write_csv(path, ["t_s", "mag_x", "mag_y", "mag_z", "acc_x", "acc_y", "acc_z"], rows)


def gen_turn_gyro(path, seed):
    """A level vehicle at rest for 3 s, then turning right at 20°/s through 540°; yaw gyro with
    a bias and a scale error."""
    rng = random.Random(seed)
    rows, h, dt = [], 0.2, 0.02
    for k in range(int((3.0 + 27.0) / dt)):
        t = k * dt
        rate = 0.0 if t < 3.0 else math.radians(20.0)
        h += rate * dt
        m = raw_mag(to_body(rot_zyx(h, 0.0, 0.0), FIELD_NED), rng)
        rows.append([t, m[0], m[1], 1.02 * rate + 0.004 + rng.gauss(0, 0.001)])
    write_csv(path, ["t_s", "mag_x", "mag_y", "gyr_z"], rows)


def gen_imu(path, seed, gyro_scale=1.0, acc_scale=1.0, mag_every=1, seconds=60.0, rate=100.0):
    """A hand-held IMU turning about every axis with pauses; the magnetometer on every
    `mag_every`-th row (empty cells between)."""
    rng = random.Random(seed)
    q = [1.0, 0.0, 0.0, 0.0]
    rows, dt = [], 1.0 / rate
    for k in range(int(seconds * rate)):
        t = k * dt
        moving = (t % 6.0) > 1.5
        w = [0.9 * math.sin(0.7 * t), 0.6 * math.cos(0.5 * t), 1.1 * math.sin(0.3 * t + 1.0)]
        if not moving:
            w = [0.0, 0.0, 0.0]
        # Body → NED quaternion q; rotate NED vectors into the body with its conjugate.
        qw, qx, qy, qz = q
        r = [
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
            [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
            [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)],
        ]
        acc = [v + rng.gauss(0, 0.03) for v in to_body(r, [0.0, 0.0, -9.80665])]
        mag = [v + rng.gauss(0, 0.2) for v in to_body(r, FIELD_NED)]
        gyr = [v + 0.01 + rng.gauss(0, 0.002) for v in w]
        row = [t] + [gyro_scale * v for v in gyr] + [acc_scale * v for v in acc]
        row += mag if k % mag_every == 0 else [None, None, None]
        rows.append(row)
        # q ← q ⊗ exp(w dt / 2)
        angle = math.sqrt(sum(v * v for v in w)) * dt
        if angle > 0:
            s = math.sin(angle / 2) / (angle / dt)
            d = [math.cos(angle / 2), w[0] * s, w[1] * s, w[2] * s]
            q = [
                qw * d[0] - qx * d[1] - qy * d[2] - qz * d[3],
                qw * d[1] + qx * d[0] + qy * d[3] - qz * d[2],
                qw * d[2] - qx * d[3] + qy * d[0] + qz * d[1],
                qw * d[3] + qx * d[2] - qy * d[1] + qz * d[0],
            ]
            n = math.sqrt(sum(v * v for v in q))
            q = [v / n for v in q]
    header = ["t_s", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z", "mag_x", "mag_y",
              "mag_z"]
    write_csv(path, header, rows)


def gen_drive(path, seed, speeds=False, own_rows=False, seconds=400.0):
    """A rear-wheel car: a full circle at the start, then straights and corners; cumulative
    wheel distances (or wheel speeds), a raw yaw gyro and an uncalibrated level compass."""
    rng = random.Random(seed)
    track, dt = 1.55, 0.1
    h, n, e, dl, dr = 0.4, 0.0, 0.0, 0.0, 0.0
    rows = []
    for k in range(int(seconds / dt)):
        t = k * dt
        v = 0.0 if t < 2.0 else min(8.0, 2.0 * (t - 2.0))
        if t < 2.0:
            yaw_rate = 0.0
        elif t < 40.0:
            yaw_rate = v / 12.0
        else:
            phase = (t - 40.0) % 30.0
            yaw_rate = (0.15 if phase < 10.0 else 0.0) * (1 if int((t - 40) / 30) % 2 == 0 else -1)
        vl, vr = v + yaw_rate * track / 2, v - yaw_rate * track / 2
        dl += 1.003 * vl * dt
        dr += 0.998 * vr * dt
        h += yaw_rate * dt
        n += v * math.cos(h) * dt
        e += v * math.sin(h) * dt
        gyr = 1.015 * yaw_rate + math.radians(0.5) + rng.gauss(0, 0.0005)
        b = to_body(rot_zyx(h, 0.0, 0.0), FIELD_NED)
        m = raw_mag(b, rng, noise=0.2)
        wheels = [vl, vr] if speeds else [round(dl / 0.02) * 0.02, round(dr / 0.02) * 0.02]
        if own_rows:
            rows.append([t] + wheels + [None, None, None])
            rows.append([t + 0.03] + [None, None, gyr, None, None])
            if k % 2 == 0:
                rows.append([t + 0.06] + [None, None, None, m[0], m[1]])
        else:
            rows.append([t] + wheels + [gyr, m[0], m[1]])
    wheel_cols = ["speed_l_mps", "speed_r_mps"] if speeds else ["dist_l_m", "dist_r_m"]
    write_csv(path, ["t_s"] + wheel_cols + ["gyr_z", "mag_x", "mag_y"], rows)


def generate(d):
    d.mkdir(parents=True, exist_ok=True)
    gen_circle(d / "circle.csv", 540.0, 720, 1, gz=True)
    gen_circle(d / "half.csv", 150.0, 200, 2)
    gen_tumble(d / "tumble.csv", 3)
    gen_turn_gyro(d / "turn_gyro.csv", 4)
    gen_imu(d / "imu.csv", 5)
    gen_imu(d / "imu_slow_mag.csv", 6, mag_every=10, seconds=40.0)
    gen_imu(d / "imu_degs.csv", 7, gyro_scale=180.0 / math.pi, seconds=40.0)
    gen_imu(d / "imu_g.csv", 8, acc_scale=1.0 / 9.80665, seconds=40.0)
    gen_drive(d / "drive.csv", 9)
    gen_drive(d / "drive_speeds.csv", 10, speeds=True, seconds=300.0)
    gen_drive(d / "drive_own_rows.csv", 11, own_rows=True, seconds=300.0)
    (d / "vehicle.json").write_text('{"track_m": 1.55, "odometer_wheels": "rear"}\n')
    (d / "front.json").write_text(
        '{"track_m": 1.5, "wheelbase_m": 2.7, "odometer_wheels": "front", "pitman_ratio": 0.13}\n')
    (d / "robot.json").write_text('{"track_m": 0.4, "odometer_wheels": "differential"}\n')
    (d / "misspelt.json").write_text('{"track_m": 1.55, "odometer_wheel": "rear"}\n')
    (d / "empty.csv").write_text("")
    (d / "header_only.csv").write_text("t_s,mag_x,mag_y\n")
    (d / "not_a_number.csv").write_text("t_s,mag_x,mag_y\n0,1,2\n0.1,x,3\n")
    (d / "backwards.csv").write_text("t_s,mag_x,mag_y\n0,1,2\n0.1,2,3\n0.05,3,4\n")
    (d / "fake.gz").write_text("t_s,mag_x,mag_y\n0,1,2\n")
    (d / "binary.csv").write_bytes(bytes(range(256)) * 4)
    with open(d / "circle.csv") as f:
        lines = f.read().splitlines()
    (d / "semicolon.txt").write_text("\n".join(l.replace(",", ";") for l in lines) + "\n")
    (d / "no_header.csv").write_text("\n".join(lines[1:]) + "\n")
    (d / "renamed.csv").write_text("\n".join(["time,mx,my"] + lines[1:]) + "\n")
    (d / "short.csv").write_text("\n".join(lines[:6]) + "\n")
    with open(d / "imu.csv") as f:
        imu = f.read().splitlines()
    # Gyro x and y swapped: wrong axes.
    swapped = [imu[0]]
    for l in imu[1:]:
        c = l.split(",")
        c[1], c[2] = c[2], c[1]
        swapped.append(",".join(c))
    (d / "imu_swapped.csv").write_text("\n".join(swapped) + "\n")
    (d / "imu_short.csv").write_text("\n".join(imu[:30]) + "\n")


# ---------------------------------------------------------------------------------------------
# Cases


def cases(inp, data, mcap):
    """(name, argv, stdin file or None, outputs to hash (relative to the case's folder))."""
    c = []

    def add(name, argv, outputs=(), stdin=None):
        c.append((name, [str(a) for a in argv], stdin, list(outputs)))

    # Help and usage of every command.
    for cmd in [[], ["demo"], ["calibrate"], ["heading"], ["field"], ["orientation"], ["drive"],
                ["inspect"], ["batch"], ["eval"], ["eval", "broad"]]:
        add("help-" + ("-".join(cmd) or "top"), cmd + ["--help"])
        add("shorthelp-" + ("-".join(cmd) or "top"), cmd + ["-h"])
    add("version", ["--version"])
    add("usage-nothing", [])
    add("usage-unknown", ["frobnicate"])
    add("usage-calibrate-nomethod", ["calibrate", "--input", inp / "circle.csv", "--output", "c.json"])
    add("usage-bad-method", ["calibrate", "--method", "circle", "--input", inp / "circle.csv",
                             "--output", "c.json"])

    # Demo.
    for seed in ["1", "2"]:
        add("demo-" + seed, ["demo", "--seed", seed, "--out", "demo"],
            ["demo/compass_calibration.svg", "demo/drive_tracks.svg", "demo/orientation_error.svg"])

    # Field.
    for name, args in [("london", ["--lat", "51.5", "--lon", "-0.13", "--date", "2026.5"]),
                       ("south", ["--lat", "-45", "--lon", "170", "--alt-km", "2", "--date",
                                  "2027-03-01"]),
                       ("pole", ["--lat", "86", "--lon", "160", "--date", "2026"]),
                       ("extrapolate", ["--lat", "10", "--lon", "10", "--date", "2031",
                                        "--allow-extrapolation"]),
                       ("too-late", ["--lat", "10", "--lon", "10", "--date", "2031"]),
                       ("bad-lat", ["--lat", "north", "--lon", "10", "--date", "2026"]),
                       ("no-lon", ["--lat", "10", "--date", "2026"]),
                       ("deep", ["--lat", "10", "--lon", "10", "--alt-km", "-5", "--date", "2026"])]:
        add("field-" + name, ["field"] + args)

    # Calibrate: every method on the synthetic recordings, and what it refuses.
    two_d = ["ellipse", "online-ellipse", "binned-ellipse", "merit-circle", "turn"]
    three_d = ["ellipsoid", "online-ellipsoid", "ellipsoid-accel"]
    for m in two_d:
        add(f"cal-{m}-circle", ["calibrate", "--method", m, "--input", inp / "circle.csv",
                                "--output", "cal.json"], ["cal.json"])
        add(f"cal-{m}-circle-expected", ["calibrate", "--method", m, "--input", inp / "circle.csv",
                                         "--output", "cal.json", "--expected-field", "18.1"],
            ["cal.json"])
        add(f"cal-{m}-circle-wmm", ["calibrate", "--method", m, "--input", inp / "circle.csv",
                                    "--output", "cal.json", "--mag-unit", "uT", "--lat", "51.5",
                                    "--lon", "-0.13", "--date", "2026.5"], ["cal.json"])
        add(f"cal-{m}-half", ["calibrate", "--method", m, "--input", inp / "half.csv",
                              "--output", "cal.json"], ["cal.json"])
        add(f"cal-{m}-half-accept", ["calibrate", "--method", m, "--input", inp / "half.csv",
                                     "--output", "cal.json", "--accept-poor"], ["cal.json"])
    for m in three_d:
        add(f"cal-{m}-tumble", ["calibrate", "--method", m, "--input", inp / "tumble.csv",
                                "--output", "cal.json"], ["cal.json"])
        add(f"cal-{m}-tumble-expected", ["calibrate", "--method", m, "--input",
                                         inp / "tumble.csv", "--output", "cal.json",
                                         "--expected-field", "48", "--accept-poor"], ["cal.json"])
        add(f"cal-{m}-circle", ["calibrate", "--method", m, "--input", inp / "circle.csv",
                                "--output", "cal.json"], ["cal.json"])
    for m in ["ellipse", "turn", "binned-ellipse"]:
        add(f"cal-{m}-turn-gyro", ["calibrate", "--method", m, "--input", inp / "turn_gyro.csv",
                                   "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-gz", ["calibrate", "--method", "ellipse", "--input", inp / "circle.csv.gz",
                           "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-stdin", ["calibrate", "--method", "ellipse", "--input", "-", "--output", "-"],
        stdin=inp / "circle.csv")
    add("cal-ellipse-semicolon", ["calibrate", "--method", "ellipse", "--input",
                                  inp / "semicolon.txt", "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-semicolon-given", ["calibrate", "--method", "ellipse", "--delimiter", ";",
                                        "--input", inp / "semicolon.txt", "--output", "cal.json"],
        ["cal.json"])
    add("cal-ellipse-no-header", ["calibrate", "--method", "ellipse", "--no-header", "--column",
                                  "t_s=1,mag_x=2,mag_y=3", "--input", inp / "no_header.csv",
                                  "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-renamed", ["calibrate", "--method", "ellipse", "--column",
                                "t_s=time,mag_x=mx,mag_y=-my", "--input", inp / "renamed.csv",
                                "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-renamed-missing", ["calibrate", "--method", "ellipse", "--input",
                                        inp / "renamed.csv", "--output", "cal.json"])
    add("cal-ellipse-axes-flu", ["calibrate", "--method", "ellipse", "--axes", "flu", "--input",
                                 inp / "circle.csv", "--output", "cal.json"], ["cal.json"])
    add("cal-ellipse-axes-mirror", ["calibrate", "--method", "ellipse", "--axes", "fru",
                                    "--input", inp / "circle.csv", "--output", "cal.json"],
        ["cal.json"])
    for f in ["empty.csv", "header_only.csv", "not_a_number.csv", "backwards.csv", "fake.gz",
              "binary.csv", "short.csv", "missing.csv"]:
        add(f"cal-ellipse-{f}", ["calibrate", "--method", "ellipse", "--input", inp / f,
                                 "--output", "cal.json"], ["cal.json"])
        add(f"cal-ellipsoid-{f}", ["calibrate", "--method", "ellipsoid", "--input", inp / f,
                                   "--output", "cal.json"], ["cal.json"])
    add("cal-output-is-input", ["calibrate", "--method", "ellipse", "--input", inp / "circle.csv",
                                "--output", inp / "circle.csv"])
    add("cal-expected-and-place", ["calibrate", "--method", "ellipse", "--input",
                                   inp / "circle.csv", "--output", "cal.json",
                                   "--expected-field", "18", "--lat", "1", "--lon", "1"])
    add("cal-place-no-unit", ["calibrate", "--method", "ellipse", "--input", inp / "circle.csv",
                              "--output", "cal.json", "--lat", "1", "--lon", "1"])
    add("cal-wrong-unit", ["calibrate", "--method", "ellipse", "--input", inp / "circle.csv",
                           "--output", "cal.json", "--mag-unit", "nT"])
    add("cal-wrong-unit-accept", ["calibrate", "--method", "ellipse", "--input",
                                  inp / "circle.csv", "--output", "cal.json", "--mag-unit", "nT",
                                  "--accept-field-mismatch"], ["cal.json"])
    add("cal-bad-expected", ["calibrate", "--method", "ellipse", "--input", inp / "circle.csv",
                             "--output", "cal.json", "--expected-field", "-1"])
    add("cal-log-option-on-csv", ["calibrate", "--method", "ellipse", "--input",
                                  inp / "circle.csv", "--output", "cal.json", "--mag-topic", "x"])

    # Heading: each calibration kind on its recordings (the calibrations made first, in the
    # case's folder).
    def with_cal(name, method, cal_input, argv, outputs, extra_cal=()):
        add(name, ["@cal", method, cal_input, *extra_cal, "@then"] + argv, outputs)

    for m in ["ellipse", "binned-ellipse", "turn"]:
        with_cal(f"heading-{m}", m, inp / "circle.csv",
                 ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv",
                  "--output", "h.csv"], ["h.csv"])
    with_cal("heading-true", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv", "--output",
              "h.csv", "--lat", "51.5", "--lon", "-0.13", "--date", "2026.5"], ["h.csv"])
    with_cal("heading-precision", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv", "--output",
              "h.csv", "--precision", "4"], ["h.csv"])
    with_cal("heading-gz-out", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv", "--output",
              "h.csv.gz"], ["h.csv.gz"])
    with_cal("heading-stdout", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv", "--output",
              "-"], [])
    for m in ["ellipsoid", "ellipsoid-accel", "online-ellipsoid"]:
        with_cal(f"heading-{m}-tilt", m, inp / "tumble.csv",
                 ["heading", "--calibration", "cal.json", "--input", inp / "tumble.csv",
                  "--output", "h.csv"], ["h.csv"], ["--accept-poor"])
        with_cal(f"heading-{m}-imu", m, inp / "tumble.csv",
                 ["heading", "--calibration", "cal.json", "--input", inp / "imu.csv", "--output",
                  "h.csv"], ["h.csv"], ["--accept-poor"])
    with_cal("heading-3d-level", "ellipsoid", inp / "tumble.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "circle.csv", "--output",
              "h.csv"], ["h.csv"], ["--accept-poor"])
    with_cal("heading-empty", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "header_only.csv",
              "--output", "h.csv"], ["h.csv"])
    with_cal("heading-backwards", "ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", inp / "backwards.csv",
              "--output", "h.csv"], ["h.csv"])
    add("heading-missing-cal", ["heading", "--calibration", "nope.json", "--input",
                                inp / "circle.csv", "--output", "h.csv"])
    add("heading-cal-is-vehicle", ["heading", "--calibration", inp / "vehicle.json", "--input",
                                   inp / "circle.csv", "--output", "h.csv"])
    add("heading-both-stdin", ["heading", "--calibration", "-", "--input", "-", "--output",
                               "h.csv"])

    # Orientation.
    for f in ["imu.csv", "imu_slow_mag.csv"]:
        add(f"ori-{f}", ["orientation", "--input", inp / f, "--output", "o.csv"], ["o.csv"])
        add(f"ori-{f}-status", ["orientation", "--input", inp / f, "--output", "o.csv",
                                "--status"], ["o.csv"])
        add(f"ori-{f}-euler", ["orientation", "--method", "euler-detector", "--input", inp / f,
                               "--output", "o.csv", "--status", "--frame", "enu"], ["o.csv"])
        add(f"ori-{f}-nomag", ["orientation", "--input", inp / f, "--output", "o.csv",
                               "--no-mag", "--status", "--gyro-timing", "instantaneous"],
            ["o.csv"])
    add("ori-plot", ["orientation", "--input", inp / "imu.csv", "--output", "o.csv", "--plot",
                     "o.svg"], ["o.csv", "o.svg"])
    add("ori-degs", ["orientation", "--input", inp / "imu_degs.csv", "--output", "o.csv"],
        ["o.csv"])
    add("ori-degs-unit", ["orientation", "--input", inp / "imu_degs.csv", "--output", "o.csv",
                          "--gyro-unit", "deg/s"], ["o.csv"])
    add("ori-degs-accept", ["orientation", "--input", inp / "imu_degs.csv", "--output", "o.csv",
                            "--accept-units"], ["o.csv"])
    add("ori-g", ["orientation", "--input", inp / "imu_g.csv", "--output", "o.csv"], ["o.csv"])
    add("ori-g-unit", ["orientation", "--input", inp / "imu_g.csv", "--output", "o.csv",
                       "--acc-unit", "g"], ["o.csv"])
    add("ori-swapped", ["orientation", "--input", inp / "imu_swapped.csv", "--output", "o.csv"],
        ["o.csv"])
    add("ori-swapped-accept", ["orientation", "--input", inp / "imu_swapped.csv", "--output",
                               "o.csv", "--accept-axes"], ["o.csv"])
    add("ori-mag-unit", ["orientation", "--input", inp / "imu.csv", "--output", "o.csv",
                         "--mag-unit", "nT"], ["o.csv"])
    add("ori-short", ["orientation", "--input", inp / "imu_short.csv", "--output", "o.csv"],
        ["o.csv"])
    add("ori-axes-flu", ["orientation", "--input", inp / "imu.csv", "--output", "o.csv",
                         "--axes", "flu", "--accept-axes"], ["o.csv"])
    for f in ["empty.csv", "header_only.csv", "circle.csv", "binary.csv"]:
        add(f"ori-{f}", ["orientation", "--input", inp / f, "--output", "o.csv"], ["o.csv"])

    # Drive.
    for f, v in [("drive.csv", "vehicle.json"), ("drive_speeds.csv", "vehicle.json"),
                 ("drive_own_rows.csv", "vehicle.json"), ("drive.csv", "front.json"),
                 ("drive.csv", "robot.json")]:
        add(f"drive-{f}-{v}", ["drive", "--vehicle", inp / v, "--input", inp / f, "--output",
                               "d.csv", "--extra", "sigma,status,calibration,trust"], ["d.csv"])
    for m in ["seed-odometer-compass", "seed-gyro-compass"]:
        add(f"drive-{m}", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                           inp / "drive.csv", "--output", "d.csv", "--method", m, "--extra",
                           "sigma,status,trust"], ["d.csv"])
    add("drive-single-pass", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                              inp / "drive.csv", "--output", "d.csv", "--single-pass",
                              "--calibration-out", "learned.json"], ["d.csv", "learned.json"])
    add("drive-learned-chain", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                                inp / "drive.csv", "--output", "d1.csv", "--calibration-out",
                                "learned.json", "@then", "drive", "--vehicle",
                                inp / "vehicle.json", "--input", inp / "drive_speeds.csv",
                                "--output", "d2.csv", "--calibration-in", "learned.json"],
        ["d1.csv", "d2.csv", "learned.json"])
    add("drive-true", ["drive", "--vehicle", inp / "vehicle.json", "--input", inp / "drive.csv",
                       "--output", "d.csv", "--lat", "51.5", "--lon", "-0.13", "--date",
                       "2026.5", "--precision", "6"], ["d.csv"])
    add("drive-degs", ["drive", "--vehicle", inp / "vehicle.json", "--input", inp / "drive.csv",
                       "--output", "d.csv", "--gyro-unit", "deg/s"], ["d.csv"])
    add("drive-degs-accept", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                              inp / "drive.csv", "--output", "d.csv", "--gyro-unit", "deg/s",
                              "--accept-units"], ["d.csv"])
    add("drive-negated-gyro", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                               inp / "drive.csv", "--output", "d.csv", "--column",
                               "gyr_z=-gyr_z"], ["d.csv"])
    add("drive-swapped-wheels", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                                 inp / "drive.csv", "--output", "d.csv", "--column",
                                 "dist_l_m=dist_r_m,dist_r_m=dist_l_m"], ["d.csv"])
    add("drive-misspelt-vehicle", ["drive", "--vehicle", inp / "misspelt.json", "--input",
                                   inp / "drive.csv", "--output", "d.csv"], ["d.csv"])
    for f in ["empty.csv", "header_only.csv", "circle.csv", "binary.csv"]:
        add(f"drive-{f}", ["drive", "--vehicle", inp / "vehicle.json", "--input", inp / f,
                           "--output", "d.csv"], ["d.csv"])
    add("drive-header-only-wheels", ["drive", "--vehicle", inp / "vehicle.json", "--input", "-",
                                     "--output", "d.csv"], ["d.csv"], stdin=inp / "drive_hdr.csv")
    add("drive-calibration-extra-seed", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                                         inp / "drive.csv", "--output", "d.csv", "--method",
                                         "seed-gyro-compass", "--extra", "calibration"])

    # Inspect.
    for f in ["imu.csv", "imu_slow_mag.csv", "imu_degs.csv", "imu_g.csv", "imu_swapped.csv",
              "drive.csv", "drive_speeds.csv", "drive_own_rows.csv", "circle.csv", "tumble.csv",
              "header_only.csv", "empty.csv", "binary.csv"]:
        add(f"inspect-{f}", ["inspect", inp / f])
        add(f"inspect-json-{f}", ["inspect", "--json", inp / f])
    add("inspect-stdin", ["inspect", "-"], stdin=inp / "imu.csv")

    # Batch over a folder of the synthetic recordings.
    add("batch-inspect", ["batch", inp / "batchdir", "--out", "out", "--jobs", "2", "--",
                          "inspect"], ["out/results.csv"])
    add("batch-calibrate", ["batch", inp / "batchdir", "--out", "out", "--jobs", "1",
                            "--results", "out/r.json", "--", "calibrate", "--method", "ellipse"],
        ["out/r.json"])
    add("batch-orientation", ["batch", inp / "batchdir", "--out", "out", "--jobs", "2", "--",
                              "orientation", "--status"], ["out/results.csv"])

    # Real recordings, where present.
    if data is not None:
        sph = data / "magcal_sunsided_mpu6050_hmc5883l"
        gauss = ["--column", "mag_x=mag_x_gauss,mag_y=mag_y_gauss,mag_z=mag_z_gauss"]
        for m in three_d[:2]:
            add(f"real-cal-{m}-sphere", ["calibrate", "--method", m, "--input",
                                         sph / "full-sphere/mag.csv.gz", "--output", "cal.json",
                                         "--mag-unit", "G"] + gauss, ["cal.json"])
        for m in two_d:
            add(f"real-cal-{m}-pan", ["calibrate", "--method", m, "--input",
                                      sph / "pan-along-z-pointing-up/mag.csv.gz", "--output",
                                      "cal.json"] + gauss, ["cal.json"])
        with_cal("real-heading-pan", "ellipse", sph / "pan-along-z-pointing-up/mag.csv.gz",
                 ["heading", "--calibration", "cal.json", "--input",
                  sph / "pan-along-z-pointing-up/mag.csv.gz", "--output", "h.csv"] + gauss,
                 ["h.csv"], gauss)
        ck = data / "magcal_ck_explorer/acc_mag_log.csv"
        ck_cols = ["--column", "mag_x=mx,mag_y=my,mag_z=mz,acc_x=ax,acc_y=ay,acc_z=az"]
        for m in ["ellipsoid", "ellipsoid-accel"]:
            add(f"real-cal-{m}-ck", ["calibrate", "--method", m, "--input", ck, "--output",
                                     "cal.json", "--accept-poor"] + ck_cols, ["cal.json"])
        with_cal("real-heading-ck", "ellipsoid-accel", ck,
                 ["heading", "--calibration", "cal.json", "--input", ck, "--output", "h.csv"]
                 + ck_cols, ["h.csv"], ck_cols + ["--accept-poor"])
        xio = data / "xio_fusion/sensor_data.csv"
        xio_cols = ["--column",
                    "t_s=Time (s),gyr_x=Gyroscope X (deg/s),gyr_y=Gyroscope Y (deg/s),"
                    "gyr_z=Gyroscope Z (deg/s),acc_x=Accelerometer X (g),"
                    "acc_y=Accelerometer Y (g),acc_z=Accelerometer Z (g),"
                    "mag_x=Magnetometer X (uT),mag_y=Magnetometer Y (uT),"
                    "mag_z=Magnetometer Z (uT)"]
        add("real-ori-xio", ["orientation", "--input", xio, "--output", "o.csv", "--gyro-unit",
                             "deg/s", "--acc-unit", "g", "--status"] + xio_cols, ["o.csv"])
        add("real-ori-xio-refused", ["orientation", "--input", xio, "--output", "o.csv"]
            + xio_cols, ["o.csv"])
        add("real-inspect-xio", ["inspect", xio] + xio_cols)
        add("real-inspect-json-xio", ["inspect", "--json", xio] + xio_cols)
        add("real-inspect-xio-raw", ["inspect", xio])
        imu = sph / "full-sphere/imu.csv.gz"
        imu_cols = ["--column", "acc_x=acc_x_g,acc_y=acc_y_g,acc_z=acc_z_g,gyr_x=gyr_x_dps,"
                                "gyr_y=gyr_y_dps,gyr_z=gyr_z_dps"]
        add("real-inspect-mpu", ["inspect", imu] + imu_cols)
        add("real-ori-mpu", ["orientation", "--input", imu, "--output", "o.csv", "--gyro-unit",
                             "deg/s", "--acc-unit", "g"] + imu_cols, ["o.csv"])
        trials = sorted((data / "broad/trials").glob("*.csv.gz"))
        for t in trials[:20:4]:
            stem = t.name.split(".")[0]
            add(f"real-ori-broad-{stem}", ["orientation", "--input", t, "--output", "o.csv",
                                           "--status", "--frame", "enu"], ["o.csv"])
            add(f"real-ori-broad-euler-{stem}", ["orientation", "--input", t, "--output",
                                                 "o.csv", "--method", "euler-detector"],
                ["o.csv"])
            add(f"real-inspect-broad-{stem}", ["inspect", t])
        add("real-eval-broad", ["eval", "broad", data / "broad"])
        add("real-eval-broad-json", ["eval", "broad", data / "broad", "--json", "--method",
                                     "euler-detector"])
        add("real-eval-broad-nomag", ["eval", "broad", data / "broad/trials", "--no-mag",
                                      "--json"])
        add("real-eval-broad-missing", ["eval", "broad", "nowhere"])
        berlin = data / "vehicle_smartloc_berlin/DRIVE.csv"
        add("real-drive-berlin", ["drive", "--vehicle", inp / "vehicle.json", "--input", berlin,
                                  "--output", "d.csv", "--extra", "sigma,status,trust"],
            ["d.csv"])
        add("real-inspect-berlin", ["inspect", berlin])
        comma = data / "vehicle_comma2k19_example"
        add("real-inspect-comma-imu", ["inspect", comma / "imu.csv", "--column",
                                       "t_s=t_boot_s,acc_x=acc_f_mps2,acc_y=acc_r_mps2,"
                                       "acc_z=acc_d_mps2,gyr_x=gyr_f_rps,gyr_y=gyr_r_rps,"
                                       "gyr_z=gyr_d_rps"])
        px4 = data / "px4_ulog_samples"
        for u in ["sample.ulg", "sample_log_small.ulg", "sample_appended_multiple.ulg"]:
            log = px4 / u
            stem = u.split(".")[0]
            add(f"ulog-inspect-{stem}", ["inspect", log])
            add(f"ulog-inspect-json-{stem}", ["inspect", "--json", log])
            add(f"ulog-ori-{stem}", ["orientation", "--input", log, "--output", "o.csv",
                                     "--status"], ["o.csv"])
            add(f"ulog-ori-nomag-{stem}", ["orientation", "--input", log, "--output", "o.csv",
                                           "--mag-topic", "none"], ["o.csv"])
            add(f"ulog-cal-{stem}", ["calibrate", "--method", "ellipsoid", "--input", log,
                                     "--output", "cal.json", "--accept-poor"], ["cal.json"])
            add(f"ulog-cal-accel-{stem}", ["calibrate", "--method", "ellipsoid-accel", "--input",
                                           log, "--output", "cal.json", "--accept-poor"],
                ["cal.json"])
            with_cal(f"ulog-heading-{stem}", "ellipsoid", inp / "tumble.csv",
                     ["heading", "--calibration", "cal.json", "--input", log, "--output",
                      "h.csv"], ["h.csv"])
            with_cal(f"ulog-heading-2d-{stem}", "ellipse", inp / "circle.csv",
                     ["heading", "--calibration", "cal.json", "--input", log, "--output",
                      "h.csv", "--lat", "47.4", "--lon", "8.5", "--date", "2026"], ["h.csv"])
            add(f"ulog-drive-{stem}", ["drive", "--vehicle", inp / "vehicle.json", "--input",
                                       log, "--output", "d.csv"], ["d.csv"])
        log = px4 / "sample.ulg"
        add("ulog-gz", ["@gzip", log, "s.ulg.gz", "@then", "orientation", "--input", "s.ulg.gz",
                        "--output", "o.csv"], ["o.csv"])
        add("ulog-stdin", ["orientation", "--input", "-", "--output", "o.csv"], ["o.csv"],
            stdin=log)
        add("ulog-delimiter", ["orientation", "--input", log, "--output", "o.csv", "--delimiter",
                               ";"])
        add("ulog-gyro-unit", ["orientation", "--input", log, "--output", "o.csv", "--gyro-unit",
                               "deg/s"])
        add("ulog-bad-topic", ["orientation", "--input", log, "--output", "o.csv", "--imu-topic",
                               "nothing"])
        add("ulog-mag-topic", ["calibrate", "--method", "ellipsoid", "--input", log, "--output",
                               "cal.json", "--mag-topic", "sensor_mag", "--accept-poor"],
            ["cal.json"])
        add("ulog-cal-2d", ["calibrate", "--method", "ellipse", "--input", log, "--output",
                            "cal.json", "--accept-poor"], ["cal.json"])
        add("ulog-cal-nomag", ["calibrate", "--method", "ellipsoid", "--input", log, "--output",
                               "cal.json", "--mag-topic", "none"], ["cal.json"])
        add("ulog-cut", ["@cut", log, "cut.ulg", "@then", "orientation", "--input", "cut.ulg",
                         "--output", "o.csv"], ["o.csv"])
        add("ulog-cut-accept", ["@cut", log, "cut.ulg", "@then", "orientation", "--input",
                                "cut.ulg", "--output", "o.csv", "--accept-incomplete"], ["o.csv"])
        add("ulog-eval-topic", ["eval", "broad", data / "broad", "--imu-topic", "x"])

    # The MCAP fixture.
    add("mcap-inspect", ["inspect", mcap])
    add("mcap-inspect-json", ["inspect", "--json", mcap])
    add("mcap-ori", ["orientation", "--input", mcap, "--output", "o.csv", "--status"], ["o.csv"])
    add("mcap-ori-nomag", ["orientation", "--input", mcap, "--output", "o.csv", "--mag-topic",
                           "none"], ["o.csv"])
    add("mcap-cal", ["calibrate", "--method", "ellipsoid", "--input", mcap, "--output",
                     "cal.json", "--accept-poor"], ["cal.json"])
    add("mcap-cal-2d", ["calibrate", "--method", "online-ellipse", "--input", mcap, "--output",
                        "cal.json", "--accept-poor"], ["cal.json"])
    with_cal("mcap-heading", "ellipsoid-accel", inp / "tumble.csv",
             ["heading", "--calibration", "cal.json", "--input", mcap, "--output", "h.csv"],
             ["h.csv"])
    with_cal("mcap-heading-2d", "binned-ellipse", inp / "circle.csv",
             ["heading", "--calibration", "cal.json", "--input", mcap, "--output", "h.csv"],
             ["h.csv"])
    for v in ["vehicle.json", "robot.json", "front.json"]:
        add(f"mcap-drive-{v}", ["drive", "--vehicle", inp / v, "--input", mcap, "--output",
                                "d.csv", "--extra", "sigma,status,calibration,trust"], ["d.csv"])
    add("mcap-drive-seed", ["drive", "--vehicle", inp / "vehicle.json", "--input", mcap,
                            "--output", "d.csv", "--method", "seed-gyro-compass"], ["d.csv"])
    add("mcap-gz", ["@gzip", mcap, "b.mcap.gz", "@then", "inspect", "b.mcap.gz"])
    add("mcap-stdin", ["drive", "--vehicle", inp / "vehicle.json", "--input", "-", "--output",
                       "d.csv"], ["d.csv"], stdin=mcap)
    add("mcap-cut", ["@cut", mcap, "cut.mcap", "@then", "inspect", "cut.mcap"])
    add("mcap-cut-accept", ["@cut", mcap, "cut.mcap", "@then", "inspect", "cut.mcap",
                            "--accept-incomplete"])
    add("mcap-column", ["orientation", "--input", mcap, "--output", "o.csv", "--column",
                        "gyr_x=a"])
    add("mcap-axes", ["orientation", "--input", mcap, "--output", "o.csv", "--axes", "flu"])
    add("mcap-odometry-topic", ["drive", "--vehicle", inp / "vehicle.json", "--input", mcap,
                                "--output", "d.csv", "--odometry-topic", "/nothing"])
    add("mcap-mag-unit", ["calibrate", "--method", "ellipsoid", "--input", mcap, "--output",
                          "cal.json", "--mag-unit", "nT"])
    return c


# ---------------------------------------------------------------------------------------------
# Running


def sha(b):
    return hashlib.sha256(b).hexdigest()[:16]


def normalise(text, case_dir, inp, data, root, timings=False):
    for path, name in [(case_dir, "$CASE"), (inp, "$INPUTS"), (root, "$ROOT")] + (
            [(data, "$DATA")] if data else []):
        text = text.replace(str(path), name)
    if timings:
        # Batch's timings and rates.
        text = re.sub(r"\b\d+(\.\d+)? ?s\b", "<s>", text)
        text = re.sub(r"\d+(\.\d+)? (files|samples)/s", "<rate>", text)
    return text


def normalise_results(path):
    """A batch results table without its seconds column (CSV or JSON)."""
    raw = path.read_bytes()
    if path.suffix == ".json":
        rows = json.loads(raw)
        for r in rows if isinstance(rows, list) else rows.get("rows", []):
            if isinstance(r, dict) and "seconds" in r:
                r["seconds"] = 0
        return json.dumps(rows, sort_keys=True).encode()
    rows = list(csv.reader(io.StringIO(raw.decode())))
    k = rows[0].index("seconds") if rows and "seconds" in rows[0] else None
    for r in rows[1:]:
        if k is not None and k < len(r):
            r[k] = "0"
    return json.dumps(rows).encode()


def run_one(binary, argv, stdin, cwd, env):
    stdin_bytes = Path(stdin).read_bytes() if stdin else b""
    p = subprocess.run([binary] + argv, input=stdin_bytes, cwd=cwd, env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=900)
    return p.returncode, p.stdout, p.stderr


def record(out, binary, data):
    out = Path(out).resolve()
    inp = out.parent / "inputs"
    if not (inp / "imu.csv").exists():
        generate(inp)
        (inp / "batchdir").mkdir(exist_ok=True)
        for f in ["circle.csv", "half.csv", "imu.csv", "imu_short.csv", "header_only.csv"]:
            shutil.copy(inp / f, inp / "batchdir" / f)
        (inp / "drive_hdr.csv").write_text("t_s,dist_l_m,dist_r_m,gyr_z\n")
    mcap = ROOT / "crates/truenorth-logs/tests/data/ros2_small.mcap"
    if out.exists():
        shutil.rmtree(out)
    (out / "cases").mkdir(parents=True)
    env = dict(os.environ)
    env.pop("TRUENORTH_BATCH_CHILD", None)
    env["TMPDIR"] = str(out / "tmp")
    (out / "tmp").mkdir()
    manifest = []
    inputs = sorted(p for p in inp.rglob("*") if p.is_file())
    for p in inputs:
        manifest.append(f"input:{p.relative_to(inp)}\t-\t{sha(p.read_bytes())}")
    all_cases = cases(inp, data, mcap)
    for i, (name, argv, stdin, outputs) in enumerate(all_cases):
        d = out / "cases" / name
        d.mkdir()
        steps, cur = [], []
        for a in argv:
            if a == "@then":
                steps.append(cur)
                cur = []
            else:
                cur.append(a)
        steps.append(cur)
        results = []
        for step in steps:
            if step and step[0] == "@cal":
                method, src, *extra = step[1:]
                step = ["calibrate", "--method", method, "--input", src, "--output",
                        "cal.json"] + extra
            if step and step[0] == "@gzip":
                with open(step[1], "rb") as f, gzip.GzipFile(str(d / step[2]), "wb",
                                                             mtime=0) as g:
                    g.write(f.read())
                continue
            if step and step[0] == "@cut":
                b = Path(step[1]).read_bytes()
                (d / step[2]).write_bytes(b[: len(b) * 2 // 3])
                continue
            e = dict(env)
            if not (step and step[0] == "batch"):
                e["TRUENORTH_BATCH_CHILD"] = "1"
            results.append(run_one(binary, step, stdin if step is steps[-1] else None, d, e))
        code, so, se = results[-1]
        earlier = ";".join(str(r[0]) for r in results[:-1])
        batch = any(s and s[0] == "batch" for s in steps)
        so_t = normalise(so.decode("utf-8", "replace"), d, inp, data, ROOT, batch)
        se_t = normalise(se.decode("utf-8", "replace"), d, inp, data, ROOT, batch)
        if batch:
            # Worker order and progress differ between runs: compare the sorted lines.
            se_t = "\n".join(sorted(se_t.splitlines()))
        files = []
        for o in outputs:
            p = d / o
            if not p.exists():
                files.append(f"{o}=absent")
                continue
            b = normalise_results(p) if name.startswith("batch") and o.startswith("out/") and (
                p.name.startswith("results") or p.name.startswith("r.")) else p.read_bytes()
            if p.suffix == ".json" and name.startswith(("cal", "real-cal", "ulog-cal", "mcap-cal")):
                b = normalise(b.decode(), d, inp, data, ROOT).encode()
            files.append(f"{o}={sha(b)}")
        if name.startswith("batch"):
            outs = sorted(p for p in (d / "out").rglob("*") if p.is_file() and
                          not p.name.startswith((".truenorth-batch", "results", "r.")))
            for p in outs:
                files.append(f"{p.relative_to(d)}={sha(p.read_bytes())}")
        (d / "stdout.txt").write_text(so_t[:KEEP_BYTES])
        (d / "stderr.txt").write_text(se_t[:KEEP_BYTES])
        manifest.append("\t".join([name, f"{earlier};{code}" if earlier else str(code),
                                   sha(so_t.encode()), sha(se_t.encode())] + files))
        print(f"[{i + 1}/{len(all_cases)}] {name}: {code}", file=sys.stderr)
    (out / "manifest.tsv").write_text("\n".join(manifest) + "\n")
    print(f"{len(all_cases)} cases, {len(manifest)} manifest lines: {out / 'manifest.tsv'}")


def compare(a, b):
    la = Path(a, "manifest.tsv").read_text().splitlines()
    lb = Path(b, "manifest.tsv").read_text().splitlines()
    da = {l.split("\t")[0]: l for l in la}
    db = {l.split("\t")[0]: l for l in lb}
    differ = 0
    for k in sorted(set(da) | set(db)):
        if da.get(k) != db.get(k):
            differ += 1
            print(f"DIFFERS {k}\n  before {da.get(k)}\n  after  {db.get(k)}")
    runs = [l for l in la if not l.startswith("input:")]
    compared = sum(len(l.split("\t")) - 1 for l in runs)
    print(f"{len(runs)} cases, {compared} outputs (exit statuses, stdout, stderr, files) and "
          f"{len(la) - len(runs)} inputs compared: {differ} differ")
    return 1 if differ else 0


def main():
    args = sys.argv[1:]
    if len(args) >= 2 and args[0] == "record":
        binary = os.environ.get("TRUENORTH_BIN")
        data = os.environ.get("TRUENORTH_SHARED_DATA", str(ROOT.parent / "shared/data"))
        rest = args[2:]
        while rest:
            if rest[0] == "--bin":
                binary, rest = rest[1], rest[2:]
            elif rest[0] == "--data":
                data, rest = rest[1], rest[2:]
            else:
                sys.exit(f"unknown option {rest[0]}")
        if binary is None:
            target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
            binary = str(Path(target) / "debug/truenorth")
        data = Path(data).resolve() if Path(data).is_dir() else None
        if data is None:
            print("note: no shared data: the real recordings are left out", file=sys.stderr)
        record(args[1], str(Path(binary).resolve()), data)
    elif len(args) == 3 and args[0] == "compare":
        sys.exit(compare(args[1], args[2]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
