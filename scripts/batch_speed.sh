#!/usr/bin/env bash
# Throughput of `truenorth batch` over the 33 logs that examples/python/dask_fleet.py maps on
# Dask (the 13 magnetometer logs of the HMC5883L set calibrated with the 3-D ellipsoid, the
# 20 BROAD trials through the quaternion filter in the ENU frame), printed beside the Dask
# figure, and what starting one process per file costs.
#
#   scripts/batch_speed.sh            # every core
#   JOBS=1 scripts/batch_speed.sh     # one worker
#
# The shared recordings: $TRUENORTH_SHARED_DATA, else ../shared/data.
set -euo pipefail
cd "$(dirname "$0")/.."
data="${TRUENORTH_SHARED_DATA:-../shared/data}"
jobs="${JOBS:-$(nproc)}"
if [ ! -d "$data/magcal_sunsided_mpu6050_hmc5883l" ] || [ ! -d "$data/broad/trials" ]; then
    echo "batch_speed: skipped: no shared recordings at $data" >&2
    exit 0
fi
cargo build -q -p truenorth-cli --release
bin="$PWD/target/release/truenorth"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# The magnetometer logs are all named mag.csv.gz: one folder of links named by their set.
mkdir -p "$work/mag"
for d in "$data"/magcal_sunsided_mpu6050_hmc5883l/*/; do
    ln -s "$(realpath "$d/mag.csv.gz")" "$work/mag/$(basename "$d").csv.gz"
done

now() { date +%s.%N; }
samples() { grep -o '"samples": [0-9]*' "$1" | awk '{s += $2} END {print s + 0}'; }

start="$(now)"
"$bin" batch "$work/mag" --out "$work/cal" --results "$work/cal.json" --quiet -j "$jobs" \
    -- calibrate --method ellipsoid --column mag_x=mag_x_gauss,mag_y=mag_y_gauss,mag_z=mag_z_gauss \
    >/dev/null || true
"$bin" batch "$data/broad/trials" --out "$work/ori" --results "$work/ori.json" --quiet -j "$jobs" \
    -- orientation --frame enu >/dev/null || true
end="$(now)"
files=$(( $(grep -c '"path"' "$work/cal.json") + $(grep -c '"path"' "$work/ori.json") ))
rows=$(( $(samples "$work/cal.json") + $(samples "$work/ori.json") ))
statuses="$(grep -ho '"status": "[a-z-]*"' "$work/cal.json" "$work/ori.json" | tr -d '"' | sort | uniq -c |
    awk '{printf "%s%s %s", (NR > 1 ? ", " : ""), $1, $3}')"

# A rerun: every file skipped as done (hashing only, no process started).
rerun_start="$(now)"
"$bin" batch "$data/broad/trials" --out "$work/ori" --quiet -j "$jobs" -- orientation --frame enu >/dev/null
rerun_end="$(now)"

# The cost of one process per file: start the binary on an empty file, which it refuses
# before reading anything, 50 times.
: >"$work/empty.csv"
spawn_start="$(now)"
for _ in $(seq 50); do
    "$bin" calibrate --method ellipse --input "$work/empty.csv" --output "$work/x.json" 2>/dev/null || true
done
spawn_end="$(now)"

awk -v s="$start" -v e="$end" -v f="$files" -v r="$rows" -v j="$jobs" -v st="$statuses" \
    -v rs="$rerun_start" -v re="$rerun_end" -v ss="$spawn_start" -v se="$spawn_end" 'BEGIN {
    t = e - s
    printf "truenorth batch, %d workers: %d files (%s), %d samples in %.2f s: %.1f files/s, %.0f samples/s\n", j, f, st, r, t, f / t, r / t
    printf "Dask (examples/python/dask_fleet.py, 2 worker processes): 5.3 files/s, 190000 samples/s\n"
    printf "rerun, all 20 BROAD trials skipped as done: %.3f s\n", re - rs
    printf "one process per file: %.1f ms to start and end one\n", (se - ss) / 50 * 1000
}'
