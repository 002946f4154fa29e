# SPDX-License-Identifier: MIT
"""bindings/cffi/sph_cdef.h: cffi parses it, its layouts are the C compiler's, and it drives the
library (issue 22: cffi's cdef rejects sph_c.h itself)."""
import json
import os

import pytest

cffi = pytest.importorskip("cffi", reason="python3-cffi parses the declaration file")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
CDEF = os.path.join(ROOT, "bindings", "cffi", "sph_cdef.h")
API = os.path.join(ROOT, "bindings", "api", "sph_api.json")


@pytest.fixture(scope="module")
def ffi():
    f = cffi.FFI()
    with open(CDEF) as fh:
        f.cdef(fh.read())
    return f


@pytest.fixture(scope="module")
def api():
    with open(API) as fh:
        return json.load(fh)


def test_every_struct_has_the_compilers_layout(ffi, api):
    # sph_api.json's sizes and offsets were measured by the C compiler on the real header.
    for s in api["structs"]:
        assert ffi.sizeof(s["name"]) == s["size"], s["name"]
        for field in s["fields"]:
            assert ffi.offsetof(s["name"], field["name"]) == field["offset"], (s["name"], field["name"])


def test_every_function_and_enum_is_declared(ffi, api):
    import sph

    lib = ffi.dlopen(str(sph.library_path()))
    for e in api["enums"]:
        for m in e["members"]:
            assert getattr(lib, m["name"]) == m["value"], m["name"]
    for d in api["defines"]:
        if isinstance(d.get("value"), int):
            assert getattr(lib, d["name"]) == d["value"], d["name"]
    names = {f["name"] for f in api["functions"]}
    with open(CDEF) as fh:
        text = fh.read()
    for name in names:
        assert f" {name}(" in text or f"*{name}(" in text, name


def test_drives_the_library(ffi):
    import sph  # finds the library as the other tests do (SPH_LIBRARY in ctest)

    lib = ffi.dlopen(str(sph.library_path()))
    assert lib.sph_get_version() == (lib.SPH_VERSION_MAJOR << 22) | (lib.SPH_VERSION_MINOR << 12) | lib.SPH_VERSION_PATCH
    cdef = ffi.new("sph_context_def*")
    assert lib.sph_context_def_init_sized(cdef, ffi.sizeof("sph_context_def")) == lib.SPH_OK
    cdef.backend = lib.SPH_BACKEND_CPU
    cdef.cpu_worker_count = 1
    ctx = ffi.new("sph_context**")
    assert lib.sph_context_create(cdef, ctx) == lib.SPH_OK
    try:
        wdef = ffi.new("sph_world_def*")
        assert lib.sph_world_def_init_sized(wdef, ffi.sizeof("sph_world_def")) == lib.SPH_OK
        wdef.capacity = 1000
        world = ffi.new("sph_world**")
        assert lib.sph_world_create(ctx[0], wdef, world) == lib.SPH_OK
        box = ffi.new("sph_fill_box_desc*")
        assert lib.sph_fill_box_desc_init_sized(box, ffi.sizeof("sph_fill_box_desc")) == lib.SPH_OK
        box.min.x, box.min.y, box.min.z = 0.0, 0.0, 0.0
        box.max.x, box.max.y, box.max.z = 0.1, 0.1, 0.1
        filled = ffi.new("uint32_t*")
        assert lib.sph_world_fill_box(world[0], box, filled) >= lib.SPH_OK
        count = ffi.new("uint32_t*")
        assert lib.sph_world_get_particle_count(world[0], count) == lib.SPH_OK
        assert count[0] == filled[0] > 0
        lib.sph_world_destroy(world[0])
    finally:
        lib.sph_context_destroy(ctx[0])
