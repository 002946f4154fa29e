# SPDX-License-Identifier: MIT
"""SDF assets and the objects placed in a world: colliders, sources, sinks, force fields."""
import ctypes
import os
import weakref

import numpy as np

from . import _generated as _g
from ._errors import check
from ._loader import library
from ._struct import _convert, check_int, check_real, enum_arg

__all__ = ["Sdf", "Collider", "Source", "Sink", "ForceField", "as_transform", "grid_transform", "WorldSceneMixin"]


def as_transform(t):
    """A Transform from a Transform, a dict of its fields, a position (x, y, z), or a pair
    (position, rotation) with rotation a quaternion (x, y, z, w). None is the identity."""
    if t is None:
        return _g.Transform()
    if isinstance(t, _g.Transform):
        return t
    if isinstance(t, dict):
        return _g.Transform(**t)
    t = list(t)
    if len(t) == 3 and all(np.isscalar(v) for v in t):
        return _g.Transform(position=t)
    if len(t) == 2 and not any(np.isscalar(v) for v in t):
        return _g.Transform(position=t[0], rotation=t[1])
    raise ValueError("a transform is a Transform, a dict, a position (x, y, z) or (position, rotation)")


def grid_transform(voxel_size=1.0, origin=(0.0, 0.0, 0.0)):
    """index_to_local for an axis-aligned grid: sample (i, j, k) sits at origin + voxel_size * (i, j, k).
    voxel_size must be finite and > 0 (ValueError): 0 made the all-zero map, which the C API
    reads as the identity (1 m voxels), and a negative size a mirrored grid."""
    s = check_real(voxel_size, "voxel_size")
    if not (np.isfinite(s) and s > 0):
        raise ValueError(f"voxel_size: must be finite and > 0, got {s}")
    ox, oy, oz = (float(v) for v in origin)
    return [s, 0, 0, ox, 0, s, 0, oy, 0, 0, s, oz]


def _grid(values, components, index_to_local, what):
    """(GridDesc, array kept alive) for a (nk, nj, ni) or (nk, nj, ni, 3) array; i is fastest."""
    a = np.ascontiguousarray(values, dtype=np.float32)
    want = 4 if components == 3 else 3
    if a.ndim != want or (components == 3 and a.shape[3] != 3):
        shape = "(nk, nj, ni, 3)" if components == 3 else "(nk, nj, ni)"
        raise ValueError(f"{what}: expected an array of shape {shape} (i fastest), got {a.shape}")
    d = _g.GridDesc(dims=(a.shape[2], a.shape[1], a.shape[0]), components=components,
                    data=a.ctypes.data_as(ctypes.POINTER(ctypes.c_float)))
    if index_to_local is not None:
        d.index_to_local = np.asarray(index_to_local, np.float32).reshape(12)
    return d, a


def _memory(memory):
    """A MemoryKind from itself, its int, or "host" / "cuda" (also "cuda_device")."""
    if isinstance(memory, str):
        name = memory.strip().upper()
        if name == "CUDA":
            return _g.MemoryKind.CUDA_DEVICE
    return enum_arg(_g.MemoryKind, memory, "memory")


def _device_pointer(value, what):
    """A device address (an int, or an object with __cuda_array_interface__) as a float pointer."""
    cai = getattr(value, "__cuda_array_interface__", None)
    if cai is not None:
        value = cai["data"][0]
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what}: with memory=\"cuda\" expected a device address (an int), got {type(value).__name__}")
    address = check_int(ctypes.c_uint64, value.__index__(), what)
    return ctypes.cast(ctypes.c_void_p(address), ctypes.POINTER(ctypes.c_float))


def _dims3(value, what):
    """Three uint32 sample counts (i, j, k)."""
    if value is None:
        raise ValueError(f"{what}: required with memory=\"cuda\" (device memory has no shape): (ni, nj, nk)")
    value = tuple(value)
    if len(value) != 3:
        raise ValueError(f"{what}: expected 3 sample counts (i, j, k), got {len(value)}")
    return tuple(check_int(ctypes.c_uint32, v, f"{what}[{i}]") for i, v in enumerate(value))


