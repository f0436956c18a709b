"""Fixtures of the Python module's tests: the command-line tool and the
repository (ctest's python.pytest passes them in ROBOMILL_CLI and
ROBOMILL_SOURCE; PYTHONPATH points at build/python)."""

import os
import pathlib

import pytest

SOURCE = pathlib.Path(os.environ.get("ROBOMILL_SOURCE",
                                     pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def source() -> pathlib.Path:
    return SOURCE


@pytest.fixture(scope="session")
def cli() -> str:
    path = os.environ.get("ROBOMILL_CLI", str(SOURCE / "build" / "robomill"))
    if not os.access(path, os.X_OK):
        pytest.skip(f"no robomill command line at {path} (set ROBOMILL_CLI)")
    return path
