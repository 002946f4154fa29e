# SPDX-License-Identifier: MIT
"""Worlds: defs, params, spawning from numpy, fills, stepping, reading back, stats, errors."""
import ctypes
import gc

import numpy as np
import pytest

import sph
from sph import _generated as _g


def raw(name, *args):
    """Calls a C function directly (for arguments the Pythonic layer never passes)."""
    return sph._errors.check(getattr(sph.library(), name)(*args), name)


def error(fn, *args, **kwargs):
    with pytest.raises(sph.SphError) as e:
        fn(*args, **kwargs)
    assert e.value.message, "the library explained the failure"
    return e.value.result


# ---- creation -------------------------------------------------------------------------------------
def test_definition_resolves_defaults(world):
    d = world.definition
    assert isinstance(d, sph.WorldDef)
    assert d.capacity == 4096
    assert d.kernel_radius == pytest.approx(1.8 * 0.02)
    assert d.integrator == sph.Integrator.SYMPLECTIC_EULER and isinstance(d.integrator, sph.Integrator)
    assert d.rest_density == 1000
    assert world.particle_mass > 0


def test_world_from_a_def_and_keywords(ctx):
    d = sph.WorldDef(particle_spacing=0.05, integrator=sph.Integrator.RK4)
    with ctx.world(d, capacity=7) as w:
        assert (w.definition.capacity, w.definition.integrator) == (7, sph.Integrator.RK4)
    assert d.capacity == 65536  # the caller's def is not modified


@pytest.mark.parametrize("fields, result", [
    ({"capacity": 2**31}, sph.Result.ERROR_INVALID_ARGUMENT),
    ({"particle_spacing": -1.0}, sph.Result.ERROR_INVALID_ARGUMENT),
    ({"particle_spacing": float("nan")}, sph.Result.ERROR_INVALID_ARGUMENT),
    ({"kernel_radius": 0.01}, sph.Result.ERROR_INVALID_ARGUMENT),
    ({"rest_density": -1.0}, sph.Result.ERROR_INVALID_ARGUMENT),
    ({"integrator": 9}, sph.Result.ERROR_UNSUPPORTED),
    ({"features": 0x80}, sph.Result.ERROR_UNSUPPORTED),
    ({"struct_size": 8}, sph.Result.ERROR_VERSION_MISMATCH),
])
def test_bad_world_def(ctx, fields, result):
    assert error(ctx.world, **fields) == result


def test_zero_fields_of_the_world_def_are_its_defaults(ctx):
    with ctx.world(capacity=0, particle_spacing=0.0, rest_density=0.0) as w:
        d = w.definition
        assert (d.capacity, d.rest_density) == (65536, 1000.0)
        assert d.particle_spacing == pytest.approx(0.02) and d.kernel_radius == pytest.approx(1.8 * 0.02)


def test_unknown_field_is_an_error_not_a_silent_typo(ctx):
    with pytest.raises(AttributeError, match="capacityy"):
        ctx.world(capacityy=10)


# ---- runtime parameters ------------------------------------------------------------------------
def test_params_round_trip(world):
    p = world.params
    assert tuple(p.gravity) == pytest.approx((0, -9.81, 0))
    p.gravity = (0, 0, -1)
    p.viscosity = 2.5
    world.params = p
    assert world.params == p
    q = world.set_params(step_factor=0.2)
    assert world.params.step_factor == pytest.approx(0.2) and tuple(q.gravity) == (0, 0, -1)


def test_params_take_a_dict(world):
    """w.params = {...}, as every other params setter: the named fields over the defaults."""
    world.set_params(viscosity=2.5)
    world.params = {"gravity": (0, 0, -1), "step_factor": 0.2}
    p = world.params
    assert tuple(p.gravity) == (0, 0, -1) and p.step_factor == pytest.approx(0.2)
    assert p.viscosity == sph.WorldParams().viscosity, "a field not named is at its default"
    with pytest.raises(AttributeError, match="no_such_field"):
        world.params = {"no_such_field": 1}
    assert error(setattr, world, "params", {"stiffness": -1.0}) == sph.Result.ERROR_INVALID_ARGUMENT
    assert world.params == p
    with pytest.raises(TypeError):
        world.params = sph.TaitParams()


