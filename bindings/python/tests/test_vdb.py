# SPDX-License-Identifier: MIT
"""SDF assets from OpenVDB files (the optional helper library libsph_vdb)."""
import pytest

import sph
from conftest import HELPERS

pytestmark = pytest.mark.skipif("sph_vdb" not in HELPERS, reason="libsph_vdb is not built (no OpenVDB)")


def test_load_a_level_set(ctx, tmp_path):
    vdb = pytest.importorskip("pyopenvdb", reason="python3-openvdb writes the test file")
    ball = vdb.createLevelSetSphere(radius=0.1, center=(0.5, 0, 0), voxelSize=0.01, halfWidth=3.0)
    ball.name = "ball"
    path = tmp_path / "ball.vdb"
    vdb.write(str(path), grids=[ball])
    with ctx.load_vdb(path) as s, sph.Sdf.from_vdb(ctx, str(path), "ball") as named:
        # The asset's local frame is the file's world frame.
        assert s.sample((0.5, 0, 0)) < -0.02  # inside (the narrow band clamps deep values)
        assert s.sample((0.5, 0.1, 0)) == pytest.approx(0.0, abs=0.01)  # on the surface
        assert named.dims == s.dims
    with pytest.raises(sph.SphError) as e:
        ctx.load_vdb(path, "no such grid")
    assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT and "no such grid" in e.value.message


def test_load_errors(ctx, tmp_path):
    with pytest.raises(sph.SphError) as e:
        ctx.load_vdb(tmp_path / "missing.vdb")
    assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT and e.value.message
    garbage = tmp_path / "garbage.vdb"
    garbage.write_bytes(b"not a vdb file" * 10)
    with pytest.raises(sph.SphError) as e:
        ctx.load_vdb(garbage)
    assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
    lib = sph.helper_library("sph_vdb")
    assert lib.sph_vdb_get_last_error().decode()  # still explains the last failure


def test_load_on_a_closed_context(tmp_path):
    c = sph.Context("cpu", cpu_worker_count=1)
    c.close()
    with pytest.raises(sph.SphError) as e:
        c.load_vdb(tmp_path / "x.vdb")
    assert e.value.result in (sph.Result.ERROR_INVALID_HANDLE, sph.Result.ERROR_INVALID_ARGUMENT)
