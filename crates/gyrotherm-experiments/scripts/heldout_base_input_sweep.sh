#!/usr/bin/env bash
# Held-out sweep for the residual LSTM reading the base prediction (`--base-input`):
# 3 units × 2 test profiles × 4 seed pairs × {gated, forced} × {features only, + base}, train
# `seed-shock`. Each output's SUMMARY line ends with raw linear poly base lstm (× noise floor);
# compare the last two. Runs whose output already holds a SUMMARY line are skipped.
# Usage: heldout_base_input_sweep.sh <heldout binary> <out dir> [jobs] [extra heldout args]
set -u
bin=$1; out=$2; jobs=${3:-2}; shift 3 2>/dev/null || shift $#
extra="$*"
dir=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
declare -A cfg=(
  [gated]=""
  [forced]="--validation-every 0 --epochs 150"
  [gated-base]="--base-input"
  [forced-base]="--base-input --validation-every 0 --epochs 150"
)
for unit in default variant_b variant_c; do
  for test in slow-ramp fast-cycle; do
    for pair in 7:11 21:23 3:5 41:43; do
      for c in "${!cfg[@]}"; do
        echo "$unit $test $pair $c ${cfg[$c]} $extra"
      done
    done
  done
done | sed 's/ *$//' | xargs -P "$jobs" -L 1 bash -c '
  unit=$0; test=$1; pair=$2; c=$3; shift 3
  tr=${pair%:*}; te=${pair#*:}
  f="'"$out"'/$unit.$test.$tr.$c.txt"
  grep -q ^SUMMARY "$f" 2>/dev/null && exit 0
  if [ "$unit" != default ]; then export HELDOUT_UNIT="'"$dir"'/heldout_units/$unit.json"; fi
  "'"$bin"'" --train seed-shock --test "$test" --train-seed "$tr" --test-seed "$te" "$@" \
    > "$f" 2>&1'
