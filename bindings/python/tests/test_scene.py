# SPDX-License-Identifier: MIT
"""SDF assets, colliders, sources, sinks, force fields and events."""
import ctypes
import gc
import math

import numpy as np
import pytest

import sph


def error(fn, *args, **kwargs):
    with pytest.raises(sph.SphError) as e:
        fn(*args, **kwargs)
    assert e.value.message, "the library explained the failure"
    return e.value.result


def sphere_grid(n=13, radius=0.1):
    """A sphere's signed distance on an n^3 grid of voxel radius/3, centred on the origin."""
    voxel = radius / 3
    origin = -(n - 1) / 2 * voxel
    c = origin + voxel * np.arange(n)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")  # (k, j, i): i fastest
    return np.sqrt(x * x + y * y + z * z) - radius, voxel, (origin,) * 3


# ---- SDF assets -------------------------------------------------------------------------------------
def test_shape_assets(ctx):
    with ctx.shape("sphere", radius=0.2, voxel_size=0.02) as ball:
        assert ball.sample((0, 0, 0)) == pytest.approx(-0.2, abs=0.01)
        assert ball.sample((0.5, 0, 0)) == pytest.approx(0.3, abs=0.02)
        assert all(d > 20 for d in ball.dims)
        assert "Sdf" in repr(ball)
    assert repr(ball) == "<sph.Sdf closed>"
    assert error(ball.sample, (0, 0, 0)) == sph.Result.ERROR_INVALID_HANDLE
    ball.close()  # idempotent
    tank = sph.Sdf.shape(ctx, sph.Shape.BOX, half_extents=(0.3, 0.3, 0.3), wall_thickness=0.05, voxel_size=0.05,
                         open_top=True)
    assert tank.sample((0, 0, 0)) > 0  # the cavity is outside the solid
    tank.close()
    assert error(ctx.shape, "sphere", radius=-1.0) == sph.Result.ERROR_INVALID_ARGUMENT
    with pytest.raises(ValueError):
        ctx.shape(42)  # not a Shape member


def test_mesh_assets(ctx):
    """A cube of side 0.2 m as 12 triangles: its asset is the box's distance (here at the
    centre, -0.1 m, and 0.1 m outside a face), within half a voxel."""
    corners = np.array([[x, y, z] for z in (-0.1, 0.1) for y in (-0.1, 0.1) for x in (-0.1, 0.1)])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    triangles = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    with sph.Sdf.from_mesh(ctx, corners, triangles, voxel_size=0.02) as cube:
        assert cube.sample((0, 0, 0)) == pytest.approx(-0.1, abs=0.01)
        assert cube.sample((0.2, 0, 0)) == pytest.approx(0.1, abs=0.01)
        assert cube.dims == (19, 19, 19)  # 0.2 m is 10 voxels of 2 cm: 11 centres, and 4 each side
    flipped = [(a, c, b) for a, b, c in triangles]  # either orientation has the same inside
    with sph.Sdf.from_mesh(ctx, corners, np.array(flipped), voxel_size=0.02, band_width=2,
                           padding_voxels=2) as cube:
        assert cube.sample((0, 0, 0)) == pytest.approx(-0.1, abs=0.01)
    assert error(sph.Sdf.from_mesh, ctx, corners, [(0, 1, 8)]) == sph.Result.ERROR_INVALID_ARGUMENT
    assert error(sph.Sdf.from_mesh, ctx, corners, triangles, band_width=0.5) == sph.Result.ERROR_INVALID_ARGUMENT
    with pytest.raises(ValueError):
        sph.Sdf.from_mesh(ctx, np.zeros((4, 2)), triangles)
    with pytest.raises(ValueError):
        sph.Sdf.from_mesh(ctx, corners, [(0, -1, 2)])


def test_unknown_shape_value_is_unsupported(ctx):
    d = sph.ShapeDesc()
    d.shape = 42
    out = ctypes.POINTER(sph.raw.sph_sdf)()
    r = sph.library().sph_sdf_create_shape(ctx.handle, ctypes.byref(d), ctypes.byref(out))
    assert r == sph.Result.ERROR_UNSUPPORTED


