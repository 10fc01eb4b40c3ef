"""Shared fixtures: the real recordings, the `truenorth` command built from the same tree,
and the rule for what is missing (skipped, loudly; a failure when CI is set)."""

import os
import pathlib
import shutil

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def missing(what: str) -> None:
    """Skips the test visibly, or fails it when CI is set (the data and tools must be there)."""
    if os.environ.get("CI"):
        pytest.fail(f"{what} (required when CI is set)")
    pytest.skip(f"SKIPPED: {what}")


def shared_data() -> pathlib.Path:
    """The shared recordings: $TRUENORTH_SHARED_DATA, else ../shared/data beside the repo."""
    env = os.environ.get("TRUENORTH_SHARED_DATA")
    return pathlib.Path(env) if env else REPO.parent / "shared" / "data"


@pytest.fixture
def data() -> pathlib.Path:
    d = shared_data()
    if not d.is_dir():
        missing(f"no shared data at {d} (set TRUENORTH_SHARED_DATA)")
    return d


@pytest.fixture
def cli() -> str:
    """The `truenorth` binary: $TRUENORTH_BIN, else the repo's target/{release,debug}."""
    env = os.environ.get("TRUENORTH_BIN")
    candidates = [env] if env else [
        str(REPO / "target" / p / "truenorth") for p in ("release", "debug")
    ]
    for c in candidates:
        if c and pathlib.Path(c).is_file():
            return c
    found = shutil.which("truenorth")
    if found and not env:
        return found
    missing("no `truenorth` binary (cargo build -p truenorth-cli, or set TRUENORTH_BIN)")
    return ""


def load_csv(path: pathlib.Path) -> tuple[list[str], np.ndarray]:
    """A CSV (or .csv.gz) with a header row as (names, float rows); empty cells are NaN."""
    import gzip

    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as f:
        names = f.readline().strip().split(",")
        rows = np.genfromtxt(f, delimiter=",", dtype=float)
    return names, np.atleast_2d(rows)