class Sdf:
    """A signed-distance asset (sph_sdf; negative inside) owned by a context, shared by the
    colliders, sources, sinks and force fields of any world on that context.

    Create one with ``Sdf.shape(ctx, "box", half_extents=(1, 0.5, 1), wall_thickness=0.05)``
    (or ``ctx.shape(...)``) or ``Sdf.from_grid(ctx, distance, voxel_size=0.01)``. close()
    releases the caller's reference; objects that use the asset keep it alive. Closing the
    context closes its assets.
    """

    def __init__(self, context, ptr):
        self._ptr = ptr
        self.context = context
        if ptr is not None:
            context._children.add(self)

    @classmethod
    def shape(cls, context, shape=_g.Shape.BOX, **fields):
        """An analytic shape sampled into a grid (sph_sdf_create_shape); fields are those of
        ShapeDesc (half_extents, radius, half_height, wall_thickness, voxel_size, flags,
        padding_voxels); flags takes ShapeFlag members or names. ``open_top=True`` sets
        ShapeFlag.OPEN_TOP."""
        open_top = fields.pop("open_top", False)
        shape = enum_arg(_g.Shape, shape, "shape")
        desc = _g.ShapeDesc(shape=shape, **fields)
        if open_top:
            desc.flags |= _g.SPH_SHAPE_FLAG_OPEN_TOP
        out = ctypes.POINTER(_g.sph_sdf)()
        check(library().sph_sdf_create_shape(context_handle(context), ctypes.byref(desc), ctypes.byref(out)),
              "sph_sdf_create_shape")
        return cls(context, out)

    @classmethod
    def from_grid(cls, context, distance, *, index_to_local=None, voxel_size=None, origin=(0, 0, 0),
                  velocity=None, friction=None, memory="host", dims=None):
        """An asset from sampled grids (sph_sdf_create; copied).

        distance: (nk, nj, ni) signed distances in metres (i fastest, like OpenVDB's index
        space); velocity: optional (nk, nj, ni, 3) surface velocity, m/s; friction: optional
        (nk, nj, ni) coefficients. The grid's placement is index_to_local (12 floats, a
        row-major 3x4 map) or voxel_size and origin (see grid_transform).

        memory="cuda" (MemoryKind.CUDA_DEVICE; CUDA contexts only): the grids are already in the
        context's device memory. distance, velocity and friction are then device addresses
        (ints, or objects with ``__cuda_array_interface__`` such as cupy arrays: their data
        pointer), float32, i fastest, laid out as above, and ``dims=(ni, nj, nk)`` gives their
        size. A CPU context raises SphError(ERROR_UNSUPPORTED).
        """
        memory = _memory(memory)
        if index_to_local is not None and voxel_size is not None:
            # voxel_size (and origin) was ignored beside index_to_local, without a word.
            raise TypeError("from_grid(): give index_to_local= or voxel_size= (with origin=), not both")
        if index_to_local is None and voxel_size is not None:
            index_to_local = grid_transform(voxel_size, origin)
        if memory != _g.MemoryKind.HOST:
            return cls._from_device_grid(context, memory, _dims3(dims, "dims"), index_to_local, distance, velocity,
                                         friction)
        dist, keep = _grid(distance, 1, index_to_local, "distance")
        desc = _g.SdfDesc(distance=dist)
        keep = [keep]
        if velocity is not None:
            vel, a = _grid(velocity, 3, index_to_local, "velocity")
            keep += [vel, a]
            desc.velocity = ctypes.pointer(vel)
        if friction is not None:
            fri, a = _grid(friction, 1, index_to_local, "friction")
            keep += [fri, a]
            desc.friction = ctypes.pointer(fri)
        out = ctypes.POINTER(_g.sph_sdf)()
        check(library().sph_sdf_create(context_handle(context), ctypes.byref(desc), ctypes.byref(out)),
              "sph_sdf_create")
        return cls(context, out)

    @classmethod
    def _from_device_grid(cls, context, memory, dims, index_to_local, distance, velocity, friction):
        """from_grid's memory="cuda" path: GridDescs of device addresses."""
        def grid(address, components, what):
            d = _g.GridDesc(dims=dims, components=components, memory=memory, data=_device_pointer(address, what))
            if index_to_local is not None:
                d.index_to_local = np.asarray(index_to_local, np.float32).reshape(12)
            return d

        desc = _g.SdfDesc(distance=grid(distance, 1, "distance"))
        keep = []
        if velocity is not None:
            keep.append(grid(velocity, 3, "velocity"))
            desc.velocity = ctypes.pointer(keep[-1])
        if friction is not None:
            keep.append(grid(friction, 1, "friction"))
            desc.friction = ctypes.pointer(keep[-1])
        out = ctypes.POINTER(_g.sph_sdf)()
        check(library().sph_sdf_create(context_handle(context), ctypes.byref(desc), ctypes.byref(out)),
              "sph_sdf_create")
        return cls(context, out)

    @classmethod
    def from_mesh(cls, context, vertices, indices, *, voxel_size=None, band_width=None, padding_voxels=None):
        """An asset from a triangle mesh (sph_sdf_create_from_mesh; the arrays are copied).

        vertices: (n, 3) positions in the asset's local frame, m; indices: (m, 3) or a flat
        sequence of vertex indices, three per triangle, counter-clockwise seen from outside
        (clockwise throughout works too). The mesh may have small holes. voxel_size (m),
        band_width (voxels of exact distance around the surface) and padding_voxels (grid
        margin) default as in MeshDesc. Voxel (0, 0, 0) sits at the vertices' minimum corner
        less padding_voxels voxels.
        """
        v = np.ascontiguousarray(vertices, dtype=np.float32)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices: expected an array of shape (n, 3), got {v.shape}")
        i = np.asarray(indices)
        if i.size and (not np.issubdtype(i.dtype, np.integer) or i.min() < 0 or i.max() > 0xFFFFFFFF):
            raise ValueError("indices: expected integers in [0, 2^32)")
        i = np.ascontiguousarray(i, dtype=np.uint32).reshape(-1)
        if len(v) > 0xFFFFFFFF or len(i) > 0xFFFFFFFF:
            raise ValueError("vertices, indices: at most 2^32 - 1 of each")
        desc = _g.MeshDesc(vertex_count=len(v), index_count=len(i),
                           vertices=v.ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
                           indices=i.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32)))
        for name, value in (("voxel_size", voxel_size), ("band_width", band_width),
                            ("padding_voxels", padding_voxels)):
            if value is not None:
                setattr(desc, name, value)
        out = ctypes.POINTER(_g.sph_sdf)()
        check(library().sph_sdf_create_from_mesh(context_handle(context), ctypes.byref(desc), ctypes.byref(out)),
              "sph_sdf_create_from_mesh")
        return cls(context, out)

    @classmethod
    def from_vdb(cls, context, path, grid_name=None):
        """Loads a level-set FloatGrid from a .vdb file (sph_vdb_load_sdf, in the optional
        helper library libsph_vdb; SphLoadError when it is not built). The asset's local frame
        is the file's world frame. grid_name None takes the first float level set."""
        from ._errors import SphError
        from ._loader import helper_library

        vdb = helper_library("sph_vdb")
        out = ctypes.POINTER(_g.sph_sdf)()
        code = vdb.sph_vdb_load_sdf(context_handle(context), os.fsencode(path),
                                    grid_name.encode("utf-8") if grid_name else None, ctypes.byref(out))
        if code < 0:
            raise SphError(code, vdb.sph_vdb_get_last_error().decode("utf-8", "replace"), "sph_vdb_load_sdf")
        return cls(context, out)

    @property
    def handle(self):
        """The sph_sdf* (a NULL pointer once closed)."""
        return self._ptr if self._ptr is not None else ctypes.POINTER(_g.sph_sdf)()

    @property
    def dims(self):
        """Grid samples along (i, j, k) (sph_sdf_get_dims)."""
        dims = (ctypes.c_uint32 * 3)()
        check(library().sph_sdf_get_dims(self.handle, dims), "sph_sdf_get_dims")
        return tuple(dims)

    def sample(self, local_point):
        """Signed distance at a point of the asset's local frame, m (sph_sdf_sample)."""
        d = ctypes.c_float()
        check(library().sph_sdf_sample(self.handle, _convert(_g.Vec3, local_point, "local_point"), ctypes.byref(d)),
              "sph_sdf_sample")
        return d.value

    def update(self, channel, data, origin=(0, 0, 0), *, memory="host", size=None):
        """Overwrites a box of one channel starting at grid index origin (i, j, k) with data
        of shape (sk, sj, si) or, for the velocity channel, (sk, sj, si, 3) (sph_sdf_update).
        Updating a channel the asset lacks creates it. With the walls in the density, send only
        the box that changed: the CPU backend's next step recomputes only that box's reach of the
        asset's boundary map.

        memory="cuda" (MemoryKind.CUDA_DEVICE; CUDA contexts only): data is a device address of
        the context's device (an int, or an object with ``__cuda_array_interface__``: its data
        pointer), float32, i fastest, and ``size=(si, sj, sk)`` gives the box. A CPU context
        raises SphError(ERROR_UNSUPPORTED)."""
        channel = enum_arg(_g.SdfChannel, channel, "channel")
        memory = _memory(memory)
        if memory != _g.MemoryKind.HOST:
            size = (ctypes.c_uint32 * 3)(*_dims3(size, "size"))
            origin = tuple(origin)
            if len(origin) != 3:
                raise ValueError(f"origin: expected 3 grid indices (i, j, k), got {len(origin)}")
            at = (ctypes.c_uint32 * 3)(*(check_int(ctypes.c_uint32, v, f"origin[{i}]") for i, v in enumerate(origin)))
            check(library().sph_sdf_update(self.handle, int(channel), at, size, _device_pointer(data, "data"),
                                           int(memory)), "sph_sdf_update")
            return
        a = np.ascontiguousarray(data, dtype=np.float32)
        # The library reads size[0] * size[1] * size[2] * components floats: the array's shape
        # must be exactly the channel's (a 3-D array for the velocity channel was read three
        # times its size).
        if channel == _g.SdfChannel.VELOCITY:
            if a.ndim != 4 or a.shape[3] != 3:
                raise ValueError(f"data: the velocity channel needs shape (sk, sj, si, 3), got {a.shape}")
        elif a.ndim != 3:
            raise ValueError(f"data: the {channel.name.lower()} channel needs shape (sk, sj, si), got {a.shape}")
        if 0 in a.shape:
            raise ValueError(f"data: the box is empty (shape {a.shape})")
        origin = tuple(origin)
        if len(origin) != 3:
            raise ValueError(f"origin: expected 3 grid indices (i, j, k), got {len(origin)}")
        size = (ctypes.c_uint32 * 3)(*(check_int(ctypes.c_uint32, n, "data shape") for n in a.shape[2::-1]))
        at = (ctypes.c_uint32 * 3)(*(check_int(ctypes.c_uint32, v, f"origin[{i}]") for i, v in enumerate(origin)))
        check(library().sph_sdf_update(self.handle, int(channel), at, size,
                                       a.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), _g.SPH_MEMORY_HOST),
              "sph_sdf_update")

    def close(self):
        """Releases the caller's reference (sph_sdf_destroy). Idempotent."""
        if self._ptr is not None:
            check(library().sph_sdf_destroy(self._ptr), "sph_sdf_destroy")
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            if getattr(self, "_ptr", None) is not None:
                library().sph_sdf_destroy(self._ptr)
                self._ptr = None
        except Exception:  # noqa: BLE001
            pass

    def __repr__(self):
        return "<sph.Sdf closed>" if self._ptr is None else f"<sph.Sdf {self.dims}>"


