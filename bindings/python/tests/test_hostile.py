# SPDX-License-Identifier: MIT
"""Hostile use of the Python binding (issue 23, item 2): array shapes the library would read
past, and integers ctypes would wrap silently into C's fixed-width types. Part of the
hostile-input suite (the C side is ctest label `hostile`; this file is collected by name)."""
import ctypes
import re

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


# ---- review of the Python binding: arguments that passed silently or failed obscurely -----------
def test_remove_particles_refuses_ids_that_are_not_integers(world):
    # np.asarray(ids, dtype=np.int64) truncated 1.7 to 1 and removed particle 1.
    world.fill_box((0, 0, 0), (0.06, 0.06, 0.06))
    ids = sorted(world.ids().tolist())
    for bad in ([1.7], np.array([1.0]), 1.7, ["x"]):
        with pytest.raises(TypeError, match=r"ids: expected integers \(uint32\), got"):
            world.remove_particles(bad)
    for bad in ([-1], [2**32]):
        with pytest.raises(ValueError, match="ids: .* does not fit uint32"):
            world.remove_particles(bad)
    assert sorted(world.ids().tolist()) == ids, "nothing was removed"
    world.remove_particles([1, np.int64(2)])
    world.remove_particles(np.array([3], np.uint32))
    assert sorted(world.ids().tolist()) == [i for i in ids if i not in (1, 2, 3)]


def test_vectors_and_quaternions_take_exactly_their_components(ctx, world):
    # A short sequence was zero-filled: gravity=[] became (0, 0, 0), (0, -9.81) (0, -9.81, 0),
    # a rotation (0, 0, 1) the quaternion (0, 0, 1, 0).
    gravity = world.params.gravity
    for bad in ([], (0, -9.81), (0, -9.81, 0, 0), np.array([0, -9.81])):
        with pytest.raises(ValueError, match=rf"WorldParams\.gravity: expected 3 values \(x, y, z\), got {len(bad)}"):
            world.set_params(gravity=bad)
    with pytest.raises(TypeError, match=r"WorldParams\.gravity: expected 3 values"):
        world.set_params(gravity=5)
    assert world.params.gravity == gravity
    with pytest.raises(ValueError, match=r"FillBoxDesc\.velocity: expected 3 values \(x, y, z\), got 2"):
        world.fill_box((0, 0, 0), (0.05, 0.05, 0.05), velocity=(1, 2))
    assert len(world) == 0
    with pytest.raises(ValueError, match="position: expected 3 values"):
        world.add_probe((1, 2))
    with pytest.raises(ValueError, match=r"ShapeDesc\.half_extents: expected 3 values \(x, y, z\), got 2"):
        ctx.shape("box", half_extents=(0.2, 0.05))
    with sphere_sdf(ctx) as s:
        with pytest.raises(ValueError, match="local_point: expected 3 values"):
            s.sample((0, 0))
        with pytest.raises(ValueError, match=r"Transform\.rotation: expected 4 values \(x, y, z, w\), got 3"):
            world.add_collider(s, ((0, 0, 0), (0, 0, 1)))
        collider = world.add_collider(s, ((0, 0, 0), (0, 0, 0, 1)))
        with pytest.raises(ValueError, match="point: expected 3 values"):
            collider.set_load_point((1, 2))
    # Every valid spelling still works: tuples, lists, numpy arrays, named tuples, structs, dicts.
    import collections
    Point = collections.namedtuple("Point", "x y z")
    for good in ((0, -1, 0), [0, -1, 0], np.array([0, -1, 0], np.float64), Point(0, -1, 0), sph.Vec3(0, -1, 0),
                 {"x": 0, "y": -1, "z": 0}):
        assert tuple(world.set_params(gravity=good).gravity) == (0, -1, 0)
    assert tuple(sph.Transform(rotation=(0, 0, 0, 1)).rotation) == (0, 0, 0, 1)