def test_grid_assets_and_updates(ctx):
    dist, voxel, origin = sphere_grid()
    vel = np.zeros(dist.shape + (3,), np.float32)
    with ctx.sdf(dist, voxel_size=voxel, origin=origin, velocity=vel, friction=np.ones(dist.shape)) as s:
        assert s.dims == (13, 13, 13)
        assert s.sample((0, 0, 0)) == pytest.approx(-0.1, abs=0.01)
        s.update("distance", np.full((2, 2, 2), 0.5), origin=(5, 5, 5))
        assert s.sample((0, 0, 0)) > 0.3
        s.update(sph.SdfChannel.VELOCITY, np.ones((1, 1, 1, 3)))
        assert error(s.update, "distance", np.zeros((2, 2, 2)), origin=(12, 12, 12)) \
            == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(s.update, "distance", np.full((1, 1, 1), np.nan)) == sph.Result.ERROR_INVALID_ARGUMENT
        with pytest.raises(ValueError):
            s.update("distance", np.zeros(4))
    with sph.Sdf.from_grid(ctx, dist, index_to_local=sph.grid_transform(voxel, origin)) as s2:
        assert s2.sample((0, 0, 0)) == pytest.approx(-0.1, abs=0.01)
    bad = dist.copy()
    bad[0, 0, 0] = np.inf
    assert error(ctx.sdf, bad) == sph.Result.ERROR_INVALID_ARGUMENT
    singular = [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0]  # no y axis
    assert error(ctx.sdf, dist, index_to_local=singular) == sph.Result.ERROR_INVALID_ARGUMENT
    with ctx.sdf(dist, index_to_local=np.zeros(12)) as s3:  # all zeros: the identity (1 m voxels)
        assert s3.sample((0, 0, 0)) == np.float32(dist[0, 0, 0])  # the sample at voxel (0, 0, 0)
    with pytest.raises(ValueError):
        ctx.sdf(np.zeros((4, 4)))


def test_raw_sdf_errors(ctx):
    lib = sph.library()
    with ctx.shape("sphere", radius=0.1, voxel_size=0.05) as s:
        one = (ctypes.c_uint32 * 3)(1, 1, 1)
        data = (ctypes.c_float * 1)(0.0)
        r = lib.sph_sdf_update(s.handle, 0, one, one, data, sph.MemoryKind.CUDA_DEVICE)
        assert r == sph.Result.ERROR_UNSUPPORTED  # device memory on a CPU context
        assert lib.sph_sdf_update(s.handle, 9, one, one, data, 0) == sph.Result.ERROR_UNSUPPORTED
    d = sph.SdfDesc()  # distance.data NULL
    out = ctypes.POINTER(sph.raw.sph_sdf)()
    assert lib.sph_sdf_create(ctx.handle, ctypes.byref(d), ctypes.byref(out)) == sph.Result.ERROR_INVALID_ARGUMENT


def test_context_is_busy_while_assets_live():
    c = sph.Context("cpu", cpu_worker_count=1)
    s = c.shape("sphere", radius=0.1, voxel_size=0.05)
    assert sph.library().sph_context_destroy(c.handle) == sph.Result.ERROR_BUSY
    s.close()
    assert sph.library().sph_context_destroy(c.handle) == sph.Result.OK
    c._ptr = None


# ---- colliders -------------------------------------------------------------------------------------
def test_a_floor_holds_the_water(ctx):
    def drop(with_floor):
        with ctx.world(capacity=4000, particle_spacing=0.03) as w, \
                ctx.shape("plane", half_extents=(1, 0.1, 1), voxel_size=0.03) as floor:
            if with_floor:
                w.add_collider(floor)
            w.fill_box((-0.1, 0.02, -0.1), (0.1, 0.2, 0.1))
            for _ in range(30):
                w.step(1 / 60)
            return w.positions()[:, 1].min()
    assert drop(False) < -1.0  # free fall: g t^2 / 2 = 1.23 m in 0.5 s
    assert drop(True) > -0.05  # held by the plane at y = 0


def test_prepare_builds_the_boundary_maps_ahead_of_the_step(ctx):
    # sph_world_prepare: the walls' boundary-density map is built by the call (the world holds
    # it: 16 bytes a voxel of the 0.2 m box at 1 cm), and the step after it gives the particles a
    # step without it gives, bit for bit.
    def walled(prepare):
        with ctx.world(capacity=4096, particle_spacing=0.02, features="boundary_density") as w, \
                ctx.shape("box", half_extents=(0.1, 0.1, 0.1), voxel_size=0.01) as box:
            w.add_collider(box, inverted=True)
            w.fill_box((-0.09, -0.09, -0.09), (0.09, 0.0, 0.09))
            before = w.stats().memory_bytes
            if prepare:
                w.prepare()
                assert w.stats().memory_bytes >= before + 16 * 21 ** 3
            w.step(0.01)
            return w.positions()
    assert np.array_equal(walled(True), walled(False))


