"""gyrotherm: temperature compensation of fiber optic gyroscopes, from Python.

- Allan family, a drop-in for allantools: ``adev``, ``oadev``, ``mdev``, ``hdev``, ``ohdev``,
  ``tdev`` take ``(data, rate=1.0, data_type="phase", taus=None)`` and return
  ``(taus, devs, errs, ns)`` on allantools' τ set; ``deviation`` adds Greenhall EDF
  confidence bounds; ``edf_greenhall`` and ``confidence_interval`` as in allantools.
- Gyro figures: ``bias_stability``, ``noise_terms``, ``scale_factor``.
- Logs and models: ``read_log``, ``read_lot`` (a lot database of ``gyrotherm lot``), ``fit`` → ``Model`` (``save``, ``Model.load``,
  ``compensate``, ``summary``, ``export``: C, Rust, ArduPilot or PX4 parameters, as
  ``gyrotherm export --target``); model files are the CLI's JSON.
- Inertial units: ``gyro_col``/``temp_col`` lists in ``read_log`` and ``fit`` (→ the same
  ``Model``: one file for the unit, ``compensate`` per axis; a single gyro is a unit of one
  axis), as the CLI's comma-separated lists;
  ``evaluate`` (figures and spec verdicts per axis) and ``compare`` (methods per axis, with
  the unit's own multi-sensor fit) as ``gyrotherm evaluate``/``compare --json`` print them.

Errors derive from ``GyrothermError`` (a ``ValueError`` and, as allantools raises for the
same faults, a ``RuntimeError``) and carry the CLI's messages.
"""

from ._gyrotherm import (
    AllanError,
    CompensationError,
    FitError,
    GyrothermError,
    LogError,
    MetricsError,
    ModelError,
    __version__,
    FIT_DEFAULTS,
    READ_DEFAULTS,
    METHOD_NAMES,
    GYRO_UNIT_NAMES,
    DELIMITER_NAMES,
    SETTINGS_JSON as _SETTINGS_JSON,
)
from ._allan import (
    ONE_SIGMA_CI,
    Deviation,
    adev,
    confidence_interval,
    deviation,
    edf_greenhall,
    hdev,
    mdev,
    oadev,
    ohdev,
    tdev,
)
from ._figures import bias_stability, noise_terms, scale_factor
from ._logs import read_log, read_lot
from ._model import (
    COVERAGE_NAMES,
    NO_COVERAGE,
    STATUS_NAMES,
    EVALUATE_DEFAULTS,
    Compensation,
    CoverageVerdicts,
    GyrothermWarning,
    Model,
    UnitModel,
    compare,
    evaluate,
    fit,
)



def settings():
    """Every setting of ``train``, ``compensate``, ``allan`` and ``evaluate`` with its default
    and accepted values, as the library describes them (``gyrotherm settings --json``)."""
    import json

    return json.loads(_SETTINGS_JSON)


__all__ = [
    "DELIMITER_NAMES",
    "EVALUATE_DEFAULTS",
    "FIT_DEFAULTS",
    "GYRO_UNIT_NAMES",
    "METHOD_NAMES",
    "READ_DEFAULTS",
    "settings",
    "AllanError",
    "Compensation",
    "COVERAGE_NAMES",
    "CoverageVerdicts",
    "CompensationError",
    "Deviation",
    "FitError",
    "GyrothermError",
    "GyrothermWarning",
    "LogError",
    "MetricsError",
    "Model",
    "UnitModel",
    "ModelError",
    "ONE_SIGMA_CI",
    "NO_COVERAGE",
    "STATUS_NAMES",
    "__version__",
    "adev",
    "bias_stability",
    "compare",
    "confidence_interval",
    "deviation",
    "edf_greenhall",
    "evaluate",
    "fit",
    "hdev",
    "mdev",
    "noise_terms",
    "oadev",
    "ohdev",
    "read_log",
    "read_lot",
    "scale_factor",
    "tdev",
]