def test_bad_params_change_nothing(world):
    before = world.params
    assert error(world.set_params, stiffness=-1.0) == sph.Result.ERROR_INVALID_ARGUMENT
    assert error(world.set_params, dt_max=1e-9) == sph.Result.ERROR_INVALID_ARGUMENT  # < dt_min
    assert error(world.set_params, step_factor=11.0) == sph.Result.ERROR_INVALID_ARGUMENT
    assert world.params == before
    # A 0 that was never a valid value takes the default (zero means default, sph_c.h).
    world.set_params(max_substeps=0)
    assert world.params.max_substeps == 10000
    world.params = before
    p = sph.WorldParams()
    p.struct_size = 4
    assert error(setattr, world, "params", p) == sph.Result.ERROR_VERSION_MISMATCH
    assert error(raw, "sph_world_get_params", world.handle, ctypes.byref(p)) == sph.Result.ERROR_VERSION_MISMATCH
    s = sph.Stats()
    s.struct_size = 4
    assert error(raw, "sph_world_get_stats", world.handle, ctypes.byref(s)) == sph.Result.ERROR_VERSION_MISMATCH
    d = sph.WorldDef()
    d.struct_size = 4
    assert error(raw, "sph_world_get_def", world.handle, ctypes.byref(d)) == sph.Result.ERROR_VERSION_MISMATCH


# ---- spawning and reading back -----------------------------------------------------------------
def _by_id(world, first):
    order = np.argsort(world.ids())
    return order, world.ids()[order] - first


def test_spawn_and_read_back_by_id(world):
    rng = np.random.default_rng(1)
    pos = rng.uniform(-1, 1, (300, 3)).astype(np.float32)
    vel = rng.uniform(-2, 2, (300, 3)).astype(np.float32)
    first = world.spawn(pos, vel)
    assert len(world) == world.particle_count == 300
    ids = world.ids()
    assert ids.dtype == np.uint32 and sorted(ids - first) == list(range(300))
    got_pos, got_vel = world.positions(), world.velocities()
    assert got_pos.dtype == np.float32 and got_pos.shape == (300, 3)
    np.testing.assert_array_equal(got_pos, pos[ids - first])
    np.testing.assert_array_equal(got_vel, vel[ids - first])
    second = world.spawn(np.zeros((2, 3)))  # float64 is converted; ids continue
    assert second == first + 300


def test_spawn_uses_the_row_stride_of_numpy_views(world):
    table = np.zeros((100, 7), np.float32)  # x y z vx vy vz tag
    table[:, 0] = np.arange(100)
    table[:, 3:6] = 1.5
    pos, vel = table[:, 0:3], table[:, 3:6]
    assert pos.strides == (28, 4) and not pos.flags.c_contiguous
    first = world.spawn(pos, vel)
    ids = world.ids()
    np.testing.assert_array_equal(world.positions()[:, 0], ids - first)
    assert (world.velocities() == 1.5).all()


def test_spawn_single_point_and_empty(world):
    world.spawn((0.1, 0.2, 0.3))
    world.spawn(np.empty((0, 3), np.float32))
    assert len(world) == 1
    np.testing.assert_allclose(world.positions(), [[0.1, 0.2, 0.3]])


def test_spawn_errors_leave_the_world_unchanged(ctx):
    with ctx.world(capacity=8) as w:
        assert error(w.spawn, np.zeros((9, 3))) == sph.Result.ERROR_CAPACITY
        bad = np.zeros((3, 3))
        bad[1, 1] = np.inf
        assert error(w.spawn, bad) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.spawn, np.zeros((2, 3)), np.full((2, 3), np.nan)) == sph.Result.ERROR_INVALID_ARGUMENT
        assert len(w) == 0
        with pytest.raises(ValueError):
            w.spawn(np.zeros((2, 2)))
        with pytest.raises(ValueError):
            w.spawn(np.zeros((2, 3)), np.zeros((3, 3)))