class _WorldObject:
    """An object inside a world, named by a generational id (ids of destroyed objects are
    rejected with SphError(ERROR_INVALID_HANDLE))."""

    def __init__(self, world, id_):
        self.world = world
        self.id = id_

    @property
    def bits(self):
        """The id's bits (what events name as object_bits)."""
        return self.id.bits

    def destroy(self):
        """Removes the object from its world. Idempotent (a null id is a no-op in C)."""
        if self.id.bits:
            self._destroy()
            self.id = type(self.id)()

    def close(self):
        self.destroy()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.destroy()

    def __repr__(self):
        return f"<sph.{type(self).__name__} {self.id.bits:#x}>"


class Collider(_WorldObject):
    """A placed SDF the fluid cannot enter (World.add_collider)."""

    def _destroy(self):
        check(library().sph_collider_destroy(self.world.handle, self.id), "sph_collider_destroy")

    @property
    def transform(self):
        """The current pose (sph_collider_get_transform)."""
        t = _g.Transform()
        check(library().sph_collider_get_transform(self.world.handle, self.id, ctypes.byref(t)),
              "sph_collider_get_transform")
        return t

    def move_to(self, target):
        """Kinematic motion: reach `target` over the next step, pushing fluid on the way
        (sph_collider_set_target_transform)."""
        t = as_transform(target)
        check(library().sph_collider_set_target_transform(self.world.handle, self.id, ctypes.byref(t)),
              "sph_collider_set_target_transform")

    def teleport(self, transform):
        """Moves at once, with no velocity (sph_collider_teleport)."""
        t = as_transform(transform)
        check(library().sph_collider_teleport(self.world.handle, self.id, ctypes.byref(t)), "sph_collider_teleport")

    @property
    def material(self):
        """The surface material, a ColliderMaterial: restitution, friction, stickiness
        (sph_collider_get_material)."""
        m = _g.ColliderMaterial()
        check(library().sph_collider_get_material(self.world.handle, self.id, ctypes.byref(m)),
              "sph_collider_get_material")
        return m

    @material.setter
    def material(self, material):
        """Replaces the material: a ColliderMaterial, or a dict of its fields with the others at
        their defaults (0) (sph_collider_set_material)."""
        m = material if isinstance(material, _g.ColliderMaterial) else _g.ColliderMaterial(**dict(material))
        check(library().sph_collider_set_material(self.world.handle, self.id, ctypes.byref(m)),
              "sph_collider_set_material")

    def set_material(self, restitution=0.0, friction=0.0, stickiness=0.0):
        """Changes restitution [0, 1], friction >= 0 and stickiness >= 0: the same as setting
        ``material`` to a ColliderMaterial of these three."""
        self.material = _g.ColliderMaterial(restitution=restitution, friction=friction, stickiness=stickiness)

    @property
    def loads(self):
        """The fluid's loads over the last step, a ColliderLoads: force (N) and torque (N m) about
        ``point``, world frame, time averages over ``frame_time`` (sph_collider_get_loads; needs
        the world feature "collider_loads")."""
        l = _g.ColliderLoads()
        check(library().sph_collider_get_loads(self.world.handle, self.id, ctypes.byref(l)),
              "sph_collider_get_loads")
        return l

    def set_load_point(self, point):
        """The point, in the collider's own frame, that the loads' torque is about (default the
        origin; pass the body's centre of mass) (sph_collider_set_load_point)."""
        p = _convert(_g.Vec3, point, "point")
        check(library().sph_collider_set_load_point(self.world.handle, self.id, ctypes.byref(p)),
              "sph_collider_set_load_point")

    def set_load_threshold(self, force):
        """After each step whose mean force on the collider reaches ``force`` newtons, the step
        reports a COLLIDER_LOAD_EXCEEDED event (count: the force in N); 0 = none
        (sph_collider_set_load_threshold)."""
        check(library().sph_collider_set_load_threshold(self.world.handle, self.id, check_real(force, "force")),
              "sph_collider_set_load_threshold")


