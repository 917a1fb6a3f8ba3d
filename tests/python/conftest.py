# pytest set-up for the Python module's tests (run by ctest: tests/python/CMakeLists.txt sets
# GALE_BIN, the gale binary, and PYTHONPATH to build/python): fixtures for the binary, the
# source tree and a scratch folder.
import os
import pathlib
import subprocess

import pytest


@pytest.fixture(scope="session")
def gale_bin():
    path = os.environ.get("GALE_BIN")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("GALE_BIN must name the gale binary (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def src():
    return pathlib.Path(os.environ.get("GALE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


def run_gale(gale_bin, *args, cwd=None, check=True):
    """Runs gale with NO_COLOR; returns the CompletedProcess (text mode)."""
    env = dict(os.environ, NO_COLOR="1")
    r = subprocess.run([gale_bin, *map(str, args)], cwd=cwd, env=env, capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"gale {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    return r
