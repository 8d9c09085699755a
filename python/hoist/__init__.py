"""hoist -- hoist-twin's shaft model, simulator and load estimator from Python.

The same code as the programs (hoist-sim, hoist-estimate), with numpy arrays
in and out and batch runs on C++ threads with the GIL released::

    import hoist
    cfg = hoist.Config.from_file("shaft.toml")       # or hoist.Config.paper()
    cfg.set("load.eccentric_force", 1500.0)
    r = hoist.simulate(cfg, profile="paper", t_end=20.0)
    r["theta"].max()                                  # numpy arrays, hoist-sim's CSV columns

    runs = hoist.simulate_batch([cfg.copy().set("guide_ropes.preload", [T, T])
                                 for T in (2e4, 3e4, 4e4)], threads=2)

The trip records of the history database: hoist.trips(db_url) (a table),
hoist.trip(db_url, n) (one record with its depth bins), hoist.record_trips(cfg,
measurements) (the offline trip pipeline).

See docs/python.md for the worked example and every function's contract.
"""
from collections.abc import Mapping as _Mapping
import os as _os

from . import _hoist
from ._hoist import (Config, InputError, ConfigError, ProfileError, MeasurementError,  # noqa: F401
                     RunError, HistoryError, __version__, ESTIMATE_COLUMNS, DEFAULT_MAX_STEP)

__all__ = ["Config", "Result", "simulate", "simulate_batch", "estimate", "ESTIMATE_COLUMNS", "read_log", "sweep", "trips", "trip", "record_trips",
           "TRIPS_COLUMNS", "HistoryError", "InputError", "ConfigError",
           "ProfileError", "MeasurementError", "RunError", "DEFAULT_MAX_STEP", "__version__"]


class Result(_Mapping):
    """The rows of a run: a read-only mapping from column name to a 1-d numpy array.

    ``r["theta"]``, ``r.columns`` (the names in the programs' CSV order),
    ``len(r)`` (number of columns), ``r.rows`` (number of rows), ``r.to_pandas()``.
    A simulation's Result also has ``r.shapes`` (a Result with hoist-sim's
    shape columns t, x, y1, y2, or None) and ``r.info`` (the run's modes,
    substeps, initial state and static correction).  The arrays own their
    memory (no per-element copies); they are writable, so copy before changing.
    """

    def __init__(self, columns, shapes=None, info=None):
        self._data = dict(columns)
        self.shapes = Result(shapes) if shapes is not None else None
        self.info = dict(info or {})

    def __getitem__(self, name):
        try:
            return self._data[name]
        except KeyError:
            raise KeyError(f"{name!r}: no such column; columns: {', '.join(self._data)}") from None

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)

    @property
    def columns(self):
        """The column names, in the programs' CSV order."""
        return list(self._data)

    @property
    def rows(self):
        """The number of rows (0 for no columns)."""
        return len(next(iter(self._data.values()))) if self._data else 0

    def to_pandas(self):
        """The columns as a pandas.DataFrame (needs pandas)."""
        try:
            import pandas
        except ImportError as e:
            raise ImportError("Result.to_pandas() needs pandas (apt-get install python3-pandas)") from e
        return pandas.DataFrame(self._data, columns=self.columns)

    def __repr__(self):
        return f"Result({self.rows} rows: {', '.join(self._data)})"


def _check_profile(profile):
    return _os.fspath(profile) if isinstance(profile, _os.PathLike) else profile


