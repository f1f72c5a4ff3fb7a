#!/usr/bin/env bash
# Run every cargo-fuzz target (or the ones named) for N seconds each and print, per target,
# the executions, edge coverage, corpus size and crashes libFuzzer reports.
#
#   bench/fuzz.sh N [TARGET...]        e.g. bench/fuzz.sh 60, bench/fuzz.sh 900 csvlog allan
#   FUZZ_PARALLEL=2 bench/fuzz.sh 900  two targets at a time (nice'd)
#
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`). The corpus grows
# in fuzz/corpus/TARGET (not committed) from the committed seeds in fuzz/seeds/TARGET;
# crashes land in fuzz/artifacts/TARGET; logs in bench/out/fuzz/TARGET.log.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:?usage: bench/fuzz.sh SECONDS [TARGET...]}
shift
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(csvlog model_file compensator allan export ulog dataflash)
fi
parallel=${FUZZ_PARALLEL:-1}
logs=bench/out/fuzz
mkdir -p "$logs"

for t in "${targets[@]}"; do
    (cd fuzz && nice cargo +nightly fuzz build -O "$t")
done

run_one() {
    local t=$1
    mkdir -p "fuzz/corpus/$t"
    # -rss_limit_mb: a case that needs more is a finding (runaway allocation), not noise.
    (cd fuzz && nice cargo +nightly fuzz run -O "$t" "corpus/$t" "seeds/$t" -- \
        -max_total_time="$secs" -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 \
        >"../$logs/$t.log" 2>&1) || true
}

running=0
for t in "${targets[@]}"; do
    echo "fuzzing $t for $secs s (log: $logs/$t.log)" >&2
    run_one "$t" &
    running=$((running + 1))
    if [ "$running" -ge "$parallel" ]; then
        wait -n || true
        running=$((running - 1))
    fi
done
wait

printf '%-12s %10s %8s %8s %7s %8s %s\n' target seconds execs exec/s cov corpus crashes
for t in "${targets[@]}"; do
    log=$logs/$t.log
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    last=$(grep -E "^#[0-9]+" "$log" | tail -1 || true)
    cov=$(echo "$last" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*' || echo '?')
    corp=$(echo "$last" | grep -o 'corp: [0-9]*' | grep -o '[0-9]*' || echo '?')
    crashes=$(find "fuzz/artifacts/$t" -type f \( -name 'crash-*' -o -name 'oom-*' -o -name 'timeout-*' -o -name 'leak-*' \) 2>/dev/null | wc -l)
    printf '%-12s %10s %8s %8s %7s %8s %s\n' "$t" "$secs" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${corp:-?}" "$crashes"
done
