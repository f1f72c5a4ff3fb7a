#!/usr/bin/env bash
# Instruction counts (valgrind --tool=callgrind), which do not move with machine load:
#   - one flight step, LSTM I = 2, H = 8 (gyrotherm-core example `lstm_steps`);
#   - one training epoch, 30,000 steps, I = 2, H = 8, f32, one network (gyrotherm example
#     `train_bench`: forward, backward through time and the optimiser step).
# Each figure is the difference of two runs that differ only in the number of steps (or
# epochs), divided by that difference: start-up, set-up and exit cancel out.
#
#   bench/callgrind.sh            (needs valgrind; builds the two examples in release)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not found (apt-get install valgrind)" >&2; exit 1; }
cargo build --release -q -p gyrotherm-core --example lstm_steps
cargo build --release -q -p gyrotherm --example train_bench
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Total instructions (Ir) of one run under callgrind.
ir() {
  valgrind --tool=callgrind --callgrind-out-file="$work/cg.out" "$@" >/dev/null 2>"$work/cg.err" || {
    cat "$work/cg.err" >&2; exit 1; }
  sed -n 's/^==[0-9]*== Collected : \([0-9]*\)$/\1/p' "$work/cg.err"
}

steps_a=100000
steps_b=300000
a=$(ir target/release/examples/lstm_steps "$steps_a")
b=$(ir target/release/examples/lstm_steps "$steps_b")
awk -v a="$a" -v b="$b" -v na="$steps_a" -v nb="$steps_b" 'BEGIN {
  printf "flight_step_instructions=%.1f (lstm_steps %d vs %d steps: %d vs %d Ir)\n", (b - a) / (nb - na), na, nb, a, b }'

a=$(ir target/release/examples/train_bench 1 f32 single)
b=$(ir target/release/examples/train_bench 3 f32 single)
awk -v a="$a" -v b="$b" 'BEGIN {
  printf "train_epoch_instructions=%.0f (%.1f per step of 30,000; train_bench 1 vs 3 epochs: %d vs %d Ir)\n", (b - a) / 2, (b - a) / 2 / 30000, a, b }'