class Source(_WorldObject):
    """Emits particles where its region SDF is negative (World.add_source)."""

    def _destroy(self):
        check(library().sph_source_destroy(self.world.handle, self.id), "sph_source_destroy")

    def set_transform(self, transform):
        t = as_transform(transform)
        check(library().sph_source_set_transform(self.world.handle, self.id, ctypes.byref(t)),
              "sph_source_set_transform")


class Sink(_WorldObject):
    """Removes particles in a region or outside bounds (World.add_sink)."""

    def _destroy(self):
        check(library().sph_sink_destroy(self.world.handle, self.id), "sph_sink_destroy")


class ForceField(_WorldObject):
    """Adds an acceleration to particles (World.add_force_field)."""

    def _destroy(self):
        check(library().sph_force_field_destroy(self.world.handle, self.id), "sph_force_field_destroy")

    def set_transform(self, transform):
        t = as_transform(transform)
        check(library().sph_force_field_set_transform(self.world.handle, self.id, ctypes.byref(t)),
              "sph_force_field_set_transform")


class Probe(_WorldObject):
    """A point probe or a gauge line sampled inside every step (World.add_probe)."""

    def _destroy(self):
        check(library().sph_probe_destroy(self.world.handle, self.id), "sph_probe_destroy")

    @property
    def reading(self):
        """The reading of the last step, a ProbeReading: density (kg/m^3), pressure and
        pressure_max (Pa), velocity (m/s), kernel_sum (the fluid fraction), water_height (m,
        gauges), samples and time (s) (sph_probe_get_reading)."""
        r = _g.ProbeReading()
        check(library().sph_probe_get_reading(self.world.handle, self.id, ctypes.byref(r)),
              "sph_probe_get_reading")
        return r

    def set_pressure_threshold(self, pressure):
        """After each step whose reading's pressure_max reaches ``pressure`` Pa, the step reports a
        PROBE_PRESSURE_EXCEEDED event (count: the peak in Pa); 0 = none
        (sph_probe_set_pressure_threshold)."""
        check(library().sph_probe_set_pressure_threshold(self.world.handle, self.id,
                                                         check_real(pressure, "pressure")),
              "sph_probe_set_pressure_threshold")


