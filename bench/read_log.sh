#!/usr/bin/env bash
# Read a 10-million-row test log (issue 2 benchmark): throughput in MB/s on one core and
# peak memory (max RSS), for read_log (whole log into a TestLog) and the streaming LogReader.
#
#   bench/read_log.sh [ROWS]        (default 10000000; the log is made in a temp dir)
#
# MB/s is file bytes / wall time of the read (one thread). Peak RSS is the process's
# VmHWM (printed by the example) and /usr/bin/time's max RSS where available.
set -euo pipefail
rows="${1:-10000000}"
cd "$(dirname "$0")/.."
cargo build --release -q -p gyrotherm --example read_log_bench
bin=target/release/examples/read_log_bench
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
"$bin" gen "$dir/log.csv" "$rows"
"$bin" gen "$dir/table.csv" "$rows" --table
head -3 "$dir/log.csv"
timer=()
if [ -x /usr/bin/time ]; then timer=(/usr/bin/time -f "  (cpu %U s user + %S s sys, max RSS %M kB)"); fi
for f in log table; do
  for mode in stream read; do
    "${timer[@]}" "$bin" "$mode" "$dir/$f.csv"
  done
done
