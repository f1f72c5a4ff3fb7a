"""Type stubs of the public gyrotherm API."""

import os
from typing import Any, Callable, Dict, Iterable, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
__all__: List[str]

PathLike = Union[str, os.PathLike[str]]
ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
TauArg = Union[None, str, float, npt.ArrayLike]
AllanResult = Tuple[FloatArray, FloatArray, FloatArray, FloatArray]

ONE_SIGMA_CI: float
STATUS_NAMES: Dict[int, str]
COVERAGE_NAMES: Dict[int, str]
NO_COVERAGE: int

class GyrothermError(ValueError, RuntimeError): ...
class LogError(GyrothermError): ...
class ModelError(GyrothermError): ...
class AllanError(GyrothermError): ...
class MetricsError(GyrothermError): ...
class FitError(GyrothermError): ...
class CompensationError(GyrothermError): ...
class GyrothermWarning(UserWarning): ...

# Allan family (allantools signatures and return tuples: taus, devs, errs, ns)
def adev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...
def oadev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...
def mdev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...
def hdev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...
def ohdev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...
def tdev(data: ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: TauArg = None) -> AllanResult: ...

class Deviation(NamedTuple):
    taus: FloatArray
    devs: FloatArray
    lo: FloatArray
    hi: FloatArray
    edf: FloatArray
    alpha: npt.NDArray[np.int64]
    ns: FloatArray

def deviation(
    data: ArrayLike,
    rate: float = 1.0,
    data_type: str = "phase",
    kind: str = "oadev",
    taus: TauArg = None,
    alpha: Optional[int] = None,
) -> Deviation: ...
def edf_greenhall(
    alpha: int,
    d: int,
    m: int,
    N: int,
    overlapping: bool = False,
    modified: bool = False,
    verbose: bool = False,
) -> float: ...
def confidence_interval(dev: Any, edf: float, ci: float = ...) -> Tuple[Any, Any]: ...

# Gyro figures
def bias_stability(rate_dps: ArrayLike, rate_hz: float, tau_s: float = 100.0) -> float: ...
def noise_terms(rate_dps: ArrayLike, rate_hz: float) -> Dict[str, Any]: ...
def scale_factor(
    log: Any = None,
    *,
    time_s: Optional[ArrayLike] = None,
    gyro_dps: Optional[ArrayLike] = None,
    table_dps: Optional[ArrayLike] = None,
    settle_s: float = 10.0,
    reference_scale: Optional[float] = None,
    **read_options: Any,
) -> Dict[str, Any]: ...

# Logs
FIT_DEFAULTS: Dict[str, Any]
EVALUATE_DEFAULTS: Dict[str, Any]
READ_DEFAULTS: Dict[str, Any]
METHOD_NAMES: List[str]
GYRO_UNIT_NAMES: List[str]
DELIMITER_NAMES: List[str]
def settings() -> Dict[str, List[Dict[str, Any]]]: ...

def read_log(
    path: PathLike,
    *,
    as_frame: Optional[bool] = None,
    # Defaults: the library's (gyrotherm.READ_DEFAULTS), not restated here.
    table_axis: Optional[str] = ...,
    time_col: str = ...,
    gyro_col: Union[str, Sequence[str]] = ...,
    temp_col: Union[str, Sequence[str]] = ...,
    table_col: str = ...,
    gyro_unit: str = ...,
    fill_gaps_max_s: Optional[float] = ...,
    sample_period_s: Optional[float] = ...,
    delimiter: str = ...,
    format: Optional[str] = ...,
    instance: int = ...,
) -> Any: ...

def read_lot(db: PathLike, *, as_frame: Optional[bool] = None) -> Any: ...

# Models
class Compensation(NamedTuple):
    bias_dps: FloatArray
    scale: FloatArray
    rate_dps: FloatArray
    status: npt.NDArray[np.uint8]

class CoverageVerdicts(NamedTuple):
    coverage: npt.NDArray[np.uint8]
    sigma_dph: FloatArray

class Model:
    def __init__(self, raw: Any) -> None: ...
    @classmethod
    def load(cls, path: PathLike) -> Model: ...
    @classmethod
    def from_json(cls, text: str) -> Model: ...
    def save(self, path: PathLike) -> None: ...
    def to_json(self) -> str: ...
    @property
    def method(self) -> Optional[str]: ...
    @property
    def bias_kind(self) -> Optional[str]: ...
    @property
    def scale_kind(self) -> Optional[str]: ...
    @property
    def training(self) -> Optional[Dict[str, Any]]: ...
    @property
    def gyro_cols(self) -> List[str]: ...
    @property
    def temp_cols(self) -> List[str]: ...
    @property
    def axes(self) -> List[Dict[str, Any]]: ...
    def compensate(self, time_s: ArrayLike, gyro: Any, temp: Any) -> Any: ...
    def coverage(self, time_s: ArrayLike, gyro: Any, temp: Any) -> Any: ...
    def compensate_log(self, log: Any) -> Dict[str, Compensation]: ...
    def compensate_csv(self, input: PathLike, out: PathLike, **options: Any) -> Dict[str, Any]: ...
    def export(self, target: str, out: PathLike, *, instance: Optional[int] = ..., axis: Optional[str] = ..., device_id: Optional[int] = ...) -> List[str]: ...
    def summary(self) -> str: ...

UnitModel = Model

def fit(
    static: Union[PathLike, Iterable[PathLike], None] = (),
    table: Union[PathLike, Iterable[PathLike], None] = (),
    # Defaults: the library's (gyrotherm.FIT_DEFAULTS), not restated here.
    method: str = ...,
    *,
    epochs: Optional[int] = ...,
    seed: int = ...,
    hidden: Optional[int] = ...,
    windows: Optional[int] = ...,
    bias_window_s: float = ...,
    settle_s: float = ...,
    poly_temp_degree: int = ...,
    poly_rate_degree: int = ...,
    cross: bool = ...,
    validate_on_runs: bool = ...,
    progress: Union[bool, Callable[..., Any], None] = False,
    **log_options: Any,
) -> Model: ...

def evaluate(
    log: PathLike,
    model: Union[Model, PathLike, None] = None,
    *,
    # Defaults: the library's (gyrotherm.EVALUATE_DEFAULTS), not restated here.
    column: str = ...,
    spec: Optional[PathLike] = None,
    tau_s: Optional[float] = ...,
    settle_s: float = ...,
    reference_scale: Optional[float] = ...,
    **log_options: Any,
) -> Dict[str, Any]: ...
def compare(
    train: Union[PathLike, Iterable[PathLike]],
    test: Union[PathLike, Iterable[PathLike]],
    *,
    methods: Optional[Iterable[str]] = None,
    tau_s: Optional[float] = None,
    spec: Optional[PathLike] = None,
    method: str = ...,
    epochs: Optional[int] = ...,
    seed: int = ...,
    hidden: Optional[int] = ...,
    windows: Optional[int] = ...,
    bias_window_s: float = ...,
    settle_s: float = ...,
    poly_temp_degree: int = ...,
    poly_rate_degree: int = ...,
    cross: bool = ...,
    validate_on_runs: bool = ...,
    **log_options: Any,
) -> Dict[str, Any]: ...
