"""Fitting, model files and compensation: the CLI's ``train`` and ``compensate``."""

from __future__ import annotations

import os
import sys
import time
import warnings
from typing import Any, Callable, Dict, Iterable, List, NamedTuple, Optional, Union

import numpy as np

from . import _gyrotherm as _g
from ._logs import columns, read_options

PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[bool, Callable[[str, int, float], Any], None]

#: Per-sample status codes of :meth:`Model.compensate` (the flight compensator's): ok, held
#: (temperature rejected, B and K held), degraded (no good temperature for too long),
#: invalid (gyro sample not finite: no rate), fallback (a unit's axis whose further sensor is
#: given up on, compensating on its fallback model on its first sensor alone).
STATUS_NAMES: Dict[int, str] = dict(_g.STATUS_NAMES)


#: Per-sample coverage codes of :meth:`Model.coverage`: inside the (T, dT) region training
#: covered, at its edge (within one cell), or outside; ``NO_COVERAGE`` (255) where there is
#: no verdict (before the first step, or a model file without a coverage map).
COVERAGE_NAMES: Dict[int, str] = dict(_g.COVERAGE_NAMES)
NO_COVERAGE: int = _g.NO_COVERAGE

class GyrothermWarning(UserWarning):
    """The model extrapolates (temperature or its rate leaves the training range), or a
    loaded model file has no content checksum."""


class Compensation(NamedTuple):
    """Compensated samples, one value per input sample."""

    bias_dps: np.ndarray
    """Predicted bias B, °/s."""
    scale: np.ndarray
    """Predicted scale factor K (output °/s per input °/s)."""
    rate_dps: np.ndarray
    """Compensated rate G = (Ĝ − B)/K, °/s."""
    status: np.ndarray
    """Status code per sample (uint8, see ``STATUS_NAMES``; 0 is ok)."""



class CoverageVerdicts(NamedTuple):
    """What the model knows at each sample: the ``coverage`` and ``sigma_dph`` columns of
    ``gyrotherm compensate``."""

    coverage: np.ndarray
    """Coverage code per sample (uint8, see ``COVERAGE_NAMES``; 255 is no verdict)."""
    sigma_dph: np.ndarray
    """1σ estimate of the residual bias error of the compensated output, °/h (NaN where there
    is no verdict)."""

def _warn(messages: Iterable[str]) -> None:
    for m in messages:
        warnings.warn(m, GyrothermWarning, stacklevel=3)


def _export(
    self,
    target: str,
    out: PathLike,
    *,
    instance: Optional[int] = None,
    axis: Optional[str] = None,
    device_id: Optional[int] = None,
) -> List[str]:
    """Write the model for ``target`` into the folder ``out`` (created if missing), as
    ``gyrotherm export --target`` does: ``"c"`` (``gyrotherm_model.h`` and
    ``gyrotherm_model.c``), ``"rust"`` (``gyrotherm_model.rs``), or an autopilot's gyro
    temperature calibration, ``"ardupilot"`` (``gyro_tcal.parm``) or ``"px4"``
    (``gyro_tc.params``): a cubic in temperature fitted to the model's steady-state bias.
    ``instance`` (the autopilot's IMU, from 0), ``axis`` (``"x"``, ``"y"`` or ``"z"``: the
    axis a single-gyro model fills) and ``device_id`` (PX4's gyro device id, required
    there) are for the autopilot targets only. Returns the lines the CLI prints (files
    written, the polynomial's fit per axis, what it does not carry); its warnings (a
    narrow training range) come as ``GyrothermWarning``. Raises ``gyrotherm.ModelError``."""
    lines, warns = self._raw.export(
        target, os.fspath(out), instance=instance, axis=axis, device_id=device_id
    )
    _warn(warns)
    return lines


