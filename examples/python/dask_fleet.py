"""Calibrate and evaluate a fleet of logs on Dask with the truenorth Python package.

Two maps over real recordings, each log a task:

* calibration: every magnetometer log of the HMC5883L recording set
  (`magcal_sunsided_mpu6050_hmc5883l/*/mag.csv.gz`) with the 3-D least-squares ellipsoid;
  a log that cannot support a calibration (a sensor left unmoved) comes back with the
  library's reason instead of a result;
* evaluation: the quaternion filter over the BROAD benchmark's trials, scored with BROAD's
  metric (`truenorth.broad_rmse`), as `truenorth eval broad` scores it.

Run on this machine (a LocalCluster of one process per core):

    python examples/python/dask_fleet.py --data ../shared/data

On a cluster: start a scheduler and workers where the logs are readable at the same path
(a shared file system or object store), with the package installed on every worker
(`pip install ./crates/truenorth-py`), and pass the scheduler's address:

    dask scheduler                       # on one machine
    dask worker tcp://SCHEDULER:8786     # on each worker machine
    python examples/python/dask_fleet.py --data /shared/logs --scheduler tcp://SCHEDULER:8786

Only `Client(address)` changes; the functions mapped are the same. (With dask-jobqueue or
dask-kubernetes, build the cluster object there and pass it to `Client`.)
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time
from typing import Any, Optional

import numpy as np

import truenorth as tn

SUNSIDED = "magcal_sunsided_mpu6050_hmc5883l"


def calibrate_log(path: str) -> dict[str, Any]:
    """One magnetometer log (`t_s,mag_x_gauss,mag_y_gauss,mag_z_gauss`) → one result row."""
    start = time.perf_counter()
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    row: dict[str, Any] = {"file": path, "samples": len(rows)}
    try:
        cal = tn.calibrate("ellipsoid", rows[:, 1:4], t_s=rows[:, 0])
        q = cal.quality
        row.update(
            verdict=cal.verdict.grade,
            field_gauss=cal.field,
            heading_error_bound_deg=q.heading_error_bound_deg,
            heading_noise_rms_deg=q.heading_noise_rms_deg,
            coverage=q.coverage,
            error=None,
        )
    except tn.TruenorthError as e:
        row.update(verdict=None, error=str(e))
    row["seconds"] = time.perf_counter() - start
    return row


def evaluate_trial(path: str) -> dict[str, Any]:
    """One BROAD trial (`t_s, gyr, acc, mag, qw..qz, movement`) → its BROAD RMSE."""
    start = time.perf_counter()
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    est = tn.QuaternionFilter().update_array(
        rows[:, 0], rows[:, 1:4], rows[:, 4:7], rows[:, 7:10], frame="enu"
    )
    rmse = tn.broad_rmse(est["quaternion"], rows[:, 10:14], rows[:, 14] > 0.5) or {}
    return {"file": path, "samples": len(rows), **rmse, "seconds": time.perf_counter() - start}


def fleet(data: pathlib.Path, trials: Optional[int] = None) -> tuple[list[str], list[str]]:
    """The logs: every magnetometer log, and the BROAD trials (the first `trials` of them)."""
    mags = sorted(str(p) for p in (data / SUNSIDED).glob("*/mag.csv.gz"))
    broad = sorted(str(p) for p in (data / "broad" / "trials").glob("*.csv.gz"))
    return mags, broad[:trials] if trials is not None else broad


def run(client: Any, data: pathlib.Path, trials: Optional[int] = None) -> dict[str, Any]:
    """Maps both functions over the fleet on `client`; the rows and the throughput."""
    mags, broad = fleet(data, trials)
    start = time.perf_counter()
    calibrations = client.gather(client.map(calibrate_log, mags))
    evaluations = client.gather(client.map(evaluate_trial, broad))
    seconds = time.perf_counter() - start
    files = len(mags) + len(broad)
    samples = sum(r["samples"] for r in calibrations + evaluations)
    return {
        "calibrations": calibrations,
        "evaluations": evaluations,
        "files": files,
        "seconds": seconds,
        "files_per_s": files / seconds,
        "samples_per_s": samples / seconds,
    }


def report(result: dict[str, Any]) -> str:
    lines = ["calibration (ellipsoid):"]
    for r in result["calibrations"]:
        name = pathlib.Path(r["file"]).parent.name
        if r["error"]:
            lines.append(f"  {name:45s} refused: {r['error'][:90]}")
        else:
            lines.append(
                f"  {name:45s} {r['verdict']:6s} field {r['field_gauss']:.4f} G, "
                f"bound {r['heading_error_bound_deg']:.2f} deg, noise {r['heading_noise_rms_deg']:.2f} deg"
            )
    lines.append("evaluation (quaternion filter, BROAD RMSE deg total/heading/inclination):")
    for r in result["evaluations"]:
        name = pathlib.Path(r["file"]).name
        lines.append(
            f"  {name:45s} {r.get('total_deg', float('nan')):6.2f} "
            f"{r.get('heading_deg', float('nan')):6.2f} {r.get('inclination_deg', float('nan')):6.2f}"
        )
    lines.append(
        f"{result['files']} files in {result['seconds']:.1f} s: {result['files_per_s']:.2f} files/s, "
        f"{result['samples_per_s']:.0f} samples/s"
    )
    return "\n".join(lines)


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", type=pathlib.Path, default=pathlib.Path("../shared/data"))
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster processes (default 2)")
    p.add_argument("--trials", type=int, help="only the first N BROAD trials")
    args = p.parse_args(argv)
    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        with Client(args.scheduler) as client:
            print(report(run(client, args.data, args.trials)))
    else:
        with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            print(report(run(client, args.data, args.trials)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