def test_collider_pose_material_and_lifetime(ctx, world):
    with ctx.shape("box", half_extents=(0.1, 0.1, 0.1), voxel_size=0.05) as box:
        c = world.add_collider(box, (1, 2, 3), restitution=0.5, friction=0.2)
    assert c.bits != 0 and "Collider" in repr(c)
    assert tuple(c.transform.position) == (1, 2, 3)
    c.teleport(((0, 1, 0), (0, 0, 0, 2)))  # normalised by the library
    t = c.transform
    assert tuple(t.position) == (0, 1, 0) and tuple(t.rotation) == (0, 0, 0, 1)
    c.move_to({"position": (0, 1.01, 0)})
    world.step(1 / 60)
    assert tuple(c.transform.position) == pytest.approx((0, 1.01, 0))
    m = c.material  # as the def gave it
    assert (m.restitution, m.friction, m.stickiness) == pytest.approx((0.5, 0.2, 0.0))
    c.material = {"restitution": 0.25, "stickiness": 3.0}  # friction back to its default, 0
    m = c.material
    assert (m.restitution, m.friction, m.stickiness) == (0.25, 0.0, 3.0)
    assert error(setattr, c, "material", {"friction": -1.0}) == sph.Result.ERROR_INVALID_ARGUMENT
    assert c.material.stickiness == 3.0  # a refused material changes nothing
    c.set_material(restitution=1.0, friction=0.0, stickiness=2.0)
    assert (c.material.restitution, c.material.stickiness) == (1.0, 2.0)
    assert error(c.set_material, restitution=2.0) == sph.Result.ERROR_INVALID_ARGUMENT
    assert error(c.teleport, (0, np.nan, 0)) == sph.Result.ERROR_INVALID_ARGUMENT
    assert error(c.teleport, ((0, 0, 0), (0, 0, 0, 1e-9))) == sph.Result.ERROR_INVALID_ARGUMENT
    c.teleport(((0, 1, 0), (0, 0, 0, 0)))  # the all-zero quaternion (a zeroed struct) is the identity
    assert tuple(c.transform.rotation) == (0, 0, 0, 1)
    stale = sph.Collider(world, c.id.copy())
    c.destroy()
    c.destroy()  # a null id is a no-op
    assert error(stale.destroy) == sph.Result.ERROR_INVALID_HANDLE
    assert error(lambda: stale.transform) == sph.Result.ERROR_INVALID_HANDLE
    with pytest.raises(ValueError):
        sph.as_transform((1, 2))


def test_collider_errors(ctx, world):
    with ctx.shape("sphere", radius=0.1, voxel_size=0.05) as s:
        assert error(world.add_collider, s, restitution=-1.0) == sph.Result.ERROR_INVALID_ARGUMENT
        assert error(world.add_collider, s, flags=0x80) == sph.Result.ERROR_UNSUPPORTED
        assert error(world.add_collider, s, reserved0=1) == sph.Result.ERROR_INVALID_ARGUMENT
        inverted = world.add_collider(s, inverted=True)
        inverted.destroy()
    closed = sph.Sdf(ctx, None)
    assert error(world.add_collider, closed) == sph.Result.ERROR_INVALID_ARGUMENT  # NULL sdf
    with sph.Context("cpu", cpu_worker_count=1) as other:
        foreign = other.shape("sphere", radius=0.1, voxel_size=0.05)
        assert error(world.add_collider, foreign) == sph.Result.ERROR_INVALID_ARGUMENT
        foreign.close()