class Model:
    """A fitted compensation model: the JSON file ``gyrotherm train`` writes and
    ``gyrotherm compensate`` reads, of a single gyro or of an inertial unit (a single gyro is a
    unit of one axis). Make one with :func:`fit` or :meth:`Model.load`."""

    def __init__(self, raw: "_g.RawModel") -> None:
        if not isinstance(raw, _g.RawModel):
            raise TypeError("make a Model with gyrotherm.fit(...) or Model.load(path)")
        self._raw = raw

    @classmethod
    def load(cls, path: PathLike) -> "Model":
        """Read and check a model file of either form (raises ``gyrotherm.ModelError``; warns,
        ``GyrothermWarning``, when the file has no content checksum)."""
        raw = _g.RawModel.load(os.fspath(path))
        _warn(raw.load_warnings)
        return cls(raw)

    @classmethod
    def from_json(cls, text: str) -> "Model":
        """Parse and check model JSON text of either form."""
        return cls(_g.RawModel.from_json(text))

    def save(self, path: PathLike) -> None:
        """Write the model file (atomically; the same bytes as ``gyrotherm train``)."""
        self._raw.save(os.fspath(path))

    def to_json(self) -> str:
        """The model file's text."""
        return self._raw.to_json()

    @property
    def method(self) -> Optional[str]:
        """The method every axis was fitted with (``gyrotherm.METHOD_NAMES``; ``"lstm"`` for
        files written before the methods were one list); None where a unit's axes differ
        (see :attr:`axes`)."""
        return self._raw.method

    @property
    def bias_kind(self) -> Optional[str]:
        """What every axis's bias model is made of (None: no bias model, or the axes
        differ)."""
        return self._raw.bias_kind

    @property
    def scale_kind(self) -> Optional[str]:
        """What every axis's scale-factor model is made of (None: no scale-factor model, or
        the axes differ)."""
        return self._raw.scale_kind

    @property
    def training(self) -> Optional[Dict[str, Any]]:
        """Training facts of a model of one axis (ranges, digest, epochs, loss, seed,
        inputs); None for a unit of several, whose axes each have theirs in :attr:`axes`."""
        return self._raw.training

    @property
    def gyro_cols(self) -> List[str]:
        """The gyro columns, in the order of the axes (one for a single gyro)."""
        return self._raw.gyro_cols

    @property
    def temp_cols(self) -> List[str]:
        """The temperature columns a log must hold."""
        return self._raw.temp_cols

    @property
    def axes(self) -> List[Dict[str, Any]]:
        """Per axis: ``gyro``, ``temps`` (the sensors its model reads), ``cv_rms`` (the
        cross-validated RMS of each sensor tried, None without cross-validation),
        ``method``, ``bias_kind``, ``scale_kind`` and ``training``."""
        return self._raw.axes

    def _samples(self, time_s, gyro, temp):
        """The arrays the binding takes, and whether one axis was given as a plain array."""
        t = np.ascontiguousarray(time_s, dtype=np.float64)
        one = _one_series(gyro)
        if one:
            if len(self.gyro_cols) != 1:
                raise _g.CompensationError(
                    f"gyro: one array given, the model has {len(self.gyro_cols)} axes "
                    f"({', '.join(self.gyro_cols)}); give a dict keyed by gyro column"
                )
            gyro = [gyro]
            if _one_series(temp):
                temp = [temp]
        g = _ordered(gyro, self.gyro_cols, "gyro")
        c = _ordered(temp, self.temp_cols, "temp")
        for name, a in [("time_s", t), *zip(self.gyro_cols, g), *zip(self.temp_cols, c)]:
            if a.ndim != 1:
                raise _g.CompensationError(f"{name}: need a 1-D array, got shape {a.shape}")
        if one and not len(t) == len(g[0]) == len(c[0]):
            raise _g.CompensationError(
                f"time_s, gyro_dps and temp_c differ in length ({len(t)}, {len(g[0])}, "
                f"{len(c[0])}); give one value per sample in each"
            )
        return t, g, c, one

    def compensate(self, time_s, gyro, temp):
        """Compensate samples with each axis's flight compensator, sample by sample: the
        numbers ``gyrotherm compensate`` writes. Every sample gets a status
        (``STATUS_NAMES``) instead of an exception; warns (``GyrothermWarning``) where the
        temperature or its rate leaves the training range.

        A single gyro: ``time_s`` (s, increasing), ``gyro`` (output, °/s) and ``temp`` (°C)
        as arrays; returns its :class:`Compensation`. Any model: ``gyro`` and ``temp`` map
        each of :attr:`gyro_cols` and :attr:`temp_cols` to its samples (a dict, or sequences
        in those orders); returns per gyro column its :class:`Compensation` (the CLI's
        ``G_bias``, ``G_scale``, ``G_comp`` and ``G_status``)."""
        t, g, c, one = self._samples(time_s, gyro, temp)
        axes, warns = self._raw.compensate(t, g, c)
        _warn(warns)
        out = {name: Compensation(*cols) for name, cols in zip(self.gyro_cols, axes)}
        return next(iter(out.values())) if one else out

    def coverage(self, time_s, gyro, temp):
        """Per sample, whether the temperature and its rate lie inside, at the edge of or
        outside the region the training logs covered, and the 1σ residual bias error there
        (°/h): the ``coverage`` and ``sigma_dph`` columns ``gyrotherm compensate`` writes for
        the same samples. Arrays as :meth:`compensate` takes them; a :class:`CoverageVerdicts`
        for a single gyro's arrays, else one per gyro column (an axis that reads several
        sensors: on its first sensor's temperature and rate). Warns (``GyrothermWarning``)
        where an axis has no verdict: a model file without a coverage map (every code is then
        ``NO_COVERAGE``)."""
        t, g, c, one = self._samples(time_s, gyro, temp)
        axes, notes = self._raw.coverage(t, g, c)
        _warn(notes)
        out = {name: CoverageVerdicts(*cols) for name, cols in zip(self.gyro_cols, axes)}
        return next(iter(out.values())) if one else out

    def compensate_log(self, log) -> Dict[str, Compensation]:
        """:meth:`compensate` of a log as :func:`read_log` returns it (read with the model's
        columns: ``gyro_col=model.gyro_cols, temp_col=model.temp_cols``): per gyro column."""
        (t,) = columns(log, ["time_s"])
        return self.compensate(
            t, columns(log, self.gyro_cols), columns(log, self.temp_cols)
        )

    def compensate_csv(self, input: PathLike, out: PathLike, **options: Any) -> Dict[str, Any]:
        """``gyrotherm compensate --input INPUT --out OUT`` with the same log options (a column
        option not given is the model's, as the CLI reads it): every input column, then per
        axis its compensated columns (a single gyro's ``bias_dps``, ``scale``,
        ``gyro_comp_dps``, ``status``, ``coverage`` and ``sigma_dph``). Returns the rows
        written, the lines per status over every axis (``ok``, ``held``, ``degraded``,
        ``invalid``, ``fallback``), the same per gyro column (``axes``) and the warnings (also
        issued as warnings)."""
        if options.get("fill_gaps_max_s") is not None:
            raise _g.CompensationError(
                "fill_gaps_max_s does not apply to compensate: the compensator bridges time gaps "
                "itself and writes one output line per input line"
            )
        # Columns not named here are the model's own (the ones it was trained on).
        rows, per_axis, warns = self._raw.compensate_csv(
            os.fspath(input), os.fspath(out), read_options(options), sorted(options)
        )
        _warn(warns)
        keys = ("ok", "held", "degraded", "invalid", "fallback")
        axes = {g: dict(zip(keys, n)) for g, n in zip(self.gyro_cols, per_axis)}
        result: Dict[str, Any] = {"rows": rows}
        result.update({k: sum(a[k] for a in axes.values()) for k in keys})
        result["axes"] = axes
        result["warnings"] = warns
        return result

    export = _export

    def summary(self) -> str:
        """What the model is, what it was trained on and (after :func:`fit`) how training
        went; a unit's axes, the sensor each reads and its models."""
        return self._raw.summary()

    def __repr__(self) -> str:
        return repr(self._raw)