# The kind of object each event type names (docs/api.md, sph_event_type).
_EVENT_OBJECT_KINDS = {
    int(_g.EventType.SOURCE_CAPACITY_REACHED): Source,
    int(_g.EventType.CAPACITY_GROWN): Source,
    int(_g.EventType.SINK_REMOVED): Sink,
    int(_g.EventType.COLLIDER_LOAD_EXCEEDED): Collider,
    int(_g.EventType.PROBE_PRESSURE_EXCEEDED): Probe,
}


# ---- World methods --------------------------------------------------------------------------------
def context_handle(context):
    """The sph_context* of a Context argument; TypeError for anything else (None was an
    AttributeError about .handle). A closed Context passes NULL, which the library refuses."""
    handle = getattr(context, "handle", None)
    if not isinstance(handle, ctypes.POINTER(_g.sph_context)):
        raise TypeError(f"context: expected an sph.Context, got {type(context).__name__}")
    return handle


def _sdf_handle(sdf, what):
    """The sph_sdf* of an Sdf argument; TypeError for anything else (None was an AttributeError
    about .handle). A closed Sdf passes NULL, which the library refuses naming the field."""
    if not isinstance(sdf, Sdf):
        raise TypeError(f"{what}: expected an sph.Sdf, got {type(sdf).__name__}")
    return sdf.handle


