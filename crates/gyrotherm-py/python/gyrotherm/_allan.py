"""Allan family with allantools' signatures, τ sets and return tuples.

``adev``, ``oadev``, ``mdev``, ``hdev``, ``ohdev`` and ``tdev`` take
``(data, rate=1.0, data_type="phase", taus=None)`` and return
``(taus, devs, errs, ns)`` exactly as allantools 2024.6 does, so ``import gyrotherm as at``
works in an existing script. The τ list is made here, the way allantools makes it; the sums
run in the Rust library with the GIL released.

Why the τ set differs from ``gyrotherm allan --taus octave``: the CLI stops at Stable32's
largest averaging factor, N/4 for the overlapping estimators and N/5 for the non-overlapping ones,
which its reference tests against Stable32 need. allantools has no such stop: its octave list
is 2^k for every k up to log2(len(phase)), and it keeps every τ that leaves at least two
terms. On 1e8 rate samples OADEV therefore gets m = 2^25 = 33,554,432 (n = 32,891,137
terms), which the CLI's limit of 25,000,000 leaves out: 26 τ against 25.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Optional, Tuple, Union

import numpy as np

from . import _gyrotherm as _g
from ._gyrotherm import AllanError

ONE_SIGMA_CI: float = _g.ONE_SIGMA_CI

_KINDS = ("adev", "oadev", "mdev", "hdev", "ohdev")


def _array(data, what: str = "data") -> np.ndarray:
    try:
        a = np.ascontiguousarray(data, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise AllanError(f"{what}: not an array of numbers ({e})") from None
    if a.ndim != 1:
        raise AllanError(f"{what}: need a 1-D array, got shape {a.shape}")
    return a


def _rate(rate) -> float:
    try:
        r = float(rate)
    except (TypeError, ValueError):
        raise AllanError(f"rate = {rate!r} is not a number (the sample rate in Hz)") from None
    if not (math.isfinite(r) and r > 0.0):
        raise AllanError(f"rate = {r} Hz is not a positive finite sample rate")
    return r


def _taus_seconds(taus, n_phase: int, rate: float) -> np.ndarray:
    """allantools' ``tau_generator`` τ list (seconds) before validation."""
    if taus is None or (isinstance(taus, list) and len(taus) == 0):
        taus = "octave"
    if isinstance(taus, str):
        if taus == "all":
            return (1.0 / rate) * np.linspace(1.0, n_phase, n_phase)
        if taus == "octave":
            maxn = np.floor(np.log2(n_phase))
            return (1.0 / rate) * np.logspace(0, int(maxn), int(maxn + 1), base=2.0)
        if taus == "log10":
            maxn = np.log10(n_phase)
            return (1.0 / rate) * np.logspace(0, maxn, int(10 * maxn), base=10.0)
        if taus == "decade":
            maxn = np.floor(np.log10(n_phase))
            out = []
            for k in range(int(maxn + 1)):
                out.append(1.0 * (1.0 / rate) * pow(10.0, k))
                out.append(2.0 * (1.0 / rate) * pow(10.0, k))
                out.append(4.0 * (1.0 / rate) * pow(10.0, k))
            return np.array(out)
        raise AllanError(
            f"taus = {taus!r} is not a τ set; use 'octave', 'decade', 'all', 'log10' "
            "or an array of τ in seconds"
        )
    try:
        t = np.atleast_1d(np.asarray(taus, dtype=np.float64))
    except (TypeError, ValueError) as e:
        raise AllanError(f"taus: not an array of τ in seconds ({e})") from None
    if t.ndim != 1:
        raise AllanError(f"taus: need a 1-D array of τ in seconds, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise AllanError("taus: every τ must be a finite number of seconds")
    return t


def _terms(kind: str, n_samples: int, m: np.ndarray) -> np.ndarray:
    """Number of terms of each estimator for N rate samples (N + 1 phase points)."""
    n = n_samples
    if kind == "adev":
        return np.floor(n / m) - 1
    if kind == "oadev":
        return n + 1 - 2 * m
    if kind == "mdev":
        return n + 2 - 3 * m
    if kind == "hdev":
        return np.floor(n / m) - 2
    return n + 1 - 3 * m  # ohdev


def averaging_factors(kind: str, n_phase: int, rate: float, taus=None) -> np.ndarray:
    """The averaging factors m (float array, ascending) that allantools evaluates for
    ``kind`` on ``n_phase`` phase points: its τ list rounded to multiples of 1/rate, then
    every m that leaves at least two terms."""
    if kind not in _KINDS:
        raise AllanError(f"unknown deviation kind `{kind}`; use adev, oadev, mdev, hdev or ohdev")
    if n_phase < 1:
        raise AllanError("data is empty")
    m = np.round(_taus_seconds(taus, n_phase, rate) * rate)
    m = np.unique(m[(m < n_phase) & (m > 0)])
    m = m[_terms(kind, n_phase - 1, m) > 1]
    if len(m) == 0:
        need = 3 if kind in ("hdev", "ohdev") else 2
        raise AllanError(
            f"{n_phase - 1} samples is too short for this deviation at these τ "
            f"(need at least {need + 1} phase points per τ, as allantools)"
        )
    return m


def _phase_points(data: np.ndarray, data_type: str) -> int:
    if data_type == "phase":
        return len(data)
    if data_type == "freq":
        return len(data) + 1
    raise AllanError(f"data_type = {data_type!r}; use 'phase' or 'freq'")


def _dev(kind: str, data, rate, data_type, taus):
    x = _array(data)
    r = _rate(rate)
    n_phase = _phase_points(x, data_type)
    m = averaging_factors(kind, n_phase, r, taus)
    ms = [int(v) for v in m]
    if data_type == "freq":
        devs, ns = _g.dev_freq(x, kind, ms)
    else:
        devs, ns = _g.dev_phase(x, kind, ms)
        devs = devs * r
    taus_used = m / float(r)
    return taus_used, devs, devs / np.sqrt(ns), ns


Result = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
TauArg = Union[None, str, float, "np.typing.ArrayLike"]


def adev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Non-overlapping Allan deviation (allantools.adev): (taus, devs, errs, ns)."""
    return _dev("adev", data, rate, data_type, taus)


def oadev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Overlapping Allan deviation (allantools.oadev): (taus, devs, errs, ns)."""
    return _dev("oadev", data, rate, data_type, taus)


def mdev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Modified Allan deviation (allantools.mdev): (taus, devs, errs, ns)."""
    return _dev("mdev", data, rate, data_type, taus)


def hdev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Non-overlapping Hadamard deviation (allantools.hdev): (taus, devs, errs, ns)."""
    return _dev("hdev", data, rate, data_type, taus)


def ohdev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Overlapping Hadamard deviation (allantools.ohdev): (taus, devs, errs, ns)."""
    return _dev("ohdev", data, rate, data_type, taus)


def tdev(data, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> Result:
    """Time deviation τ·MDEV/√3 (allantools.tdev): (taus, devs, errs, ns)."""
    t, md, _, ns = _dev("mdev", data, rate, data_type, taus)
    td = t * md / np.sqrt(3.0)
    return t, td, td / np.sqrt(ns), ns


class Deviation(NamedTuple):
    """A deviation curve with Greenhall EDF and 68.3 % (by default) confidence bounds."""

    taus: np.ndarray
    devs: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    edf: np.ndarray
    alpha: np.ndarray
    ns: np.ndarray


def deviation(
    data,
    rate: float = 1.0,
    data_type: str = "phase",
    kind: str = "oadev",
    taus: TauArg = None,
    alpha: Optional[int] = None,
) -> Deviation:
    """A deviation with confidence bounds, at the τ set of the allantools-style function of
    the same ``kind``: Greenhall & Riley (2003) EDF and χ² bounds at 68.3 %, as
    ``gyrotherm allan`` prints them. The noise exponent α is identified at every τ (lag-1
    autocorrelation, B1 ratio for short τ counts) unless ``alpha`` is given.
    Phase data is differenced to frequency first."""
    x = _array(data)
    r = _rate(rate)
    n_phase = _phase_points(x, data_type)
    m = averaging_factors(kind, n_phase, r, taus)
    y = x if data_type == "freq" else np.ascontiguousarray(np.diff(x) * r)
    if alpha is not None and not isinstance(alpha, (int, np.integer)):
        raise AllanError(f"alpha = {alpha!r}: give an integer noise exponent (-4..2) or None")
    d = _g.deviation_bounds(y, kind, [int(v) for v in m], None if alpha is None else int(alpha))
    return Deviation(
        taus=m / float(r),
        devs=d["dev"],
        lo=d["lo"],
        hi=d["hi"],
        edf=d["edf"],
        alpha=d["alpha"].astype(np.int64),
        ns=d["n"],
    )


def edf_greenhall(
    alpha: int,
    d: int,
    m: int,
    N: int,
    overlapping: bool = False,
    modified: bool = False,
    verbose: bool = False,
) -> float:
    """Greenhall & Riley (2003) equivalent degrees of freedom (allantools.edf_greenhall):
    noise exponent ``alpha``, difference order ``d`` (2 Allan, 3 Hadamard), averaging factor
    ``m``, ``N`` phase points. NaN where the algorithm is undefined."""
    del verbose
    return _g.edf_greenhall(int(alpha), int(d), int(m), int(N), bool(overlapping), bool(modified))


def confidence_interval(dev, edf, ci: float = ONE_SIGMA_CI):
    """χ² confidence interval (lo, hi) of a deviation with ``edf`` degrees of freedom
    (allantools.confidence_interval)."""
    ci_l = min(abs(ci), abs(ci - 1)) / 2
    ci_h = 1 - ci_l
    chi2_l = _g.chi2_inv(ci_l, float(edf))
    chi2_h = _g.chi2_inv(ci_h, float(edf))
    variance = dev * dev
    return (np.sqrt(float(edf) * variance / chi2_h), np.sqrt(float(edf) * variance / chi2_l))
