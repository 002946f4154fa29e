# SPDX-License-Identifier: MIT
"""Test set-up: imports the package from this checkout, counts the C functions the tests reach.

Run from the repository root with the library to test in SPH_LIBRARY:
    SPH_LIBRARY=build/libsph.so python3 -m pytest -q bindings/python/tests
With SPH_TEST_INSTALLED=1 the tests import the installed package instead (the wheel check,
bindings/python/check_wheel.sh) and test_installed.py checks that they did.
"""
import collections
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
if os.environ.get("SPH_TEST_INSTALLED") != "1":
    sys.path.insert(0, os.path.dirname(HERE))  # bindings/python

import sph  # noqa: E402
from sph import _loader  # noqa: E402

#: C function name -> number of calls made through the package during this session.
CALLS = collections.Counter()


class _CountingLibrary:
    """Stands in for the CDLL: forwards every attribute and counts calls of sph_* functions."""

    def __init__(self, lib):
        self._lib = lib
        self._sph_path = lib._sph_path

    def __getattr__(self, name):
        fn = getattr(self._lib, name)
        if not name.startswith("sph_"):
            return fn

        def counted(*args):
            CALLS[name] += 1
            return fn(*args)

        return counted


_loader._library = _CountingLibrary(_loader.library())
#: Optional helper libraries (libsph_vdb) this run can load; their functions are counted too.
HELPERS = []
for _name in sph.raw.LIBRARIES[1:]:
    if _name in _loader.CORE_VARIANTS:  # libsph_mpi: the core library itself under mpirun (tests/mpi)
        continue
    try:
        _loader._helpers[_name] = _CountingLibrary(_loader.helper_library(_name))
        HELPERS.append(_name)
    except sph.SphLoadError:
        pass


def pytest_collection_modifyitems(config, items):
    # The coverage check runs last, after everything else had the chance to call the library.
    items.sort(key=lambda item: item.get_closest_marker("coverage_last") is not None)
    config._sph_collected_files = {os.path.basename(str(item.fspath)) for item in items}


def pytest_configure(config):
    config.addinivalue_line("markers", "coverage_last: run after every other test")


@pytest.fixture
def ctx():
    """A CPU context with one worker thread (the tests are small; one thread is fastest)."""
    with sph.Context("cpu", cpu_worker_count=1) as c:
        yield c


@pytest.fixture
def world(ctx):
    with ctx.world(capacity=4096, particle_spacing=0.02) as w:
        yield w
