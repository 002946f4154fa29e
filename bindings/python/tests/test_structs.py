# SPDX-License-Identifier: MIT
"""The generated structs: defaults from the library, keyword construction, conversions."""
import ctypes

import numpy as np
import pytest

import sph


def test_defaults_come_from_the_init_functions():
    p = sph.WorldParams()
    assert p.struct_size == ctypes.sizeof(sph.WorldParams) == 52
    assert (p.max_substeps, p.stiffness, p.viscosity, p.tension_ratio) == (10000, 100, 1, 0)
    d = sph.WorldDef()
    assert d.header_version == sph.raw.SPH_VERSION  # what the inline sph_world_def_init adds
    assert sph.ContextDef().header_version == sph.raw.SPH_VERSION
    assert sph.ContextDef().device_ordinal == -1
    assert sph.Stats().struct_size == ctypes.sizeof(sph.Stats)


def test_keyword_and_positional_construction():
    p = sph.WorldParams(gravity=(0, 0, -1), viscosity=3)
    assert tuple(p.gravity) == (0, 0, -1) and p.viscosity == 3
    v = sph.Vec3(1, 2, 3)
    assert tuple(v) == (1, 2, 3) and list(v) == [1, 2, 3]
    p.gravity = np.array([4, 5, 6], np.float64)
    assert tuple(p.gravity) == (4, 5, 6)
    p.gravity = {"x": 1, "y": 0, "z": 0}
    assert p.gravity == sph.Vec3(1, 0, 0)
    s = sph.Stats(stage_ms=range(8))
    assert list(s.stage_ms) == list(range(8))
    with pytest.raises(ValueError):
        sph.Stats(stage_ms=[1, 2])
    with pytest.raises(TypeError):
        sph.Vec3(1, 2, 3, 4)
    with pytest.raises(AttributeError):
        sph.WorldParams(gravty=(0, 0, 0))
    with pytest.raises(TypeError):
        iter(sph.WorldParams())


def test_enum_fields_read_back_as_enums():
    d = sph.ContextDef(backend=sph.Backend.CPU)
    assert d.backend is sph.Backend.CPU
    d.backend = 77  # unknown values pass through as ints (a newer library may know them)
    assert d.backend == 77


def test_equality_copy_repr_and_dict():
    a = sph.WorldParams(viscosity=2)
    b = a.copy()
    assert a == b and a is not b
    b.viscosity = 3
    assert a != b
    assert "viscosity=2.0" in repr(a) and "Vec3(x=0.0, y=-9.81, z=0.0)" in repr(a)
    d = a.to_dict()
    assert d["gravity"] == {"x": 0.0, "y": pytest.approx(-9.81), "z": 0.0}
    assert "positions=NULL" in repr(sph.SpawnDesc())
    assert sph.ContextDef().to_dict()["log_fn"] is None


def test_c_and_python_names_are_the_same_classes():
    assert sph.raw.sph_world_params is sph.WorldParams
    assert sph.WorldParams._sph_c_name_ == "sph_world_params"
    assert sph.raw.sph_result is ctypes.c_int32
