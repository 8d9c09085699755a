# Type stubs of the package hoist (python/hoist/__init__.py, python/src/*.cpp).
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str
ESTIMATE_COLUMNS: list[str]
#: The default largest integration step [s] (hoist-sim --max-step; the model's kDefaultMaxStep).
DEFAULT_MAX_STEP: float
TRIPS_COLUMNS: list[str]

_Array = npt.NDArray[np.float64]
_ArrayLike = npt.ArrayLike
ProfileArg = Union[
    str,
    os.PathLike[str],
    tuple[_ArrayLike, _ArrayLike, _ArrayLike],
    tuple[_ArrayLike, _ArrayLike, _ArrayLike, _ArrayLike],
    Mapping[str, _ArrayLike],
]
ConfigValue = Union[bool, int, float, str, Sequence[Union[bool, int, float, str]]]

class InputError(ValueError):
    source: str
    line: int
    key: str
    index: Optional[int]

class ConfigError(InputError): ...
class ProfileError(InputError): ...
class MeasurementError(InputError): ...

class RunError(RuntimeError):
    index: Optional[int]

class HistoryError(RuntimeError): ...

class Config:
    source: str
    @staticmethod
    def paper() -> Config: ...
    @staticmethod
    def from_file(path: str) -> Config: ...
    @staticmethod
    def from_toml(text: str, source: str = "<string>") -> Config: ...
    @staticmethod
    def keys() -> list[str]: ...
    def set(self, key: str, value: ConfigValue) -> Config: ...
    def get(self, key: str) -> Any: ...
    def to_toml(self) -> str: ...
    def copy(self) -> Config: ...
    def __copy__(self) -> Config: ...
    def __deepcopy__(self, memo: dict[int, Any]) -> Config: ...
    def __eq__(self, other: object) -> bool: ...

class Result(Mapping[str, _Array]):
    shapes: Optional[Result]
    info: dict[str, Any]
    def __init__(self, columns: Mapping[str, _Array], shapes: Optional[Mapping[str, _Array]] = ...,
                 info: Optional[Mapping[str, Any]] = ...) -> None: ...
    def __getitem__(self, name: str) -> _Array: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    @property
    def columns(self) -> list[str]: ...
    @property
    def rows(self) -> int: ...
    def to_pandas(self) -> Any: ...

def simulate(
    cfg: Config,
    profile: ProfileArg = "paper",
    *,
    dt: float = 0.01,
    max_step: float = 0.0025,
    t_end: Optional[float] = None,
    modes: Optional[int] = None,
    initial: Optional[Literal["static", "rest", "config"]] = None,
    method: Literal["fast", "paper"] = "fast",
    static_correction: Union[None, bool, Literal["on", "off"]] = None,
    rho_inf: Optional[float] = None,
    shape_times: Sequence[float] = (),
    shape_points: int = 401,
    estop_at: Optional[float] = None,
    estop_decel: float = 3.0,
    estop_jerk: float = 10.0,
    progress: Optional[Callable[[float], object]] = None,
) -> Result: ...

def simulate_batch(
    configs: Sequence[Config],
    profile: ProfileArg = "paper",
    *,
    threads: int = 0,
    progress: Optional[Callable[[int, int], object]] = None,
    dt: float = 0.01,
    max_step: float = 0.0025,
    t_end: Optional[float] = None,
    modes: Optional[int] = None,
    initial: Optional[Literal["static", "rest", "config"]] = None,
    method: Literal["fast", "paper"] = "fast",
    static_correction: Union[None, bool, Literal["on", "off"]] = None,
    rho_inf: Optional[float] = None,
    shape_times: Sequence[float] = (),
    shape_points: int = 401,
    estop_at: Optional[float] = None,
    estop_decel: float = 3.0,
    estop_jerk: float = 10.0,
) -> list[Result]: ...

def estimate(
    cfg: Config,
    measurements: Union[str, os.PathLike[str], Mapping[str, _ArrayLike]],
    *,
    modes: Optional[int] = None,
    max_step: Optional[float] = None,
    progress: Optional[Callable[[float], object]] = None,
) -> Result: ...

def read_log(path: Union[str, os.PathLike[str]], *, lenient: bool = False) -> dict[str, Result]: ...

def sweep(
    cfg: Config,
    key: str,
    values: Sequence[Any],
    profile: ProfileArg = "paper",
    *,
    threads: int = 0,
    progress: Optional[Callable[[int, int], object]] = None,
    keep_runs: bool = False,
    **options: Any,
) -> dict[str, Any]: ...

_DbUrl = Union[str, os.PathLike[str]]

def trips(db_url: _DbUrl, *, shaft: Optional[str] = None) -> Result: ...

def trip(db_url: _DbUrl, n: int, *, shaft: str = "") -> dict[str, Any]: ...

def record_trips(
    cfg: Config,
    measurements: Union[str, os.PathLike[str], Mapping[str, _ArrayLike]],
    *,
    modes: Optional[int] = None,
    max_step: Optional[float] = None,
    progress: Optional[Callable[[float], object]] = None,
) -> list[dict[str, Any]]: ...
