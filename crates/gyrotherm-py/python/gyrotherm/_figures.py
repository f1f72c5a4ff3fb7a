"""Gyro figures: bias stability, Allan noise terms, scale-factor figures."""

from __future__ import annotations

import json
from typing import Any, Dict, Optional

import numpy as np

from . import _gyrotherm as _g
from ._logs import columns, read_log
from ._logs import read_options as _read_options


def _rates(rate_dps) -> np.ndarray:
    a = np.ascontiguousarray(rate_dps, dtype=np.float64)
    if a.ndim != 1:
        raise _g.MetricsError(f"rate_dps: need a 1-D array, got shape {a.shape}")
    return a


def bias_stability(rate_dps, rate_hz: float, tau_s: float = 100.0) -> float:
    """Bias stability, °/h (GJB 2426A / IEEE Std 952): sample standard deviation (n − 1)
    of consecutive non-overlapping ``tau_s`` means of the rate (°/s) sampled at ``rate_hz``.
    ``tau_s`` must be a whole number of samples; at least two means must fit."""
    value, _means, _per_mean = _g.bias_stability(_rates(rate_dps), float(rate_hz), float(tau_s))
    return value


def noise_terms(rate_dps, rate_hz: float) -> Dict[str, Any]:
    """Noise terms read off the octave OADEV curve of a rate (°/s) sampled at ``rate_hz``,
    as the ``noise`` object of ``gyrotherm allan --json``: ``arw_deg_rt_h`` (angle random
    walk, °/√h), ``bias_instability_dph`` (°/h), ``rrw_deg_h_rt_h`` (rate random walk,
    °/h/√h), ``quantization_arcsec``, ``rate_ramp_deg_h2`` (°/h²). Each is a dict with
    ``value``, ``tau_read_s`` (τ it was read at) and ``fit_tau_min_s``/``fit_tau_max_s``
    (the τ range of its slope), or None where the curve has no such region."""
    return json.loads(_g.noise_terms(_rates(rate_dps), float(rate_hz)))


def scale_factor(
    log=None,
    *,
    time_s=None,
    gyro_dps=None,
    table_dps=None,
    settle_s: float = 10.0,
    reference_scale: Optional[float] = None,
    **read_options: Any,
) -> Dict[str, Any]:
    """Scale-factor figures of a rate-table log, as ``gyrotherm evaluate --json`` gives them:
    ``scale_factor`` K and ``intercept_dps`` (least squares over the table rates),
    ``nonlinearity_ppm``, ``asymmetry_ppm``, ``scale_positive``/``scale_negative``,
    ``sf_thermal_error_ppm`` (max |K(t) − K_ref|/K_ref), ``rate_points`` and
    ``scale_over_time``.

    ``log``: a path (read with ``read_options``), or the dict/DataFrame of :func:`read_log`;
    or give ``time_s``, ``gyro_dps`` and ``table_dps`` arrays. The first ``settle_s`` seconds
    of each table rate are dropped.
    """
    if log is not None:
        # read_log keys the columns by their names in the file.
        names = ["time_s", "gyro_dps", "table_dps"]
        if isinstance(log, (str, bytes)) or hasattr(log, "__fspath__"):
            opts = _read_options(read_options)
            names = [opts["time_col"], opts["gyro_col"], opts["table_col"]]
            log = read_log(log, as_frame=False, **read_options)
        elif read_options:
            raise TypeError("log options apply only when log is a path")
        time_s, gyro_dps, table_dps = columns(log, names)
    if time_s is None or gyro_dps is None or table_dps is None:
        raise TypeError("give a log, or time_s, gyro_dps and table_dps arrays")
    t, g, w = (np.ascontiguousarray(a, dtype=np.float64) for a in (time_s, gyro_dps, table_dps))
    return _g.scale_factor(t, g, w, float(settle_s), reference_scale)
