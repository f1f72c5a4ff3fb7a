#!/usr/bin/env bash
# Byte identity of what the commands write, across a change of the code's structure.
#
#   bench/identity.sh record DIR [BIN]   # run the fixed commands with BIN, keep the outputs in DIR
#   bench/identity.sh check DIR [BIN]    # run them again with BIN and compare with DIR
#
# BIN defaults to target/release/gyrotherm (built here when missing). Record with the binary
# before the change, check with the one after it. The commands cover simulated logs (one gyro,
# an inertial unit, a rate-table run, a run with sensor faults), model files for every method
# (one gyro) and for units (3 axes × 4 sensors; 1 axis × 2 sensors), compensated logs (batch
# and --stream), the C and Rust exports of each model, and what the judging commands print and
# draw (compare, report, evaluate, lot add; one gyro and a unit).
#
# Model files are compared after removing what may legitimately differ: the content digest,
# the creator line and the trained-with column names (keys in $IGNORED_KEYS). Exported files are
# compared with any 64-digit hexadecimal digest masked. Everything else must be equal byte for
# byte. Prints one line per output (same / DIFFERENT) and the counts; exits 1 when any differs.
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-}"
dir="${2:-}"
bin="${3:-target/release/gyrotherm}"
IGNORED_KEYS="content_sha256,creator,columns,trained_columns"
if [ -z "$mode" ] || [ -z "$dir" ] || { [ "$mode" != record ] && [ "$mode" != check ]; }; then
    sed -n '2,17p' "$0" >&2
    exit 2
fi
if [ "$bin" = target/release/gyrotherm ] && [ ! -x "$bin" ]; then
    cargo build --release -q -p gyrotherm-cli
fi
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"