# ---- sources, sinks, events ------------------------------------------------------------------------
def test_source_fills_its_region_and_reports_capacity(ctx):
    with ctx.world(capacity=300, particle_spacing=0.02) as w, ctx.shape("sphere", radius=0.05,
                                                                             voxel_size=0.01) as ball:
        w.set_params(gravity=(0, 0, 0))
        src = w.add_source(ball, (0, 0, 0))
        w.step(1 / 60)
        n = len(w)
        assert n > 20
        assert np.linalg.norm(w.positions(), axis=1).max() <= 0.05 + 0.01
        assert w.events() == []
        src.set_transform((1, 0, 0))
        flood = w.add_source(ctx.shape("box", half_extents=(0.2, 0.2, 0.2), voxel_size=0.02), (3, 0, 0),
                             mode="continuous")
        w.step(1 / 60)
        assert len(w) == 300
        ev = w.events()
        assert any(e.type == sph.EventType.SOURCE_CAPACITY_REACHED and e.object_bits == flood.bits and e.count > 0
                   for e in ev), ev
        flood.destroy()
        src.destroy()
        assert error(w.add_source, ball, spacing=-1.0) == sph.Result.ERROR_INVALID_ARGUMENT


def test_sink_removes_particles_and_reports_their_ids(ctx):
    with ctx.world(capacity=4000, particle_spacing=0.03) as w:
        w.fill_box((-0.1, 0.0, -0.1), (0.1, 0.2, 0.1))
        below = w.ids()[w.positions()[:, 1] < 0.1]
        sink = w.add_sink(bounds=((-1, 0.1, -1), (1, 1, 1)))
        w.set_params(gravity=(0, 0, 0))
        w.step(1 / 240)
        removed = w.removed_ids()
        assert removed.dtype == np.uint32 and set(removed) == set(below)
        assert len(w) > 0 and (w.positions()[:, 1] >= 0.1).all()
        ev = w.events()
        assert [(e.type, e.count, e.object_bits) for e in ev] == [(sph.EventType.SINK_REMOVED, len(below), sink.bits)]
        sink.destroy()
        with ctx.shape("sphere", radius=0.05, voxel_size=0.01) as ball:
            region = w.add_sink(ball, (0, 0.15, 0))
            w.step(1 / 240)
            assert len(w.removed_ids()) > 0
            region.destroy()
        assert error(w.add_sink) == sph.Result.ERROR_INVALID_ARGUMENT  # REGION mode without a region


def test_force_fields(ctx):
    with ctx.world(capacity=2000, particle_spacing=0.03) as w:
        w.set_params(gravity=(0, 0, 0))
        w.fill_sphere((0, 0, 0), 0.06)
        push = w.add_force_field("uniform", vector=(2, 0, 0))
        w.step(0.05)
        assert w.velocities()[:, 0].mean() == pytest.approx(0.1, rel=0.05)
        push.set_transform(((0, 0, 0), (0, 0, 1, 0)))  # rotated 180 degrees about z: now -x
        w.step(0.05)
        assert abs(w.velocities()[:, 0].mean()) < 0.02
        push.destroy()
        grid = np.zeros((4, 4, 4, 3), np.float32)
        grid[..., 1] = 3.0
        up = w.add_force_field("grid", grid=grid, grid_index_to_local=sph.grid_transform(0.2, (-0.3, -0.3, -0.3)))
        w.step(0.05)
        assert w.velocities()[:, 1].mean() == pytest.approx(0.15, rel=0.1)
        up.destroy()
        with ctx.shape("sphere", radius=0.5, voxel_size=0.1) as region:
            radial = w.add_force_field(sph.ForceFieldKind.RADIAL, region=region, strength=1.0, falloff_radius=1.0)
            radial.destroy()
        assert error(w.add_force_field, "grid") == sph.Result.ERROR_INVALID_ARGUMENT  # no grid
        assert error(w.add_force_field, "uniform", vector=(np.nan, 0, 0)) == sph.Result.ERROR_INVALID_ARGUMENT


def test_events_two_call_pattern_raw(world):
    n = ctypes.c_uint32(7)
    lib = sph.library()
    assert lib.sph_world_get_events(world.handle, None, 0, ctypes.byref(n)) == sph.Result.OK and n.value == 0
    assert lib.sph_world_get_events(world.handle, None, 1, ctypes.byref(n)) == sph.Result.ERROR_INVALID_ARGUMENT
    assert lib.sph_world_get_removed_ids(world.handle, None, 0, None) == sph.Result.ERROR_INVALID_ARGUMENT


# ---- the CUDA tier ---------------------------------------------------------------------------------------
def test_cuda_tier_on_a_cpu_world_is_unsupported(world):
    for call in (lambda: world.cuda_attribute(sph.Attribute.POSITION), lambda: world.cuda_array(sph.Attribute.ID),
                 lambda: world.cuda_epoch, lambda: world.cuda_device, lambda: world.cuda_stream,
                 lambda: world.cuda_record_event(1), lambda: world.cuda_wait_event(1),
                 lambda: world.cuda_step_begin_on_stream(1.0 / 60.0, 0)):
        assert error(call) == sph.Result.ERROR_UNSUPPORTED
    assert error(world.step_wait) == sph.Result.ERROR_INVALID_ARGUMENT  # nothing was started


