# Type stubs of the extension hoist._hoist (python/src/*.cpp); use the package hoist.
from typing import Any, Optional

from . import (Config as Config, ConfigError as ConfigError, InputError as InputError,
               MeasurementError as MeasurementError, ProfileError as ProfileError, RunError as RunError,
               HistoryError as HistoryError)

__version__: str
ESTIMATE_COLUMNS: list[str]

def _simulate(cfg: Config, profile: Any, dt: float, max_step: float, t_end: Optional[float],
              modes: Optional[int], initial: str, method: str, static_correction: Any,
              rho_inf: Optional[float], shape_times: list[float], shape_points: int,
              estop_at: Optional[float], estop_decel: float, estop_jerk: float,
              progress: Any) -> tuple[dict[str, Any], Optional[dict[str, Any]], dict[str, Any]]: ...
def _simulate_batch(configs: list[Config], profile: Any, threads: int, progress: Any, dt: float,
                    max_step: float, t_end: Optional[float], modes: Optional[int], initial: str, method: str,
                    static_correction: Any, rho_inf: Optional[float], shape_times: list[float],
                    shape_points: int, estop_at: Optional[float], estop_decel: float,
                    estop_jerk: float) -> list[tuple[dict[str, Any], Optional[dict[str, Any]], dict[str, Any]]]: ...
def _estimate(cfg: Config, measurements: Any, modes: Optional[int], max_step: Optional[float],
              progress: Any) -> dict[str, Any]: ...
def _trips(db_url: str, shaft: Optional[str]) -> dict[str, Any]: ...
def _trip(db_url: str, n: int, shaft: str) -> dict[str, Any]: ...
def _record_trips(cfg: Config, measurements: Any, modes: Optional[int], max_step: Optional[float],
                  progress: Any) -> list[dict[str, Any]]: ...