def simulate(cfg, profile="paper", *, dt=0.01, max_step=DEFAULT_MAX_STEP, t_end=None, modes=None, initial=None,
             method="fast", static_correction=None, rho_inf=None, shape_times=(), shape_points=401,
             estop_at=None, estop_decel=3.0, estop_jerk=10.0, progress=None):
    """Run the shaft model over a hoist profile: hoist-sim from Python.

    Parameters are hoist-sim's options (same defaults, same checks, same
    numbers to the last bit):

    cfg : Config
        The shaft (Config.paper(), Config.from_file(path), ...).
    profile : str, os.PathLike, (t, v, a[, l]) or {"t":..., "v":..., "a":...[, "l":...]}
        A SPEC ("paper", "trapezoid:vmax=5,travel=250", "scurve:...", "estop:...",
        "rest:t_end=60"), a profile CSV path, or numpy arrays [s, m/s, m/s^2, m];
        without l, l is integrated from v starting at hoisting_rope.initial_length.
        Arrays are checked as a CSV would be (hoist.ProfileError names the row:
        line = index + 2).
    dt : float
        Output step [s], in [1e-6, 1].
    max_step : float
        Largest integration step [s] (each dt is split into equal substeps); 0: dt.
    t_end : float or None
        End time [s]; None: the profile's end.
    modes : int or None
        Assumed modes per rope (overrides model.modes).
    initial : "static", "rest", "config" or None
        Initial state (None/"config": the config's model.initial).
    method : "fast" or "paper"
        The structured KKT solver, or the paper's literal partition.
    static_correction : bool, "on", "off" or None
        Residual guide-rope flexibility (None: the config's; method="paper" needs off).
    rho_inf : float or None
        Generalized-alpha spectral radius (overrides model.rho_inf).
    shape_times : sequence of float
        Times [s] at which the guide-rope shapes are taken (hoist-sim --shape-times).
    shape_points : int
        Depth samples per shape.
    estop_at, estop_decel, estop_jerk : float
        An emergency stop at estop_at [s] (rounded to an output step): the
        profile up to it, then the look-ahead forecast's "estop" scenario
        (|a| builds up at estop_jerk [m/s^3] to estop_decel [m/s^2] against
        the motion, eases off so that v and a reach 0 together, then rest).
        The run equals the twin's e-stop forecast made at that time.
    progress : callable(fraction) or None
        Called about every 50 ms from the calling thread.

    Returns
    -------
    Result
        hoist-sim's CSV columns t, l, v, a, x_c, y_c, theta, lambda_0..lambda_4;
        r.shapes (t, x, y1, y2) when shape_times is given; r.info.

    Raises
    ------
    ConfigError, ProfileError (InputError, a ValueError: .source, .line, .key),
    ValueError (an option, named), RunError (the state became non-finite or
    implausible: the message names the time and the quantity),
    KeyboardInterrupt (Ctrl-C stops the run).

    The GIL is released while the model runs.
    """
    cols, shapes, info = _hoist._simulate(cfg, _check_profile(profile), dt, max_step, t_end, modes,
                                          initial or "", method, static_correction, rho_inf,
                                          list(shape_times), shape_points, estop_at, estop_decel, estop_jerk,
                                          progress)
    return Result(cols, shapes, info)


def simulate_batch(configs, profile="paper", *, threads=0, progress=None, dt=0.01, max_step=DEFAULT_MAX_STEP,
                   t_end=None, modes=None, initial=None, method="fast", static_correction=None,
                   rho_inf=None, shape_times=(), shape_points=401, estop_at=None, estop_decel=3.0,
                   estop_jerk=10.0):
    """Run simulate() for every configuration, on C++ threads with the GIL released.

    configs : sequence of Config
        One run each, all with the same profile and options (those of simulate()).
    threads : int
        Worker threads; 0 (default): one per hardware thread.
    progress : callable(done, total) or None
        Called from the calling thread whenever runs have finished.

    Returns the list of Results, in the order of `configs`.

    One failing configuration cancels the others and raises its error (the
    first by index), with the message starting "simulate_batch: configs[i]:"
    and the attribute .index = i; no result is returned.  Ctrl-C stops every
    run and raises KeyboardInterrupt; every thread has ended when it does.
    """
    configs = list(configs)
    for i, c in enumerate(configs):
        if not isinstance(c, Config):
            raise TypeError(f"simulate_batch: configs[{i}] is a {type(c).__name__}, not a hoist.Config")
    out = _hoist._simulate_batch(configs, _check_profile(profile), threads, progress, dt, max_step, t_end,
                                 modes, initial or "", method, static_correction, rho_inf,
                                 list(shape_times), shape_points, estop_at, estop_decel, estop_jerk)
    return [Result(c, s, i) for c, s, i in out]


def estimate(cfg, measurements, *, modes=None, max_step=None, progress=None):
    """Estimate the eccentric load from recorded data: hoist-estimate from Python.

    cfg : Config
        The twin's shaft and its [sensors]/[estimator] settings (a daemon
        configuration read with Config.from_file keeps them).
    measurements : str, os.PathLike or dict of arrays
        hoist-estimate's measurement CSV (t,l,v,a[,f_y,omega,rope_load]), or a
        dict with those column names; a nan in a sensor column is a row without
        that sample (an empty CSV field).  Checked as the CSV is
        (hoist.MeasurementError names the column and the line = index + 2).
    modes : int or None
        Assumed modes per rope (overrides model.modes; hoist-estimate --modes).
    max_step : float or None
        Largest integration step [s]; None: the config's [service] max_step,
        else 0.0025 s (hoist-estimate --max-step).
    progress : callable(fraction) or None

    Returns a Result with hoist-estimate's output columns (ESTIMATE_COLUMNS),
    one row per measurement row, the same numbers as hoist-estimate writes; a
    value not observed (its sensor not seen yet) is nan with its sigma; the
    flags and counters are floats (0.0/1.0, counts).  The GIL is released.
    """
    cols = _hoist._estimate(cfg, _check_profile(measurements), modes, max_step, progress)
    return Result(cols)


