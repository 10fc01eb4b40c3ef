#!/usr/bin/env bash
# Reading speed and peak memory of the truenorth CLI, side by side with pandas' and
# polars' read_csv of the same files, in one run.
#
# Usage: scripts/io_speed.sh [ROWS...]        (default: 100000 1000000 10000000)
# Env:   TRUENORTH=path/to/truenorth (default: target/release/truenorth, built if absent)
#        TRUENORTH_BEFORE=another build, to measure its calibrate ellipse and heading beside
#        IO_SPEED_DIR=scratch dir (default: a temporary directory, removed at the end)
#
# For each size it writes a 2-D compass file (t_s,mag_x,mag_y: ten turns of a tilted
# ellipse with noise), a 3-D one (t_s,mag_x,mag_y,mag_z: a tumble), an IMU file
# (t_s,gyr_*,acc_*,mag_*), a tumbling IMU for the joint fit (t_s,acc_*,mag_*) and a
# drive log (t_s,dist_l_m,dist_r_m,gyr_z), then prints one
# table row per command: wall time (s), CPU time (user + system, s: the work done, which a
# machine loaded by other jobs stretches less than the wall time) and peak resident memory
# (MB), from /usr/bin/time -v.
# pandas and polars are measured only when importable (a line says when they are skipped).
set -euo pipefail

cd "$(dirname "$0")/.."
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(100000 1000000 10000000)
bin=${TRUENORTH:-target/release/truenorth}
if [ ! -x "$bin" ]; then
    cargo build --release -p truenorth-cli >&2
fi
[ -x /usr/bin/time ] || { echo "io_speed: /usr/bin/time is needed (apt-get install time)" >&2; exit 1; }
dir=${IO_SPEED_DIR:-$(mktemp -d)}
mkdir -p "$dir"
[ -z "${IO_SPEED_DIR:-}" ] && trap 'rm -rf "$dir"' EXIT

gen() { # gen KIND ROWS FILE
    awk -v kind="$1" -v n="$2" 'BEGIN {
        srand(1); pi = 3.141592653589793
        if (kind == "2d") print "t_s,mag_x,mag_y"
        else if (kind == "3d") print "t_s,mag_x,mag_y,mag_z"
        else if (kind == "imu") print "t_s,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z"
        else if (kind == "tumble") print "t_s,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z"
        else print "t_s,dist_l_m,dist_r_m,gyr_z"
        for (k = 0; k < n; k++) {
            t = k * 0.01; a = 2 * pi * 10 * k / n
            if (kind == "2d") {
                printf "%.2f,%.3f,%.3f\n", t, 20 + 31 * cos(a) + 2 * sin(a) + rand() - 0.5, -10 + 4 * cos(a) + 27 * sin(a) + rand() - 0.5
            } else if (kind == "3d") {
                b = pi * (k + 0.5) / n; c = 2 * pi * 37 * k / n
                printf "%.2f,%.3f,%.3f,%.3f\n", t, 20 + 48 * sin(b) * cos(c) + rand() - 0.5, -10 + 45 * sin(b) * sin(c) + rand() - 0.5, 5 + 50 * cos(b) + rand() - 0.5
            } else if (kind == "imu") {
                y = 0.05 * t
                printf "%.2f,%.5f,%.5f,%.5f,%.4f,%.4f,%.4f,%.3f,%.3f,%.3f\n", t, 0.001 * (rand() - 0.5), 0.001 * (rand() - 0.5), 0.05, 0.01 * (rand() - 0.5), 0.01 * (rand() - 0.5), -9.81, 20 * cos(y), -20 * sin(y), 45
            } else if (kind == "tumble") {
                # Yaw 37 turns, pitch +-1.3 rad 23 times, roll 53 turns; the earth field
                # (20, 0, 45) and gravity turned into the body (yaw, then pitch, then roll).
                y = 2 * pi * 37 * k / n; p = 1.3 * sin(2 * pi * 23 * k / n); r = 2 * pi * 53 * k / n
                for (s = 0; s < 2; s++) {
                    vx = (s == 0) ? 20 : 0; vy = 0; vz = (s == 0) ? 45 : -9.81
                    ax = cos(y) * vx + sin(y) * vy; ay = -sin(y) * vx + cos(y) * vy; vx = ax; vy = ay
                    ax = cos(p) * vx - sin(p) * vz; az = sin(p) * vx + cos(p) * vz; vx = ax; vz = az
                    ay = cos(r) * vy + sin(r) * vz; az = -sin(r) * vy + cos(r) * vz; vy = ay; vz = az
                    if (s == 0) { mx = vx; my = vy; mz = vz } else { gx = vx; gy = vy; gz = vz }
                }
                printf "%.2f,%.4f,%.4f,%.4f,%.3f,%.3f,%.3f\n", t, 0.1 + 1.01 * gx + 0.02 * (rand() - 0.5), -0.05 + 0.99 * gy + 0.02 * (rand() - 0.5), 0.2 + gz + 0.02 * (rand() - 0.5), 15 + 1.1 * mx + 0.05 * my + rand() - 0.5, -8 + 0.05 * mx + 0.95 * my + 0.02 * mz + rand() - 0.5, 5 + 0.02 * my + mz + rand() - 0.5
            } else {
                d = 10 * t
                printf "%.2f,%.4f,%.4f,%.5f\n", t, d + 0.05 * t, d - 0.05 * t, 0.0645 + 0.001 * (rand() - 0.5)
            }
        }
    }' > "$3"
}

