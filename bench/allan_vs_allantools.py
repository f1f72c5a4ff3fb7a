"""Time allantools' octave OADEV on N white-noise rate samples (same job as the Rust bench).

Usage: python3 bench/allan_vs_allantools.py N
Prints: allantools_oadev_octave_s=<seconds> n=<N> taus=<count>
"""
import sys
import time

import allantools
import numpy as np

n = int(sys.argv[1])
y = np.random.default_rng(1).random(n) - 0.5
t = time.perf_counter()
taus, devs, errs, ns = allantools.oadev(y, rate=1.0, data_type="freq", taus="octave")
s = time.perf_counter() - t
print(f"allantools_oadev_octave_s={s:.3f} n={n} taus={len(taus)} allantools={allantools.__version__}")
