# SPDX-License-Identifier: MIT
"""Distributed worlds (include/sph_mpi.h) with mpi4py: one world spread over the ranks of an
MPI communicator (docs/distributed.md).

The package must load libsph_mpi, which holds the whole of sph_c.h as well, instead of libsph
(never both: each keeps its own registry of worlds)::

    SPH_LIBRARY=build/libsph_mpi.so mpirun -np 2 python3 script.py

    from mpi4py import MPI          # initialises MPI (MPI_Init) before any world is made
    import sph, sph.mpi

    comm = MPI.COMM_WORLD
    with sph.Context("cpu") as ctx:
        world = sph.mpi.DistributedWorld(ctx, comm, particle_spacing=0.02)
        world.add_particles(xyz if comm.rank == 0 else None)   # (n, 3); ids in rank order
        for _ in range(10):
            world.step(1 / 60)
        merged = world.gather()     # on rank 0: positions, velocities, ids of every rank, by id
        world.close()               # collective, before MPI_Finalize (mpi4py's, at exit)

A DistributedWorld dropped without close() is never destroyed by the garbage collector: its
destroy is collective (it frees the world's communicator), and the collector runs at different
times on different ranks, so a destroy from __del__ could wait for ranks that never come. It
warns (ResourceWarning) and leaks the world, and its Context leaks too (sph_context_destroy would
destroy the world): close() every DistributedWorld, on every rank.

The communicator crosses as its Fortran handle (``comm.py2f()``, an MPI_Fint), so the library
needs nothing of mpi4py but that MPI is initialised; a plain int handle is taken as well.
Calls marked COLLECTIVE must be made by every rank, in the same order, with the same scalar
arguments. The rest of World's methods (colliders, sinks, force fields, copy_attribute, stats)
work per rank: positions() and ids() read this rank's own particles.

Each function of sph_mpi.h is one method below, named after it. A function added to the header
gets its method here, its call in tests/mpi/python/test_mpi_world.py, and is then covered: the
package-wide check (bindings/python/tests/test_zz_coverage.py) wants a wrapper for every
generated function, and the mpirun test wants every sph_mpi_* function called.
"""
import ctypes
import warnings

import numpy as np

from . import _generated as _g
from ._checkpoint import _path_bytes
from ._core import World, _float_ptr, _vec3_rows
from ._errors import SphLoadError, check
from ._loader import library
from ._struct import check_real

__all__ = ["DistributedWorld", "comm_handle", "library_has_mpi"]

#: The handles of distributed worlds dropped without close(), kept here (never destroyed).
_LEAKED = []


def library_has_mpi():
    """True when the package's library is libsph_mpi (it exports sph_mpi.h's functions)."""
    return hasattr(library(), "sph_mpi_world_create")


def _mpi_library():
    lib = library()
    if not hasattr(lib, "sph_mpi_world_create"):
        raise SphLoadError("distributed worlds need libsph_mpi as the package's library: set SPH_LIBRARY to the "
                           "full path of libsph_mpi.so (built where CMake finds MPI: SPH_WITH_MPI), not libsph.so")
    return lib


def comm_handle(comm):
    """The Fortran handle (MPI_Fint) of an mpi4py communicator (comm.py2f()), or an int as it is."""
    if isinstance(comm, (int, np.integer)):
        return int(comm)
    try:
        return int(comm.py2f())
    except AttributeError:
        raise TypeError(f"comm: expected an mpi4py communicator or its Fortran handle (int), got "
                        f"{type(comm).__name__}") from None


