#!/usr/bin/env python3
"""Which simulator bias term carries the unit model's error (docs/experiments/imu-worst-case.md).

Reads the per-axis files `imu_family --dump DIR` writes (100 s means of the bias error
e = estimate - truth and of each simulator term, deg/h) and prints, per case: the std of e,
each term's share of e's variance alone (R^2 of e on 1 + term), the joint fit on all terms
(R^2, and per term the coefficient and its unique share: R^2 lost when it is left out).
Plain Python (no numpy): ordinary least squares by normal equations on a few columns.

usage: imu_worst_case.py DIR [FILE-STEM ...]   (stems like 1024-x-airborne; default: all)
"""
import math
import os
import sys

TERMS = ["poly", "shupe", "shupe_tc", "stress", "grad", "sat"]


def read(path):
    with open(path) as f:
        head = f.readline().split()
        cols = {h: [] for h in head}
        for line in f:
            for h, v in zip(head, line.split()):
                cols[h].append(float(v))
    return cols


def ols_r2(y, xs):
    """R^2 and coefficients of y on 1 + xs (normal equations, Gauss-Jordan with pivoting)."""
    n = len(y)
    cols = [[1.0] * n] + xs
    k = len(cols)
    a = [[sum(ci[t] * cj[t] for t in range(n)) for cj in cols] for ci in cols]
    b = [sum(ci[t] * y[t] for t in range(n)) for ci in cols]
    # A tiny ridge keeps an all-zero term (a unit without it) from making A singular.
    for i in range(k):
        a[i][i] += 1e-12 * (a[i][i] + 1e-30)
    m = [row[:] + [bi] for row, bi in zip(a, b)]
    for c in range(k):
        p = max(range(c, k), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        if abs(m[c][c]) < 1e-300:
            continue
        for r in range(k):
            if r != c:
                f = m[r][c] / m[c][c]
                m[r] = [x - f * z for x, z in zip(m[r], m[c])]
    beta = [m[i][k] / m[i][i] if abs(m[i][i]) > 1e-300 else 0.0 for i in range(k)]
    fit = [sum(beta[j] * cols[j][t] for j in range(k)) for t in range(n)]
    my = sum(y) / n
    sst = sum((v - my) ** 2 for v in y)
    sse = sum((v - f) ** 2 for v, f in zip(y, fit))
    return (1 - sse / sst if sst > 0 else 0.0), beta[1:]


def std(v):
    m = sum(v) / len(v)
    return math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))


def main():
    d = sys.argv[1]
    stems = sys.argv[2:] or sorted(f[:-4] for f in os.listdir(d) if f.endswith(".tsv"))
    print("| case | std e °/h | recon std | " + " | ".join(f"R² {t}" for t in TERMS)
          + " | joint R² | " + " | ".join(f"β {t} (unique)" for t in TERMS) + " |")
    print("|---" * (4 + 2 * len(TERMS)) + "|")
    for s in stems:
        c = read(os.path.join(d, s + ".tsv"))
        e = c["e_dph"]
        single = [ols_r2(e, [c[t]])[0] if std(c[t]) > 0 else 0.0 for t in TERMS]
        live = [t for t in TERMS if std(c[t]) > 0]
        r2, beta = ols_r2(e, [c[t] for t in live])
        uniq = {}
        for t in live:
            rest = [c[u] for u in live if u != t]
            uniq[t] = r2 - ols_r2(e, rest)[0]
        b = dict(zip(live, beta))
        cells = [f"{b[t]:+.2f} ({uniq[t]:.2f})" if t in b else "–" for t in TERMS]
        print(f"| {s} | {std(e):.4f} | {std(c['recon']):.1e} | "
              + " | ".join(f"{x:.2f}" for x in single)
              + f" | {r2:.2f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
