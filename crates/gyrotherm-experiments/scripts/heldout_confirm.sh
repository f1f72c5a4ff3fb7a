#!/usr/bin/env bash
# Confirmation set for the default recipe: seed pairs never used while choosing its
# settings (those used 7→11, 21→23, 3→5, 41→43). Default unit, train seed-shock (static +
# table), test slow-ramp and fast-cycle; prints the SUMMARY lines (×floor: raw linear poly
# base lstm).
# Usage: heldout_confirm.sh <heldout binary> [extra heldout args]
set -u
bin=$1; shift
for pair in 101:103 111:113 121:123 131:133 141:143 151:153 161:163 171:173; do
  for test in slow-ramp fast-cycle; do
    "$bin" --train seed-shock --test "$test" --train-seed "${pair%:*}" \
      --test-seed "${pair#*:}" "$@" 2>&1 | grep SUMMARY
  done
done
