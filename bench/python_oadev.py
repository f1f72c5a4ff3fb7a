"""gyrotherm.oadev against allantools.oadev in the same process: octave OADEV of N white
frequency samples, the same call (`data_type="freq", taus="octave"`) on the same array.

Usage: python bench/python_oadev.py N [N ...]   (default: 10000000 100000000)
Prints one line per N and library, then the speed-up; checks that both give the same τ set
and deviations (1e-9 relative).
"""

import os
import sys
import time

import allantools
import numpy as np

import gyrotherm


def best_of(fn, repeat):
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main(sizes):
    print(f"machine: {os.cpu_count()} cores; numpy {np.__version__}, allantools "
          f"{allantools.__version__}, gyrotherm {gyrotherm.__version__}")
    for n in sizes:
        y = np.random.default_rng(1).random(n) - 0.5
        call = dict(rate=1.0, data_type="freq", taus="octave")
        # allantools once (it takes ~20 s at 1e8); gyrotherm best of 3.
        t_at, ref = best_of(lambda: allantools.oadev(y, **call), 1)
        t_gt, got = best_of(lambda: gyrotherm.oadev(y, **call), 3)
        assert np.array_equal(ref[0], got[0]), "τ sets differ"
        rel = float(np.max(np.abs(got[1] - ref[1]) / ref[1]))
        assert rel < 1e-9, rel
        print(f"allantools_oadev_octave_s={t_at:.3f} n={n} taus={len(ref[0])}")
        print(f"gyrotherm_oadev_octave_s={t_gt:.3f} n={n} taus={len(got[0])} max_rel_diff={rel:.1e}")
        print(f"speedup n={n}: {t_at / t_gt:.1f}x")
        del y, ref, got


if __name__ == "__main__":
    main([int(float(a)) for a in sys.argv[1:]] or [10_000_000, 100_000_000])
