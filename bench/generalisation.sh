#!/usr/bin/env bash
# The generalisation benchmark (record: docs/experiments/generalisation.md): every method
# trained on each unit of a simulated family and judged on three held-out profiles.
#
#   bench/generalisation.sh [design|confirm] [extra arguments for the harness]
#
# design (default): the 30 units settings are chosen on (unit seeds 1000-1029);
# confirm: 30 other units (5000-5029), run once at the end. Both cores; prints the tables
# and the wall time, and writes the per-case figures to target/generalisation-<family>.tsv.
set -euo pipefail
family="${1:-design}"
shift || true
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm-experiments --bin generalisation
start=$(date +%s)
target/release/generalisation --family "$family" --units 30 --threads 2 \
  --cases "target/generalisation-$family.tsv" "$@"
echo "bench/generalisation.sh $family: $(( $(date +%s) - start )) s wall"