#: The name an inertial unit's model had when it was a class of its own; it is :class:`Model`.
UnitModel = Model


def _keyed(values) -> bool:
    return isinstance(values, dict) or hasattr(values, "keys")


def _one_series(values) -> bool:
    """Whether ``values`` are one axis's samples (a 1-D array or a sequence of numbers), not
    one array per column."""
    if isinstance(values, np.ndarray):
        return values.ndim == 1
    if _keyed(values):
        return False
    try:
        first = next(iter(values))
    except StopIteration:
        return True
    except TypeError:
        return False
    return np.ndim(first) == 0


def _ordered(values, names: List[str], what: str):
    if _keyed(values):
        missing = [n for n in names if n not in values]
        if missing:
            raise _g.CompensationError(
                f"{what}: no samples for {', '.join(missing)}, which the model needs"
            )
        values = [values[n] for n in names]
    values = [np.ascontiguousarray(v, dtype=np.float64) for v in values]
    if len(values) != len(names):
        raise _g.CompensationError(
            f"{what}: {len(values)} arrays given, the model needs {len(names)} "
            f"({', '.join(names)})"
        )
    return values


class _PrintProgress:
    """``progress=True``: a single gyro's fit prints one line per target on stderr at most
    every 2 s, and the last; a unit's a line as each axis and sensor starts and finishes,
    with the seconds since the fit began (the lines ``gyrotherm train`` prints)."""

    def __init__(self, epochs: Optional[int]) -> None:
        self.epochs = epochs
        self.last: Dict[str, float] = {}
        self.started = time.monotonic()

    def __call__(self, *step: Any) -> None:
        if len(step) == 4:
            self._axis(*step)
        else:
            self._epoch(*step)

    def _axis(self, event: str, gyro: str, temp: Optional[str], cv_rms: Optional[float]) -> None:
        at = time.monotonic() - self.started
        if event == "axis_start":
            text = f"{gyro}: axis starts"
        elif event == "start":
            text = f"{gyro}: fitting on {temp}"
        elif event == "scoring":
            text = (f"{gyro}: auto: fitting thermal and thermal-lstm without a static run and "
                    "scoring them on it")
        elif event == "lstm":
            text = f"{gyro}: auto: training thermal-lstm on {temp}"
        elif event == "done":
            score = "-" if cv_rms is None else f"{cv_rms:.3e}"
            text = f"{gyro}: {temp} done (cross-validated RMS {score})"
        else:
            text = f"{gyro}: axis done, reads {temp}"
        print(f"gyrotherm: [{at:6.1f} s] {text}", file=sys.stderr, flush=True)

    def _epoch(self, target: str, epoch: int, loss: float) -> None:
        now = time.monotonic()
        final = self.epochs is not None and epoch + 1 >= self.epochs
        if not final and now - self.last.get(target, -1e9) < 2.0:
            return
        self.last[target] = now
        total = f"/{self.epochs}" if self.epochs else ""
        print(
            f"gyrotherm: {target} epoch {epoch + 1}{total}, loss {loss:.4e}",
            file=sys.stderr,
            flush=True,
        )


