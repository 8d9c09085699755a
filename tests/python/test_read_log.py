"""hoist.read_log: an LCM log to arrays per channel with hoist-log2csv's columns.

The log is written here byte by byte (lcm-logger's format) with winder_t
messages encoded by lcm-gen's Python code, so the values read back are known.
"""
import os
import shutil
import struct
import subprocess

import numpy as np
import pytest

import hoist
from conftest import BUILD, SOURCE

SYNC = 0xEDA1DA01


def write_log(path, events):
    with open(path, "wb") as f:
        for n, (utime, channel, data) in enumerate(events):
            ch = channel.encode()
            f.write(struct.pack(">IqqII", SYNC, n, utime, len(ch), len(data)) + ch + data)


@pytest.fixture(scope="module")
def winder_type(tmp_path_factory):
    if not shutil.which("lcm-gen"):
        pytest.skip("lcm-gen not installed (package liblcm-bin)")
    d = tmp_path_factory.mktemp("lcmgen")
    subprocess.run(["lcm-gen", "-p", "--ppath", str(d), str(SOURCE / "msgs" / "winder_t.lcm")], check=True)
    return _load(d)


def _load(d):
    # lcm-gen writes package "hoist" as d/hoist/winder_t.py, which would shadow the module under test:
    # load the file directly under another name.
    import importlib.util
    spec = importlib.util.spec_from_file_location("lcm_winder_t", os.path.join(d, "hoist", "winder_t.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.winder_t


def test_read_log_gives_the_logged_values(tmp_path, winder_type):
    os.environ.setdefault("HOIST_LOG2CSV", str(BUILD / "bin" / "hoist-log2csv"))
    events = []
    for i in range(20):
        m = winder_type()
        m.utime = 1_000_000 + 10_000 * i
        m.seq = i
        m.v = 0.25 * i
        m.a = 1.0 / 3.0
        m.has_length = True
        m.length = 50.0 + 0.1 * i
        events.append((m.utime, "HOIST_WINDER", m.encode()))
    write_log(tmp_path / "trip.lcm", events)
    logs = hoist.read_log(tmp_path / "trip.lcm")
    assert list(logs) == ["HOIST_WINDER"]
    w = logs["HOIST_WINDER"]
    assert isinstance(w, hoist.Result) and w.rows == 20
    assert w["seq"].tolist() == list(range(20))
    assert np.array_equal(w["v"], 0.25 * np.arange(20))
    assert np.all(w["a"] == 1.0 / 3.0)  # 17 significant digits: exact
    assert np.array_equal(w["length"], 50.0 + 0.1 * np.arange(20))


def test_read_log_errors(tmp_path):
    os.environ.setdefault("HOIST_LOG2CSV", str(BUILD / "bin" / "hoist-log2csv"))
    with pytest.raises(hoist.InputError):
        hoist.read_log(tmp_path / "missing.lcm")
    (tmp_path / "junk.lcm").write_bytes(b"\x00" * 64)
    with pytest.raises((hoist.RunError, hoist.InputError)):
        hoist.read_log(tmp_path / "junk.lcm")
