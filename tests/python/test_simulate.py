"""hoist.simulate against hoist-sim on the same inputs (to 1e-12; in practice bit for bit)."""
import numpy as np
import pytest

import hoist
from conftest import read_csv, run

COLUMNS = ["t", "l", "v", "a", "x_c", "y_c", "theta",
           "lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"]


def assert_same(result, csv, columns=COLUMNS):
    assert result.columns == list(columns)
    for c in columns:
        a, b = result[c], csv[c]
        assert a.shape == b.shape, c
        scale = max(1.0, float(np.max(np.abs(b))))
        assert np.max(np.abs(a - b)) <= 1e-12 * scale, c


@pytest.mark.parametrize("args, kwargs", [
    (["--t-end", "8", "--modes", "12"], dict(t_end=8.0, modes=12)),
    (["--t-end", "5", "--modes", "8", "--initial", "rest", "--dt", "0.005", "--max-step", "0"],
     dict(t_end=5.0, modes=8, initial="rest", dt=0.005, max_step=0.0)),
    (["--t-end", "4", "--modes", "6", "--method", "paper", "--static-correction", "off"],
     dict(t_end=4.0, modes=6, method="paper", static_correction=False)),
    (["--t-end", "3", "--modes", "10", "--rho-inf", "0.5", "--static-correction", "off"],
     dict(t_end=3.0, modes=10, rho_inf=0.5, static_correction="off")),
    # The e-stop forecast: the paper trip cut at 6.004 s (rounded to 6.0), stopped at 2.5 m/s^2 and 8 m/s^3.
    (["--t-end", "12", "--modes", "8", "--estop-at", "6.004", "--estop-decel", "2.5", "--estop-jerk", "8"],
     dict(t_end=12.0, modes=8, estop_at=6.004, estop_decel=2.5, estop_jerk=8.0)),
])
def test_same_numbers_as_hoist_sim(tmp_path, hoist_sim, args, kwargs):
    cfg_path = tmp_path / "shaft.toml"
    cfg_path.write_text("[load]\neccentric_force = 1500.0\noffset = 0.8\n[cage]\nmass = 820.0\n")
    out = tmp_path / "out.csv"
    run([hoist_sim, "--config", cfg_path, "--profile", "paper", "--out", out, "-q"] + args)
    r = hoist.simulate(hoist.Config.from_file(str(cfg_path)), "paper", **kwargs)
    assert_same(r, read_csv(out))
    assert r.rows == len(read_csv(out)["t"])


def test_profile_spec_csv_and_arrays_agree_with_hoist_sim(tmp_path, hoist_sim):
    spec = "scurve:vmax=4,amax=0.8,jmax=0.6,travel=120,t_end=40,dt=0.02"
    prof = tmp_path / "profile.csv"
    out = tmp_path / "out.csv"
    shapes = tmp_path / "shapes.csv"
    run([hoist_sim, "--profile", spec, "--write-profile", prof, "--out", out, "--modes", "10", "--t-end", "12",
         "--shape-out", shapes, "--shape-times", "3,7.5", "--shape-points", "51", "-q"])
    cfg = hoist.Config.paper()
    ref = read_csv(out)
    by_spec = hoist.simulate(cfg, spec, modes=10, t_end=12.0, shape_times=[7.5, 3.0], shape_points=51)
    assert_same(by_spec, ref)
    assert_same(by_spec.shapes, read_csv(shapes), ["t", "x", "y1", "y2"])
    assert_same(hoist.simulate(cfg, str(prof), modes=10, t_end=12.0), ref)
    import pathlib
    assert_same(hoist.simulate(cfg, pathlib.Path(prof), modes=10, t_end=12.0), ref)
    p = read_csv(prof)
    assert_same(hoist.simulate(cfg, (p["t"], p["v"], p["a"], p["l"]), modes=10, t_end=12.0), ref)
    assert_same(hoist.simulate(cfg, {"t": p["t"], "v": p["v"], "a": p["a"], "l": p["l"]}, modes=10, t_end=12.0), ref)


def test_arrays_without_l_integrate_from_the_initial_length(tmp_path, hoist_sim):
    t = np.arange(0.0, 6.0 + 1e-9, 0.05)
    v = np.minimum(t, 2.0)
    a = np.where(t < 2.0, 1.0, 0.0)
    prof = tmp_path / "tva.csv"
    np.savetxt(prof, np.column_stack([t, v, a]), delimiter=",", header="t,v,a", comments="", fmt="%.17g")
    out = tmp_path / "out.csv"
    run([hoist_sim, "--profile", prof, "--out", out, "--modes", "8", "-q"])
    assert_same(hoist.simulate(hoist.Config.paper(), (t, v, a), modes=8), read_csv(out))


def test_result_is_a_mapping_of_numpy_arrays():
    r = hoist.simulate(hoist.Config.paper(), t_end=1.0, modes=4)
    assert isinstance(r, hoist.Result) and len(r) == 12 and list(r) == COLUMNS
    assert all(isinstance(r[c], np.ndarray) and r[c].dtype == np.float64 for c in r)
    # The arrays own their buffers (handed over from C++, not built element by element).
    assert r["theta"].flags["C_CONTIGUOUS"] and r["theta"].base is not None
    assert r.info["modes"] == 4 and r.shapes is None
    with pytest.raises(KeyError, match="no such column"):
        r["tilt"]
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pandas"):
            r.to_pandas()
    else:
        assert list(r.to_pandas().columns) == COLUMNS


@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(dt=0.0), ValueError, "dt"),
    (dict(max_step=-1.0), ValueError, "max_step"),
    (dict(modes=0), ValueError, "modes"),
    (dict(initial="moving"), ValueError, "initial"),
    (dict(method="rk4"), ValueError, "method"),
    (dict(method="paper", static_correction=True), ValueError, "static correction"),
    (dict(static_correction="maybe"), ValueError, "static_correction"),
    (dict(t_end=float("nan")), ValueError, "t_end"),
    (dict(shape_times=[100.0]), ValueError, "shape_times"),
    (dict(estop_at=5.0), ValueError, "--estop-at"),
    (dict(estop_at=0.5, estop_decel=0.0), ValueError, "estop_decel"),
    (dict(profile="trapezoid:vmax=x"), hoist.ProfileError, "trapezoid.vmax"),
    (dict(profile="warp"), hoist.ProfileError, "warp"),
    (dict(profile=([0.0, 1.0], [0.0, 1.0])), ValueError, "t, v, a"),
    (dict(profile=([0.0, 1.0, 0.5], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])), hoist.ProfileError, "t"),
    (dict(profile={"t": [0.0, 1.0], "v": [0.0, 0.0]}), ValueError, "'a' is missing"),
    (dict(profile=42), TypeError, "profile"),
])
def test_option_errors_name_the_option(kwargs, exc, words):
    with pytest.raises(exc) as e:
        hoist.simulate(hoist.Config.paper(), **{"modes": 4, "t_end": 1.0, **kwargs})
    assert words in str(e.value), str(e.value)


def test_a_profile_that_leaves_the_shaft_is_refused():
    cfg = hoist.Config.paper().set("hoisting_rope.initial_length", 200.0)
    with pytest.raises(hoist.ProfileError, match="shaft|leaves|L - 2h"):
        hoist.simulate(cfg, "paper", modes=4)


def test_progress_is_called_with_fractions():
    seen = []
    hoist.simulate(hoist.Config.paper(), t_end=20.0, modes=30, progress=seen.append)
    assert seen and all(0.0 <= f <= 1.0 for f in seen) and seen[-1] == 1.0
