#!/usr/bin/env bash
# Cross-check of the MCAP fixture against the Python reference reader, for CI: installs the
# Python `mcap` reader and its ROS 2 decoder, then runs the test that compares every decoded
# number and fails if it skipped. Run from anywhere inside the repository.
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
python3 -m pip install --quiet mcap mcap-ros2-support
out=$(cargo test -p truenorth-logs --test mcap_fixture the_python_mcap_reader_agrees -- --nocapture 2>&1)
echo "$out" | grep -E "agrees|test result"
echo "$out" | grep -q "python mcap reader agrees on all" || { echo "$out"; exit 1; }
