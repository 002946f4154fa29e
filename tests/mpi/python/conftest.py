# SPDX-License-Identifier: MIT
"""Set-up of the Python tests of distributed worlds, run on every rank under mpirun:

    SPH_LIBRARY=build/libsph_mpi.so mpirun --oversubscribe -np 2 \
        python3 -m pytest -q -p no:cacheprovider tests/mpi/python

Imports mpi4py first (MPI_Init), the package from this checkout, and counts the sph_* calls
that go through the package (as bindings/python/tests/conftest.py does for libsph), so the last
test can ask that every function of sph_mpi.h was called.
"""
import collections
import os
import sys

from mpi4py import MPI  # noqa: F401 - initialises MPI before any world is made

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "bindings", "python"))

import pytest  # noqa: E402

import sph  # noqa: E402
from sph import _loader  # noqa: E402

#: C function name -> calls made through the package in this session.
CALLS = collections.Counter()


class _CountingLibrary:
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


@pytest.fixture
def comm():
    return MPI.COMM_WORLD


@pytest.fixture
def ctx():
    with sph.Context("cpu", cpu_worker_count=1) as c:
        yield c
