#!/usr/bin/env bash
# Train `thermal` on a 1 kHz, 45-minute, three-axis autopilot log and print wall time and
# peak memory (the reader reduces the samples to one row per model step as it reads).
#
#   bench/autopilot_log.sh [ulog|dataflash] [MINUTES] [RATE_HZ]    defaults: ulog 45 1000
#
# Writes the log with the `autopilot_log` example (not part of the product) under
# bench/out/autopilot_log/; needs GNU time (/usr/bin/time).
set -euo pipefail
cd "$(dirname "$0")/.."
format=${1:-ulog}
minutes=${2:-45}
rate=${3:-1000}
case $format in ulog) ext=ulg ;; dataflash) ext=bin ;; *) echo "format: ulog or dataflash" >&2; exit 2 ;; esac
out=bench/out/autopilot_log
mkdir -p "$out"
log=$out/gyro.$ext
nice cargo build --release -q -p gyrotherm-cli
nice cargo run --release -q -p gyrotherm --example autopilot_log -- "$format" "$log" "$minutes" "$rate"
ls -l "$log"
/usr/bin/time -v target/release/gyrotherm train --method thermal --input "$log" \
    --out "$out/model.json" 2> "$out/time.txt" || { cat "$out/time.txt"; exit 1; }
grep -v '^\s' "$out/time.txt" | grep -v '^Command' || true
wall=$(grep 'Elapsed (wall clock)' "$out/time.txt" | awk '{print $NF}')
rss=$(grep 'Maximum resident set size' "$out/time.txt" | awk '{print $NF}')
echo "autopilot_log: $format, $minutes min at $rate Hz: wall $wall, max RSS $((rss / 1024)) MiB"
