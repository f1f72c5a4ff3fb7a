#!/usr/bin/env python3
"""Share of held-out 100 s windows within +-1 sigma, per growth of sigma per cell.

Reads the window files `imu_family --sigma FILE` writes (one line per 100 s window of each
held-out static run and axis). Sigma is linear in the map's growth per cell, so each window's
sigma at growth g is sigma_g0 + g * (sigma_g1 - sigma_g0). Prints, for the axes that kept
their LSTM, those whose gate left it out, and all axes, the share inside coverage, at its
edge, outside it, and outside it on the airborne flights. Record:
docs/experiments/coverage.md.

    python3 bench/growth_share.py WINDOWS.tsv [MORE.tsv ...] [--growths 0.5,1,1.5]
"""
import csv
import sys

GROWTHS = (0.5, 0.75, 1.0, 1.5, 2.0)


def main(argv):
    growths = GROWTHS
    files = []
    it = iter(argv)
    for a in it:
        if a == "--growths":
            growths = tuple(float(g) for g in next(it).split(","))
        else:
            files.append(a)
    if not files:
        sys.exit(__doc__)
    rows = []
    for f in files:
        with open(f) as fh:
            rows += list(csv.DictReader(fh, delimiter="\t"))
    if not rows:
        sys.exit("no windows in " + ", ".join(files))
    if "sigma_g0_dph" not in rows[0]:
        sys.exit("the files lack sigma_g0_dph: written by an imu_family older than this script")

    def sigma(r, g):
        s0 = float(r["sigma_g0_dph"])
        return s0 + g * (float(r["sigma_g1_dph"]) - s0)

    # The sigma compensate wrote follows the map's own growth: recover it from the windows
    # outside coverage and say how far the linear form is from the written sigma there.
    est = sorted(
        (float(r["sigma_dph"]) - float(r["sigma_g0_dph"]))
        / (float(r["sigma_g1_dph"]) - float(r["sigma_g0_dph"]))
        for r in rows
        if float(r["sigma_g1_dph"]) - float(r["sigma_g0_dph"]) > 1e-3
    )
    if est:
        g_file = round(est[len(est) // 2], 3)
        err = max(abs(float(r["sigma_dph"]) - sigma(r, g_file)) for r in rows)
        print(f"{len(rows)} windows; the files' growth {g_file}: "
              f"max |sigma - linear form| = {err:.2e} deg/h")

    def share(rs, g):
        n = len(rs)
        k = sum(1 for r in rs if abs(float(r["resid_dph"])) <= sigma(r, g))
        return f"{100 * k / n:.1f} % ({n})" if n else "-"

    print("| axes | growth / cell | inside | edge | outside | airborne outside |")
    print("|---|---|---|---|---|---|")
    sets = (
        ("LSTM kept", lambda r: r["lstm"] == "1"),
        ("LSTM left out", lambda r: r["lstm"] == "0"),
        ("all", lambda r: True),
    )
    for name, keep in sets:
        rs = [r for r in rows if keep(r)]
        for g in growths:
            cells = [share([r for r in rs if r["coverage"] == c], g) for c in "012"]
            air = share([r for r in rs if r["coverage"] == "2" and r["profile"] == "airborne"], g)
            print(f"| {name} | {g} | " + " | ".join(cells) + f" | {air} |")


if __name__ == "__main__":
    main(sys.argv[1:])
