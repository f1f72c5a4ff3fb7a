#!/usr/bin/env bash
# The Python package: wall time of `pip install ./crates/gyrotherm-py` into a clean venv, then
# gyrotherm.oadev vs allantools.oadev on 1e7 and 1e8 samples in the same run.
# Usage: bench/python_vs_allantools.sh [N ...]      (default: 1e7 1e8)
#   COLD=1: build with an empty cargo target directory (every dependency compiled).
# Needs the package index (maturin, numpy, allantools); the venv lives in target/bench-pyvenv.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=target/bench-pyvenv
rm -rf "$VENV"
python3 -m venv "$VENV"
"$VENV/bin/pip" install --quiet --disable-pip-version-check allantools numpy
if [ "${COLD:-0}" = 1 ]; then
    export CARGO_TARGET_DIR="$(mktemp -d)"
    trap 'rm -rf "$CARGO_TARGET_DIR"' EXIT
fi
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
START=$(date +%s.%N)
"$VENV/bin/pip" install --quiet --disable-pip-version-check ./crates/gyrotherm-py
END=$(date +%s.%N)
awk -v s="$START" -v e="$END" -v c="${COLD:-0}" \
    'BEGIN { printf "pip_install_s=%.1f (%s cargo target dir)\n", e - s, c == 1 ? "empty" : "this workspace'"'"'s" }'
"$VENV/bin/python" bench/python_oadev.py "$@"
