#!/usr/bin/env bash
# Held-out sweep for the residual recipe's term selection: 3 units × 2 test
# profiles × 4 seed pairs, every base and every set of the ladder, run in parallel.
# Usage: heldout_sweep.sh <heldout binary> <out dir> [extra heldout args]
set -u
bin=$1; out=$2; shift 2
dir=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
fam=$(for d in 1 2 3; do for s in "" "+fast" "+fast+mid"; do printf "family:T%s%s," "$d" "$s"; done; done)
bases="selected,tailored,linear,linear-t2,${fam%,}"
for unit in default variant_b variant_c; do
  for test in slow-ramp fast-cycle; do
    for pair in 7:11 21:23 3:5 41:43; do
      tr=${pair%:*}; te=${pair#*:}
      (
        if [ "$unit" != default ]; then export HELDOUT_UNIT="$dir/heldout_units/$unit.json"; fi
        "$bin" --train seed-shock --test "$test" --train-seed "$tr" --test-seed "$te" \
          --bases "$bases" "$@" > "$out/$unit.$test.$tr.txt" 2>&1
      ) &
    done
  done
done
wait
