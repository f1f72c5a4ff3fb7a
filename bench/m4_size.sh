#!/usr/bin/env bash
# Flash and RAM of `gyrotherm export --target c` models on a Cortex-M4F, with Debian's
# gcc-arm-none-eabi (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi).
# Usage: bench/m4_size.sh
# Models: linear, poly and the default `thermal` method (ridge on identified thermal states)
# trained here on simulated fast-cycle runs, and the `published`-recipe LSTM of
# crates/gyrotherm-core/examples/flight_loop/model.json (bias and scale-factor LSTMs), and
# the same model with both LSTMs widened to 32 and to 64 hidden units (random weights: the
# sizes, not the numbers, set flash, RAM and stack).
# Then an inertial unit: 3 gyros and 4 temperature sensors (case + one per coil), `thermal`
# trained on simulated runs of unit 1000 of the design family (`simulate --imu`: a static
# run and a rate-table run per axis) with the default multi-sensor fit (each axis may read
# several sensors; the line after the table says which), exported with gt_step_imu.
# Per model: the object file's text, data and bss; flash = text + data; RAM = data + bss +
# sizeof(gt_state) (one gyro axis; the whole unit for the unit); stack: an upper bound for one gt_step (gt_step_imu) call; and the flash a linked image grows by against an empty
# main (--specs=nano.specs, -Wl,--gc-sections): the model plus the soft-float double
# routines and libm's floor that it pulls in (the M4F FPU is single precision).
set -euo pipefail
cd "$(dirname "$0")/.."
command -v arm-none-eabi-gcc >/dev/null || {
    echo "needs arm-none-eabi-gcc: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi" >&2
    exit 2
}
cargo build --release -q -p gyrotherm-cli
bin=target/release/gyrotherm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
CFLAGS=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os -std=c99
    -ffp-contract=off -ffunction-sections -fdata-sections -fno-common -fstack-usage
    -Wall -Wextra -Werror -pedantic)
LDFLAGS=(--specs=nano.specs --specs=nosys.specs -Wl,--gc-sections)
$bin simulate --profile fast-cycle --seed 1 --out "$work/s.csv" 2>/dev/null
$bin simulate --profile fast-cycle --seed 2 --table-rate 20 --out "$work/t.csv" 2>/dev/null
for m in linear poly thermal; do
    $bin train --method $m --input "$work/s.csv" --input "$work/t.csv" --out "$work/$m.json" 2>/dev/null
done
cp crates/gyrotherm-core/examples/flight_loop/model.json "$work/published.json"
for h in 32 64; do
    python3 - "$work/published.json" "$h" >"$work/lstm$h.json" <<'PY'
import json, random, sys
m = json.load(open(sys.argv[1]))
h = int(sys.argv[2])
m.pop("content_sha256", None)
rng = random.Random(h)
for t in ("bias", "scale"):
    p = m[t]["lstm"]["params"]
    i, k = p["input_size"], 0.3 / h ** 0.5
    vec = lambda n: [rng.uniform(-k, k) for _ in range(n)]
    p.update(hidden_size=h, w_ih=vec(4 * h * i), w_hh=vec(4 * h * h), b_ih=vec(4 * h),
             b_hh=vec(4 * h), w_out=vec(h))
json.dump(m, sys.stdout)
PY
done
arm-none-eabi-gcc "${CFLAGS[@]}" bench/m4/size_main.c "${LDFLAGS[@]}" -o "$work/empty.elf" -lm
empty=$(arm-none-eabi-size "$work/empty.elf" | awk 'NR==2 {print $1 + $2}')
echo "arm-none-eabi-gcc $(arm-none-eabi-gcc -dumpversion); flags: ${CFLAGS[*]}"
printf '%-10s %-20s %6s %6s %6s %8s %8s %7s %14s\n' model parts text data bss flash RAM stack "linked +flash"
for m in linear poly thermal published lstm32 lstm64; do
    dir="$work/$m"
    $bin export --model "$work/$m.json" --target c --out "$dir" 2>/dev/null
    arm-none-eabi-gcc "${CFLAGS[@]}" -c "$dir/gyrotherm_model.c" -o "$dir/model.o"
    # Upper bound on gt_step's stack: the sum of every function's frame in the file.
    stack=$(awk '{s += $(NF-1)} END {print s}' "$dir/model.su")
    read -r text data bss _ < <(arm-none-eabi-size "$dir/model.o" | awk 'NR==2')
    printf '#include "gyrotherm_model.h"\ngt_state probe;\n' > "$dir/probe.c"
    arm-none-eabi-gcc "${CFLAGS[@]}" -I "$dir" -c "$dir/probe.c" -o "$dir/probe.o"
    state=$(arm-none-eabi-size "$dir/probe.o" | awk 'NR==2 {print $3}')
    arm-none-eabi-gcc "${CFLAGS[@]}" -DWITH_MODEL -I "$dir" bench/m4/size_main.c \
        "$dir/gyrotherm_model.c" "${LDFLAGS[@]}" -o "$dir/image.elf" -lm
    image=$(arm-none-eabi-size "$dir/image.elf" | awk 'NR==2 {print $1 + $2}')
    parts=$(python3 -c "import json,sys; m=json.load(open(sys.argv[1])); print('/'.join(next(iter(m[t])) if m.get(t) else 'none' for t in ('bias','scale')))" "$work/$m.json")
    case "$m" in lstm32 | lstm64) parts="$parts (${m#lstm} units)" ;; esac
    printf '%-10s %-20s %6d %6d %6d %8d %8d %7d %14d\n' "$m" "$parts" "$text" "$data" "$bss" \
        $((text + data)) $((data + bss + state)) "$stack" $((image - empty))
