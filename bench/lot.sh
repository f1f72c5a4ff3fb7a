#!/usr/bin/env bash
# Lot benchmark: `lot report` on 1,000 units, and `lot add` against `compare` on real units.
# 1. 1,000 runs with synthetic figures (examples/lot_fill.rs, a library call) into an SQLite
#    lot; time `gyrotherm lot report` on it (target: <= 2 s).
# 2. Five units of the simulator's family (`simulate --unit random --unit-seed N`, seed-shock
#    profile, a static and a ±20 °/s rate-table held-out log each, a linear model): time
#    `lot add` (judge + record) and `compare --methods linear` (fit + judge) on the same logs.
# Usage: bench/lot.sh [OUT_DIR] (default bench/out/lot). Prints a table of wall times.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-bench/out/lot}"
rm -rf "$out"; mkdir -p "$out"
cargo build --release -q -p gyrotherm-cli -p gyrotherm --example lot_fill
bin=target/release/gyrotherm
now() { date +%s.%N; }
ms() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.0f", (b - a) * 1000 }'; }

target/release/examples/lot_fill "$out/lot1000.sqlite" 1000 >/dev/null
best=999999
for i in 1 2 3; do
    t=$(now); $bin lot report --db "$out/lot1000.sqlite" --out "$out/report1000" >/dev/null; d=$(ms "$t" "$(now)")
    [ "$d" -lt "$best" ] && best=$d
done
echo "lot report, 1000 units (best of 3): ${best} ms"

printf '[limits]\nbias_stability_dph = { max = 0.05 }\nsf_thermal_error_ppm = { max = 200 }\narw_deg_rt_h = { max = 0.005 }\n' > "$out/spec.toml"
add_total=0; cmp_total=0
for n in 1 2 3 4 5; do
    for s in 1 2 3 4; do
        t=(); [ $((s % 2)) = 0 ] && t=(--table-rate 20)
        $bin simulate --unit random --unit-seed "$n" --seed "$((10 * n + s))" "${t[@]}" --out "$out/u$n-$s.csv" >/dev/null 2>&1
    done
    $bin train --method linear --input "$out/u$n-1.csv" --input "$out/u$n-2.csv" --out "$out/u$n.json" >/dev/null 2>&1
    t=$(now)
    $bin lot add --db "$out/lot5.sqlite" --unit "SN$n" --model "$out/u$n.json" --test "$out/u$n-3.csv" --test "$out/u$n-4.csv" --spec "$out/spec.toml" >/dev/null || [ $? = 1 ]
    a=$(ms "$t" "$(now)")
    t=$(now)
    $bin compare --methods linear --train "$out/u$n-1.csv" --train "$out/u$n-2.csv" --test "$out/u$n-3.csv" --test "$out/u$n-4.csv" >/dev/null 2>&1
    c=$(ms "$t" "$(now)")
    echo "unit $n: lot add ${a} ms, compare --methods linear ${c} ms"
    add_total=$((add_total + a)); cmp_total=$((cmp_total + c))
done
echo "mean of 5 units (2 logs of 30000 samples each): lot add $((add_total / 5)) ms, compare --methods linear $((cmp_total / 5)) ms"
