#!/usr/bin/env bash
# LSTM training speed beside PyTorch, in the same run: one LSTM of HIDDEN units on the
# thermal-state inputs, minibatch truncated BPTT (BATCH windows of WINDOW steps, BURN_IN out
# of the loss), Adam lr 5e-3 cosine, clip 1, f32, on THREADS threads, STEPS Adam steps.
#
#   bench/lstm_vs_pytorch.sh [HIDDEN 32] [STEPS 10] [BATCH 128] [WINDOW 768] [BURN_IN 256] [THREADS 2]
#
# PyTorch comes from $PYTHON (default python3); install it with
# `pip install torch --index-url https://download.pytorch.org/whl/cpu`.
set -euo pipefail
cd "$(dirname "$0")/.."
hidden=${1:-32} steps=${2:-10} batch=${3:-128} window=${4:-768} burn_in=${5:-256} threads=${6:-2}
python=${PYTHON:-python3}
cargo build --release -q -p gyrotherm --example train_minibatch
ours=$(target/release/examples/train_minibatch - "$hidden" "$steps" "$batch" "$window" "$burn_in" f32 "$threads")
echo "$ours"
peer=$("$python" bench/lstm_vs_pytorch.py "$hidden" "$steps" "$batch" "$window" "$burn_in" "$threads")
echo "$peer"
ms() { sed -n 's/.*(\([0-9.]*\) ms per Adam step).*/\1/p' <<<"$1"; }
awk -v a="$(ms "$ours")" -v b="$(ms "$peer")" \
    'BEGIN { printf "gyrotherm is %.1f× as fast as PyTorch per Adam step (%.1f ms against %.1f ms)\n", b / a, a, b }'