# Write every output of the fixed command list into $1.
produce() {
    local out="$1"
    mkdir -p "$out"
    cd "$out"
    local g=("$bin")
    # The export target's flag: `--target` where the binary has it, else the older `--lang`.
    local lang=--lang
    if "$bin" export --help 2>/dev/null | grep -q -- '--target'; then lang=--target; fi
    # Logs: one gyro (static, table, held-out, faults), an inertial unit (static, table, flight).
    "${g[@]}" simulate --profile seed-shock --seed 1 --out s.csv
    "${g[@]}" simulate --profile seed-shock --seed 2 --table-rate 20 --out t.csv
    "${g[@]}" simulate --profile slow-ramp --seed 3 --out held.csv
    "${g[@]}" simulate --profile airborne --seed 4 --spikes-per-hour 2 --dropouts-per-hour 1 \
        --stuck-temp-per-hour 1 --out faults.csv
    local unit=(--imu --unit random --unit-seed 1000)
    "${g[@]}" simulate "${unit[@]}" --seed 5 --out us.csv
    "${g[@]}" simulate "${unit[@]}" --seed 6 --table-rate 20 --table-axis x --out ut.csv
    "${g[@]}" simulate "${unit[@]}" --seed 7 --profile airborne --out uf.csv
    # One gyro: every method (the LSTM methods with few epochs, to keep the run short).
    local m
    for m in thermal linear poly residual generic direct published; do
        local extra=()
        case "$m" in residual | generic | direct | published) extra=(--epochs 30) ;; esac
        "${g[@]}" train --input s.csv --input t.csv --method "$m" "${extra[@]}" \
            --out "m-$m.json"
        "${g[@]}" compensate --model "m-$m.json" --input held.csv --out "c-$m.csv"
        "${g[@]}" compensate --model "m-$m.json" --stream <faults.csv >"cs-$m.csv"
        "${g[@]}" export --model "m-$m.json" "$lang" c --out "x-$m-c" >/dev/null
        "${g[@]}" export --model "m-$m.json" "$lang" rust --out "x-$m-rust" >/dev/null
    done
    # Units: 3 axes × 4 sensors, and 1 axis × 2 sensors, with `thermal` by name (the default
    # was `thermal` when the baseline was recorded; it is `auto` since).
    "${g[@]}" train --method thermal --input us.csv --input ut.csv --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps \
        --temp-col temp_case_c,temp_x_c,temp_y_c,temp_z_c --out u3.json
    "${g[@]}" train --method thermal --input us.csv --input ut.csv --gyro-col gyro_x_dps \
        --temp-col temp_case_c,temp_x_c --out u1.json
    local u
    for u in u3 u1; do
        "${g[@]}" compensate --model "$u.json" --input uf.csv --out "c-$u.csv"
        "${g[@]}" compensate --model "$u.json" --stream <uf.csv >"cs-$u.csv"
        "${g[@]}" export --model "$u.json" "$lang" c --out "x-$u-c" >/dev/null
        "${g[@]}" export --model "$u.json" "$lang" rust --out "x-$u-rust" >/dev/null
    done
    # What the judging commands print and draw, for one gyro and a unit, with a spec sheet:
    # the comparison (text, JSON), the report (its table and page), the evaluation (a column,
    # a model's output, a unit's axes) and a lot record. A missed limit exits 1, not an error.
    printf 'name = "loose"\n[limits]\nbias_stability_dph = { max = 1 }\n' >spec.toml
    local lists=(--gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps --temp-col temp_case_c,temp_x_c)
    local judged=(--methods linear,thermal --spec spec.toml)
    # The comparison's own method (a unit's fit): `thermal`, where the binary can be told it.
    if "$bin" compare --help 2>/dev/null | grep -q -- '--method <'; then
        judged+=(--method thermal)
    fi
    "${g[@]}" compare --train s.csv --train t.csv --test held.csv "${judged[@]}" >j-compare.txt || [ $? -eq 1 ]
    "${g[@]}" compare --json --train s.csv --train t.csv --test held.csv "${judged[@]}" \
        >j-compare.json.txt || [ $? -eq 1 ]
    "${g[@]}" compare --train us.csv --train ut.csv --test uf.csv "${lists[@]}" "${judged[@]}" \
        >j-compare-unit.txt || [ $? -eq 1 ]
    "${g[@]}" report --train s.csv --train t.csv --test held.csv "${judged[@]}" --out j-report \
        >j-report.txt || [ $? -eq 1 ]
    "${g[@]}" report --train us.csv --train ut.csv --test uf.csv "${lists[@]}" "${judged[@]}" \
        --out j-report-unit >j-report-unit.txt || [ $? -eq 1 ]
    "${g[@]}" evaluate --input held.csv --spec spec.toml >j-evaluate.txt || [ $? -eq 1 ]
    "${g[@]}" evaluate --json --input held.csv --model m-thermal.json >j-evaluate-model.json.txt
    "${g[@]}" evaluate --input uf.csv "${lists[@]}" --spec spec.toml >j-evaluate-unit.txt || [ $? -eq 1 ]
    "${g[@]}" lot add --db j-lot.db --unit A1 --model m-thermal.json --test held.csv \
        --spec spec.toml >j-lot.txt || [ $? -eq 1 ]
    "${g[@]}" lot add --db j-lot.db --unit U1 --model u3.json --test uf.csv --spec spec.toml \
        >j-lot-unit.txt || [ $? -eq 1 ]
    rm -f j-lot.db
    cd - >/dev/null
}

# Print a file in its compared form.
normal() {
    case "$1" in
    *.json)
        python3 - "$1" "$IGNORED_KEYS" <<'PY'
import json, sys
drop = set(sys.argv[2].split(","))
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in drop}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
with open(sys.argv[1]) as f:
    text = f.read()
try:
    print(json.dumps(strip(json.loads(text)), sort_keys=True))
except ValueError:
    print(text)
PY
        ;;
    *) sed -E 's/[0-9a-f]{64}/<digest>/g' "$1" ;;
    esac
}

if [ "$mode" = record ]; then
    rm -rf "$dir"
    produce "$dir" >/dev/null 2>&1 || { echo "a command failed; rerun without redirection" >&2; produce "$dir"; }
    echo "recorded $(find "$dir" -type f | wc -l) outputs in $dir with $bin"
    exit 0
fi

new="$(mktemp -d)"
trap 'rm -rf "$new"' EXIT
produce "$new/out" >/dev/null 2>&1 || { echo "a command failed:" >&2; produce "$new/out"; }
same=0
differ=0
while IFS= read -r f; do
    rel="${f#"$dir"/}"
    if [ ! -f "$new/out/$rel" ]; then
        echo "MISSING   $rel"
        differ=$((differ + 1))
    elif cmp -s <(normal "$f") <(normal "$new/out/$rel"); then
        same=$((same + 1))
    else
        echo "DIFFERENT $rel"
        differ=$((differ + 1))
    fi
done < <(find "$dir" -type f | sort)
echo "identity: $same same, $differ different or missing (of $((same + differ)) recorded outputs)"
[ "$differ" -eq 0 ]
