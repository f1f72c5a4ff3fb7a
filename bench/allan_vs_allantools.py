"""Time allantools' octave OADEV on N white-noise rate samples (same job as the Rust bench).

Usage: python3 bench/allan_vs_allantools.py N
Prints: allantools_oadev_octave_s=<seconds> n=<N> taus=<count> cpu_s=<CPU seconds> and the
process's peak RSS (the samples plus what allantools adds).
"""
import resource
import sys
import time

import allantools
import numpy as np

n = int(sys.argv[1])
y = np.random.default_rng(1).random(n) - 0.5
t, c = time.perf_counter(), time.process_time()
taus, devs, errs, ns = allantools.oadev(y, rate=1.0, data_type="freq", taus="octave")
s, cpu = time.perf_counter() - t, time.process_time() - c
print(f"allantools_oadev_octave_s={s:.3f} n={n} taus={len(taus)} cpu_s={cpu:.2f} allantools={allantools.__version__}")
print(f"allantools_peak_rss_mb={resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}")