def test_growable_world_grows_on_demand_up_to_its_maximum(ctx):
    # max_capacity lets the capacity grow: to max(needed, 2 x capacity), up to the maximum.
    with ctx.world(capacity=10, max_capacity=100, particle_spacing=0.05) as w:
        assert w.definition.max_capacity == 100
        row = np.array([[0.05 * i, 0.0, 0.0] for i in range(100)], dtype=np.float32)
        w.spawn(row[:25])
        s = w.stats()
        assert (s.capacity, s.max_capacity, s.capacity_growths) == (25, 100, 1)
        w.spawn(row[25:26])
        assert (w.stats().capacity, w.definition.capacity) == (50, 50)
        with pytest.raises(sph.SphError) as e:
            w.spawn(row[26:] + np.float32(1.0))  # 26 + 74 = 100 fits, 101 would not
            w.spawn(row[:1] + np.float32(2.0))
        assert e.value.result == sph.Result.ERROR_CAPACITY
        assert "max_capacity 100" in e.value.message
        assert w.particle_count == 100 and w.stats().capacity == 100
    # The default is a fixed world.
    with ctx.world(capacity=10) as w:
        assert w.definition.max_capacity == 10
        assert error(w.spawn, np.zeros((11, 3), dtype=np.float32)) == sph.Result.ERROR_CAPACITY


def test_raw_spawn_desc_errors(world):
    d = sph.SpawnDesc(count=1)  # positions NULL
    assert error(raw, "sph_world_spawn", world.handle, ctypes.byref(d), None) == sph.Result.ERROR_INVALID_ARGUMENT
    pos = np.zeros((2, 3), np.float32)
    d = sph.SpawnDesc(count=2, positions=pos.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), position_stride=8)
    assert error(raw, "sph_world_spawn", world.handle, ctypes.byref(d), None) == sph.Result.ERROR_INVALID_ARGUMENT
    assert len(world) == 0


def test_copy_attribute_into_given_and_strided_arrays(world):
    n = world.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
    table = np.full((n, 8), -7, np.float32)
    out = world.copy_attribute(sph.Attribute.POSITION, out=table[:, 2:5])
    assert np.shares_memory(out, table) and out.base is not None
    np.testing.assert_array_equal(table[:, 2:5], world.positions())
    assert (table[:, :2] == -7).all() and (table[:, 5:] == -7).all()
    dens = np.empty(n, np.float32)
    assert world.copy_attribute(sph.Attribute.DENSITY, out=dens) is not None
    part = world.copy_attribute(sph.Attribute.ID, first=n - 3)
    assert len(part) == 3 and (part == world.ids()[-3:]).all()
    assert len(world.copy_attribute(sph.Attribute.VELOCITY, first=2, count=5)) == 5
    assert len(world.copy_attribute(sph.Attribute.PRESSURE, first=n)) == 0
    with pytest.raises(ValueError):
        world.copy_attribute(sph.Attribute.POSITION, out=np.empty((n, 3), np.float64))
    with pytest.raises(ValueError):
        world.copy_attribute(sph.Attribute.ID, out=np.empty(n, np.float32))


def test_copy_attribute_errors(world):
    world.fill_sphere((0, 0, 0), 0.04)
    n = len(world)
    assert error(world.copy_attribute, sph.Attribute.ID, first=n + 1) == sph.Result.ERROR_INVALID_ARGUMENT
    buf = np.empty(30, np.float32)

    def copy(attribute, dst, size, stride, first, count):
        return raw("sph_world_copy_attribute", world.handle, attribute, dst, size, stride, first, count, None)
    p = buf.ctypes.data
    assert error(copy, 0, p, 8, 0, 0, 10) == sph.Result.ERROR_BUFFER_TOO_SMALL
    assert error(copy, 0, p, 120, 4, 0, 10) == sph.Result.ERROR_INVALID_ARGUMENT  # stride < 12
    assert error(copy, 0, None, 120, 0, 0, 10) == sph.Result.ERROR_INVALID_ARGUMENT
    assert error(copy, 99, p, 120, 0, 0, 10) == sph.Result.ERROR_UNSUPPORTED


def test_attribute_formats_come_from_the_header():
    assert sph.attribute_format(sph.Attribute.POSITION) == (np.dtype(np.float32), 3)
    assert sph.attribute_format(sph.Attribute.DENSITY) == (np.dtype(np.float32), 1)
    assert sph.attribute_format(sph.Attribute.ID) == (np.dtype(np.uint32), 1)
    for a in sph.Attribute:
        sph.attribute_format(a)  # every attribute documents its format


