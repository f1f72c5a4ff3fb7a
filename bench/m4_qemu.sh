#!/usr/bin/env bash
# Run the exported C model on an emulated Cortex-M4F (QEMU mps2-an386, semihosting) and compare
# its output with the host's `gyrotherm compensate --stream`, line by line, bit for bit.
# Needs: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm
# Usage: bench/m4_qemu.sh
# Models as bench/m4_size.sh (linear, poly, the default thermal method, the published-recipe LSTM of
# the flight_loop example); runs: 30,000-line seed-shock static run without and with injected
# temperature faults (spikes, NaN bursts, stuck readings, dropouts).
set -euo pipefail
cd "$(dirname "$0")/.."
for tool in arm-none-eabi-gcc qemu-system-arm; do
    command -v $tool >/dev/null || {
        echo "needs $tool: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm" >&2
        exit 2
    }
done
cargo build --release -q -p gyrotherm-cli
bin=$PWD/target/release/gyrotherm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
M4=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard)
CFLAGS=("${M4[@]}" -Os -std=c99 -ffp-contract=off -Wall -Wextra -Werror -pedantic)
$bin simulate --profile fast-cycle --seed 1 --out "$work/s.csv" 2>/dev/null
$bin simulate --profile fast-cycle --seed 2 --table-rate 20 --out "$work/t.csv" 2>/dev/null
for m in linear poly thermal; do
    $bin train --method $m --input "$work/s.csv" --input "$work/t.csv" --out "$work/$m.json" 2>/dev/null
done
cp crates/gyrotherm-core/examples/flight_loop/model.json "$work/published.json"
$bin simulate --profile seed-shock --seed 3 --out "$work/clean.csv" 2>/dev/null
$bin simulate --profile seed-shock --seed 3 --spikes-per-hour 4 --nan-bursts-per-hour 0.5 \
    --stuck-temp-per-hour 0.5 --stuck-temp-s 120 --stuck-value-per-hour 0.3 \
    --dropouts-per-hour 1 --out "$work/faulty.csv" 2>/dev/null
arm-none-eabi-gcc "${M4[@]}" -Os -c bench/m4/startup.c -o "$work/startup.o"
echo "qemu: $(qemu-system-arm --version | head -1); machine mps2-an386 (Cortex-M4F)"
fail=0
for m in linear poly thermal published; do
    dir="$work/$m"
    $bin export --model "$work/$m.json" --target c --out "$dir" 2>/dev/null
    arm-none-eabi-gcc "${CFLAGS[@]}" -I "$dir" crates/gyrotherm-cli/tests/export_c/driver.c \
        "$dir/gyrotherm_model.c" "$work/startup.o" -T bench/m4/mps2.ld --specs=rdimon.specs \
        -Wl,--gc-sections -o "$dir/driver.elf" -lm
    for run in clean faulty; do
        timeout 600 qemu-system-arm -M mps2-an386 -nographic \
            -semihosting-config enable=on,target=native,arg=driver,arg="$work/$run.csv" \
            -kernel "$dir/driver.elf" > "$dir/$run.m4"
        $bin compensate --stream --model "$work/$m.json" < "$work/$run.csv" > "$dir/$run.host" 2>/dev/null
        printf '%-10s %-7s ' "$m" "$run"
        python3 bench/m4/compare.py "$dir/$run.m4" "$dir/$run.host" || fail=1
    done
done
exit $fail
