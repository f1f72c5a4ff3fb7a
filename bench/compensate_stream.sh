#!/usr/bin/env bash
# Throughput of `gyrotherm compensate --stream` through the CLI (the flight path: core
# features + compensator + CSV in/out), in lines per second.
# Usage: bench/compensate_stream.sh [RATE_HZ]   (default 100: fast-cycle at 100 Hz = 2.03M lines)
set -euo pipefail
cd "$(dirname "$0")/.."
rate_hz=${1:-100}
cargo build --release -q -p gyrotherm-cli
bin=target/release/gyrotherm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
$bin simulate --profile seed-shock --seed 1 --out "$work/train.csv" 2>/dev/null
$bin simulate --profile seed-shock --seed 2 --table-rate 20 --out "$work/table.csv" 2>/dev/null
$bin train --method ${METHOD:-lstm} --epochs ${EPOCHS:-5} --input "$work/train.csv" --input "$work/table.csv" --out "$work/model.json" 2>/dev/null
$bin simulate --profile fast-cycle --seed 3 --rate-hz "$rate_hz" --out "$work/run.csv" 2>/dev/null
lines=$(($(wc -l < "$work/run.csv") - 1))
bytes=$(wc -c < "$work/run.csv")
start=$(date +%s.%N)
$bin compensate --stream --sample-period-s "$(python3 -c "print(1/$rate_hz)")" --model "$work/model.json" < "$work/run.csv" > "$work/out.csv"
end=$(date +%s.%N)
python3 - "$start" "$end" "$lines" "$bytes" <<'PY'
import sys
s, e, n, b = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
dt = e - s
print(f"compensate --stream: {n} lines ({b/1e6:.1f} MB) in {dt:.3f} s = {n/dt/1e6:.2f} M lines/s, {b/dt/1e6:.0f} MB/s in")
PY
