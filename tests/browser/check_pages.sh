#!/usr/bin/env bash
# Make a lot report, a comparison report and an inertial unit's report (the page across axes
# and one axis's page) from simulated units with the release binary, then load the pages in
# headless Chromium (check_pages.mjs). Without chromium or node this
# says it skipped, except under CI=true, where that is a failure.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
bin="${GYROTHERM_BIN:-$repo/target/release/gyrotherm}"
if ! command -v chromium >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
    if [ "${CI:-}" = "true" ]; then
        echo "browser check: chromium or node missing (apt-get install chromium nodejs npm)" >&2
        exit 1
    fi
    echo "browser check SKIPPED: chromium or node not installed"
    exit 0
fi
[ -x "$bin" ] || (cd "$repo" && cargo build --release -p gyrotherm-cli)
if [ ! -d "$here/node_modules/playwright-core" ]; then
    (cd "$here" && npm ci --no-audit --no-fund --silent)
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
printf '[limits]\nbias_stability_dph = { max = 0.05 }\nsf_thermal_error_ppm = { max = 200 }\narw_deg_rt_h = { max = 0.005 }\n' > spec.toml
for n in 1 2 3; do
    for s in 1 2; do
        t=(); [ "$s" = 2 ] && t=(--table-rate 20)
        "$bin" simulate --profile fast-cycle --unit random --unit-seed "$n" --seed "$((10 * n + s))" "${t[@]}" --out "u$n-train$s.csv" >/dev/null 2>&1
        "$bin" simulate --profile fast-cycle --unit random --unit-seed "$n" --seed "$((10 * n + s + 2))" "${t[@]}" --out "u$n-test$s.csv" >/dev/null 2>&1
    done
    "$bin" train --method linear --input "u$n-train1.csv" --input "u$n-train2.csv" --out "u$n.json" >/dev/null 2>&1
    "$bin" lot add --db lot.sqlite --unit "SN-<$n>" --model "u$n.json" --test "u$n-test1.csv" --test "u$n-test2.csv" --spec spec.toml >/dev/null || [ $? = 1 ]
done
"$bin" lot report --db lot.sqlite --out lot-report >/dev/null
"$bin" report --train u1-train1.csv --train u1-train2.csv --test u1-test1.csv --test u1-test2.csv --methods linear,poly --out cmp-report >/dev/null 2>&1
# An inertial unit's report: the page across axes and one axis's full page.
imu=(--imu --unit random --unit-seed 1 --profile fast-cycle --truth)
"$bin" simulate "${imu[@]}" --seed 1 --out imu-s.csv >/dev/null 2>&1
"$bin" simulate "${imu[@]}" --seed 2 --table-rate 20 --table-axis y --out imu-t.csv >/dev/null 2>&1
"$bin" simulate "${imu[@]}" --seed 3 --out imu-h.csv >/dev/null 2>&1
"$bin" simulate "${imu[@]}" --seed 4 --table-rate 20 --table-axis y --out imu-ht.csv >/dev/null 2>&1
# The unit judged per axis (limits every axis's held-out runs give: the table turns y only).
printf '[limits]\nbias_stability_dph = { max = 0.05 }\narw_deg_rt_h = { max = 0.005 }\n' > unit-spec.toml
"$bin" report --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps --temp-col temp_case_c,temp_x_c \
    --train imu-s.csv --train imu-t.csv --test imu-h.csv --test imu-ht.csv --methods linear,poly \
    --spec unit-spec.toml --out imu-report >/dev/null 2>&1 || [ $? = 1 ]
# The unit in the lot beside the single-axis units: the lot page's table of each unit's axes.
"$bin" train --method linear --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps --temp-col temp_case_c,temp_x_c \
    --input imu-s.csv --input imu-t.csv --out imu.json >/dev/null 2>&1
"$bin" lot add --db lot.sqlite --unit "IMU-<1>" --model imu.json --test imu-h.csv --test imu-ht.csv \
    --spec unit-spec.toml >/dev/null || [ $? = 1 ]
"$bin" lot report --db lot.sqlite --out lot-report >/dev/null
node "$here/check_pages.mjs" lot-report/index.html cmp-report/index.html imu-report/index.html imu-report/axis2/index.html
