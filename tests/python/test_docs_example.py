"""docs/python.md's worked example runs as it stands (in a scratch directory with its two input files)."""
import os
import re
import shutil
import subprocess
import sys

from conftest import SOURCE, run


def example_code():
    text = (SOURCE / "docs" / "python.md").read_text()
    section = text.split("## Worked example", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 1, "docs/python.md: expected one python block under 'Worked example'"
    return blocks[0]


def test_worked_example_runs(tmp_path, hoist_sim):
    shutil.copy(SOURCE / "service" / "config" / "example.toml", tmp_path / "shaft.toml")
    # The recorded trip: the shaft with a heavier, more eccentric load than configured, through the sensor model.
    truth = tmp_path / "truth.toml"
    truth.write_text("[load]\neccentric_force = 1600.0\noffset = 0.9\n[model]\nmodes = 12\n")
    run([hoist_sim, "--config", truth, "--profile", "paper", "--t-end", "20",
         "--write-measurements", tmp_path / "trip.csv", "-q"])
    (tmp_path / "example.py").write_text(example_code())
    import hoist
    # The hoist under test, whatever the cwd (PYTHONPATH may be relative).
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.path.dirname(os.path.dirname(hoist.__file__)))
    p = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, env=env,
                       timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr
    png = tmp_path / "peak_tilt_vs_preload.png"
    assert png.exists() and png.stat().st_size > 10000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    m = re.search(r"Fa = (-?\d+) \+- (\d+) N", p.stdout)
    assert m, p.stdout
    assert abs(int(m.group(1)) - 1600) < 5 * int(m.group(2)) + 50, p.stdout
