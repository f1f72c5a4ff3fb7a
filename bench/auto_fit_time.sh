#!/usr/bin/env bash
# Wall time of `gyrotherm train` for one axis with each candidate `auto` scores and with
# `auto` itself, on the training the issue's speed target names: `seed-shock` plus the
# chamber profile `gyrotherm plan` proposes for the unit's airborne flight, static and
# ±20 °/s table each, at 1 Hz (unit U of the design family, default 1005, its worst case).
#
#   bench/auto_fit_time.sh [unit seed, default 1005] [repetitions, default 1] [soaks]
#
# soaks: `fixed` (default; the plan made from the flight alone) or `sized` (the plan also
# given the seed-shock run, `plan --input`, as the README advises: its first soak at each
# extreme sized to the slowest thermal lag, so the planned runs are longer).
#
# Prints the rows, the machine's load before and after, each method's wall time and what
# `auto` chose (target for `auto`: at most 60 s on the project's 2-core machine).
set -euo pipefail
unit="${1:-1005}"
reps="${2:-1}"
soaks="${3:-fixed}"
case "$soaks" in
fixed) plan_input=() ;;
sized) plan_input=(--input) ;;
*) echo "soaks: use fixed or sized, not $soaks" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm-cli
bin=target/release/gyrotherm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
u=(--unit random --unit-seed "$unit")
$bin simulate "${u[@]}" --profile seed-shock --seed 1 --out "$work/s.csv" >/dev/null 2>&1
$bin simulate "${u[@]}" --profile seed-shock --seed 2 --table-rate 20 --out "$work/t.csv" \
    >/dev/null 2>&1
# The flight the plan covers: an airborne run of the unit with a seed of its own.
$bin simulate "${u[@]}" --profile airborne --seed 3 --out "$work/flight.csv" >/dev/null 2>&1
[ "$soaks" = sized ] && plan_input+=("$work/s.csv")
$bin plan --flight "$work/flight.csv" "${plan_input[@]}" --out "$work/plan.txt" >/dev/null 2>&1
$bin simulate "${u[@]}" --profile-file "$work/plan.txt" --seed 4 --out "$work/ps.csv" \
    >/dev/null 2>&1
$bin simulate "${u[@]}" --profile-file "$work/plan.txt" --seed 5 --table-rate 20 \
    --out "$work/pt.csv" >/dev/null 2>&1
rows=0
for f in s t ps pt; do rows=$((rows + $(wc -l <"$work/$f.csv") - 1)); done
echo "unit $unit: $rows rows in 4 runs (seed-shock and planned with $soaks soaks, static and table); $(nproc) cores"
echo "load before: $(uptime)"
wall() {
    local start end
    start=$EPOCHREALTIME
    "$@" >"$work/train.out" 2>&1
    end=$EPOCHREALTIME
    echo "$end - $start" | bc
}
for r in $(seq "$reps"); do
    for m in thermal thermal-lstm auto; do
        t=$(wall $bin train --method "$m" --input "$work/s.csv" --input "$work/t.csv" \
            --input "$work/ps.csv" --input "$work/pt.csv" --out "$work/$m.json")
        echo "repetition $r: $m ${t} s"
        [ "$m" = auto ] && grep -i "auto\|chose\|candidate" "$work/train.out" | sed 's/^/    /'
    done
done
echo "load after: $(uptime)"
