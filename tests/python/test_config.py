"""hoist.Config: the programs' TOML, the same errors (naming file, line, key), set/get/to_toml."""
import pytest

import hoist


def write(tmp_path, text, name="shaft.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def test_paper_is_the_default_shaft():
    cfg = hoist.Config.paper()
    assert cfg.get("guide_ropes.preload") == [30000.0, 30000.0]
    assert cfg.get("guide_ropes.preload[1]") == 30000.0
    assert cfg.get("model.modes") == 50 and isinstance(cfg.get("model.modes"), int)
    assert cfg.get("model.static_correction") is True
    assert cfg.get("model.initial") == "static"
    assert cfg.get("load.eccentric_force") == 1000.0


def test_from_file_reads_the_values(tmp_path):
    path = write(tmp_path, "[cage]\nmass = 900.0\n[guide_ropes]\npreload = [25000, 35000.5]\n")
    cfg = hoist.Config.from_file(path)
    assert cfg.get("cage.mass") == 900.0
    assert cfg.get("guide_ropes.preload") == [25000.0, 35000.5]
    assert cfg.source == path


@pytest.mark.parametrize("text, line, key, words", [
    ("[cage]\nmass = -5.0\n", 2, "cage.mass", "> 0"),
    ("[cage]\nmas = 5.0\n", 2, "cage.mas", "did you mean"),
    ("[cage]\nmass = \"heavy\"\n", 2, "cage.mass", "must be a number"),
    ("[cagee]\nmass = 5.0\n", 1, "cagee", "unknown section"),
    ("\n\n[model]\nmodes = 2.5\n", 4, "model.modes", "integer"),
    ("[model]\ninitial = \"moving\"\n", 2, "model.initial", "static"),
    ("[guide_ropes]\npreload = [1.0]\n", 2, "guide_ropes.preload", "exactly 2"),
    ("[cage]\nhalf_height = 300.0\n", 2, "cage.half_height", ""),
    ("[load]\neccentric_force = nan\n", 2, "load.eccentric_force", "finite"),
])
def test_file_errors_name_file_line_and_key(tmp_path, text, line, key, words):
    path = write(tmp_path, text)
    with pytest.raises(hoist.ConfigError) as e:
        hoist.Config.from_file(path)
    assert isinstance(e.value, ValueError)
    assert e.value.source == path and e.value.line == line and e.value.key == key
    msg = str(e.value)
    assert msg.startswith(f"{path}:{line}: {key}: "), msg
    assert words in msg


def test_syntax_error_names_the_line(tmp_path):
    path = write(tmp_path, "[cage]\nmass = = 3\n")
    with pytest.raises(hoist.ConfigError) as e:
        hoist.Config.from_file(path)
    assert e.value.line == 2 and "TOML syntax error" in str(e.value)


def test_missing_file(tmp_path):
    with pytest.raises(hoist.ConfigError, match="cannot open"):
        hoist.Config.from_file(str(tmp_path / "nope.toml"))


def test_same_message_as_hoist_sim(tmp_path, hoist_sim):
    import subprocess
    path = write(tmp_path, "[cage]\nmass = -5.0\n")
    p = subprocess.run([hoist_sim, "--config", path, "--out", str(tmp_path / "o.csv"), "-q"],
                       capture_output=True, text=True)
    assert p.returncode == 2
    with pytest.raises(hoist.ConfigError) as e:
        hoist.Config.from_file(path)
    assert p.stderr.strip() == f"hoist-sim: error: {e.value}"


@pytest.mark.parametrize("key, value, words", [
    ("cage.mass", -1.0, "> 0"),
    ("cage.mass", "heavy", "must be a number"),
    ("cage.mas", 1.0, "did you mean"),
    ("model.modes", 2.5, "integer"),
    ("model.modes", 0, "model.modes"),
    ("model.static_correction", 1, "true or false"),
    ("model.initial", "moving", "static"),
    ("guide_ropes.preload", [1.0, 2.0, 3.0], "exactly 2"),
    ("guide_ropes.preload[2]", 1.0, "out of range"),
    ("guide_ropes.preload[1]", -1.0, "> 0"),
    ("model.rho_inf", 1.5, "model.rho_inf"),
    ("cage.half_height", 300.0, "cage.half_height"),
    ("cagee.mass", 1.0, "unknown section"),
    ("mass", 1.0, "dotted key"),
    ("estimator.nis_window", -1.0, "estimator.nis_window"),
])
def test_set_errors_name_the_key_and_change_nothing(key, value, words):
    cfg = hoist.Config.paper()
    before = cfg.to_toml()
    with pytest.raises(hoist.ConfigError) as e:
        cfg.set(key, value)
    assert words in str(e.value), str(e.value)
    assert e.value.key.split("[")[0] in (key.split("[")[0], key.split(".")[0], key), (e.value.key, key)
    assert str(e.value).startswith("Config.set: ")
    assert cfg.to_toml() == before


def test_set_get_and_chaining():
    cfg = hoist.Config.paper()
    assert cfg.set("load.eccentric_force", 1500.0) is cfg
    assert cfg.get("load.eccentric_force") == 1500.0
    cfg.set("guide_ropes.preload[1]", 25000)
    assert cfg.get("guide_ropes.preload") == [30000.0, 25000.0]
    cfg.set("model.modes", 12).set("model.initial", "rest").set("model.static_correction", False)
    assert (cfg.get("model.modes"), cfg.get("model.initial"), cfg.get("model.static_correction")) == (12, "rest", False)
    import numpy as np
    cfg.set("cage.mass", np.float64(850.0)).set("model.modes", np.int64(14))
    assert cfg.get("cage.mass") == 850.0 and cfg.get("model.modes") == 14
    with pytest.raises(KeyError, match="did you mean"):
        cfg.get("cage.mas")


def test_copy_is_independent():
    a = hoist.Config.paper()
    b = a.copy().set("cage.mass", 900.0)
    assert a.get("cage.mass") == 800.0 and b.get("cage.mass") == 900.0
    assert a != b and a == hoist.Config.paper()


def test_to_toml_round_trip_keeps_daemon_sections(tmp_path):
    text = ("[cage]\nmass = 812.5\n[load]\neccentric_force = 1234.5\n"
            "[service]\nmax_step = 0.002\n[estimator]\nnis_window = 4.0\n")
    cfg = hoist.Config.from_file(write(tmp_path, text))
    cfg.set("guide_ropes.preload", [31000.0, 29000.0])
    back = hoist.Config.from_toml(cfg.to_toml())
    assert back == cfg
    assert back.get("service.max_step") == 0.002 and back.get("estimator.nis_window") == 4.0
    # Every shaft key is written.
    for key in hoist.Config.keys():
        assert back.get(key) == cfg.get(key)
