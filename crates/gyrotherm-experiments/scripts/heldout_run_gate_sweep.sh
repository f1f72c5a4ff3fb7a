#!/usr/bin/env bash
# Held-out sweep for the leave-one-run-out gate of the residual LSTM (record:
# docs/experiments/lstm-run-gate.md): 3 units × 2 directions (train seed-shock + one profile, test the
# other) × 8 seed pairs, without and with `--run-gate`, two at a time.
# Usage: heldout_run_gate_sweep.sh <heldout binary> <out dir> [extra heldout args]
# Files: <out>/<unit>.<test profile>.<train seed>.<blocks|rungate>.txt (SUMMARY line last).
set -u
bin=$1; out=$2; shift 2
dir=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
for unit in default variant_b variant_c; do
  for dirn in seed-shock,slow-ramp:fast-cycle seed-shock,fast-cycle:slow-ramp; do
    for pair in 7:11 21:23 3:5 41:43 101:103 111:113 121:123 131:133; do
      for gate in blocks rungate; do
        echo "$unit ${dirn%:*} ${dirn#*:} ${pair%:*} ${pair#*:} $gate"
      done
    done
  done
done | xargs -P 2 -L 1 bash -c '
  unit=$0 train=$1 test=$2 a=$3 b=$4 gate=$5; shift 5
  if [ "$unit" != default ]; then export HELDOUT_UNIT="'"$dir"'/heldout_units/$unit.json"; fi
  flag=; [ "$gate" = rungate ] && flag=--run-gate
  "'"$bin"'" --train "$train" --test "$test" --train-seed "$a" --test-seed "$b" $flag "$@" \
    > "'"$out"'/$unit.$test.$a.$gate.txt" 2>&1' "$@"
