# SPDX-License-Identifier: MIT
"""The bindings cover the whole C API: every exported function is wrapped and was called."""
import glob
import os

import pytest

import sph
from sph import _generated as g

from conftest import CALLS, HELPERS

PKG = os.path.dirname(sph.__file__)
TESTS = os.path.dirname(__file__)


def _init_functions():
    """Called for every struct construction by SphStruct (sph/_struct.py)."""
    return {cls._sph_init_ for cls in g.STRUCTS if cls._sph_init_} | \
        {cls._sph_default_ for cls in g.STRUCTS if cls._sph_default_}


def test_every_function_is_used_by_the_package():
    source = "".join(open(p, encoding="utf-8").read() for p in glob.glob(os.path.join(PKG, "*.py"))
                     if not p.endswith("_generated.py"))
    missing = [f for f in g.FUNCTIONS if f".{f}(" not in source and f not in _init_functions()]
    assert not missing, f"C functions with no Pythonic wrapper in sph/: {missing}"


@pytest.mark.coverage_last
def test_every_function_was_called_by_the_tests(request):
    every_file = {os.path.basename(p) for p in glob.glob(os.path.join(TESTS, "test_*.py"))}
    if not every_file <= request.config._sph_collected_files:
        pytest.skip("only part of the suite ran")
    # libsph_mpi's own functions (sph_mpi.h, library "sph_mpi") are out of this run's scope: it
    # loads libsph. tests/mpi/python asks for every one of them under mpirun (ctest -L mpi).
    expected = {name for name, entry in g.FUNCTIONS.items() if entry[4] == "sph" or entry[4] in HELPERS}
    missing = sorted(expected - set(CALLS))
    assert not missing, f"C functions no test reached through the package: {missing}"