def _log2csv_program():
    """hoist-log2csv: $HOIST_LOG2CSV, the build tree's (build/bin next to build/python), else the PATH's."""
    import shutil
    env = _os.environ.get("HOIST_LOG2CSV")
    if env:
        return env
    here = _os.path.dirname(_os.path.abspath(__file__))
    built = _os.path.join(here, "..", "..", "bin", "hoist-log2csv")
    if _os.access(built, _os.X_OK):
        return _os.path.normpath(built)
    found = shutil.which("hoist-log2csv")
    if not found:
        raise FileNotFoundError("read_log needs the program hoist-log2csv (package hoist-twin, or set HOIST_LOG2CSV)")
    return found


def _read_csv_columns(path):
    import csv
    import numpy as np
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    cols = {}
    for k, name in enumerate(header):
        values = [r[k] if k < len(r) else "" for r in body]
        try:
            cols[name] = np.array([float(v) if v != "" else np.nan for v in values], dtype=np.float64)
        except ValueError:
            cols[name] = np.array(values, dtype=object)  # names: alarm levels, events, scenario names
    return cols


def read_log(path, *, lenient=False):
    """Read an LCM log (lcm-logger's file) into arrays per channel: hoist-log2csv from Python.

    path : str or os.PathLike
        The log file.
    lenient : bool
        hoist-log2csv --lenient (skip what it would refuse).

    Returns a dict from CSV name (the channel, e.g. "HOIST_CAGE_STATE"; a
    channel whose type changes midway also gives "CHANNEL.<type>", a forecast
    channel "CHANNEL.series") to a Result with hoist-log2csv's columns (float64
    arrays; text columns such as alarm levels as object arrays).

    The log is decoded by hoist-log2csv itself (the project's one validating
    reader and codec), found as $HOIST_LOG2CSV, next to the build tree, or on
    PATH; its error (exit status 2) is raised as hoist.InputError naming the file.
    """
    import subprocess
    import tempfile
    path = _os.fspath(path)
    with tempfile.TemporaryDirectory(prefix="hoist-read-log-") as out:
        cmd = [_log2csv_program(), path, "--out-dir", out] + (["--lenient"] if lenient else [])
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            msg = p.stderr.strip() or f"hoist-log2csv exited {p.returncode}"
            raise (InputError if p.returncode == 2 else RunError)(msg)
        return {name[:-4]: Result(_read_csv_columns(_os.path.join(out, name)))
                for name in sorted(_os.listdir(out)) if name.endswith(".csv")}


def sweep(cfg, key, values, profile="paper", *, threads=0, progress=None, keep_runs=False, **options):
    """Sweep one configuration key over `values` in one batch: peak responses as arrays.

    cfg : Config
        The base shaft (not changed).
    key : str
        A dotted key for Config.set ("cage.mass", "load.eccentric_force", ...);
        "guide_ropes.preload" sets both ropes to each value (an array key takes
        a list value per run instead: pass lists in `values`).
    values : sequence
        One run per value, validated by Config.set before anything runs
        (hoist.ConfigError names the key and, in .index, which value).
    profile, threads, progress, **options
        As simulate_batch (dt, max_step, t_end, modes, initial, method, ...).
    keep_runs : bool
        Also return the runs' Results under "runs".

    Returns a dict of numpy arrays, one entry per value: "value" and
    "peak_<column>" = max |column| over the run for x_c, y_c, theta and
    lambda_0..lambda_4, with "t_peak_<column>" the time it is reached (first
    occurrence).  These are hoist-sim's summary peaks; hoist-study's staged
    metrics (per-stage peaks, frequencies, figures) stay in hoist-study.
    """
    import numpy as np
    configs = []
    for i, v in enumerate(values):
        value = v
        if key == "guide_ropes.preload" and np.ndim(v) == 0:
            value = [v, v]
        try:
            configs.append(cfg.copy().set(key, value))
        except ConfigError as e:
            e.index = i
            raise
    runs = simulate_batch(configs, profile, threads=threads, progress=progress, **options)
    out = {"value": np.array([v if np.ndim(v) == 0 else np.nan for v in values], dtype=np.float64)}
    for c in ("x_c", "y_c", "theta", "lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"):
        k = [int(np.argmax(np.abs(r[c]))) for r in runs]
        out["peak_" + c] = np.array([abs(r[c][i]) for r, i in zip(runs, k)], dtype=np.float64)
        out["t_peak_" + c] = np.array([r["t"][i] for r, i in zip(runs, k)], dtype=np.float64)
    if keep_runs:
        out["runs"] = runs
    return out


# The shaft's memory (hoist/_trips.py): after Result, which it uses.
from ._trips import trips, trip, record_trips, TRIPS_COLUMNS  # noqa: E402
