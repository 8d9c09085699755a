"""hoist.trips, hoist.trip and hoist.record_trips against hoist-trips on a database made here
(hoist-sim --write-measurements on two trips, then hoist-trips ingest)."""
import math
import os
import sqlite3

import numpy as np
import pytest

import hoist
from conftest import program, run

TWIND = ("[model]\nmodes = 6\n[sensors]\nimu_accel_noise = 0.002\n[estimator]\nenabled = true\n"
         "[condition]\ndepth_bin = 20.0\n[history]\nkeep_days = 3650\n")
WALL0 = np.datetime64("2026-12-06T08:00:00", "us")


def two_trips_profile(path, travel=60.0, vmax=4.0, amax=1.0, dt=0.01, rest=3.0):
    """Rest, a trip down, rest, the same trip up, rest (t, v, a)."""
    ta = vmax / amax
    tc = (travel - vmax * ta) / vmax
    trip = 2 * ta + tc
    total = 3 * rest + 2 * trip
    rows = ["t,v,a"]
    for i in range(int(round(total / dt)) + 1):
        t = i * dt
        v = a = 0.0
        sign, u = 1.0, -1.0
        if rest < t < rest + trip:
            u = t - rest
        elif 2 * rest + trip < t < 2 * rest + 2 * trip:
            u, sign = t - 2 * rest - trip, -1.0
        if u >= 0:
            if u < ta:
                v, a = amax * u, amax
            elif u < ta + tc:
                v = vmax
            else:
                v, a = max(0.0, vmax - amax * (u - ta - tc)), -amax
        rows.append(f"{t!r},{sign * v!r},{sign * a!r}")
    path.write_text("\n".join(rows) + "\n")


@pytest.fixture(scope="module")
def history(tmp_path_factory, hoist_sim):
    trips_cli = program("HOIST_TRIPS", "hoist-trips")
    d = tmp_path_factory.mktemp("trips")
    two_trips_profile(d / "profile.csv")
    run([hoist_sim, "--profile", d / "profile.csv", "--modes", "8", "--write-measurements", d / "meas.csv",
         "--seed", "3", "-q", "--out", d / "sim.csv"])
    (d / "twind.toml").write_text(TWIND)
    db = d / "history.sqlite"
    run([trips_cli, "ingest", "--config", d / "twind.toml", "--measurements", d / "meas.csv", "--db", db,
         "--first-trip", "101", "--wall-start", "2026-12-06T08:00:00Z", "-q"])
    listed = run([trips_cli, "list", "--db", db, "--format", "csv"]).stdout
    return {"dir": d, "db": db, "csv": listed, "cli": trips_cli}


def csv_columns(text):
    import csv
    import io
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], [dict(zip(rows[0], r)) for r in rows[1:]]


def test_trips_has_the_list_csv_columns_and_numbers(history):
    header, rows = csv_columns(history["csv"])
    t = hoist.trips(history["db"])
    assert t.columns == header == hoist.TRIPS_COLUMNS
    assert t.rows == len(rows) == 2
    assert t["trip"].dtype == np.int64 and list(t["trip"]) == [101, 102]
    assert list(t["direction"]) == ["down", "up"]
    for c in header:
        for i, row in enumerate(rows):
            got, want = t[c][i], row[c]
            if c in ("direction", "alarms", "shaft"):
                assert got == want, c
            elif c in ("wall_start", "wall_end"):
                assert abs(got - np.datetime64(want.rstrip("Z"), "us")) < np.timedelta64(1, "ms"), c
            elif c in ("trip", "mismatch", "informative"):
                assert int(got) == int(want), c
            elif want == "":
                assert math.isnan(got), c  # not observed / not identified
            else:
                # The CSV prints 10 significant digits, 6 for a sigma.
                rel = 1e-5 if c.startswith("sigma") else 1e-9
                assert got == pytest.approx(float(want), rel=rel, abs=1e-300), c
    # The data itself: a 60 m trip down then up, departing 3 s after the wall start.
    assert t["depth_end"][0] - t["depth_start"][0] == pytest.approx(60.0, abs=1.0)
    assert t["wall_start"][0] - WALL0 == np.timedelta64(int(round(t["t_start"][0] * 1e6)), "us")
    # The estimate at arrival found the recording's load (the paper's 1000 N) within its sigma band.
    assert np.all(np.abs(t["Fa"] - 1000.0) < 5 * t["sigma_Fa"] + 10.0), t["Fa"]


