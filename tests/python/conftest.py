"""Shared set-up of the fissure pytest suites: the module comes from PYTHONPATH=build/python (ctest
sets it, with FISSURE_BIN and FISSURE_HOST_REFERENCE for the C++ side of the comparisons)."""
import os

import pytest


def _required_env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run these tests through ctest (tests/python/CMakeLists.txt sets it)")
    return value


@pytest.fixture(scope="session")
def fissure_bin():
    return _required_env("FISSURE_BIN")


@pytest.fixture(scope="session")
def host_reference():
    return _required_env("FISSURE_HOST_REFERENCE")


@pytest.fixture(scope="session")
def source_dir():
    return _required_env("FISSURE_SOURCE_DIR")
