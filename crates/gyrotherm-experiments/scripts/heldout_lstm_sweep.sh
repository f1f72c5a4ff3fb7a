#!/usr/bin/env bash
# Held-out sweep for the residual LSTM on top of the selected base: 3 units × 2 test
# profiles × 4 seed pairs × LSTM settings (gated default, forced on, tuned variants, two
# training profiles), 2 runs at a time. Each output's SUMMARY line ends with
# raw linear poly base lstm (× noise floor); compare the last two.
# Runs whose output already holds a SUMMARY line are skipped (a sweep can be resumed).
# Usage: heldout_lstm_sweep.sh <heldout binary> <out dir> [jobs]
set -u
bin=$1; out=$2; jobs=${3:-2}
dir=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
declare -A cfg=(
  [gated]=""
  [forced]="--validation-every 0 --epochs 150"
  [forced300]="--validation-every 0 --epochs 300"
  [nogate]="--min-improvement -1"
  [w2000]="--window 2000 --burn-in 500 --block 2000"
  [lr01]="--lr 0.01"
  [b16]="--batch 16 --lr 0.01"
  [pat100]="--epochs 600 --patience 100"
  [smooth100]="--smooth 100"
)
for unit in default variant_b variant_c; do
  for test in slow-ramp fast-cycle; do
    for pair in 7:11 21:23 3:5 41:43; do
      for c in "${!cfg[@]}"; do
        echo "$unit $test $pair $c seed-shock ${cfg[$c]}"
      done
      # Two training profiles: the other test profile joins seed-shock.
      other=slow-ramp; [ "$test" = slow-ramp ] && other=fast-cycle
      echo "$unit $test $pair two seed-shock,$other"
      echo "$unit $test $pair two-forced seed-shock,$other --validation-every 0 --epochs 150"
    done
  done
done | sed 's/ *$//' | xargs -P "$jobs" -L 1 bash -c '
  unit=$0; test=$1; pair=$2; c=$3; train=$4; shift 4
  tr=${pair%:*}; te=${pair#*:}
  f="'"$out"'/$unit.$test.$tr.$c.txt"
  grep -q ^SUMMARY "$f" 2>/dev/null && exit 0
  if [ "$unit" != default ]; then export HELDOUT_UNIT="'"$dir"'/heldout_units/$unit.json"; fi
  "'"$bin"'" --train "$train" --test "$test" --train-seed "$tr" --test-seed "$te" "$@" \
    > "$f" 2>&1'