done
echo "state: sizeof(gt_state) = $state bytes per axis (RAM includes it); stack: sum of the"
echo "frames of every function in gyrotherm_model.c (-fstack-usage), an upper bound for gt_step"

# Instructions per gt_step of the LSTM models (QEMU mps2-an386 with -icount shift=0; the
# Cortex-M4 takes about one cycle an instruction, more for loads, divisions and branches).
if command -v qemu-system-arm >/dev/null; then
    arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os \
        -c bench/m4/startup.c -o "$work/startup.o"
    for m in published lstm32 lstm64; do
        dir="$work/$m"
        arm-none-eabi-gcc "${CFLAGS[@]}" -I "$dir" bench/m4/step_count.c "$dir/gyrotherm_model.c" \
            "$work/startup.o" -T bench/m4/mps2.ld --specs=rdimon.specs -Wl,--gc-sections \
            -o "$dir/count.elf" -lm
        n=$(timeout 600 qemu-system-arm -M mps2-an386 -nographic -icount shift=0 \
            -semihosting-config enable=on,target=native -kernel "$dir/count.elf")
        echo "$m: $n instructions per gt_step (QEMU $(qemu-system-arm --version | head -1 | awk '{print $4}'), -icount)"
    done
else
    echo "instructions per step: needs qemu-system-arm (apt-get install qemu-system-arm)"
fi

# The inertial unit.
unit=(--imu --unit random --unit-seed 1000 --profile fast-cycle)
$bin simulate "${unit[@]}" --seed 1 --out "$work/us.csv" 2>/dev/null
inputs=(--input "$work/us.csv")
for ax in x y z; do
    $bin simulate "${unit[@]}" --seed 2 --table-rate 20 --table-axis $ax --out "$work/ut$ax.csv" 2>/dev/null
    inputs+=(--input "$work/ut$ax.csv")
done
$bin train --method thermal --gyro-col gyro_x_dps,gyro_y_dps,gyro_z_dps \
    --temp-col temp_case_c,temp_x_c,temp_y_c,temp_z_c "${inputs[@]}" --out "$work/imu.json" 2>/dev/null
dir="$work/imu"
$bin export --model "$work/imu.json" --target c --out "$dir" 2>/dev/null
arm-none-eabi-gcc "${CFLAGS[@]}" -c "$dir/gyrotherm_model.c" -o "$dir/model.o"
stack=$(awk '{s += $(NF-1)} END {print s}' "$dir/model.su")
read -r text data bss _ < <(arm-none-eabi-size "$dir/model.o" | awk 'NR==2')
printf '#include "gyrotherm_model.h"\ngt_state probe;\n' > "$dir/probe.c"
arm-none-eabi-gcc "${CFLAGS[@]}" -I "$dir" -c "$dir/probe.c" -o "$dir/probe.o"
state=$(arm-none-eabi-size "$dir/probe.o" | awk 'NR==2 {print $3}')
arm-none-eabi-gcc "${CFLAGS[@]}" -DWITH_IMU -I "$dir" bench/m4/size_main.c \
    "$dir/gyrotherm_model.c" "${LDFLAGS[@]}" -o "$dir/image.elf" -lm
image=$(arm-none-eabi-size "$dir/image.elf" | awk 'NR==2 {print $1 + $2}')
parts=$(python3 -c "import json,sys; m=json.load(open(sys.argv[1])); print('axes read ' + '; '.join('+'.join(a['temps']) for a in m['axes']))" "$work/imu.json")
printf '%-10s %-20s %6d %6d %6d %8d %8d %7d %14d\n' "imu" "3 axes, 4 sensors" "$text" "$data" "$bss" \
    $((text + data)) $((data + bss + state)) "$stack" $((image - empty))
echo "imu: $parts; sizeof(gt_state) = $state bytes for the unit (RAM includes it); stack: sum"
echo "of the frames of every function (an upper bound for gt_step_imu)"
