#!/usr/bin/env bash
# Wall time of `gyrotherm train --method thermal` for an inertial unit (3 axes, 4 sensors: case + one per coil)
# against one axis with one sensor, on the same 30,000-row runs (`seed-shock` at 1 Hz, unit
# 1000 of the design family: a static run and a ±20 °/s rate-table run turning x), in the
# same run of this script (record: docs/experiments/imu.md).
#
#   bench/imu_train_time.sh [repetitions, default 3]
#
# Prints the machine's load before and after, each repetition's wall times, and the ratio of
# the medians (target: at most 1.5 on the project's 2-core machine).
set -euo pipefail
reps="${1:-3}"
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm-cli
bin=target/release/gyrotherm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unit=(--imu --unit random --unit-seed 1000)
$bin simulate "${unit[@]}" --seed 1 --out "$work/s.csv" >/dev/null 2>&1
$bin simulate "${unit[@]}" --seed 2 --table-rate 20 --table-axis x --out "$work/t.csv" \
    >/dev/null 2>&1
echo "rows: $(($(wc -l <"$work/s.csv") - 1)) static, $(($(wc -l <"$work/t.csv") - 1)) table; $(nproc) cores"
echo "load before: $(uptime)"
# Bash's own clock (no `date` process at either end, whose start-up would be counted too).
wall() {
    local start end
    start=$EPOCHREALTIME
    "$@" >/dev/null 2>&1
    end=$EPOCHREALTIME
    echo "$end - $start" | bc
}
one=()
imu=()
for r in $(seq "$reps"); do
    a=$(wall $bin train --method thermal --input "$work/s.csv" --input "$work/t.csv" \
        --gyro-col gyro_x_dps --temp-col temp_case_c --out "$work/one.json")
    b=$(wall $bin train --method thermal --input "$work/s.csv" --input "$work/t.csv" \
        --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps \
        --temp-col temp_case_c,temp_x_c,temp_y_c,temp_z_c --out "$work/imu.json")
    echo "repetition $r: one axis, one sensor ${a} s; 3 axes, 4 sensors ${b} s"
    one+=("$a")
    imu+=("$b")
done
echo "load after: $(uptime)"
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR]=$1} END {print (NR%2) ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2}'; }
m1=$(median "${one[@]}")
m2=$(median "${imu[@]}")
echo "median: one axis, one sensor ${m1} s; 3 axes, 4 sensors ${m2} s; ratio $(echo "scale=2; $m2 / $m1" | bc)"