def test_cuda_array_interface_shape():
    view = sph.CudaAttributeView(count=5, stride=16, element_size=12, device_address=0x1000, epoch=3)
    a = sph.CudaArray(None, view, np.dtype(np.float32), 3)
    cai = a.__cuda_array_interface__
    assert cai == {"shape": (5, 3), "typestr": "<f4", "data": (0x1000, True), "strides": (16, 4), "version": 3,
                   "stream": None}
    ids = sph.CudaArray(None, sph.CudaAttributeView(count=5, stride=4), np.dtype(np.uint32), 1)
    assert ids.__cuda_array_interface__["shape"] == (5,) and ids.__cuda_array_interface__["typestr"] == "<u4"


# ---- loads on colliders -----------------------------------------------------------------------------
def test_probes(ctx):
    """World.add_probe / Probe.reading: a point in water resting in a tank reads a density near rho0
    and the water's stillness; a gauge through it reads a height of the water's order; bad input
    names the field."""
    with ctx.shape("box", half_extents=(0.05, 0.1, 0.05), voxel_size=0.01) as box:
        with ctx.world(capacity=512, particle_spacing=0.02) as world:
            tank = world.add_collider(box, (0.05, 0.1, 0.05), inverted=True)
            n = world.fill_box((0.0, 0.0, 0.0), (0.1, 0.06, 0.1))
            point = world.add_probe((0.05, 0.02, 0.05), sampling="substep")
            gauge = world.add_probe((0.05, -0.03, 0.05), gauge_length=0.2)
            assert point.reading.samples == 0
            for _ in range(10):
                world.step(0.02)
            r = point.reading
            assert r.samples == world.stats().substeps
            # Every particle of this 6 cm layer is within h = 3.6 cm of the floor or the surface,
            # where the summed densities the interpolant averages read a deficit (measured 797).
            assert 700.0 < r.density < 1100.0
            assert abs(r.velocity.y) < 0.2
            fill = n * world.particle_mass / 1000.0 / (0.1 * 0.1)
            # Below n m / (rho0 A): without walls in the density the particles near the tank's
            # walls pack tighter and the middle stands lower (measured 0.021 of 0.030 m here;
            # tests/physics_options/test_probes.c holds a gauge to a known height).
            assert 0.5 * fill < gauge.reading.water_height < 1.1 * fill
            assert gauge.reading.samples == 1
            assert error(world.add_probe, (0.0, float("nan"), 0.0)) == sph.Result.ERROR_INVALID_ARGUMENT
            assert "def->position" in sph.last_error()
            assert error(world.add_probe, (0.0, 0.0, 0.0), gauge_length=-1.0) == sph.Result.ERROR_INVALID_ARGUMENT
            assert "def->length" in sph.last_error()
            gauge.destroy()
            assert point.reading.samples > 0
            # A pressure threshold below the point's peak reports the step; a bad one is refused.
            assert error(point.set_pressure_threshold, float("nan")) == sph.Result.ERROR_INVALID_ARGUMENT
            point.set_pressure_threshold(1.0)
            world.step(0.02)
            peak = point.reading.pressure_max  # about 700 Pa, 4 cm under the surface
            hits = [e for e in world.events() if e.type == sph.EventType.PROBE_PRESSURE_EXCEEDED]
            assert peak >= 1.0
            assert len(hits) == 1 and hits[0].object_bits == point.bits
            assert math.floor(peak) - 1 <= hits[0].count <= math.floor(peak)
            point.set_pressure_threshold(0.0)
            world.step(0.02)
            assert not [e for e in world.events() if e.type == sph.EventType.PROBE_PRESSURE_EXCEEDED]
            tank.destroy()