def _paths(logs, what: str):
    if logs is None:
        return []
    if isinstance(logs, (str, bytes)) or hasattr(logs, "__fspath__"):
        logs = [logs]
    out = []
    for p in logs:
        if not (isinstance(p, str) or hasattr(p, "__fspath__")):
            raise TypeError(f"{what}: give paths of CSV logs, got {type(p).__name__}")
        out.append(os.fspath(p))
    return out


_FIT = _g.FIT_DEFAULTS


def fit(
    static: Union[PathLike, Iterable[PathLike], None] = (),
    table: Union[PathLike, Iterable[PathLike], None] = (),
    method: str = _FIT["method"],
    *,
    epochs: Optional[int] = _FIT["epochs"],
    seed: int = _FIT["seed"],
    hidden: Optional[int] = _FIT["hidden"],
    windows: Optional[int] = _FIT["windows"],
    bias_window_s: float = _FIT["bias_window_s"],
    settle_s: float = _FIT["settle_s"],
    poly_temp_degree: int = _FIT["poly_temp_degree"],
    poly_rate_degree: int = _FIT["poly_rate_degree"],
    cross: bool = _FIT["cross"],
    validate_on_runs: bool = _FIT["validate_on_runs"],
    progress: Progress = False,
    **log_options: Any,
) -> Model:
    """Fit a compensation model, as ``gyrotherm train --input S… --input T… --method …``
    (same defaults, same checks, same file).

    ``static``: static logs (bias model); ``table``: rate-table logs (scale-factor model).
    ``method``: one of ``gyrotherm.METHOD_NAMES``: ``"auto"`` (the default: the
    better of ``"thermal"`` and ``"thermal-lstm"`` on held-out runs), ``"thermal"``,
    ``"thermal-lstm"``, ``"residual"``, ``"generic"``, ``"direct"``, ``"published"`` (He et al. 2024 as
    published), ``"linear"`` or ``"poly"``. ``bias_window_s``/``settle_s`` in
    seconds. ``progress``: True prints
    epochs and loss to stderr; a callable gets ``(target, epoch, loss)``. Log options
    (``time_col``, ``gyro_unit``, ``fill_gaps_max_s``, ``delimiter`` …) apply to every log.
    The GIL is released while reading and training.

    An inertial unit: ``gyro_col`` and ``temp_col`` as lists (or the CLI's comma-separated
    text) fit every axis as ``gyrotherm train --gyro-col … --temp-col …`` does and return its
    :class:`Model` (the same file). Table logs go in ``table`` (one per axis; the axis is
    found, or named by ``table_axis=``). ``progress``: True prints a line as each axis and
    sensor starts and finishes; a callable gets ``(event, gyro, temp, cv_rms)``, event
    ``"axis_start"`` (``temp`` None), ``"start"``, ``"done"`` (with the sensor's
    cross-validated RMS) or ``"axis"`` (the axis is done and reads ``temp``); with ``"auto"``
    also ``"scoring"`` (``temp`` None) as each left-out static run's fold starts and ``"lstm"``
    as a ``thermal-lstm`` training on sensor ``temp`` starts.
    """
    static_paths = _paths(static, "static")
    table_paths = _paths(table, "table")
    if not static_paths and not table_paths:
        raise _g.FitError("no training logs given; pass static=[...] and/or table=[...]")
    settings = _fit_settings(
        method, epochs, seed, hidden, windows, bias_window_s, settle_s, poly_temp_degree,
        poly_rate_degree, cross, validate_on_runs,
    )
    options = read_options(log_options)
    if progress is True:
        callback = _PrintProgress(epochs)
    elif progress is False or progress is None:
        callback = None
    elif callable(progress):
        callback = progress
    else:
        raise TypeError(
            "progress: give True, False or a callable(target, epoch, loss) (a unit: "
            "callable(event, gyro, temp, cv_rms))"
        )
    raw = _g.fit(static_paths, table_paths, settings, options, callback)
    _warn(raw.load_warnings)
    return Model(raw)


