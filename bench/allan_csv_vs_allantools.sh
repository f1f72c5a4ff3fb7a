#!/usr/bin/env bash
# End to end on a CSV log: `gyrotherm allan --kind oadev --taus octave` (read and check the
# log, octave OADEV with noise identification and confidence bounds, print the table) beside
# pandas read_csv + allantools.oadev(taus="octave") on the same file, in the same run.
#
#   [RUNS=3] bench/allan_csv_vs_allantools.sh [ROWS]   (default 10000000 rows, 1 run)
#
# The log is the 100 Hz bench log of bench/read_log.sh (made in a temp dir). Each side's wall
# time, CPU time (user + sys) and peak RSS come from /usr/bin/time; the speed-up is the
# allantools side's wall time over gyrotherm's. Needs python3 with pandas and allantools
# (pip install pandas allantools). On a shared machine run it a few times and take the best.
set -euo pipefail
rows="${1:-10000000}"
cd "$(dirname "$0")/.."
python3 -c 'import pandas, allantools' 2>/dev/null || {
  echo "allan_csv_vs_allantools.sh: needs pandas and allantools (pip install pandas allantools)" >&2
  exit 1; }
[ -x /usr/bin/time ] || { echo "allan_csv_vs_allantools.sh: needs /usr/bin/time" >&2; exit 1; }
cargo build --release -q -p gyrotherm --example read_log_bench
cargo build --release -q -p gyrotherm-cli
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
target/release/examples/read_log_bench gen "$dir/log.csv" "$rows"
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); log: $rows rows, $(du -m "$dir/log.csv" | cut -f1) MB"
cat > "$dir/peer.py" <<'PY'
import sys
import allantools
import pandas as pd
df = pd.read_csv(sys.argv[1], comment="#")
t = df["time_s"].to_numpy()
rate = 1.0 / float(pd.Series(t[1:101] - t[:100]).median())
taus, dev, err, n = allantools.oadev(df["gyro_dps"].to_numpy(), rate=rate, data_type="freq",
                                     taus="octave")
print(f"allantools {allantools.__version__}: {len(taus)} taus, oadev(tau={taus[0]:g} s) = {dev[0]:.6g}")
PY
fmt="%e %U %S %M"
for run in $(seq "${RUNS:-1}"); do
  /usr/bin/time -f "$fmt" -o "$dir/g.time" target/release/gyrotherm allan --input "$dir/log.csv" \
    --kind oadev --taus octave > "$dir/g.out"
  /usr/bin/time -f "$fmt" -o "$dir/p.time" python3 "$dir/peer.py" "$dir/log.csv" > "$dir/p.out"
  read -r gw gu gs gm < "$dir/g.time"
  read -r pw pu ps pm < "$dir/p.time"
  awk -v r="$run" -v gw="$gw" -v gu="$gu" -v gs="$gs" -v gm="$gm" \
      -v pw="$pw" -v pu="$pu" -v ps="$ps" -v pm="$pm" 'BEGIN {
    printf "run %d: gyrotherm allan %.2f s wall (cpu %.2f s, peak RSS %.0f MB); ", r, gw, gu + gs, gm / 1024
    printf "pandas+allantools %.2f s wall (cpu %.2f s, peak RSS %.0f MB); speedup %.1fx wall, %.1fx cpu\n",
      pw, pu + ps, pm / 1024, pw / gw, (pu + ps) / (gu + gs) }'
done
head -3 "$dir/g.out"
cat "$dir/p.out"
