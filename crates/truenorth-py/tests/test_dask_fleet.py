"""The Dask example (examples/python/dask_fleet.py) on a LocalCluster over the real logs."""

import importlib.util
import math
import os

import pytest

from conftest import REPO, missing


def dask_or_skip():
    try:
        import dask  # noqa: F401
        from dask.distributed import Client, LocalCluster
    except ImportError:
        if os.environ.get("CI") and os.environ.get("TRUENORTH_PYTHON") == "required":
            pytest.fail("dask and distributed are not installed (TRUENORTH_PYTHON=required)")
        pytest.skip("SKIPPED: dask / distributed not installed (pip install dask distributed)")
    return Client, LocalCluster


def load_example():
    path = REPO / "examples" / "python" / "dask_fleet.py"
    spec = importlib.util.spec_from_file_location("dask_fleet", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_fleet_runs_on_a_local_cluster_as_it_runs_serially(data):
    Client, LocalCluster = dask_or_skip()
    fleet = load_example()
    mags, trials = fleet.fleet(data, trials=2)
    if not mags or not trials:
        missing(f"no magnetometer logs or BROAD trials under {data}")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        result = fleet.run(client, data, trials=2)
    print("\n" + fleet.report(result))
    assert result["files"] == len(mags) + len(trials)
    by_name = {os.path.basename(os.path.dirname(r["file"])): r for r in result["calibrations"]}
    assert by_name["full-sphere"]["verdict"] == "good"
    # A sensor left unmoved cannot determine an ellipsoid: the library's reason comes back.
    assert by_name["unmoved-with-x-pointing-forward"]["error"]
    # The cluster's results are the serial ones, bit for bit.
    serial = fleet.evaluate_trial(trials[0])
    remote = result["evaluations"][0]
    for key in ("total_deg", "heading_deg", "inclination_deg"):
        assert math.isfinite(remote[key]) and remote[key] == serial[key]
    assert fleet.calibrate_log(mags[0])["verdict"] == result["calibrations"][0]["verdict"]