#: The library's defaults of ``gyrotherm evaluate`` (``--tau-s``, ``--settle-s``,
#: ``--reference-scale``).
EVALUATE_DEFAULTS: Dict[str, Any] = dict(_g.EVALUATE_DEFAULTS)


def evaluate(
    log: PathLike,
    model: Union[Model, PathLike, None] = None,
    *,
    column: str = EVALUATE_DEFAULTS["column"],
    spec: Optional[PathLike] = None,
    tau_s: Optional[float] = EVALUATE_DEFAULTS["tau_s"],
    settle_s: float = EVALUATE_DEFAULTS["settle_s"],
    reference_scale: Optional[float] = EVALUATE_DEFAULTS["reference_scale"],
    **log_options: Any,
) -> Dict[str, Any]:
    """A log's figures, as ``gyrotherm evaluate --json`` prints them.

    A single-axis log (one ``gyro_col`` and ``temp_col``, no model): the figures of
    ``column`` (the gyro column by default, or a numeric extra column named ``*_dps``,
    ``*_dph`` or ``*_rad_s``), under ``evaluate --json``'s keys, with ``"column"`` the name in
    the file; with ``spec`` also ``"verdict"``.

    An inertial unit's figures per axis, with ``gyro_col``/``temp_col`` lists (the CLI's
    ``--gyro-col``/``--temp-col``), or a ``model`` (``--model UNIT.json``, whose columns are
    read).

    Returns ``{"tau_s": …, "axes": [...]}``, one dict per gyro column in column order:
    ``gyro``, ``temps`` (the sensors its model reads), ``raw`` and ``compensated`` (with a
    model) figures under ``evaluate --json``'s keys. With ``spec`` (a spec sheet, TOML) each
    axis has a ``verdict`` (of the compensated output with a model, else of the raw column,
    per figure: value, unit, limits, pass, margin) and the result a ``"verdict"``: ``pass``
    only when every axis passes, ``failed_axes``, ``judged``. A missed limit is no exception
    (the CLI exits 1): read ``result["verdict"]["pass"]``. The GIL is released.
    """
    raw_model = None
    if model is not None:
        if not isinstance(model, Model):
            model = Model.load(model)
        raw_model = model._raw
    options = read_options(log_options)
    import json

    text, notes = _g.evaluate(
        os.fspath(log),
        options,
        str(column),
        raw_model,
        None if spec is None else os.fspath(spec),
        None if tau_s is None else float(tau_s),
        float(settle_s),
        None if reference_scale is None else float(reference_scale),
    )
    _warn(notes)
    import json

    return json.loads(text)


