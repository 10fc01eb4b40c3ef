#!/usr/bin/env bash
# Every command's wall time beside polars' and pandas' read_csv of the same files, the
# commands alternated round after round so that a machine whose speed drifts slows all of
# them alike; prints each one's best and median wall time, its median's ratio to polars'
# median read of the file it reads, and its peak resident memory.
#
# Usage: scripts/speed_table.sh DIR [ROUNDS] [BIN]
#   DIR     the files scripts/io_speed.sh leaves in IO_SPEED_DIR (2d, 3d, imu, tumble and
#           drive .csv of one size): `IO_SPEED_DIR=DIR scripts/io_speed.sh 10000000`
#   ROUNDS  rounds (default 3)
#   BIN     the truenorth build (default target/release/truenorth)
# polars' and pandas' times are the read_csv call alone (the interpreter's start and the
# import excluded), the truenorth commands' the whole process (start, read, work, write).
set -euo pipefail

[ $# -ge 1 ] || { sed -n '2,14p' "$0" >&2; exit 2; }
d=$1 rounds=${2:-3} bin=${3:-"$(dirname "$0")/../target/release/truenorth"}
for f in 2d 3d imu tumble drive; do
    [ -f "$d/$f.csv" ] || { echo "speed_table: $d/$f.csv is missing (run scripts/io_speed.sh with IO_SPEED_DIR=$d)" >&2; exit 1; }
done
python3 -c 'import polars, pandas' 2>/dev/null || { echo "speed_table: pip install polars pandas" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo '{"track_m": 1.55, "odometer_wheels": "rear"}' >"$out/vehicle.json"
"$bin" calibrate --method ellipse --input "$d/2d.csv" --output "$out/cal.json" --accept-poor 2>/dev/null

one() { # one LABEL FILE-KIND COMMAND...: wall time and peak memory of one run
    local label=$1 kind=$2 wall user sys mem
    shift 2
    /usr/bin/time -f "%e %U %S %M" -o "$out/t" "$@" >/dev/null 2>&1 || { echo "speed_table: failed: $*" >&2; exit 1; }
    read -r wall user sys mem <"$out/t"
    echo "$label $kind $wall $((mem / 1024))"
}
reader() { # reader LIBRARY KIND: the read_csv call alone
    echo "$1-read_csv-$2 $2 $(python3 -c "import $1, sys, time; t = time.perf_counter(); $1.read_csv(sys.argv[1]); print(f'{time.perf_counter() - t:.3f}')" "$d/$2.csv") -"
}

for _ in $(seq "$rounds"); do
    for kind in 2d 3d imu tumble drive; do reader polars "$kind"; done
    reader pandas 2d
    for m in ellipse online-ellipse binned-ellipse merit-circle turn; do
        one "calibrate-$m" 2d "$bin" calibrate --method "$m" --input "$d/2d.csv" --output "$out/c.json" --accept-poor
    done
    for m in ellipsoid online-ellipsoid; do
        one "calibrate-$m" 3d "$bin" calibrate --method "$m" --input "$d/3d.csv" --output "$out/c.json" --accept-poor
    done
    one calibrate-ellipsoid-accel tumble "$bin" calibrate --method ellipsoid-accel --input "$d/tumble.csv" --output "$out/c.json" --accept-poor
    one heading 2d "$bin" heading --calibration "$out/cal.json" --input "$d/2d.csv" --output "$out/h.csv"
    one "heading--precision-7" 2d "$bin" heading --calibration "$out/cal.json" --input "$d/2d.csv" --output "$out/h.csv" --precision 7
    one orientation imu "$bin" orientation --input "$d/imu.csv" --output "$out/a.csv" --accept-units --accept-axes
    one drive drive "$bin" drive --vehicle "$out/vehicle.json" --input "$d/drive.csv" --output "$out/t.csv"
done | awk '
    { key = $1; kind[key] = $2; n[key]++; x[key, n[key]] = $3; if ($4 != "-" && $4 > mem[key]) mem[key] = $4 }
    END {
        for (k in n) {
            m = n[k]; for (i = 1; i <= m; i++) a[i] = x[k, i]
            for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            best[k] = a[1]; med[k] = (m % 2) ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
        }
        printf "%-34s %-7s %7s %9s %10s %8s\n", "command", "file", "best s", "median s", "x polars", "peak MB"
        for (k in n) {
            p = med["polars-read_csv-" kind[k]]
            printf "%-34s %-7s %7.2f %9.2f %10.2f %8s\n", k, kind[k], best[k], med[k], med[k] / p, (k in mem) ? mem[k] : "-"
        }
    }' | (IFS= read -r header; echo "$header"; sort)