# ---- fills ---------------------------------------------------------------------------------------------
def test_fills(ctx):
    with ctx.world(capacity=20000, particle_spacing=0.02) as w:
        box = w.fill_box((0, 0, 0), (0.1, 0.1, 0.1), velocity=(1, 0, 0))
        sphere = w.fill_sphere(center=(1, 1, 1), radius=0.05)
        assert box > 50 and sphere > 20 and len(w) == box + sphere
        v = w.velocities()
        assert (v[:, 0] == 1).sum() == box
        inside = np.linalg.norm(w.positions() - 1, axis=1) <= 0.05 + 1e-6
        assert inside.sum() == sphere
        assert error(w.fill_box, (1, 1, 1), (0, 0, 0)) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.fill_sphere, (0, 0, 0), -1) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.fill_sphere, (0, 0, np.nan), 1) == sph.Result.ERROR_INVALID_ARGUMENT
    with ctx.world(capacity=10) as small:
        assert error(small.fill_box, (0, 0, 0), (0.2, 0.2, 0.2)) == sph.Result.ERROR_CAPACITY
        assert len(small) == 0


# ---- stepping and statistics ---------------------------------------------------------------------
def test_step_and_stats(world):
    s = world.stats()
    assert s.substeps == 0 and s.simulated_time == 0
    n = world.fill_sphere((0, 0, 0), 0.06)
    assert world.step(1 / 120) == sph.Result.OK
    s = world.stats()
    assert s.particle_count == n and 0 < s.substeps <= 20
    assert s.frame_time == pytest.approx(1 / 120) and s.simulated_time == pytest.approx(1 / 120)
    assert 500 < s.density_mean < 1100 and s.density_min <= s.density_mean <= s.density_max
    assert s.memory_bytes > 0
    d = s.to_dict()
    assert d["substeps"] == s.substeps and len(d["stage_ms"]) == 8
    times = sph.stage_times(s)
    assert set(times) == set(sph.Stage) and all(t >= 0 for t in times.values())
    # Gravity pulled everything down.
    assert world.velocities()[:, 1].mean() < 0


def test_step_incomplete_when_substeps_run_out(world):
    world.fill_sphere((0, 0, 0), 0.04)
    world.set_params(max_substeps=2)
    assert world.step(0.5) == sph.Result.INCOMPLETE
    s = world.stats()
    assert s.substeps == 2 and s.frame_time < 0.5


