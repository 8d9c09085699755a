"""The shaft's memory from Python: the history database's trip records and the
offline trip pipeline (issue 34; docs/python.md, docs/condition.md).

Imported by hoist/__init__.py: use hoist.trips, hoist.trip, hoist.record_trips.
"""
import os as _os

from . import _hoist
from . import Result

__all__ = ["trips", "trip", "record_trips", "TRIPS_COLUMNS"]

#: The columns of hoist.trips, those of `hoist-trips list --format csv`, in its order.
TRIPS_COLUMNS = ["trip", "direction", "t_start", "t_end", "Fa", "sigma_Fa", "moment", "sigma_moment",
                 "preload_scale", "sigma_preload_scale", "mismatch", "alarms", "shaft", "wall_start",
                 "wall_end", "depth_start", "depth_end", "peak_speed", "informative", "imbalance",
                 "sigma_imbalance", "nis_peak", "min_clearance"]


def _record(d):
    d = dict(d)
    d["bins"] = Result(d["bins"])
    return d


def trips(db_url, *, shaft=None):
    """The trip records of a history database as a table: hoist-trips list from Python.

    db_url : str or os.PathLike
        The database, as hoist-trips --db takes it: a SQLite file (a plain
        path, ``sqlite:rel/path`` or ``sqlite:///abs/path``) or
        ``postgresql://[user@]host[:port]/db`` (the password from
        ~/.pgpass / PGPASSFILE, never in the URL).  Opened read-only: a
        SQLite file is never created, migrated or written.
    shaft : str or None
        Only this shaft's trips ("" is the default shaft, as hoist-trips
        without --shaft); None: every shaft (hoist-trips --all-shafts).

    Returns a Result ordered by (shaft, trip) with the columns of
    ``hoist-trips list --format csv`` (TRIPS_COLUMNS): Fa, moment and their
    sigmas are the estimates at arrival; preload_scale is the identified
    guide-rope preload scale s (1 = as commissioned) with its sigma.
    float64 arrays, except trip (int64), mismatch and informative (bool),
    wall_start and wall_end (datetime64[us], UTC), direction ("down"/"up"),
    alarms (the kinds joined with ';') and shaft (str).  A sigma that is not
    observed (empty in the CSV) is nan, and so is the preload scale of a
    trip without an identification.

    Raises ValueError naming db_url for a bad URL; hoist.HistoryError (a
    RuntimeError) naming the database when it cannot be opened or read, is
    not a hoist-twin history database, or has a newer schema.
    """
    return Result(_hoist._trips(_os.fspath(db_url), shaft))


def trip(db_url, n, *, shaft=""):
    """One trip record with its depth bins: hoist-trips show from Python.

    db_url : as for hoist.trips (read-only).
    n : int
        The trip number.
    shaft : str
        The shaft ("": the default shaft).

    Returns a dict: "shaft", "trip", every stored column by the database's
    names (docs/condition.md "Schema": wall_start_us, t_start, direction
    (+1 down, -1 up), fa_end, sigma_fa_end, id_scale, id_sigma_scale,
    mismatch, alarms, ...; a negative sigma = not observed), and "bins": a
    Result with one row per depth bin (depth_lo, samples, fy_rms, resid_rms,
    ...).  Raises KeyError when the trip is not stored, and the errors of
    hoist.trips.
    """
    return _record(_hoist._trip(_os.fspath(db_url), int(n), shaft))


def record_trips(cfg, measurements, *, modes=None, max_step=None, progress=None):
    """The offline trip pipeline on a recorded run: hoist-trips ingest from Python, without the database.

    The recording is split into trips (rest -> moving -> rest) and one record
    is built per trip with the load estimator's loads and the guide-rope
    preload identified -- the same numbers hoist-trips ingest stores for the
    same configuration and file (it runs the same function, recordTrips).

    cfg : Config
        The shaft with its [sensors], [estimator] and [condition] settings
        (Config.from_file reads hoist-trips' configuration, [history] and
        [condition] included; cfg.set("condition.depth_bin", 5.0) works).
    measurements : str, os.PathLike or dict of arrays
        As hoist.estimate: hoist-estimate's measurement columns
        t,l,v,a[,f_y,omega,rope_load] (e.g. hoist-sim --write-measurements).
    modes : int or None
        hoist-trips ingest --modes (overrides model.modes).
    max_step : float or None
        hoist-trips ingest --max-step; None: [service] max_step, else 0.0025 s.
    progress : callable(fraction) or None
        Called about every 50 ms; Ctrl-C stops the run (KeyboardInterrupt).

    Returns a list of records as hoist.trip gives them, numbered 1, 2, ...
    in this run, shaft "", without wall-clock times (0) and alarms (the
    condition alarms need the shaft's history: hoist-trips ingest decides
    them).  A trip still moving at the end of the recording gives no record.
    Raises hoist.MeasurementError, ValueError (an option), hoist.RunError.
    The GIL is released while the pipeline runs (about 1 s per trip at n = 25).
    """
    meas = _os.fspath(measurements) if isinstance(measurements, _os.PathLike) else measurements
    return [_record(r) for r in _hoist._record_trips(cfg, meas, modes, max_step, progress)]