def test_voxel_size_must_be_finite_and_positive(ctx):
    # voxel_size=0 built the all-zero index_to_local, which the C API reads as the identity (1 m
    # voxels); a negative one mirrored the grid.
    d = np.full((3, 3, 3), -0.01, np.float32)
    for bad in (0, 0.0, -0.01, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="voxel_size: must be finite and > 0"):
            ctx.sdf(d, voxel_size=bad)
        with pytest.raises(ValueError, match="voxel_size"):
            sph.grid_transform(bad)
    with ctx.sdf(d, voxel_size=0.01) as s:
        assert s.sample((0.01, 0.01, 0.01)) < 0 and s.sample((2.0, 2.0, 2.0)) > 0


def test_enum_arguments_name_the_argument_and_the_choices(ctx, world):
    # Names that are no member raised a bare KeyError ('ONCE'); now as the struct fields do.
    with sphere_sdf(ctx) as s:
        cases = [
            (lambda: sph.Context("gpu"), "backend: 'gpu' is not one of auto, cpu, cuda"),
            (lambda: ctx.shape("spher", radius=1), "shape: 'spher' is not one of plane, box, sphere"),
            (lambda: world.add_source(s, mode="once"), "mode: 'once' is not one of fill_once, continuous"),
            (lambda: world.add_sink(mode="everywhere"), "mode: 'everywhere' is not one of region, outside_bounds"),
            (lambda: world.add_probe((0, 0, 0), sampling="every"), "sampling: 'every' is not one of frame, substep"),
            (lambda: world.add_force_field("whirl"), "kind: 'whirl' is not one of uniform, radial, vortex, grid"),
            (lambda: s.update("bogus", np.ones((1, 1, 1), np.float32)),
             "channel: 'bogus' is not one of distance, velocity, friction"),
            (lambda: ctx.world(solver="sph"), "WorldDef.solver: 'sph' is not one of wcsph, dfsph"),
        ]
        for call, message in cases:
            with pytest.raises(ValueError, match=re.escape(message)):
                call()
        # Members, names in any case and ints still work.
        world.add_source(s, (1, 0, 0), mode="Continuous").destroy()
        world.add_probe((0, 0, 0), sampling=sph.ProbeSampling.SUBSTEP).destroy()
        world.add_force_field(int(sph.ForceFieldKind.UNIFORM)).destroy()
    with sph.Context(" CPU ", cpu_worker_count=1) as c:
        assert c.backend is sph.Backend.CPU


def test_add_functions_refuse_keywords_they_do_not_use(ctx, world):
    # add_probe(pos, length=0.3) made a point probe: ProbeDef.length is a gauge's, and the
    # point probe ignored it. Keywords that another argument sets were overwritten.
    with pytest.raises(TypeError, match="'length'.*gauge_length="):
        world.add_probe((0, -0.01, 0), length=0.3)
    with pytest.raises(TypeError, match="length= and gauge_length="):
        world.add_probe((0, -0.01, 0), gauge_length=0.2, length=0.3)
    with pytest.raises(TypeError, match="kind= and gauge_length="):
        world.add_probe((0, -0.01, 0), gauge_length=0.2, kind="point")
    with pytest.raises(TypeError, match="bounds_min= and bounds="):
        world.add_sink(bounds=((-1, -1, -1), (1, 1, 1)), bounds_min=(0, 0, 0))
    with pytest.raises(TypeError, match="grid_index_to_local="):
        world.add_force_field("uniform", grid_index_to_local=sph.grid_transform(0.1))
    # A keyword that is no field raises TypeError, as for any Python function (still also the
    # AttributeError a misspelt struct field raises).
    with sphere_sdf(ctx) as s:
        for call in (lambda: world.add_probe((0, 0, 0), pressure_threshold=5),
                     lambda: world.add_source(s, start=0.5), lambda: world.add_collider(s, name="x"),
                     lambda: world.add_sink(type="outside_bounds"), lambda: world.add_force_field(axis=(0, 1, 0)),
                     lambda: ctx.shape("box", bogus=1), lambda: ctx.world(capacityy=10)):
            with pytest.raises(TypeError, match="has no field"):
                call()
    with pytest.raises(AttributeError, match="has no field"):
        world.add_probe((0, 0, 0), pressure_threshold=5)
    # The spellings that make a gauge.
    world.fill_box((-0.05, 0, -0.05), (0.05, 0.05, 0.05))
    gauges = [world.add_probe((0, -0.01, 0), gauge_length=0.2),
              world.add_probe((0, -0.01, 0), kind="gauge", length=0.2)]
    world.step(1 / 60)
    assert all(g.reading.water_height > 0.02 for g in gauges)


