"""Fixtures of the hoist Python module's tests (run by CTest: tests/python/CMakeLists.txt).

HOIST_SIM / HOIST_ESTIMATE name the programs the module is compared with;
HOIST_SOURCE_DIR the checkout (docs/python.md).  Outside CTest they default
to <checkout>/build.
"""
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("HOIST_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BUILD = SOURCE / "build"


def program(env, name):
    path = os.environ.get(env, str(BUILD / "bin" / name))
    if not os.access(path, os.X_OK):
        pytest.fail(f"{name} not found at {path} (set {env})")
    return path


@pytest.fixture(scope="session")
def hoist_sim():
    return program("HOIST_SIM", "hoist-sim")


@pytest.fixture(scope="session")
def hoist_estimate():
    return program("HOIST_ESTIMATE", "hoist-estimate")


def run(cmd):
    """Run a program; fail the test with its stderr if it fails."""
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if p.returncode != 0:
        pytest.fail(f"{' '.join(map(str, cmd))} exited {p.returncode}: {p.stderr}")
    return p


def read_csv(path):
    """A CSV with a header as {column: float array} (empty fields: nan)."""
    data = np.genfromtxt(path, delimiter=",", names=True, missing_values="", filling_values=np.nan,
                         deletechars="", dtype=float)
    return {name: np.atleast_1d(data[name]) for name in data.dtype.names}