def test_collider_loads(ctx):
    """Collider.loads / set_load_point (SPH_FEATURE_COLLIDER_LOADS): refused without the feature;
    with it, water resting on a tank's floor presses it with about its weight, and the torque is
    about the load point."""
    with ctx.shape("box", half_extents=(0.05, 0.05, 0.05), voxel_size=0.01) as box:
        with ctx.world(capacity=256, particle_spacing=0.02) as plain:
            tank = plain.add_collider(box, (0.05, 0.05, 0.05), inverted=True)
            assert error(lambda: tank.loads) == sph.Result.ERROR_FEATURE_DISABLED
            assert error(tank.set_load_point, (0, 0, 0)) == sph.Result.ERROR_FEATURE_DISABLED
            assert error(tank.set_load_threshold, 1.0) == sph.Result.ERROR_FEATURE_DISABLED
        with ctx.world(capacity=256, particle_spacing=0.02, features="collider_loads") as world:
            tank = world.add_collider(box, (0.05, 0.05, 0.05), inverted=True)
            assert tank.loads.frame_time == 0.0
            tank.set_load_point((0.05, 0.0, 0.0))  # 5 cm to +x of the tank's centre
            n = world.fill_box((0.0, 0.0, 0.0), (0.1, 0.04, 0.1))
            for _ in range(10):
                world.step(0.02)
            loads = tank.loads
            weight = n * world.particle_mass * 9.81
            assert loads.frame_time == pytest.approx(0.02)
            assert loads.point.x == pytest.approx(0.1) and loads.point.y == pytest.approx(0.05)
            assert loads.force.y == pytest.approx(-weight, rel=0.3)  # settling: within 30 % per frame
            # The weight's line is at x = 0.05, 5 cm to -x of the point: tau_z = -0.05 * F_y.
            assert loads.torque.z == pytest.approx(-0.05 * loads.force.y, rel=0.2)
            # A threshold below the force reports the step; above it, nothing; bad values refused.
            assert error(tank.set_load_threshold, -1.0) == sph.Result.ERROR_INVALID_ARGUMENT
            tank.set_load_threshold(0.5 * weight)
            world.step(0.02)
            force = math.sqrt(tank.loads.force.x ** 2 + tank.loads.force.y ** 2 + tank.loads.force.z ** 2)
            hits = [e for e in world.events() if e.type == sph.EventType.COLLIDER_LOAD_EXCEEDED]
            assert len(hits) == 1 and hits[0].object_bits == tank.bits
            assert math.floor(force) - 1 <= hits[0].count <= math.floor(force)
            tank.set_load_threshold(10.0 * weight)
            world.step(0.02)
            assert not [e for e in world.events() if e.type == sph.EventType.COLLIDER_LOAD_EXCEEDED]


# ---- events to the objects they name (World.object_of) ----------------------------------------------
def test_object_of_maps_a_capacity_event_to_its_source(ctx):
    with ctx.world(capacity=300, particle_spacing=0.02) as w, \
            ctx.shape("box", half_extents=(0.2, 0.2, 0.2), voxel_size=0.02) as box, \
            ctx.shape("sphere", radius=0.05, voxel_size=0.01) as ball:
        w.set_params(gravity=(0, 0, 0))
        small = w.add_source(ball, (1, 0, 0))
        flood = w.add_source(box, (3, 0, 0), mode="continuous")
        w.step(1 / 60)
        ev = [e for e in w.events() if e.type == sph.EventType.SOURCE_CAPACITY_REACHED]
        assert ev, w.events()
        assert all(w.object_of(e) is flood for e in ev)
        assert small.bits != flood.bits
        # A sink's removal names the Sink; an event of no object gives None.
        sink = w.add_sink(bounds=((-10, -10, -10), (2, 10, 10)))
        w.step(1 / 60)
        removed = [e for e in w.events() if e.type == sph.EventType.SINK_REMOVED]
        assert removed and w.object_of(removed[0]) is sink
        assert w.object_of(sph.Event(type=sph.EventType.PRESSURE_SOLVE_CAPPED, count=1, object_bits=0)) is None
        # The same bits under another kind's event name nothing of that kind.
        assert w.object_of(sph.Event(type=sph.EventType.COLLIDER_LOAD_EXCEEDED, object_bits=flood.bits)) is None
        # An unknown event type: the one object of any kind with those bits.
        # (None when ids of two kinds share those bits: the kind cannot be told.)
        shared = any(o.bits == sink.bits for o in (small, flood))
        assert w.object_of(sph.Event(type=99, object_bits=sink.bits)) is (None if shared else sink)
        # A destroyed object, and a dropped wrapper (the world keeps weak references only), give None.
        stale = ev[0]
        flood.destroy()
        assert w.object_of(stale) is None
        bits = small.bits
        del small
        gc.collect()
        assert w.object_of(sph.Event(type=sph.EventType.SOURCE_CAPACITY_REACHED, object_bits=bits)) is None


