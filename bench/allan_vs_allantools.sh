#!/usr/bin/env bash
# Octave OADEV of an N-sample rate series: gyrotherm vs Python allantools, side by side.
# Usage: bench/allan_vs_allantools.sh [N]   (default N = 100000000)
# Needs network once for `pip install allantools numpy` (into target/allantools-venv).
# Prints wall and CPU seconds of each and the peak RSS of each process (gyrotherm holds the
# samples and builds the phase in their buffer; allantools holds its own arrays).
set -euo pipefail
cd "$(dirname "$0")/.."
N="${1:-100000000}"
VENV="${VENV:-target/allantools-venv}"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet allantools numpy
fi
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB"
RUST_OUT=$(GYROTHERM_ALLAN_N="$N" cargo bench --quiet -p gyrotherm --bench allan 2>/dev/null | grep -E "gyrotherm_oadev|peak_rss")
echo "$RUST_OUT"
PY_OUT=$("$VENV/bin/python" bench/allan_vs_allantools.py "$N")
echo "$PY_OUT"
# Speed-up of the full gyrotherm run (noise ID + Greenhall bounds) over allantools' oadev.
RS=$(echo "$RUST_OUT" | sed -n 's/^gyrotherm_oadev_octave_s=\([0-9.]*\).*/\1/p')
PS=$(echo "$PY_OUT" | sed -n 's/^allantools_oadev_octave_s=\([0-9.]*\).*/\1/p')
RC=$(echo "$RUST_OUT" | sed -n 's/^gyrotherm_oadev_octave_s=.* cpu_s=\([0-9.]*\).*/\1/p')
PC=$(echo "$PY_OUT" | sed -n 's/^allantools_oadev_octave_s=.* cpu_s=\([0-9.]*\).*/\1/p')
# Wall-time ratio, and the CPU-time ratio (which holds up when other work shares the cores;
# gyrotherm uses two threads, so its wall time on an idle machine is about half its CPU time).
awk -v r="$RS" -v p="$PS" -v rc="$RC" -v pc="$PC" 'BEGIN {
  printf "speedup=%.1fx (wall)", p / r
  if (rc > 0) printf ", %.1fx (CPU)", pc / rc
  printf "\n" }'