def test_sdf_arguments_must_be_sdf_assets(ctx, world):
    # add_collider(None) was AttributeError: 'NoneType' object has no attribute 'handle'.
    with pytest.raises(TypeError, match="sdf: expected an sph.Sdf, got NoneType"):
        world.add_collider(None)
    with pytest.raises(TypeError, match="region: expected an sph.Sdf, got NoneType"):
        world.add_source(None)
    with pytest.raises(TypeError, match="region: expected an sph.Sdf, got str"):
        world.add_sink("x")
    with pytest.raises(TypeError, match="region: expected an sph.Sdf, got int"):
        world.add_force_field("radial", region=3, strength=1.0)
    world.add_sink(bounds=((-1, -1, -1), (1, 1, 1))).destroy()  # no region: a bounds sink
    world.add_force_field("radial", strength=1.0).destroy()


def test_context_arguments_must_be_contexts(ctx):
    # World(None) and Sdf.shape(None) were AttributeError: 'NoneType' object has no attribute 'handle'.
    with pytest.raises(TypeError, match="context: expected an sph.Context, got NoneType"):
        sph.World(None, capacity=64)
    with pytest.raises(TypeError, match="context: expected an sph.Context, got str"):
        sph.Sdf.shape("cpu", "sphere", radius=0.1, voxel_size=0.02)
    with pytest.raises(TypeError, match="context: expected an sph.Context, got NoneType"):
        sph.Sdf.from_grid(None, np.zeros((4, 4, 4), np.float32), voxel_size=0.01)
    # voxel_size= beside index_to_local= was ignored without a word.
    with pytest.raises(TypeError, match="not both"):
        sph.Sdf.from_grid(ctx, np.zeros((4, 4, 4), np.float32), voxel_size=0.01,
                          index_to_local=sph.grid_transform(0.02))
    with sph.World(ctx, capacity=64) as w:  # the real thing still works
        assert w.particle_count == 0


def test_out_arrays_and_step_arguments_are_checked(world):
    world.fill_box((0, 0, 0), (0.05, 0.05, 0.05))
    # A 0-d out= passed the shape check and failed at len() ("len() of unsized object").
    for read, dtype in ((world.ids, np.uint32), (world.densities, np.float32), (world.pressures, np.float32)):
        with pytest.raises(ValueError, match=r"out: .* shape \(n,\), got .* \(\)"):
            read(out=np.empty((), dtype))
    with pytest.raises(ValueError, match=r"out: POSITION needs dtype float32 and shape \(n, 3\), got float32 \(3,\)"):
        world.positions(out=np.empty(3, np.float32))
    with pytest.raises(TypeError, match="out: expected a numpy array, got list"):
        world.ids(out=[0] * 5)
    out = np.empty(len(world), np.uint32)
    assert world.ids(out=out) is not None and sorted(out.tolist()) == list(range(len(world)))
    # float("0.01") parsed a string: step("0.01") ran a step.
    for call in (lambda: world.step("0.01"), lambda: world.step_begin("0.01"), lambda: world.step(None)):
        with pytest.raises(TypeError, match="frame_dt: expected a real number"):
            call()
    with pytest.raises(TypeError, match="step_budget: expected a real number, got str"):
        world.step_budget = "1"
    assert world.stats().substeps == 0, "no step ran"
    assert world.step(np.float32(1e-3)) == sph.Result.OK and world.step(1) in (sph.Result.OK, sph.Result.INCOMPLETE)