@pytest.mark.parametrize("dt", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_frame_dt(world, dt):
    assert error(world.step, dt) == sph.Result.ERROR_INVALID_ARGUMENT


def test_closed_world_is_an_invalid_handle(ctx):
    w = ctx.world(capacity=10)
    w.close()
    assert w.closed and repr(w) == "<sph.World closed>"
    for call in (lambda: w.particle_count, lambda: w.step(0.01), w.positions, w.stats, lambda: w.params,
                 lambda: w.definition, lambda: w.particle_mass, lambda: w.fill_sphere((0, 0, 0), 1)):
        assert error(call) == sph.Result.ERROR_INVALID_HANDLE


def test_two_worlds_are_independent(ctx):
    with ctx.world(capacity=1000) as a, ctx.world(capacity=1000) as b:
        a.fill_sphere((0, 0, 0), 0.05)
        b.set_params(gravity=(0, 0, 0))
        b.fill_sphere((0, 0, 0), 0.05)
        a.step(0.01)
        b.step(0.01)
        assert a.velocities()[:, 1].mean() < -0.05
        assert abs(b.velocities()[:, 1].mean()) < 1e-3


def test_asynchronous_step_matches_step(ctx):
    # sph_world_step_begin / _wait / _poll (issue 21 item 1): the same frames as step(), the
    # world held meanwhile (WORLD_LOCKED), misuse refused.
    with ctx.world(capacity=4096, particle_spacing=0.02) as a, ctx.world(capacity=4096, particle_spacing=0.02) as b:
        for w in (a, b):
            w.fill_box((0.0, 0.0, 0.0), (0.16, 0.16, 0.16))
        for _ in range(2):
            assert a.step(1.0 / 60.0) == sph.Result.OK
            b.step_begin(1.0 / 60.0)
            with pytest.raises(sph.SphError) as locked:
                b.particle_count
            assert locked.value.result == sph.Result.ERROR_WORLD_LOCKED
            while not b.step_done():
                pass
            assert b.step_wait() == sph.Result.OK
            assert np.array_equal(a.positions(), b.positions())
        with pytest.raises(sph.SphError, match="no step was begun"):
            b.step_wait()
        with pytest.raises(sph.SphError, match="no step was begun"):
            b.step_done()
        with pytest.raises(sph.SphError, match="frame_dt"):
            b.step_begin(float("nan"))


def test_close_with_a_step_in_flight_keeps_the_world():
    with sph.Context("cpu", cpu_worker_count=1) as c:
        w = c.world(capacity=4096, particle_spacing=0.02)
        w.fill_box((0.0, 0.0, 0.0), (0.16, 0.16, 0.16))
        w.step_begin(1.0 / 60.0)
        assert error(w.close) == sph.Result.ERROR_WORLD_LOCKED
        assert not w.closed
        assert w.step_wait() == sph.Result.OK
        w.close()
        assert w.closed


def test_dropping_a_world_with_a_step_in_flight_waits_for_it():
    """__del__ cancels and collects the step, then destroys the world: its context closes."""
    before = sph.live_object_count()
    c = sph.Context("cpu", cpu_worker_count=1)
    w = c.world(capacity=20000, particle_spacing=0.01)
    w.fill_box((0.0, 0.0, 0.0), (0.2, 0.2, 0.2))
    w.step_begin(1.0)
    assert sph.live_object_count() == before + 2
    del w
    gc.collect()
    assert sph.live_object_count() == before + 1, "the world was destroyed"
    c.close()
    assert sph.live_object_count() == before


class _HeldTasks:
    """A task system (ContextDef.enqueue_task/finish_task) that runs each task when enqueued,
    except while `hold` is set: then it runs it in finish_task."""

    def __init__(self):
        self.hold = False
        self.held = {}
        self.enqueue = _g.sph_enqueue_task_fn(self._enqueue)
        self.finish = _g.sph_finish_task_fn(self._finish)

    def _enqueue(self, task, item_count, _min_range, task_context, _user):
        if not self.hold:
            task(0, item_count, 0, task_context)
            return None
        handle = len(self.held) + 1
        self.held[handle] = (task, item_count, task_context)
        return handle

    def _finish(self, handle, _user):
        task, item_count, task_context = self.held.pop(handle)
        task(0, item_count, 0, task_context)


def test_dropping_a_world_whose_step_needs_python_leaks_it():
    """With Python task-system hooks, an unfinished step may need Python code to end: the
    finaliser leaks the world and its context (a ResourceWarning) instead of waiting forever."""
    from sph import _core

    tasks = _HeldTasks()
    before = sph.live_object_count()
    c = sph.Context("cpu", definition=sph.ContextDef(enqueue_task=tasks.enqueue, finish_task=tasks.finish))
    w = c.world(capacity=4096, particle_spacing=0.02)
    w.fill_box((0.0, 0.0, 0.0), (0.1, 0.1, 0.1))
    tasks.hold = True
    w.step_begin(1.0 / 60.0)
    tasks.hold = False
    assert not w.step_done(), "the step waits for its task"
    with pytest.warns(ResourceWarning, match="asynchronous step in flight"):
        del w
        gc.collect()
    ptr, context = _core._LEAKED[-1]
    assert context is c and sph.live_object_count() == before + 2
    context_ptr = c.handle
    with pytest.warns(ResourceWarning, match="leaked"):
        c.close()
    # Clean up by hand: the step runs in finish_task, then the world and the context go.
    assert sph.library().sph_world_step_wait(ptr) == sph.Result.OK
    assert sph.library().sph_world_destroy(ptr) == sph.Result.OK
    assert sph.library().sph_context_destroy(context_ptr) == sph.Result.OK
    _core._LEAKED.pop()
    assert sph.live_object_count() == before


def test_docstrings_follow_the_header():
    """What the docstrings say the library does is what sph_c.h says it does."""
    step = sph.World.step.__doc__
    assert "budget" in step and "cancel" in step, "INCOMPLETE: max_substeps, the step budget or a cancel"
    assert "current capacity" in sph.World.definition.__doc__, "sph_world_get_def reads the current capacity"
    assert "WARNING" in sph.Context.__doc__, "the log callback also gets warnings"
    assert "EXPERIMENTAL" not in sph.Feature.__doc__ and "second" not in sph.Feature.__doc__
    assert "density factor" in sph.Feature.__doc__


# ---- writing particles -------------------------------------------------------------------------
def test_set_attributes_read_back_bitwise(ctx):
    with ctx.world(capacity=2048, features="user_attribute") as w:
        n = w.fill_box((0, 0.2, 0), (0.1, 0.3, 0.1))
        w.step(0.01)
        table = np.zeros((n, 8), np.float32)  # interleaved rows: the writes read strided views
        table[:, 0:3] = w.positions() + np.float32(1e-3) / 3
        table[:, 4:7] = np.arange(3 * n, dtype=np.float32).reshape(n, 3) / 7
        ids = w.ids()
        w.set_positions(table[5:25, 0:3], first=5)
        w.set_velocities(table[5:25, 4:7], first=5)
        tags = (ids.astype(np.uint64) * 2654435761 % 2**32).astype(np.uint32)
        w.set_user_attributes(tags)
        np.testing.assert_array_equal(w.positions()[5:25].view(np.uint32), table[5:25, 0:3].view(np.uint32))
        np.testing.assert_array_equal(w.velocities()[5:25].view(np.uint32), table[5:25, 4:7].view(np.uint32))
        np.testing.assert_array_equal(w.user_attributes(), tags)
        np.testing.assert_array_equal(w.ids(), ids)
        for _ in range(10):
            w.step(0.01)
        by_id = dict(zip(ids.tolist(), tags.tolist()))
        assert [by_id[i] for i in w.ids().tolist()] == w.user_attributes().tolist()  # sorted along


def test_user_attributes_refuse_what_uint32_cannot_hold(ctx):
    """set_user_attributes never wraps or truncates: out-of-range integers raise ValueError,
    non-integers TypeError, before anything is written."""
    with ctx.world(capacity=2048, features="user_attribute") as w:
        n = w.fill_box((0, 0.2, 0), (0.1, 0.3, 0.1))
        tags = np.arange(n, dtype=np.uint32) * 3
        w.set_user_attributes(tags)
        for bad, kind in ([[2**32 + 5], ValueError], [[-1], ValueError], [[0, 2**64], ValueError],
                          [np.array([2**40], np.int64), ValueError], [np.array([2**32], np.uint64), ValueError],
                          [np.array([-3], np.int8), ValueError], [[1.9], TypeError], [np.array([1.0]), TypeError],
                          [[1, 2.5], TypeError], [["7"], TypeError]):
            with pytest.raises(kind):
                w.set_user_attributes(bad, first=1)
            np.testing.assert_array_equal(w.user_attributes(), tags, err_msg=repr(bad))
        # What fits is written, whatever its integer type (also a list mixing numpy and Python ints).
        w.set_user_attributes([2**32 - 1, np.uint64(4), True], first=2)
        w.set_user_attributes(np.array([9, 8], np.int64))
        w.set_user_attributes([])
        np.testing.assert_array_equal(w.user_attributes()[:5], [9, 8, 2**32 - 1, 4, 1])


def test_remove_particles_by_id(ctx):
    with ctx.world(capacity=2048) as w:
        w.fill_box((0, 0.2, 0), (0.1, 0.3, 0.1))
        w.step(0.01)
        ids = w.ids()
        gone = [int(ids[3]), int(ids[0]), int(ids[-1])]
        w.remove_particles(gone)
        np.testing.assert_array_equal(w.ids(), np.delete(ids, [0, 3, len(ids) - 1]))
        np.testing.assert_array_equal(w.removed_ids(), gone)
        w.remove_particles([])


def test_particle_write_errors_change_nothing(ctx):
    with ctx.world(capacity=2048) as w:
        n = w.fill_box((0, 0.2, 0), (0.1, 0.3, 0.1))
        before = w.save()
        bad = w.positions()[:4].copy()
        bad[3, 1] = np.nan
        assert error(w.set_positions, bad) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.set_velocities, np.zeros((2, 3)), first=n - 1) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.set_user_attributes, [1, 2]) == sph.Result.ERROR_FEATURE_DISABLED
        assert error(w.set_attribute, sph.Attribute.DENSITY, [1.0]) == sph.Result.ERROR_INVALID_ARGUMENT
        ids = w.ids()
        assert error(w.remove_particles, [int(ids[1]), 10**6]) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(w.remove_particles, [int(ids[1]), int(ids[1])]) == sph.Result.ERROR_INVALID_ARGUMENT
        with pytest.raises(ValueError):
            w.remove_particles([-1])
        assert w.save() == before
