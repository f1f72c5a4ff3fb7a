"""Test logs: ``read_log`` with the CLI's column mapping, units and gap options."""

from __future__ import annotations

import os
from typing import Any, Dict, Optional, Union

import numpy as np

from . import _gyrotherm as _g

PathLike = Union[str, "os.PathLike[str]"]

#: The library's defaults for reading a log (the CLI's ``--time-col`` … ``--delimiter``).
READ_DEFAULTS: Dict[str, Any] = dict(_g.READ_DEFAULTS)


def read_options(options: Dict[str, Any]) -> Dict[str, Any]:
    """The full option dict for the Rust side; unknown keys are an error."""
    options = dict(options)
    unknown = sorted(set(options) - set(READ_DEFAULTS))
    if unknown:
        raise TypeError(
            f"unknown log option(s) {', '.join(unknown)}; "
            f"use {', '.join(READ_DEFAULTS)}"
        )
    out = dict(READ_DEFAULTS)
    out.update(options)
    # A list of gyro or temperature columns is the CLI's comma-separated list.
    for k in ("gyro_col", "temp_col"):
        v = out[k]
        if not isinstance(v, (str, bytes)) and hasattr(v, "__iter__"):
            out[k] = ",".join(str(n) for n in v)
    for k in ("time_col", "gyro_col", "temp_col", "table_col", "gyro_unit", "delimiter"):
        out[k] = str(out[k])
    if out["table_axis"] is not None:
        out["table_axis"] = str(out["table_axis"])
    for k in ("fill_gaps_max_s", "sample_period_s"):
        if out[k] is not None:
            out[k] = float(out[k])
    if out["format"] is not None:
        out["format"] = str(out["format"])
    out["instance"] = int(out["instance"])
    return out


def _pandas():
    try:
        import pandas  # noqa: F401
    except ImportError:
        return None
    return pandas


def read_log(path: PathLike, *, as_frame: Optional[bool] = None, **options: Any):
    """Read and validate a test log (CSV) as ``gyrotherm`` commands do.

    Columns come back in °/s (``gyro_unit`` converts), s and °C under their names in the file
    (``time_col``, ``gyro_col``, ``temp_col`` and, for a rate-table log, ``table_col``: by
    default ``time_s``, ``gyro_dps``, ``temp_c``, ``table_dps``); pass-through columns keep
    their names too (numeric ones as float arrays). Options: ``time_col``, ``gyro_col``, ``temp_col``, ``table_col``,
    ``gyro_unit`` (``"dps"``, ``"dph"``, ``"rad/s"``), ``fill_gaps_max_s`` (max gap in s to
    interpolate), ``sample_period_s`` (s), ``delimiter`` (``","``, ``";"`` or ``"tab"``),
    ``format`` (``"csv"``, ``"ulog"``, ``"dataflash"``; default: by the file's extension) and
    ``instance`` (which of an autopilot's gyros). A PX4 ULog or ArduPilot DataFlash log holds
    a three-axis unit: name its gyro columns (``gyro_col=["gyro_x_dps", "gyro_y_dps",
    "gyro_z_dps"]``) or one of them.

    An inertial unit's log: ``gyro_col`` and ``temp_col`` take several columns, as a list or
    the CLI's comma-separated text (``gyro_col=["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]``);
    each gyro (in °/s) and each temperature then keeps its own name, the table rate is
    ``table_dps``, and the report adds ``gyro_cols``, ``temp_cols`` and ``table_axis`` (the
    gyro the table turns: ``table_axis=`` names it, else the one whose output follows it).

    Returns a pandas DataFrame when pandas is installed (``as_frame=None``, the default) or
    ``as_frame=True``, else a dict of numpy arrays. The DataFrame's ``attrs`` hold the read
    report (rows, filled samples and gaps, sample period).
    Raises ``gyrotherm.LogError`` naming file, line and column.
    """
    opts = read_options(options)
    cols, report = _g.read_log(os.fspath(path), opts)
    pd = _pandas()
    if as_frame is None:
        as_frame = pd is not None
    if not as_frame:
        return cols
    if pd is None:
        raise ImportError("read_log(as_frame=True) needs pandas; pip install pandas")
    df = pd.DataFrame({k: (v if isinstance(v, np.ndarray) else list(v)) for k, v in cols.items()})
    df.attrs.update(report)
    return df


def columns(log, names):
    """Arrays ``names`` from a dict or DataFrame returned by :func:`read_log`."""
    out = []
    for n in names:
        try:
            v = log[n]
        except KeyError:
            raise KeyError(f"the log has no column {n!r}") from None
        out.append(np.ascontiguousarray(v, dtype=np.float64))
    return out


def read_lot(db: PathLike, *, as_frame: Optional[bool] = None):
    """Read a lot database (``gyrotherm lot``): an SQLite file or a ``postgres://`` URL.

    One row per figure measured on one held-out log of one run, the rows of ``lot.csv``:
    ``run_id``, ``unit``, ``tested_at`` (RFC 3339 UTC), ``latest`` (the unit's newest run),
    ``run_verdict``, ``station``, ``model_content_sha256``, ``log``, ``figure``, ``value``,
    ``limit_min``, ``limit_max`` (NaN when not limited), ``verdict`` (``"pass"``, ``"fail"``
    or None), ``margin``, and for an inertial unit's run (``lot add --model UNIT.json``)
    ``axis`` (the axis's gyro column) and ``axis_verdict`` (the axis's verdict; the run's
    ``run_verdict`` is the unit's, a pass only when every axis passes), both None on a
    single-axis run. A DataFrame when pandas is installed (``as_frame=None``) or
    ``as_frame=True``, else a dict of arrays and lists. Raises ``gyrotherm.GyrothermError``
    (a missing, damaged or newer-schema lot, with the message the CLI prints).
    """
    cols = _g.read_lot(os.fspath(db))
    pd = _pandas()
    if as_frame is None:
        as_frame = pd is not None
    if not as_frame:
        return cols
    if pd is None:
        raise ImportError("read_lot(as_frame=True) needs pandas; pip install pandas")
    return pd.DataFrame(cols)