def _fit_settings(
    method, epochs, seed, hidden, windows, bias_window_s, settle_s, poly_temp_degree,
    poly_rate_degree, cross, validate_on_runs,
) -> Dict[str, Any]:
    """The fit keywords of :func:`fit` and :func:`compare` as the binding's settings."""
    return {
        "method": str(method),
        "epochs": None if epochs is None else int(epochs),
        "seed": int(seed),
        "hidden": None if hidden is None else int(hidden),
        "windows": None if windows is None else int(windows),
        "bias_window_s": float(bias_window_s),
        "settle_s": float(settle_s),
        "poly_temp_degree": int(poly_temp_degree),
        "poly_rate_degree": int(poly_rate_degree),
        "cross": bool(cross),
        "validate_on_runs": bool(validate_on_runs),
    }


def compare(
    train: Union[PathLike, Iterable[PathLike]],
    test: Union[PathLike, Iterable[PathLike]],
    *,
    methods: Optional[Iterable[str]] = None,
    tau_s: Optional[float] = None,
    spec: Optional[PathLike] = None,
    method: str = _FIT["method"],
    epochs: Optional[int] = _FIT["epochs"],
    seed: int = _FIT["seed"],
    hidden: Optional[int] = _FIT["hidden"],
    windows: Optional[int] = _FIT["windows"],
    bias_window_s: float = _FIT["bias_window_s"],
    settle_s: float = _FIT["settle_s"],
    poly_temp_degree: int = _FIT["poly_temp_degree"],
    poly_rate_degree: int = _FIT["poly_rate_degree"],
    cross: bool = _FIT["cross"],
    validate_on_runs: bool = _FIT["validate_on_runs"],
    **log_options: Any,
) -> Dict[str, Any]:
    """Every method fitted on the training logs and judged on the held-out ones, as
    ``gyrotherm compare --json`` prints it, for a single gyro or each axis of a unit.

    ``train``: training logs (static and rate-table, in any order); ``test``: held-out logs.
    ``methods``: names as ``compare --methods`` (default: the library's list); the fit
    keywords as :func:`fit`. A single gyro (one ``gyro_col`` and ``temp_col``): the
    comparison summary (``models``, ``tests`` with each column's figures per held-out log),
    with ``spec`` also ``verdicts`` per column. An inertial unit (``gyro_col``/``temp_col``
    lists, or an autopilot log): ``{"axes": [...], "across_axes": {...}}``: per axis
    ``gyro``, ``temp`` (the sensor the one-sensor methods read: the one whose one-sensor fit
    cross-validates best), ``comparison`` (the single-axis summary) and, with several
    sensors, ``unit_fit``: the unit's own fit of the axis as :func:`fit` builds it, on every
    sensor it keeps (``label``, ``temps``, ``performance`` per held-out log). With ``spec`` (a
    spec sheet, TOML) also ``verdicts``: per axis ``gyro``, ``columns`` (each one-sensor
    method's verdict) and ``unit_fit`` (label, verdict), as ``compare --spec --json``; a
    missed limit is ``verdict["pass"] == False``, not an exception. The GIL is released.
    """
    options = read_options(log_options)
    train_paths, test_paths = _paths(train, "train"), _paths(test, "test")
    if not train_paths or not test_paths:
        raise _g.FitError("give training logs (train=[...]) and held-out logs (test=[...])")
    settings = _fit_settings(
        method, epochs, seed, hidden, windows, bias_window_s, settle_s, poly_temp_degree,
        poly_rate_degree, cross, validate_on_runs,
    )
    text, notes = _g.compare(
        train_paths,
        test_paths,
        settings,
        options,
        None if methods is None else [str(m) for m in methods],
        None if tau_s is None else float(tau_s),
        None if spec is None else os.fspath(spec),
    )
    _warn(notes)
    import json

    return json.loads(text)
