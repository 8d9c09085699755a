"""hoist.estimate against hoist-estimate on the same measurements (hoist-sim --write-measurements)."""
import numpy as np
import pytest

import hoist
from conftest import read_csv, run

TRUTH = "[load]\neccentric_force = 1800.0\noffset = 0.9\n[model]\nmodes = 8\n"
TWIN = "[model]\nmodes = 8\n[estimator]\nnis_window = 2.0\n"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory, hoist_sim, hoist_estimate):
    d = tmp_path_factory.mktemp("est")
    (d / "truth.toml").write_text(TRUTH)
    (d / "twin.toml").write_text(TWIN)
    run([hoist_sim, "--config", d / "truth.toml", "--profile", "paper", "--t-end", "15", "--dt", "0.01",
         "--write-measurements", d / "meas.csv", "--seed", "7", "-q"])
    run([hoist_estimate, "--config", d / "twin.toml", "--measurements", d / "meas.csv", "--out", d / "est.csv",
         "-q"])
    return d


def assert_same(result, ref):
    assert result.columns == list(ref)
    for c in ref:
        a, b = result[c], ref[c]
        assert a.shape == b.shape, c
        assert np.array_equal(np.isnan(a), np.isnan(b)), c
        ok = ~np.isnan(b)
        scale = max(1.0, float(np.max(np.abs(b[ok]))) if ok.any() else 1.0)
        assert np.max(np.abs(a[ok] - b[ok]), initial=0.0) <= 1e-12 * scale, c


def test_same_numbers_as_hoist_estimate_from_the_csv(recorded):
    cfg = hoist.Config.from_file(str(recorded / "twin.toml"))
    r = hoist.estimate(cfg, str(recorded / "meas.csv"))
    ref = read_csv(recorded / "est.csv")
    assert list(ref) == hoist.ESTIMATE_COLUMNS
    assert_same(r, ref)
    # The estimate found the truth's load within its sigma band (a sanity check of the data, not of the binding).
    assert abs(r["Fa"][-1] - 1800.0) < 5 * r["sigma_Fa"][-1] + 50.0


def test_same_numbers_from_arrays(recorded):
    cfg = hoist.Config.from_file(str(recorded / "twin.toml"))
    m = read_csv(recorded / "meas.csv")
    assert_same(hoist.estimate(cfg, m), read_csv(recorded / "est.csv"))


def test_options_match_hoist_estimate(recorded, hoist_estimate):
    run([hoist_estimate, "--config", recorded / "twin.toml", "--measurements", recorded / "meas.csv",
         "--out", recorded / "est6.csv", "--modes", "6", "--max-step", "0.005", "-q"])
    cfg = hoist.Config.from_file(str(recorded / "twin.toml"))
    assert_same(hoist.estimate(cfg, str(recorded / "meas.csv"), modes=6, max_step=0.005),
                read_csv(recorded / "est6.csv"))


def test_bad_measurements_name_the_column(recorded):
    cfg = hoist.Config.paper()
    m = read_csv(recorded / "meas.csv")
    m["v"] = m["v"].copy()
    m["v"][5] = np.inf
    with pytest.raises(hoist.MeasurementError) as e:
        hoist.estimate(cfg, m)
    assert e.value.key == "v" and e.value.line == 7
    with pytest.raises(ValueError, match="modes"):
        hoist.estimate(cfg, str(recorded / "meas.csv"), modes=0)