class DistributedWorld(World):
    """This rank's part of a world spread over ``comm``'s ranks (sph_mpi_world_create;
    COLLECTIVE). ``definition`` and keyword fields as World's (a WorldDef, the same on every
    rank); ``rebalance_threshold_percent`` (1-10000, default 20) is the sph_mpi_world_def field.
    The context must be a CPU context. close() (sph_world_destroy) is collective here: close
    every rank's world, before MPI is finalised. One dropped unclosed is leaked, with a
    ResourceWarning, and so is its context (the module's docstring says why).
    """

    def __init__(self, context, comm, definition=None, *, rebalance_threshold_percent=None, **fields):
        lib = _mpi_library()
        d = definition.copy() if definition is not None else _g.WorldDef()
        for name, value in fields.items():
            setattr(d, name, value)
        md = _g.MpiWorldDef()
        if rebalance_threshold_percent is not None:
            md.rebalance_threshold_percent = rebalance_threshold_percent
        out = ctypes.POINTER(_g.sph_world)()
        check(lib.sph_mpi_world_create(context.handle, ctypes.byref(d), comm_handle(comm), ctypes.byref(md),
                                       ctypes.byref(out)), "sph_mpi_world_create")
        self._ptr = out
        self.context = context
        self.comm = comm
        context._children.add(self)

    def __del__(self):
        """Never the collective destroy: warns and leaks an open world (the module's docstring)."""
        ptr = getattr(self, "_ptr", None)
        if ptr is None:
            return
        _LEAKED.append(ptr)
        self._ptr = None
        context = getattr(self, "context", None)
        if context is not None:
            context._leaked_worlds = getattr(context, "_leaked_worlds", 0) + 1
        try:
            warnings.warn("sph.mpi.DistributedWorld dropped without close(): leaked (its destroy is collective, "
                          "so the garbage collector does not run it); close() it on every rank", ResourceWarning,
                          stacklevel=2)
        except Exception:  # noqa: BLE001 - warnings turned into errors: nothing may leave __del__
            pass

    def add_particles(self, positions=None, velocities=None):
        """COLLECTIVE. Adds this rank's particles ((n, 3) arrays; None or n = 0 adds none here)
        (sph_mpi_world_add_particles). Ids are numbered across the ranks in rank order; each
        particle moves to the rank of its slab in the next step. All-or-nothing over the ranks.
        Returns this rank's first id."""
        pos = _vec3_rows(np.zeros((0, 3), np.float32) if positions is None else positions, "positions")
        vel = None
        if velocities is not None:
            vel = np.ascontiguousarray(_vec3_rows(velocities, "velocities"))
            if vel.shape[0] != pos.shape[0]:
                raise ValueError(f"velocities: {vel.shape[0]} rows for {pos.shape[0]} positions")
        pos = np.ascontiguousarray(pos)  # the call takes packed triples, without a stride
        first = ctypes.c_uint32()
        check(_mpi_library().sph_mpi_world_add_particles(self.handle, _float_ptr(pos),
                                                         None if vel is None else _float_ptr(vel), pos.shape[0],
                                                         ctypes.byref(first)), "sph_mpi_world_add_particles")
        return first.value

    def step(self, frame_dt):
        """COLLECTIVE. Advances every rank's part by frame_dt (sph_mpi_world_step); as World.step."""
        return check(_mpi_library().sph_mpi_world_step(self.handle, check_real(frame_dt, "frame_dt")),
                     "sph_mpi_world_step")

    def counts(self):
        """COLLECTIVE. This rank's and the world's counts (sph_mpi_world_get_counts): an
        MpiCounts (rank, rank_count, local_count, global_count, ghosts, migrated, rebalances,
        the slab's axis, the cell layers it meets and its sub-layers)."""
        c = _g.MpiCounts()
        check(_mpi_library().sph_mpi_world_get_counts(self.handle, ctypes.byref(c)), "sph_mpi_world_get_counts")
        return c

    @property
    def global_count(self):
        """COLLECTIVE. Particles of the whole world."""
        return self.counts().global_count

    def gather(self, root=0, positions=True, velocities=True, ids=True):
        """COLLECTIVE. Every rank's particles on ``root``, ordered by id (sph_mpi_world_gather).

        On root: a dict with "positions" and "velocities" ((n, 3) float32) and "ids" ((n,)
        uint32), each only if asked for. Elsewhere: None.
        """
        lib = _mpi_library()
        c = self.counts()
        rank = c.rank
        n = c.global_count if rank == root else 0
        arrays = {}
        if rank == root:
            if positions:
                arrays["positions"] = np.empty((n, 3), np.float32)
            if velocities:
                arrays["velocities"] = np.empty((n, 3), np.float32)
            if ids:
                arrays["ids"] = np.empty(n, np.uint32)

        def ptr(name, ctype):
            return arrays[name].ctypes.data_as(ctypes.POINTER(ctype)) if name in arrays else None

        count = ctypes.c_uint64()
        check(lib.sph_mpi_world_gather(self.handle, int(root), ptr("positions", ctypes.c_float),
                                       ptr("velocities", ctypes.c_float), ptr("ids", ctypes.c_uint32), n,
                                       ctypes.byref(count)), "sph_mpi_world_gather")
        return arrays if rank == root else None

    def save_file(self, path):
        """COLLECTIVE. Saves the world at ``path`` (the same on every rank): each rank's checkpoint
        at path + ".rank<r>.<its hash>", then rank 0's manifest at path, which replaces the set
        (sph_mpi_world_save_file). Succeeds or raises on every rank."""
        check(_mpi_library().sph_mpi_world_save_file(self.handle, _path_bytes(path)), "sph_mpi_world_save_file")

    def restore_file(self, path):
        """COLLECTIVE. Replaces the world's state with the one saved at ``path``, saved on any rank
        count (sph_mpi_world_restore_file); on an error on any rank, every rank raises and keeps
        its state."""
        check(_mpi_library().sph_mpi_world_restore_file(self.handle, _path_bytes(path)),
              "sph_mpi_world_restore_file")

    @classmethod
    def load_file(cls, context, comm, path):
        """COLLECTIVE. A new distributed world over ``comm`` from the save at ``path``, saved on any
        rank count (sph_mpi_world_load_file). On an error on any rank, every rank raises."""
        out = ctypes.POINTER(_g.sph_world)()
        check(_mpi_library().sph_mpi_world_load_file(context.handle, comm_handle(comm), _path_bytes(path),
                                                     ctypes.byref(out)), "sph_mpi_world_load_file")
        world = cls._adopt(context, out)
        world.comm = comm
        return world

    def gather_removed_ids(self, root=0):
        """COLLECTIVE. The ids every rank's sinks removed in the last step, on ``root``, ascending
        (sph_mpi_world_gather_removed_ids); None elsewhere (``removed_ids()`` is this rank's
        own). Two collective calls on every rank: the first learns the count on root, the
        second fills an array of that size.
        """
        lib = _mpi_library()
        rank = self.counts().rank
        count = ctypes.c_uint32()
        out = ctypes.byref(count) if rank == root else None
        check(lib.sph_mpi_world_gather_removed_ids(self.handle, int(root), None, 0, out),
              "sph_mpi_world_gather_removed_ids")
        ids = np.empty(count.value if rank == root else 0, np.uint32)
        pointer = ids.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32)) if ids.size else None
        check(lib.sph_mpi_world_gather_removed_ids(self.handle, int(root), pointer, ids.size, out),
              "sph_mpi_world_gather_removed_ids")
        return ids if rank == root else None

    def __repr__(self):
        if self._ptr is None:
            return "<sph.mpi.DistributedWorld closed>"
        return f"<sph.mpi.DistributedWorld {self.particle_count} particles on this rank>"
