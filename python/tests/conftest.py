"""Shared fixtures: the module from the build (PYTHONPATH, set by CTest) and the CLI."""

import os
import shutil

import pytest

import amalgam


@pytest.fixture(scope="session")
def cli():
    """The `amalgam` executable of the same build (AMALGAM_CLI, set by CTest)."""
    path = os.environ.get("AMALGAM_CLI") or shutil.which("amalgam")
    if not path:
        pytest.fail("AMALGAM_CLI is not set: run the suite through ctest (docs/python.md)")
    return path


@pytest.fixture(scope="session")
def demo():
    """One loaded scene shared by the tests (loading is what a Scene saves)."""
    return amalgam.load("builtin:demo")