def test_trips_of_one_shaft(history):
    assert hoist.trips(history["db"], shaft="").rows == 2
    assert hoist.trips(history["db"], shaft="north").rows == 0


def test_trip_with_its_depth_bins(history):
    r = hoist.trip(history["db"], 101)
    assert (r["shaft"], r["trip"], r["direction"]) == ("", 101, 1)
    assert r["depth_bin"] == 20.0
    bins = r["bins"]
    assert isinstance(bins, hoist.Result) and bins.rows >= 3
    assert np.all(np.diff(bins["depth_lo"]) == 20.0)
    assert bins["samples"].dtype == np.int64 and bins["samples"].sum() > 0
    t = hoist.trips(history["db"])
    assert r["fa_end"] == t["Fa"][0] and r["id_scale"] == t["preload_scale"][0]
    with pytest.raises(KeyError, match="no trip 7 of shaft ''"):
        hoist.trip(history["db"], 7)


def test_record_trips_gives_what_ingest_stored(history):
    cfg = hoist.Config.from_file(str(history["dir"] / "twind.toml"))
    seen = []
    recs = hoist.record_trips(cfg, history["dir"] / "meas.csv", progress=seen.append)
    assert len(recs) == 2
    for n, r in zip((101, 102), recs):
        stored = hoist.trip(history["db"], n)
        assert set(r) == set(stored)
        # Not the pipeline's: the number, the wall clock, the alarms (decided against the history), the CPU time.
        for k in set(stored) - {"trip", "wall_start_us", "wall_end_us", "alarms", "id_cpu_seconds", "bins"}:
            assert r[k] == stored[k], k
        assert r["bins"].columns == stored["bins"].columns
        for c in stored["bins"].columns:
            assert np.array_equal(r["bins"][c], stored["bins"][c]), c
    assert [r["trip"] for r in recs] == [1, 2] and recs[0]["wall_start_us"] == 0
    assert all(0.0 <= f <= 1.0 for f in seen)


def test_record_trips_takes_condition_settings(history):
    cfg = hoist.Config.from_file(str(history["dir"] / "twind.toml"))
    assert cfg.get("condition.depth_bin") == 20.0
    with pytest.raises(hoist.ConfigError, match="condition.depth_bin"):
        cfg.set("condition.depth_bin", -1.0)
    with pytest.raises(ValueError, match="modes"):
        hoist.record_trips(cfg, history["dir"] / "meas.csv", modes=0)
    with pytest.raises(hoist.MeasurementError):
        hoist.record_trips(cfg, {"t": [0.0, 0.01], "l": [1.0, 1.0], "v": [0.0, 0.0]})


def test_bad_urls_and_foreign_databases_are_named(history, tmp_path):
    with pytest.raises(ValueError, match="db_url"):
        hoist.trips("mysql://host/db")
    missing = tmp_path / "missing.sqlite"
    with pytest.raises(hoist.HistoryError, match="missing.sqlite"):
        hoist.trips(missing)
    assert not missing.exists()  # read-only: never created
    garbage = tmp_path / "garbage.sqlite"
    garbage.write_bytes(b"this is not a database" * 100)
    with pytest.raises(hoist.HistoryError, match="garbage.sqlite"):
        hoist.trips(garbage)
    foreign = tmp_path / "foreign.sqlite"
    with sqlite3.connect(foreign) as c:
        c.execute("CREATE TABLE customers(id INTEGER, name TEXT)")
    with pytest.raises(hoist.HistoryError, match="foreign.sqlite"):
        hoist.trip(foreign, 1)
    before = os.stat(history["db"]).st_mtime_ns
    hoist.trips(history["db"])
    assert os.stat(history["db"]).st_mtime_ns == before


def test_docs_memory_example_runs(history, tmp_path):
    import re
    import shutil
    import subprocess
    import sys
    from conftest import SOURCE
    text = (SOURCE / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text.split("## The shaft's memory from Python", 1)[1], re.S)
    assert len(blocks) == 1, "docs/python.md: expected one python block under 'The shaft's memory from Python'"
    shutil.copy(history["db"], tmp_path / "history.sqlite")
    (tmp_path / "example.py").write_text(blocks[0])
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.path.dirname(os.path.dirname(hoist.__file__)))
    p = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, env=env,
                       timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    assert p.stdout.startswith("2 trips from 2026-12-06T08:00:0"), p.stdout
    assert re.search(r"trip 102 : \d+ bins of 20.0 m; worst f_y residual", p.stdout), p.stdout
    png = tmp_path / "preload_trend.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10000
