"""Compare the C driver's output (status, rate, bias, scale per line) with
`gyrotherm compensate --stream` output: parsed doubles must be equal, statuses identical.

Usage: python3 bench/m4/compare.py DRIVER_OUT STREAM_OUT
Prints: lines=<n> differ=<d>; exits 1 if any differ or the line counts disagree.
"""
import csv
import sys

a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
bad = 0
for x, y in zip(a, b):
    for k in ("status", "gyro_comp_dps", "bias_dps", "scale"):
        u, v = x[k], y[k]
        if k != "status" and u and v:
            u, v = float(u), float(v)
        if u != v:
            bad += 1
print(f"lines={len(a)} differ={bad}")
sys.exit(1 if bad or len(a) != len(b) else 0)
