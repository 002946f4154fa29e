# SPDX-License-Identifier: MIT
"""Hostile use of the Python binding (issue 23, item 2): array shapes the library would read
past, and integers ctypes would wrap silently into C's fixed-width types. Part of the
hostile-input suite (the C side is ctest label `hostile`; this file is collected by name)."""
import ctypes

import numpy as np
import pytest

import sph


def sphere_sdf(ctx, n=8):
    return ctx.shape("sphere", radius=0.05, voxel_size=0.02)


@pytest.mark.parametrize("shape", [(2, 2, 2), (2, 2, 2, 1), (2, 2, 2, 4), (2, 2, 6), (2, 2)])
def test_velocity_update_needs_three_components(ctx, shape):
    # A (2, 2, 2) array for the velocity channel made the library read 3 x 8 floats from a
    # buffer of 8 (heap-buffer-overflow under ASan): refused before the call.
    with sphere_sdf(ctx) as s:
        with pytest.raises(ValueError, match="velocity channel needs shape"):
            s.update("velocity", np.ones(shape, np.float32))
        s.update("velocity", np.ones((2, 2, 2, 3), np.float32))  # the right shape works


@pytest.mark.parametrize("channel", ["distance", "friction"])
@pytest.mark.parametrize("shape", [(2, 2, 2, 3), (2, 2), (0, 2, 2)])
def test_scalar_updates_need_three_axes(ctx, channel, shape):
    with sphere_sdf(ctx) as s:
        with pytest.raises(ValueError, match="data"):
            s.update(channel, np.ones(shape, np.float32))


@pytest.mark.parametrize("origin", [(1, 1), (1, 1, 1, 1), (-1, 0, 0), (2**32 + 1, 0, 0)])
def test_update_origin_is_three_grid_indices(ctx, origin):
    with sphere_sdf(ctx) as s:
        with pytest.raises((ValueError, OverflowError), match="origin"):
            s.update("distance", np.ones((1, 1, 1), np.float32), origin=origin)


def test_struct_fields_refuse_integers_that_do_not_fit(ctx):
    # ctypes stored 2**32 + 5 into a uint32 field as 5: a capacity the caller never asked for.
    for value in (2**32 + 5, -1, 2**64):
        with pytest.raises(OverflowError, match=r"WorldDef\.capacity"):
            sph.WorldDef(capacity=value)
    with pytest.raises(OverflowError, match="int32"):
        sph.ContextDef(device_ordinal=2**31)
    with pytest.raises(OverflowError, match=r"SpawnDesc\.position_stride"):
        sph.SpawnDesc(position_stride=2**64)
    with pytest.raises(OverflowError, match=r"GridDesc\.dims\[1\]"):
        sph.GridDesc(dims=(1, 2**32, 1))
    # Enum fields: a value beyond int32 is refused; a member, name or in-range int passes.
    with pytest.raises(OverflowError):
        sph.WorldDef(integrator=2**32)
    assert sph.WorldDef(capacity=2**32 - 1, integrator="rk4").capacity == 2**32 - 1
    assert sph.ContextDef(device_ordinal=-1).device_ordinal == -1
    with pytest.raises(OverflowError):
        ctx.world(capacity=2**32 + 5)


def test_function_arguments_refuse_integers_that_do_not_fit(world):
    world.fill_box((0, 0, 0), (0.05, 0.05, 0.05))
    n = world.particle_count
    with pytest.raises(OverflowError, match="first"):
        world.copy_attribute(sph.Attribute.DENSITY, first=2**32 + 1)
    with pytest.raises(OverflowError, match="count"):
        world.copy_attribute(sph.Attribute.DENSITY, count=-1)
    # The raw functions too: every integer parameter is range-checked by its C type.
    lib = sph.library()
    out = np.empty(n, np.float32)
    written = ctypes.c_uint32()
    with pytest.raises(ctypes.ArgumentError, match="does not fit uint32"):
        lib.sph_world_copy_attribute(world.handle, int(sph.Attribute.DENSITY), ctypes.c_void_p(out.ctypes.data),
                                     out.nbytes, 0, 2**32 + 5, n, ctypes.byref(written))
    with pytest.raises(ctypes.ArgumentError, match="does not fit uint64"):
        lib.sph_world_copy_attribute(world.handle, int(sph.Attribute.DENSITY), ctypes.c_void_p(out.ctypes.data),
                                     -1, 0, 0, n, ctypes.byref(written))
    with pytest.raises(ctypes.ArgumentError, match="does not fit int32"):
        lib.sph_world_copy_attribute(world.handle, 2**31, ctypes.c_void_p(out.ctypes.data), out.nbytes, 0, 0, n,
                                     ctypes.byref(written))
    # In range, the same call works.
    assert lib.sph_world_copy_attribute(world.handle, int(sph.Attribute.DENSITY), ctypes.c_void_p(out.ctypes.data),
                                        out.nbytes, 0, 0, n, ctypes.byref(written)) == sph.Result.OK
    assert written.value == n


def test_spawn_and_copy_shapes_are_checked(world):
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        world.spawn(np.zeros((4, 2), np.float32))
    with pytest.raises(ValueError, match="velocities"):
        world.spawn(np.zeros((4, 3), np.float32), velocities=np.zeros((3, 3), np.float32))
    world.spawn(np.arange(12, dtype=np.float32).reshape(4, 3) * 0.02)
    with pytest.raises(ValueError, match="out"):
        world.copy_attribute(sph.Attribute.POSITION, out=np.empty((4, 2), np.float32))
    with pytest.raises(ValueError, match="stride"):
        world.copy_attribute(sph.Attribute.POSITION, out=np.empty((4, 3), np.float32)[::-1])


def test_step_budget_and_cancel_bound_a_step(world):
    # What one call may cost (issue 23 item 9): a frame of 10,000 fixed substeps stops early,
    # consistent, under a budget or a cancel; bad budgets and max_substeps beyond 10^6 are refused.
    import threading
    import time
    world.fill_box((0.0, 0.0, 0.0), (0.16, 0.16, 0.16))
    world.set_params(dt_min=1e-4, dt_max=1e-4)
    assert world.step_budget == 0.0
    world.step_budget = 0.05
    assert world.step_budget == 0.05
    assert world.step(1.0) == sph.Result.INCOMPLETE
    assert 1 <= world.stats().substeps < 10000
    world.step_budget = 0.0
    for bad in (-1.0, float("nan"), 1e9):
        with pytest.raises(sph.SphError, match="max_seconds"):
            world.step_budget = bad
    world.cancel_step()  # no step running: the next one stops before its first substep
    assert world.step(1.0) == sph.Result.INCOMPLETE
    assert world.stats().substeps == 0
    timer = threading.Timer(0.05, world.cancel_step)
    timer.start()
    started = time.monotonic()
    assert world.step(1.0) == sph.Result.INCOMPLETE
    timer.join()
    assert 1 <= world.stats().substeps < 10000, time.monotonic() - started
    assert world.step(2e-4) == sph.Result.OK
    with pytest.raises(sph.SphError, match="max_substeps"):
        world.set_params(max_substeps=1_000_001)