py=""
if command -v python3 >/dev/null; then py=python3; fi
have() { [ -n "$py" ] && $py -c "import $1" 2>/dev/null; }

measure() { # measure LABEL ROWS COMMAND...
    local label=$1 rows=$2 log="$dir/time.log"
    shift 2
    if /usr/bin/time -v "$@" >"$dir/stdout" 2>"$log"; then status=ok; else status="exit $?"; fi
    local wall cpu mem
    cpu=$(awk -F': ' '/User time \(seconds\)|System time \(seconds\)/ { s += $2 } END { printf "%.2f", s }' "$log")
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; printf "%.2f", s }' "$log")
    mem=$(awk -F': ' '/Maximum resident set size/ { printf "%.1f", $2 / 1024 }' "$log")
    local note
    note=$(head -c 200 "$dir/stdout")
    printf '| %-34s | %9s | %7s | %7s | %8s | %s %s\n' "$label" "$rows" "$wall" "$cpu" "$mem" "$status" "$note"
    if [ "$status" != ok ]; then grep -v '^\s' "$log" | grep -v '^Command' | head -2 | sed 's/^/|   /'; fi
}

echo "| command                            |      rows |  wall s |   cpu s |  peak MB | status (python: the read_csv call alone, without the interpreter's start)"
echo "|------------------------------------|-----------|---------|---------|----------|-------"
echo '{"track_m": 1.55, "odometer_wheels": "rear"}' > "$dir/vehicle.json"
for n in "${sizes[@]}"; do
    for kind in 2d 3d imu tumble drive; do gen "$kind" "$n" "$dir/$kind.csv"; done
    size=$(du -m "$dir/2d.csv" | cut -f1)
    for m in ellipse online-ellipse binned-ellipse merit-circle turn; do
        measure "calibrate $m" "$n" "$bin" calibrate --method "$m" --input "$dir/2d.csv" --output "$dir/cal-$m.json" --accept-poor
    done
    for m in ellipsoid online-ellipsoid; do
        measure "calibrate $m (3-D)" "$n" "$bin" calibrate --method "$m" --input "$dir/3d.csv" --output "$dir/cal-$m.json" --accept-poor
    done
    measure "calibrate ellipsoid-accel (tumble)" "$n" "$bin" calibrate --method ellipsoid-accel --input "$dir/tumble.csv" --output "$dir/cal-accel.json" --accept-poor
    measure "heading" "$n" "$bin" heading --calibration "$dir/cal-ellipse.json" --input "$dir/2d.csv" --output "$dir/heading.csv"
    if [ -n "${TRUENORTH_BEFORE:-}" ]; then
        measure "before: calibrate ellipse" "$n" "$TRUENORTH_BEFORE" calibrate --method ellipse --input "$dir/2d.csv" --output "$dir/cal-before.json" --accept-poor
        measure "before: heading" "$n" "$TRUENORTH_BEFORE" heading --calibration "$dir/cal-ellipse.json" --input "$dir/2d.csv" --output "$dir/heading-before.csv"
    fi
    measure "heading --precision 7" "$n" "$bin" heading --calibration "$dir/cal-ellipse.json" --input "$dir/2d.csv" --output "$dir/heading7.csv" --precision 7
    measure "orientation" "$n" "$bin" orientation --input "$dir/imu.csv" --output "$dir/att.csv" --accept-units --accept-axes
    measure "drive" "$n" "$bin" drive --vehicle "$dir/vehicle.json" --input "$dir/drive.csv" --output "$dir/track.csv"
    if have pandas; then
        measure "pandas read_csv (${size} MB)" "$n" "$py" -c "import pandas, sys, time; t = time.perf_counter(); pandas.read_csv(sys.argv[1]); print(f'read_csv {time.perf_counter() - t:.2f} s')" "$dir/2d.csv"
    else
        echo "| pandas read_csv: skipped (python3 -c 'import pandas' fails; pip install pandas)"
    fi
    if have polars; then
        measure "polars read_csv (${size} MB)" "$n" "$py" -c "import polars, sys, time; t = time.perf_counter(); polars.read_csv(sys.argv[1]); print(f'read_csv {time.perf_counter() - t:.2f} s')" "$dir/2d.csv"
    else
        echo "| polars read_csv: skipped (python3 -c 'import polars' fails; pip install polars)"
    fi
done
