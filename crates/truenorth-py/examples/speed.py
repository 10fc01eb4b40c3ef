"""The Python call overhead, measured: per-array and per-sample calls of the quaternion
filter against the Rust loop over the same recording (`examples/array_loop.rs`).

    cargo build --release --example array_loop      # in crates/truenorth-py
    python examples/speed.py ../../../shared/data/broad/trials/01_undisturbed_slow_rotation_A.csv.gz

Prints ns per sample for: the array call (`update_array`, loop in Rust), the Rust loop
alone (when the example binary is built), and one `update` call per sample from Python;
and the fixed cost of one array call (an array of one row).
"""

import gzip
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import truenorth as tn

HERE = pathlib.Path(__file__).resolve().parent


def best_of(fn, repeats):
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main(path: str, repeats: int = 20) -> None:
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    n = len(rows)
    t, gyr, acc, mag = rows[:, 0], rows[:, 1:4], rows[:, 4:7], rows[:, 7:10]
    array_s = best_of(lambda: tn.QuaternionFilter().update_array(t, gyr, acc, mag), repeats)
    print(f"python array call: {n} samples, best of {repeats}: {array_s * 1e3:.3f} ms, "
          f"{array_s * 1e9 / n:.1f} ns/sample")
    f = tn.QuaternionFilter()
    one = (t[:1], gyr[:1], acc[:1], mag[:1])
    call_s = best_of(lambda: [(f.reset(), f.update_array(*one)) for _ in range(1000)], 5) / 1000
    print(f"python array call of one row with a reset (the per-array overhead): {call_s * 1e9:.0f} ns")
    m = 5000
    lists = [(t[k], gyr[k].tolist(), acc[k].tolist(), mag[k].tolist()) for k in range(m)]

    def per_sample():
        f = tn.QuaternionFilter()
        for k in range(m):
            f.update(*lists[k])

    sample_s = best_of(per_sample, 5)
    print(f"python per-sample calls: {sample_s * 1e9 / m:.1f} ns/sample (first {m} samples)")
    binary = HERE.parent / "target" / "release" / "examples" / "array_loop"
    if not binary.is_file():
        print("rust loop: SKIPPED (cargo build --release --example array_loop)")
        return
    with tempfile.NamedTemporaryFile("w", suffix=".csv") as plain:
        opener = gzip.open if path.endswith(".gz") else open
        with opener(path, "rt") as f:
            plain.write(f.read())
        plain.flush()
        out = subprocess.run([str(binary), plain.name, str(repeats)], capture_output=True,
                             text=True, check=True).stdout.strip()
    print(out)
    rust_ns = float(out.split("ms, ")[1].split(" ns")[0])
    print(f"array call / rust loop: {array_s * 1e9 / n / rust_ns:.3f}")


if __name__ == "__main__":
    main(sys.argv[1], *(int(a) for a in sys.argv[2:3]))
