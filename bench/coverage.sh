#!/usr/bin/env bash
# The coverage benchmark (record: docs/experiments/coverage.md): does the per-sample σ of
# `compensate` hold on held-out runs of a simulated family, inside and outside the training
# region?
#
#   bench/coverage.sh [design|confirm] [extra arguments for the harness]
#
# design (default): the σ scale and growth grid the settings are chosen on (unit seeds
# 1000-1029); confirm: the chosen settings only, on 30 other units (5000-5029), run once.
# The growth is also chosen on units past the design ranges: `imu_family --sigma` read by
# bench/growth_share.py (docs/experiments/coverage.md).
set -euo pipefail
family="${1:-design}"
shift || true
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm-experiments --bin coverage
if [ "$family" = design ]; then
  grid=(--scales 0.8,0.9,1,1.1,1.2 --growths 0,0.25,0.5,0.75,1,1.5,2)
else
  grid=()
fi
target/release/coverage --family "$family" --units 30 --threads 2 "${grid[@]}" "$@"
