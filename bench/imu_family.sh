#!/usr/bin/env bash
# The inertial-unit family benchmark (record: docs/experiments/imu.md): each unit's three
# axes trained on seed-shock static + one rate-table run per axis, judged on airborne and
# shock-5, with the case sensor alone, one sensor per axis chosen by cross-validation, and
# every sensor.
#
#   bench/imu_family.sh [design|confirm] [extra arguments for the harness]
#
# design (default): the 30 units settings are chosen on (unit seeds 1000-1029);
# confirm: 30 other units (5000-5029), run once at the end. Both cores; prints the table and
# the wall time, and writes the per-case figures to target/imu-family-<family>.tsv.
set -euo pipefail
family="${1:-design}"
shift || true
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm-experiments --bin imu_family
start=$(date +%s)
target/release/imu_family --family "$family" --units 30 --threads 2 \
  --cases "target/imu-family-$family.tsv" "$@"
echo "bench/imu_family.sh $family: $(( $(date +%s) - start )) s wall"
