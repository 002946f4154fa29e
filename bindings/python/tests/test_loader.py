# SPDX-License-Identifier: MIT
"""Loading the library: search order, ABI version, exported functions, struct layouts."""
import ctypes
import ctypes.util
import json
import os
import subprocess
import sys

import pytest

import sph
from sph._struct import checked_argtype
from sph import _generated as g
from sph import _loader

API_JSON = os.path.join(os.path.dirname(__file__), "..", "..", "api", "sph_api.json")


@pytest.fixture(scope="module")
def api():
    with open(API_JSON, encoding="utf-8") as f:
        return json.load(f)


def test_abi_and_version_match_the_bindings():
    assert sph.abi_version() == g.ABI_VERSION == sph.ABI_VERSION
    assert sph.version()[0] == sph.BINDINGS_VERSION[0]
    assert sph.version() == sph.BINDINGS_VERSION  # built from the same checkout
    assert sph.make_version(*sph.version()) == g.SPH_VERSION
    assert sph.build_info().startswith("sph ")
    assert os.path.exists(sph.library_path()) or sph.library_path().startswith("lib")


def test_every_struct_size_and_offset_matches_the_c_compiler(api):
    by_name = {s["name"]: s for s in api["structs"]}
    assert len(g.STRUCTS) == len(api["structs"]) > 0
    for cls in g.STRUCTS:
        c = by_name[cls._sph_c_name_]
        assert ctypes.sizeof(cls) == c["size"] == cls._sph_size_, cls.__name__
        for f in c["fields"]:
            assert getattr(cls, f["name"]).offset == f["offset"], f"{cls.__name__}.{f['name']}"
            assert getattr(cls, f["name"]).size == f["size"], f"{cls.__name__}.{f['name']}"
    _loader.check_layouts()  # what the loader ran at import, once more


def test_layout_check_rejects_a_wrong_size():
    class Bad(g.Vec3):
        _sph_size_ = 16
    with pytest.raises(sph.SphLoadError, match="Bad: ctypes.sizeof 12 != C sizeof 16"):
        _loader.check_layouts((Bad,))
    with pytest.raises(sph.SphLoadError, match="bit pointers"):
        _loader.check_layouts((), pointer_size=4)


def test_abi_check_rejects_another_abi():
    with pytest.raises(sph.SphLoadError, match="generated for ABI 99"):
        _loader.check_abi(_loader.library(), expected=99)


def test_every_function_is_bound_with_its_prototype(api):
    lib = _loader.library()
    assert {f["name"] for f in api["functions"]} == set(g.FUNCTIONS)
    for name, (restype, argtypes, _, doc, library) in g.FUNCTIONS.items():
        if library != "sph":
            continue
        fn = getattr(lib._lib, name)
        # Integer parameters carry a range check (checked_argtype); each is its C type still.
        assert fn.restype is restype and tuple(fn.argtypes) == tuple(checked_argtype(t) for t in argtypes), name
        assert all(issubclass(got, want) for got, want in zip(fn.argtypes, argtypes)), name
        assert fn.__doc__ == doc


def test_enums_match_the_header(api):
    for e in api["enums"]:
        for m in e["members"]:
            assert getattr(g, m["name"]) == m["value"]
    assert sph.Result.ERROR_CAPACITY == g.SPH_ERROR_CAPACITY
    assert sph.Backend.CPU == g.SPH_BACKEND_CPU
    assert not hasattr(sph.Stage, "COUNT") and not hasattr(sph.Result, "FORCE32")


def test_load_of_a_missing_path_raises():
    with pytest.raises(sph.SphLoadError, match="cannot load"):
        _loader.load("/nonexistent/libsph.so.0")


def test_load_of_a_library_that_is_not_sph_raises():
    libm = ctypes.util.find_library("m") or "libm.so.6"
    with pytest.raises(sph.SphLoadError, match="not the sph library"):
        _loader.load(libm)


def test_sph_library_env_var_is_obeyed_without_fallback(tmp_path):
    code = "import sph\ntry:\n    sph.library()\nexcept sph.SphLoadError as e:\n    print('LOADERROR', e)\n"
    env = dict(os.environ, SPH_LIBRARY=str(tmp_path / "libsph.so"),
               PYTHONPATH=os.path.join(os.path.dirname(__file__), ".."))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert "LOADERROR" in out.stdout and "SPH_LIBRARY=" in out.stdout, out.stdout + out.stderr


def test_import_does_not_load_the_library(tmp_path):
    # Importing works without a library (docs, tooling); the first call loads it.
    code = "import sph\nfrom sph import _loader\nprint('LOADED' if _loader._library else 'LAZY')\n"
    env = dict(os.environ, SPH_LIBRARY=str(tmp_path / "missing.so"),
               PYTHONPATH=os.path.join(os.path.dirname(__file__), ".."))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "LAZY", out.stdout + out.stderr
