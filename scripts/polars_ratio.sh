#!/usr/bin/env bash
# The speed of `calibrate` and `heading` against polars' read_csv of the same file, with the
# commands alternated round after round so that a machine whose speed drifts (a shared or
# virtual one) slows all of them alike; prints the best and the median of each and its ratio
# to polars' median.
#
# Usage: scripts/polars_ratio.sh FILE.csv CALIBRATION.json [ROUNDS] [BIN...]
#   FILE.csv          a t_s,mag_x,mag_y file (e.g. the 2-D file of scripts/io_speed.sh)
#   CALIBRATION.json  a 2-D calibration for `heading` (e.g. `calibrate --method ellipse` of it)
#   ROUNDS            rounds (default 5)
#   BIN...            truenorth builds to compare (default target/release/truenorth)
# polars' time is the read_csv call alone (its import and the interpreter's start excluded),
# the truenorth commands' the whole process (start, read, work, write).
set -euo pipefail

[ $# -ge 2 ] || { sed -n '2,13p' "$0" >&2; exit 2; }
file=$1 cal=$2 rounds=${3:-5}
shift $(( $# >= 3 ? 3 : 2 ))
bins=("$@")
[ ${#bins[@]} -eq 0 ] && bins=("$(dirname "$0")/../target/release/truenorth")
python3 -c 'import polars' 2>/dev/null || { echo "polars_ratio: pip install polars" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

seconds() { # seconds COMMAND...: wall time of one run
    local s e
    s=$(date +%s.%N)
    "$@" >/dev/null 2>&1 || { echo "polars_ratio: failed: $*" >&2; exit 1; }
    e=$(date +%s.%N)
    echo "$e - $s" | bc
}

for _ in $(seq "$rounds"); do
    echo "polars $(python3 -c 'import polars, sys, time; t = time.perf_counter(); polars.read_csv(sys.argv[1]); print(time.perf_counter() - t)' "$file")"
    for k in "${!bins[@]}"; do
        b=${bins[$k]}
        echo "merit-circle#$k $(seconds "$b" calibrate --method merit-circle --input "$file" --output "$out/m.json" --accept-poor)"
        echo "ellipse#$k $(seconds "$b" calibrate --method ellipse --input "$file" --output "$out/e.json" --accept-poor)"
        echo "heading#$k $(seconds "$b" heading --calibration "$cal" --input "$file" --output "$out/h.csv")"
    done
done | sort -k1,1 -s | awk '
    { v[$1] = v[$1] " " $2; n[$1]++; x[$1, n[$1]] = $2 }
    END {
        for (k in n) {
            m = n[k]; for (i = 1; i <= m; i++) a[i] = x[k, i]
            for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            best[k] = a[1]; med[k] = (m % 2) ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
        }
        printf "%-16s %8s %8s %10s\n", "command#build", "best s", "median s", "x polars"
        for (k in n) printf "%-16s %8.2f %8.2f %10.2f\n", k, best[k], med[k], med[k] / med["polars"]
    }' | sort