def _set_by(function, argument, fields, *names):
    """TypeError when `fields` (a function's **fields) has a struct field that `argument` sets:
    add_probe's gauge_length= sets kind and length; the one given alongside was overwritten."""
    both = [n for n in names if n in fields]
    if both:
        raise TypeError(f"{function}() got {both[0]}= and {argument}=, which sets it: pass one of them")


class WorldSceneMixin:
    """The World methods that place objects in it and read its events."""

    # -- the wrappers this world handed out, by kind and id bits (for object_of)
    def _handed_out(self, obj):
        """Records obj (a Collider, Source, ...) in the world's weak map and returns it."""
        objects = self.__dict__.get("_objects")
        if objects is None:
            objects = self._objects = weakref.WeakValueDictionary()
        objects[(type(obj), obj.bits)] = obj
        return obj

    def object_of(self, event):
        """The Collider, Probe, Source or Sink an Event names (its object_bits), as the wrapper
        that this world's add_collider / add_probe / add_source / add_sink returned: the same
        Python object, so ``world.object_of(e) is src``. None when the event names no object
        (the DFSPH solve events), when the wrapper was dropped (the world keeps only weak
        references) or destroyed, or when it was not made here (a loaded checkpoint's objects).
        The event's type says the object's kind (EventType: SOURCE_CAPACITY_REACHED and
        CAPACITY_GROWN a Source, SINK_REMOVED a Sink, COLLIDER_LOAD_EXCEEDED a Collider,
        PROBE_PRESSURE_EXCEEDED a Probe); for a type these bindings do not know, the one object
        of any kind with those bits."""
        bits = int(event.object_bits)
        objects = self.__dict__.get("_objects")
        if not bits or objects is None:
            return None
        kind = _EVENT_OBJECT_KINDS.get(int(event.type))
        kinds = (kind,) if kind is not None else (Collider, Probe, Source, Sink)
        found = [o for o in (objects.get((k, bits)) for k in kinds) if o is not None and o.bits == bits]
        return found[0] if len(found) == 1 else None

    def add_collider(self, sdf, transform=None, *, inverted=False, **fields):
        """Places an SDF asset of this world's context as a collider (sph_collider_create).

        ``inverted=True`` makes the solid where the SDF is positive (a container). Other fields
        are those of ColliderDef: restitution, friction, stickiness, flags (ColliderFlag members
        or names, ``flags="inverted"``).
        """
        handle = _sdf_handle(sdf, "sdf")
        d = _g.ColliderDef(transform=as_transform(transform), **fields)
        d.sdf = handle
        if inverted:
            d.flags |= _g.SPH_COLLIDER_FLAG_INVERTED
        out = _g.ColliderId()
        check(library().sph_collider_create(self.handle, ctypes.byref(d), ctypes.byref(out)), "sph_collider_create")
        return self._handed_out(Collider(self, out))

    def add_source(self, region, transform=None, *, mode=_g.SourceMode.FILL_ONCE, **fields):
        """Adds a source that fills `region` (an Sdf, negative inside) with particles
        (sph_source_create). mode: SourceMode or "fill_once" / "continuous"; other fields are
        those of SourceDef (spacing, min_distance, velocity, flags, rate, user_attribute); flags
        takes SourceFlag members or names (``flags="velocity_from_field"``)."""
        handle = _sdf_handle(region, "region")
        d = _g.SourceDef(transform=as_transform(transform), mode=enum_arg(_g.SourceMode, mode, "mode"), **fields)
        d.region = handle
        out = _g.SourceId()
        check(library().sph_source_create(self.handle, ctypes.byref(d), ctypes.byref(out)), "sph_source_create")
        return self._handed_out(Source(self, out))

    def add_sink(self, region=None, transform=None, *, bounds=None, **fields):
        """Adds a sink (sph_sink_create): with `region` (an Sdf) it removes particles inside it;
        with ``bounds=(min, max)`` it removes particles outside that world-space box."""
        handle = _sdf_handle(region, "region") if region is not None else None
        if bounds is not None:
            _set_by("add_sink", "bounds", fields, "bounds_min", "bounds_max")
            fields.setdefault("mode", _g.SinkMode.OUTSIDE_BOUNDS)
            fields["bounds_min"], fields["bounds_max"] = bounds
        if "mode" in fields:
            fields["mode"] = enum_arg(_g.SinkMode, fields["mode"], "mode")
        d = _g.SinkDef(transform=as_transform(transform), **fields)
        if handle is not None:
            d.region = handle
        out = _g.SinkId()
        check(library().sph_sink_create(self.handle, ctypes.byref(d), ctypes.byref(out)), "sph_sink_create")
        return self._handed_out(Sink(self, out))

    def add_probe(self, position, *, gauge_length=None, sampling="frame", **fields):
        """Adds a probe at `position` (sph_probe_create); with ``gauge_length`` a gauge: the line
        from `position` that long along ``direction`` (default up, against gravity), reading the
        water height by a column integral. sampling: ProbeSampling or "frame" (the step's last
        substep), "substep" (every substep, averaged); other fields of ProbeDef: direction, sample_spacing.
        A keyword that is no field of ProbeDef, or length= on a point probe, raises TypeError."""
        d = _g.ProbeDef(sampling=enum_arg(_g.ProbeSampling, sampling, "sampling"), **fields)
        d.position = _convert(_g.Vec3, position, "position")
        if gauge_length is not None:
            _set_by("add_probe", "gauge_length", fields, "kind", "length")
            d.kind = _g.ProbeKind.GAUGE
            d.length = gauge_length
        elif "length" in fields and d.kind != _g.ProbeKind.GAUGE:
            # ProbeDef.length is a gauge's: on the point probe it made, length=0.3 was ignored.
            raise TypeError("add_probe() got an unexpected keyword argument 'length' (a point probe has none; "
                            "a gauge is add_probe(position, gauge_length=...))")
        out = _g.ProbeId()
        check(library().sph_probe_create(self.handle, ctypes.byref(d), ctypes.byref(out)), "sph_probe_create")
        return self._handed_out(Probe(self, out))

    def add_force_field(self, kind=_g.ForceFieldKind.UNIFORM, transform=None, *, region=None, grid=None,
                        grid_index_to_local=None, **fields):
        """Adds a force field (sph_force_field_create). kind: ForceFieldKind or "uniform",
        "radial", "vortex", "grid"; fields of ForceFieldDef: vector, strength, falloff_radius.
        region: optional Sdf limiting it; grid: (nk, nj, ni, 3) accelerations for kind GRID."""
        handle = _sdf_handle(region, "region") if region is not None else None
        if grid_index_to_local is not None and grid is None:
            raise TypeError("add_force_field(): grid_index_to_local= places grid=, which is missing")
        d = _g.ForceFieldDef(kind=enum_arg(_g.ForceFieldKind, kind, "kind"), transform=as_transform(transform),
                             **fields)
        if handle is not None:
            d.region = handle
        keep = None
        if grid is not None:
            g, a = _grid(grid, 3, grid_index_to_local, "grid")
            keep = (g, a)
            d.grid = ctypes.pointer(g)
        out = _g.ForceFieldId()
        check(library().sph_force_field_create(self.handle, ctypes.byref(d), ctypes.byref(out)),
              "sph_force_field_create")
        del keep
        return self._handed_out(ForceField(self, out))

    def events(self):
        """Events of the last step as a list of Event (type: EventType, count, object_bits;
        world.object_of(event) gives the Source, Sink, Collider or Probe it names, or compare
        object_bits with their .bits) (sph_world_get_events)."""
        n = ctypes.c_uint32()
        lib = library()
        check(lib.sph_world_get_events(self.handle, None, 0, ctypes.byref(n)), "sph_world_get_events")
        while True:  # the two-call pattern: count, then fetch (again if it grew)
            buf = (_g.Event * n.value)()
            r = check(lib.sph_world_get_events(self.handle, buf, n.value, ctypes.byref(n)), "sph_world_get_events")
            if r != _g.Result.INCOMPLETE:
                return list(buf[:n.value])

    def removed_ids(self):
        """Ids of the particles sinks removed during the last step, as a uint32 array
        (sph_world_get_removed_ids)."""
        n = ctypes.c_uint32()
        lib = library()
        check(lib.sph_world_get_removed_ids(self.handle, None, 0, ctypes.byref(n)), "sph_world_get_removed_ids")
        while True:
            out = np.empty(n.value, np.uint32)
            r = check(lib.sph_world_get_removed_ids(self.handle, out.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32)),
                                                    n.value, ctypes.byref(n)), "sph_world_get_removed_ids")
            if r != _g.Result.INCOMPLETE:
                return out[:n.value]
