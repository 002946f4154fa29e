# SPDX-License-Identifier: MIT
"""The installed wheel (SPH_TEST_INSTALLED=1, set by bindings/python/check_wheel.sh): the tests
ran against the package installed in the virtual environment, and it loaded the libsph.so.0
inside the wheel, with neither SPH_LIBRARY nor LD_LIBRARY_PATH set."""
import os
import sys

import pytest

import sph

pytestmark = pytest.mark.skipif(os.environ.get("SPH_TEST_INSTALLED") != "1",
                                reason="only for the installed wheel (bindings/python/check_wheel.sh)")

CHECKOUT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def test_the_package_is_the_installed_one():
    package = os.path.dirname(os.path.abspath(sph.__file__))
    assert package.startswith(os.path.abspath(sys.prefix) + os.sep), (package, sys.prefix)
    assert not package.startswith(os.path.join(CHECKOUT, "bindings", "python") + os.sep), package
    assert sys.prefix != sys.base_prefix, "not in a virtual environment"


def test_the_library_is_the_wheels_copy_found_without_help():
    assert "SPH_LIBRARY" not in os.environ and "LD_LIBRARY_PATH" not in os.environ
    package = os.path.dirname(os.path.abspath(sph.__file__))
    assert os.path.abspath(str(sph.library_path())) == os.path.join(package, "libsph.so.0")
    assert sph.version() == sph.BINDINGS_VERSION
