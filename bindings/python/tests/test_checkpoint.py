# SPDX-License-Identifier: MIT
"""Checkpoints: save/load through bytes and files, bitwise continuation, restore, refusals."""
import ctypes
import os

import numpy as np
import pytest

import sph


def _scene(ctx):
    w = ctx.world(capacity=2000, particle_spacing=0.04)
    w.fill_box((-0.2, 0.03, -0.1), (0.0, 0.2, 0.1))
    tank = ctx.shape("box", half_extents=(0.3, 0.3, 0.2), wall_thickness=0.05, voxel_size=0.05, flags=1)
    collider = w.add_collider(tank, ((0, 0.3, 0), (0, 0, 0, 1)))
    w.add_force_field("vortex", vector=(0, 1, 0), strength=1.0)
    w.add_sink(bounds=((-1, -1, -1), (1, 1, 1)))
    return w, collider


def _state(w):
    return [w.positions(), w.velocities(), w.densities(), w.ids()]


def test_save_load_continues_bitwise(ctx, tmp_path):
    w, collider = _scene(ctx)
    w.step(1 / 60)
    data = w.save()
    assert isinstance(data, bytes) and data[:7] == b"SPHCKPT"
    path = tmp_path / "w.sphckpt"
    w.save_file(path)
    assert path.read_bytes() == data
    assert [p.name for p in tmp_path.iterdir()] == ["w.sphckpt"], "no temporary file is left"
    w.step(1 / 60)
    expected = _state(w)
    for loaded in (ctx.load_world(data), ctx.load_world_file(path), ctx.load_world(bytearray(data))):
        with loaded:
            # The collider's id is valid in the loaded world.
            t = sph.raw.sph_transform()
            sph._errors.check(sph.library().sph_collider_get_transform(loaded.handle, collider.id, ctypes.byref(t)),
                              "sph_collider_get_transform")
            assert tuple(t.position) == pytest.approx((0, 0.3, 0))
            loaded.step(1 / 60)
            for a, b in zip(expected, _state(loaded)):
                assert a.tobytes() == b.tobytes()
    # Restore in place: back to the checkpoint, then the same frame again.
    w.restore(data)
    w.step(1 / 60)
    for a, b in zip(expected, _state(w)):
        assert a.tobytes() == b.tobytes()
    w.close()


def test_damaged_checkpoints_are_refused(ctx, tmp_path):
    with ctx.world(capacity=200) as w:
        w.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
        data = bytearray(w.save())
        live = sph.live_object_count()
        with pytest.raises(sph.SphError) as e:
            ctx.load_world(data[:-1])
        assert e.value.result == sph.Result.ERROR_CORRUPT_DATA and "truncated" in e.value.message
        data[len(data) // 2] ^= 0x40
        with pytest.raises(sph.SphError) as e:
            ctx.load_world(data)
        assert e.value.result == sph.Result.ERROR_CORRUPT_DATA and "checksum" in e.value.message
        with pytest.raises(sph.SphError) as e:
            w.restore(data)
        assert e.value.result == sph.Result.ERROR_CORRUPT_DATA
        assert sph.live_object_count() == live
        with pytest.raises(sph.SphError) as e:
            ctx.load_world_file(tmp_path / "missing.sphckpt")
        assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
        with pytest.raises(sph.SphError) as e:
            w.save_file(tmp_path / "no" / "dir" / "w.sphckpt")
        assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
        assert not os.path.exists(tmp_path / "no")
        assert w.particle_count > 0 and np.all(np.isfinite(w.positions()))
