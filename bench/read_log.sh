#!/usr/bin/env bash
# Read a 10-million-row test log (issue 2 benchmark): throughput in MB/s and peak memory
# (max RSS), for read_log (whole log into a TestLog) and the streaming LogReader, beside
# pandas read_csv on the same file (when pandas is installed).
#
#   [RUNS=3] bench/read_log.sh [ROWS]   (default 10000000 rows, 1 run; the logs are made in
#                                        a temp dir)
#
# MB/s is file bytes / wall time of the read. The reader parses on two threads; the example
# also prints the main thread's on-CPU time (the critical path, which machine noise does not
# move) and the whole process's CPU time. Peak RSS is the process's VmHWM (printed by the
# example) and /usr/bin/time's max RSS where available. On a shared machine run it a few
# times and take the best.
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
pandas_read() {
  python3 - "$1" <<'PY'
import os, sys, time
import pandas as pd
path = sys.argv[1]
t0 = time.perf_counter(); c0 = time.process_time()
df = pd.read_csv(path, comment="#")
secs = time.perf_counter() - t0; cpu = time.process_time() - c0
mb = os.path.getsize(path) / 1e6
print(f"pandas {pd.__version__} read_csv: {len(df)} rows, {mb:.1f} MB in {secs:.3f} s wall = "
      f"{mb / secs:.0f} MB/s; process CPU {cpu:.3f} s = {mb / cpu:.0f} MB/s")
PY
}
have_pandas=0
if python3 -c 'import pandas' 2>/dev/null; then have_pandas=1; else
  echo "pandas not installed: no peer figure (pip install pandas)"; fi
for run in $(seq "${RUNS:-1}"); do
  echo "run $run"
  for f in log table; do
    for mode in stream read; do
      "${timer[@]}" "$bin" "$mode" "$dir/$f.csv"
    done
    if [ "$have_pandas" = 1 ]; then pandas_read "$dir/$f.csv"; fi
  done
done