def test_object_of_maps_a_load_event_to_its_collider(ctx):
    with ctx.shape("box", half_extents=(0.05, 0.05, 0.05), voxel_size=0.01) as box, \
            ctx.world(capacity=512, particle_spacing=0.02, features="collider_loads") as world:
        tank = world.add_collider(box, (0.05, 0.05, 0.05), inverted=True)
        other = world.add_collider(box, (1, 1, 1))
        point = world.add_probe((0.05, 0.02, 0.05), sampling="substep")
        n = world.fill_box((0.0, 0.0, 0.0), (0.1, 0.06, 0.1))
        for _ in range(10):
            world.step(0.02)
        tank.set_load_threshold(0.5 * n * world.particle_mass * 9.81)
        point.set_pressure_threshold(1.0)
        world.step(0.02)
        loads = [e for e in world.events() if e.type == sph.EventType.COLLIDER_LOAD_EXCEEDED]
        assert len(loads) == 1 and world.object_of(loads[0]) is tank
        assert world.object_of(loads[0]) is not other
        pressures = [e for e in world.events() if e.type == sph.EventType.PROBE_PRESSURE_EXCEEDED]
        assert len(pressures) == 1 and world.object_of(pressures[0]) is point
        # A loaded checkpoint's world has the objects but not these wrappers.
        with ctx.load_world(world.save()) as copy:
            copy.step(0.02)
            assert [e.type for e in copy.events() if e.type == sph.EventType.COLLIDER_LOAD_EXCEEDED]
            assert all(copy.object_of(e) is None for e in copy.events())


# ---- SDF grids in device memory (memory="cuda"; refused on a CPU context) ----------------------------
def test_sdf_memory_argument(ctx):
    # Host memory, named or by enum, behaves as before.
    d = np.full((4, 4, 4), 1.0, np.float32)
    for memory in ("host", sph.MemoryKind.HOST, 0):
        with ctx.sdf(d, voxel_size=0.1, memory=memory) as s:
            s.update("distance", np.full((2, 2, 2), -0.5, np.float32), (1, 1, 1), memory=memory)
            assert s.sample((0.15, 0.15, 0.15)) == pytest.approx(-0.5)
            assert s.sample((0.0, 0.0, 0.0)) == pytest.approx(1.0)
    with ctx.sdf(d, voxel_size=0.1) as s:
        # A device address on a CPU context: the library's UNSUPPORTED (nothing is read).
        assert error(s.update, "distance", 0x1000, memory="cuda", size=(2, 2, 2)) == sph.Result.ERROR_UNSUPPORTED
        assert "memory" in sph.last_error()
        assert error(s.update, "velocity", 0x1000, (1, 1, 1), memory=sph.MemoryKind.CUDA_DEVICE,
                     size=(1, 1, 1)) == sph.Result.ERROR_UNSUPPORTED
        assert s.sample((0.0, 0.0, 0.0)) == pytest.approx(1.0)
        # Device memory has no shape: size is required; data must be an address.
        with pytest.raises(ValueError, match="size: required"):
            s.update("distance", 0x1000, memory="cuda")
        with pytest.raises(TypeError, match="device address"):
            s.update("distance", np.zeros((2, 2, 2), np.float32), memory="cuda", size=(2, 2, 2))
        with pytest.raises(ValueError, match="memory: 'gpu' is not one of host, cuda_device"):
            s.update("distance", 0x1000, memory="gpu", size=(2, 2, 2))

        class Cai:  # anything with __cuda_array_interface__ passes its data pointer
            __cuda_array_interface__ = {"data": (0x2000, False), "shape": (8,), "typestr": "<f4", "version": 3}

        assert error(s.update, "friction", Cai(), memory="cuda", size=(2, 2, 2)) == sph.Result.ERROR_UNSUPPORTED
    assert error(ctx.sdf, 0x1000, memory="cuda", dims=(4, 4, 4), voxel_size=0.1, velocity=0x2000,
                 friction=0x3000) == sph.Result.ERROR_UNSUPPORTED
    assert "memory" in sph.last_error()
    with pytest.raises(ValueError, match="dims: required"):
        ctx.sdf(0x1000, memory="cuda")
