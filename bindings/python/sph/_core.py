# SPDX-License-Identifier: MIT
"""Context and World: the Pythonic layer over the generated ctypes declarations."""
import ctypes
import re
import sys
import warnings
import weakref

import numpy as np

from . import _generated as _g
from ._checkpoint import WorldCheckpointMixin, load_world, load_world_file
from ._cuda import WorldCudaMixin
from ._errors import SphError, check
from ._loader import library
from ._options import WorldOptionsMixin, _as_struct
from ._scene import Sdf, WorldSceneMixin, context_handle
from ._struct import check_int, check_real, enum_arg

__all__ = ["Context", "World", "attribute_format", "version", "abi_version", "build_info", "result_string",
           "live_object_count", "make_version"]


# ---- library-wide queries ----------------------------------------------------------------------
def make_version(major, minor, patch):
    """Packs a version like SPH_MAKE_VERSION: (major << 22) | (minor << 12) | patch."""
    return (major << 22) | (minor << 12) | patch


def version():
    """The loaded library's version as (major, minor, patch) (sph_get_version)."""
    v = library().sph_get_version()
    return (v >> 22, (v >> 12) & 0x3FF, v & 0xFFF)


def abi_version():
    """The loaded library's ABI version (sph_get_abi_version); the SONAME major."""
    return library().sph_get_abi_version()


def build_info():
    """Version, git revision, compiler and backends of the loaded library (sph_get_build_info)."""
    return library().sph_get_build_info().decode("utf-8", "replace")


def result_string(result):
    """The library's English description of an sph_result code (sph_result_string)."""
    return library().sph_result_string(int(result)).decode("utf-8", "replace")


def live_object_count():
    """Contexts and worlds alive in the process (sph_get_live_object_count): a leak check."""
    n = ctypes.c_uint32()
    check(library().sph_get_live_object_count(ctypes.byref(n)), "sph_get_live_object_count")
    return n.value


# ---- attributes ----------------------------------------------------------------------------------
_FORMAT = re.compile(r"^\s*(?:(\d+)\s*x\s*)?(float32|float64|uint32|int32|uint64|int64)\b")


def attribute_format(attribute):
    """(numpy dtype, components) of an attribute, read from its documentation in the header
    ("3 x float32, metres", "uint32, ..."), so attributes added to the header need no code."""
    attribute = _g.Attribute(attribute)
    doc = _g.ENUM_MEMBER_DOCS.get(f"SPH_ATTRIBUTE_{attribute.name}", "")
    m = _FORMAT.match(doc)
    if not m:
        raise ValueError(f"attribute {attribute.name}: the header does not document its element format ({doc!r})")
    return np.dtype(m.group(2)), int(m.group(1) or 1)


def _vec3_rows(values, what):
    """values as an (n, 3) float32 array whose rows may be strided but whose three floats are
    packed: numpy views pass through without a copy, anything else is converted once."""
    a = np.asarray(values)
    if a.ndim == 1 and a.shape[0] == 3:
        a = a.reshape(1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{what}: expected an array of shape (n, 3), got {a.shape}")
    if a.dtype != np.float32 or a.strides[1] != 4 or a.strides[0] < 12 or a.strides[0] % 4:
        a = np.ascontiguousarray(a, dtype=np.float32)
    return a


def _integers(values, a, dtype, what):
    """`values` (already the 1-D array `a`) as `dtype`, an integer dtype, refusing what a cast
    would change: TypeError for values that are not integers (floats, strings; booleans pass as
    0 and 1), ValueError for integers outside the dtype's range. numpy's own cast wraps
    (2**32 + 5 -> 5, -1 -> 4294967295) and truncates (1.9 -> 1) silently."""
    if len(a) == 0:
        return np.empty(0, dtype)
    if a.dtype.kind not in "uib" and not isinstance(values, np.ndarray):
        a = np.asarray(values, dtype=object)  # a list mixing numpy and Python ints
    if a.dtype.kind == "O":
        if not all(isinstance(v, (int, np.integer)) for v in a.tolist()):
            kinds = sorted({type(v).__name__ for v in a.tolist() if not isinstance(v, (int, np.integer))})
            raise TypeError(f"{what}: expected integers ({dtype}), got {', '.join(kinds)}")
        a = np.array([int(v) for v in a.tolist()], dtype=object)
    elif a.dtype.kind not in "uib":
        raise TypeError(f"{what}: expected integers ({dtype}), got an array of {a.dtype}")
    lo, hi = int(a.min()), int(a.max())
    info = np.iinfo(dtype)
    if lo < info.min or hi > info.max:
        bad = lo if lo < info.min else hi
        raise ValueError(f"{what}: {bad} does not fit {dtype} ({info.min}..{info.max})")
    return a.astype(dtype)


def _float_ptr(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


#: Worlds (with their contexts) that a finaliser could neither destroy nor wait for: dropped with
#: an asynchronous step in flight that may need Python code to finish (World.__del__). Never freed.
_LEAKED = []

# The ContextDef fields whose callbacks may run on the threads of a world's asynchronous step.
_STEP_THREAD_HOOKS = ("enqueue_task", "finish_task", "alloc_fn", "free_fn")


# ---- context --------------------------------------------------------------------------------------
class Context:
    """A backend (the CPU, or one CUDA device) that worlds are created on (sph_context).

    ``Context("cpu")``, ``Context(Backend.CUDA, device_ordinal=0)``. Use it as a context
    manager or call close(), which first closes the worlds and SDF assets created on it that
    are still open (the C library refuses to destroy a context that has them).

    Args:
        backend: a Backend member or "auto" / "cpu" / "cuda" (default AUTO: CUDA when a device
            is present, else the CPU).
        device_ordinal: CUDA device (default -1 = device 0).
        cpu_worker_count: CPU backend threads (default 0 = all hardware threads).
        log: optional callable(level: LogLevel, code: Result, message: str), called on the
            calling thread, inside a call on this context or its worlds: when the call fails
            (LogLevel.ERROR with its code), and for a warning from a call that succeeds
            (LogLevel.WARNING with Result.OK, e.g. add_collider's coarse-SDF warning in a world
            with Feature.BOUNDARY_DENSITY; docs/api.md). Exceptions it raises are printed and
            swallowed (they cannot cross the C library).
        definition: a ContextDef to start from instead of the defaults. Its callbacks
            (alloc_fn/free_fn, enqueue_task/finish_task, log_fn) and what its user_data /
            user_context fields point into must outlive the context: the context keeps the
            ContextDef and the ctypes objects assigned to its fields.
    """

    def __init__(self, backend=None, *, device_ordinal=None, cpu_worker_count=None, log=None, definition=None):
        lib = library()
        d = definition.copy() if definition is not None else _g.ContextDef()
        # The copy has the definition's function pointers but not ctypes' references to the
        # Python objects behind them (log_fn, enqueue_task, finish_task, alloc_fn, free_fn: their
        # thunks) or to what its user_data / user_context fields point into (the struct's
        # _objects). The library calls them for the context's whole life, so the context keeps
        # the definition and a snapshot of those references (a later change to the definition
        # cannot drop them).
        self._definition = definition
        self._definition_refs = dict(getattr(definition, "_objects", None) or {}) if definition is not None else {}
        # Whether an asynchronous step may call back into the caller's code (World.__del__).
        self._step_hooks = definition is not None and any(
            ctypes.cast(getattr(definition, f), ctypes.c_void_p).value for f in _STEP_THREAD_HOOKS)
        if backend is not None:
            d.backend = enum_arg(_g.Backend, backend, "backend")
        if device_ordinal is not None:
            d.device_ordinal = device_ordinal
        if cpu_worker_count is not None:
            d.cpu_worker_count = cpu_worker_count
        self._log = log
        self._log_fn = _g.sph_log_fn(self._on_log) if log is not None else None
        if self._log_fn is not None:
            d.log_fn = self._log_fn
        out = ctypes.POINTER(_g.sph_context)()
        check(lib.sph_context_create(ctypes.byref(d), ctypes.byref(out)), "sph_context_create")
        self._ptr = out
        self._children = weakref.WeakSet()  # worlds and SDF assets created on this context

    def _on_log(self, _user_data, level, code, message):
        try:
            self._log(_g.LogLevel(level), _g.Result(code), message.decode("utf-8", "replace") if message else "")
        except Exception:  # noqa: BLE001 - nothing may propagate into C
            sys.excepthook(*sys.exc_info())

    @property
    def handle(self):
        """The sph_context* (a NULL pointer once closed)."""
        return self._ptr if self._ptr is not None else ctypes.POINTER(_g.sph_context)()

    @property
    def closed(self):
        return self._ptr is None

    @property
    def backend(self):
        """The Backend the context resolved to (CPU or CUDA; never AUTO)."""
        out = _g.sph_backend()
        check(library().sph_context_get_backend(self.handle, ctypes.byref(out)), "sph_context_get_backend")
        return _g.Backend(out.value)

    def set_cuda_allocator(self, alloc_fn=None, free_fn=None, user_context=None):
        """The engine's device allocator for this CUDA context's worlds
        (sph_cuda_context_set_allocator): ctypes function pointers of the types
        sph_cuda_alloc_fn and sph_cuda_free_fn (usually from the engine's own C library), both
        or neither (neither: back to cudaMalloc). Set it before the first world or SDF asset
        (else ERROR_BUSY). A CPU context raises SphError(ERROR_UNSUPPORTED)."""
        a = _g.CudaAllocator()
        if alloc_fn is not None:
            a.alloc_fn = alloc_fn
        if free_fn is not None:
            a.free_fn = free_fn
        if user_context is not None:
            a.user_context = user_context
        check(library().sph_cuda_context_set_allocator(self.handle, ctypes.byref(a)),
              "sph_cuda_context_set_allocator")
        self._cuda_allocator = (alloc_fn, free_fn, user_context, a)  # the library keeps calling them
        if alloc_fn is not None:
            self._step_hooks = True  # also from an asynchronous step's thread (World.__del__)

    def world(self, definition=None, **fields):
        """A new World on this context; see World."""
        return World(self, definition, **fields)

    def shape(self, shape="box", **fields):
        """An SDF asset of an analytic shape on this context; see Sdf.shape."""
        return Sdf.shape(self, shape, **fields)

    def sdf(self, distance, **kwargs):
        """An SDF asset from sampled grids on this context; see Sdf.from_grid."""
        return Sdf.from_grid(self, distance, **kwargs)

    def load_vdb(self, path, grid_name=None):
        """An SDF asset from a level set in a .vdb file (libsph_vdb); see Sdf.from_vdb."""
        return Sdf.from_vdb(self, path, grid_name)

    def load_world(self, data):
        """A new World on this context from checkpoint bytes (sph_world_load; see World.save).
        The context decides the backend, whichever saved it."""
        return load_world(World, self, data)

    def load_world_file(self, path):
        """A new World on this context from a checkpoint file (sph_world_load_file)."""
        return load_world_file(World, self, path)

    def close(self):
        """Closes the worlds, then the SDF assets, created on this context that are still
        open, then destroys the context (sph_context_destroy). Idempotent."""
        if self._ptr is not None:
            children = sorted(self._children, key=lambda c: not isinstance(c, World))
            for child in children:
                child.close()
            if getattr(self, "_leaked_worlds", 0):
                # A world the garbage collector leaked is on it: a distributed world dropped
                # without close() (sph.mpi; destroying the context would destroy that world, a
                # collective call this rank alone would make), or one dropped with an
                # asynchronous step in flight that it could not wait for (World.__del__).
                warnings.warn(f"sph.Context: {self._leaked_worlds} world(s) on it were dropped without close() and "
                              "leaked; the context is leaked with them", ResourceWarning, stacklevel=2)
            else:
                check(library().sph_context_destroy(self._ptr), "sph_context_destroy")
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            if getattr(self, "_ptr", None) is not None and not getattr(self, "_leaked_worlds", 0):
                library().sph_context_destroy(self._ptr)
            self._ptr = None
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    def __repr__(self):
        if self._ptr is None:
            return "<sph.Context closed>"
        return f"<sph.Context {self.backend.name}>"


# ---- world -------------------------------------------------------------------------------------------
class World(WorldSceneMixin, WorldCudaMixin, WorldOptionsMixin, WorldCheckpointMixin):
    """A particle fluid (sph_world): created on a Context, stepped, read back into numpy.

    ``World(ctx, capacity=100_000, particle_spacing=0.01)``: keyword arguments set fields of a
    default WorldDef (or of ``definition``). The world keeps its context alive. Use it as a
    context manager or call close(). Colliders, sources, sinks and force fields are added
    with add_collider/add_source/add_sink/add_force_field (see sph._scene); the zero-copy
    CUDA tier is cuda_attribute/cuda_array/cuda_epoch/... (see sph._cuda).

    Checkpoints: save() / save_file(path) / restore(data), and Context.load_world(data) /
    Context.load_world_file(path) (see sph._checkpoint).

    Optional physics is chosen here and fixed for the world's life (see sph._options):
    ``viscosity_method="clavet"`` (ViscosityMethod), ``equation_of_state="tait"``
    (EquationOfState), ``features="surface_tension|normalized_density"`` (Feature bits, also
    a list of names or ``Feature.A | Feature.B``). Their parameters are
    surface_tension_params, clavet_viscosity_params and tait_params (get/set, or
    set_*_params(**fields)); the step-size limits are ``set_params(step_limits=...)``.
    """

    def __init__(self, context, definition=None, **fields):
        d = definition.copy() if definition is not None else _g.WorldDef()
        for name, value in fields.items():
            setattr(d, name, value)
        out = ctypes.POINTER(_g.sph_world)()
        check(library().sph_world_create(context_handle(context), ctypes.byref(d), ctypes.byref(out)),
              "sph_world_create")
        self._ptr = out
        self.context = context
        context._children.add(self)

    _sph_type_ = _g.sph_world

    @classmethod
    def _adopt(cls, context, ptr):
        """A World object owning an sph_world* the library just created (a loaded checkpoint)."""
        self = cls.__new__(cls)
        self._ptr = ptr
        self.context = context
        context._children.add(self)
        return self

    # -- lifetime
    @property
    def handle(self):
        """The sph_world* (a NULL pointer once closed)."""
        return self._ptr if self._ptr is not None else ctypes.POINTER(_g.sph_world)()

    @property
    def closed(self):
        return self._ptr is None

    _step_in_flight = False  # between a step_begin() that succeeded and the step_wait() that collected it

    def close(self):
        """Destroys the world and everything in it (sph_world_destroy). Idempotent. While a step
        that step_begin() started is in flight it raises SphError(WORLD_LOCKED) and the world
        stays open: step_wait(), then close()."""
        if self._ptr is not None:
            check(library().sph_world_destroy(self._ptr), "sph_world_destroy")
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        """A world dropped without close() is destroyed here. One with an asynchronous step in
        flight is first collected: the step is cancelled (it stops at its next substep
        boundary) and waited for, so that dropping it, then closing its context, works. Except
        when the context has task-system or allocator hooks (ContextDef.enqueue_task, alloc_fn,
        ..., or set_cuda_allocator's) and the step has not finished: the step may need this
        very thread (or Python code the interpreter can no longer run) to finish, so the world
        is leaked with its context, never destroyed, with a ResourceWarning; the context's
        close() then warns instead of destroying it. step_wait() and close() before dropping a
        world avoid both."""
        try:
            ptr = getattr(self, "_ptr", None)
            if ptr is None:
                return
            lib = library()
            if self._step_in_flight and not self._collect_step_when_dropped(lib, ptr):
                return
            lib.sph_world_destroy(ptr)
            self._ptr = None
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    def _collect_step_when_dropped(self, lib, ptr):
        """__del__'s wait for the step in flight: True once collected, False when leaked."""
        done = ctypes.c_uint32()
        polled = lib.sph_world_step_poll(ptr, ctypes.byref(done))
        if polled == _g.Result.OK and not done.value and getattr(self.context, "_step_hooks", True):
            _LEAKED.append((ptr, self.context))
            self._ptr = None
            self.context._leaked_worlds = getattr(self.context, "_leaked_worlds", 0) + 1
            try:
                warnings.warn("sph.World dropped with an asynchronous step in flight on a context with task-system or "
                              "allocator hooks: leaked with its context (the step may need this thread to finish); "
                              "step_wait() and close() it first", ResourceWarning, stacklevel=2)
            except Exception:  # noqa: BLE001 - warnings turned into errors: nothing may leave __del__
                pass
            return False
        if polled == _g.Result.OK and not done.value:
            lib.sph_world_cancel_step(ptr)  # its frame is dropped with it: stop at the next substep
        lib.sph_world_step_wait(ptr)
        self._step_in_flight = False
        return True

    def __repr__(self):
        if self._ptr is None:
            return "<sph.World closed>"
        return f"<sph.World {self.particle_count} particles>"

    # -- creation-time facts
    @property
    def definition(self):
        """The WorldDef the world was created with, defaults resolved (sph_world_get_def),
        except capacity: the world's current capacity, larger than the def's once the world
        grew (never more than max_capacity)."""
        d = _g.WorldDef()
        check(library().sph_world_get_def(self.handle, ctypes.byref(d)), "sph_world_get_def")
        return d

    @property
    def particle_mass(self):
        """Mass of every particle, kg (sph_world_get_particle_mass)."""
        m = ctypes.c_float()
        check(library().sph_world_get_particle_mass(self.handle, ctypes.byref(m)), "sph_world_get_particle_mass")
        return m.value

    # -- runtime parameters
    @property
    def params(self):
        """The runtime WorldParams (sph_world_get_params); assign a WorldParams (or a dict of its
        fields, the others at their defaults, as the other params setters take) to replace them
        all at once (sph_world_set_params: validated as a whole, unchanged on error).
        set_params(**fields) changes some and keeps the others."""
        p = _g.WorldParams()
        check(library().sph_world_get_params(self.handle, ctypes.byref(p)), "sph_world_get_params")
        return p

    @params.setter
    def params(self, params):
        p = _as_struct(_g.WorldParams, params)
        check(library().sph_world_set_params(self.handle, ctypes.byref(p)), "sph_world_set_params")

    def set_params(self, **fields):
        """Changes some runtime parameters, keeping the others: ``w.set_params(gravity=(0, 0, 0))``,
        ``w.set_params(step_limits="acoustic|force")`` (StepLimit bits). Returns the
        parameters now set."""
        p = self.params
        for name, value in fields.items():
            setattr(p, name, value)
        self.params = p
        return p

    # -- particles in
    def spawn(self, positions, velocities=None):
        """Adds particles from (n, 3) arrays (sph_world_spawn; copied, all-or-nothing).

        float32 arrays whose rows are packed triples are passed as they are, row stride
        included (a column slice of a wider array costs no copy); others are converted once.
        Returns the id of the first new particle; the ids are consecutive.
        """
        pos = _vec3_rows(positions, "positions")
        desc = _g.SpawnDesc(count=pos.shape[0], positions=_float_ptr(pos), position_stride=pos.strides[0])
        if velocities is not None:
            vel = _vec3_rows(velocities, "velocities")
            if vel.shape[0] != pos.shape[0]:
                raise ValueError(f"velocities: {vel.shape[0]} rows for {pos.shape[0]} positions")
            desc.velocities = _float_ptr(vel)
            desc.velocity_stride = vel.strides[0]
        first = ctypes.c_uint32()
        check(library().sph_world_spawn(self.handle, ctypes.byref(desc), ctypes.byref(first)), "sph_world_spawn")
        return first.value

    def fill_box(self, min, max, velocity=(0.0, 0.0, 0.0)):  # noqa: A002 - the C field names
        """Fills the box [min, max] on an FCC lattice at rest density (sph_world_fill_box;
        all-or-nothing). Returns the number of particles added."""
        desc = _g.FillBoxDesc(min=min, max=max, velocity=velocity)
        n = ctypes.c_uint32()
        check(library().sph_world_fill_box(self.handle, ctypes.byref(desc), ctypes.byref(n)), "sph_world_fill_box")
        return n.value

    def fill_sphere(self, center, radius, velocity=(0.0, 0.0, 0.0)):
        """Fills a sphere on an FCC lattice (sph_world_fill_sphere). Returns the number added."""
        desc = _g.FillSphereDesc(center=center, radius=radius, velocity=velocity)
        n = ctypes.c_uint32()
        check(library().sph_world_fill_sphere(self.handle, ctypes.byref(desc), ctypes.byref(n)),
              "sph_world_fill_sphere")
        return n.value

    # -- stepping
    def step(self, frame_dt):
        """Advances the world by frame_dt seconds in adaptive substeps (sph_world_step; blocks).

        Returns Result.OK, or Result.INCOMPLETE when max_substeps ran out first, or the step
        budget (step_budget) or a cancel (cancel_step()) stopped it: the world is then as after
        its last whole substep, ready to step again (stats().frame_time and substeps say how far
        it got). Raises SphError(NON_FINITE) if a substep produced NaN/Inf, SphError(CAPACITY)
        if too many particles piled into one cell; the world is then as it was before the call.
        """
        return check(library().sph_world_step(self.handle, check_real(frame_dt, "frame_dt")), "sph_world_step")

    def prepare(self):
        """Builds now what the next step would build before its first substep (the boundary-density
        maps of the colliders' assets, CUDA's device copies), so that a loading screen pays for it
        rather than the first frame (sph_world_prepare). Optional; changes nothing a step sees."""
        check(library().sph_world_prepare(self.handle), "sph_world_prepare")

    @property
    def step_budget(self):
        """Wall-clock seconds one step may take before it stops at a substep boundary and
        returns Result.INCOMPLETE (sph_world_get_step_budget); 0 is no budget."""
        seconds = ctypes.c_double()
        check(library().sph_world_get_step_budget(self.handle, ctypes.byref(seconds)), "sph_world_get_step_budget")
        return seconds.value

    @step_budget.setter
    def step_budget(self, seconds):
        check(library().sph_world_set_step_budget(self.handle, check_real(seconds, "step_budget")),
              "sph_world_set_step_budget")

    def step_begin(self, frame_dt):
        """Starts the frame step() would run on the world's own thread and returns at once
        (sph_world_step_begin). Until step_wait() collects it every other call on the world
        raises SphError(WORLD_LOCKED), except cancel_step() and step_done()."""
        check(library().sph_world_step_begin(self.handle, check_real(frame_dt, "frame_dt")), "sph_world_step_begin")
        self._step_in_flight = True

    def step_wait(self):
        """Waits for the frame step_begin() started and returns what step() would have
        returned (Result.OK or Result.INCOMPLETE), or raises its error (sph_world_step_wait)."""
        result = library().sph_world_step_wait(self.handle)
        if result != _g.Result.ERROR_WORLD_LOCKED:  # collected (its result or its error)
            self._step_in_flight = False
        return check(result, "sph_world_step_wait")

    def step_done(self):
        """True once the frame step_begin() started has ended, so step_wait() will not block
        (sph_world_step_poll; never blocks)."""
        done = ctypes.c_uint32()
        check(library().sph_world_step_poll(self.handle, ctypes.byref(done)), "sph_world_step_poll")
        return bool(done.value)

    def cancel_step(self):
        """Asks the step running on another thread (or else the next step) to stop at its next
        substep boundary; that step returns Result.INCOMPLETE (sph_world_cancel_step). Safe to
        call from any thread while the world steps."""
        check(library().sph_world_cancel_step(self.handle), "sph_world_cancel_step")

    # -- particles out
    @property
    def particle_count(self):
        """Number of particles in the world (sph_world_get_particle_count)."""
        n = ctypes.c_uint32()
        check(library().sph_world_get_particle_count(self.handle, ctypes.byref(n)), "sph_world_get_particle_count")
        return n.value

    def __len__(self):
        return self.particle_count

    def copy_attribute(self, attribute, out=None, first=0, count=None):
        """Copies particles [first, first + count) of one attribute (sph_world_copy_attribute).

        The library writes straight into the returned array's buffer (np.empty, no second
        copy). Pass ``out`` to reuse an array: (n, 3) for vectors or (n,) for scalars of the
        attribute's dtype; its rows may be strided (e.g. a column block of a wider array).
        Particles come in the world's current order; read Attribute.ID to match them up.
        Returns the array (trimmed to the particles written).
        """
        attribute = _g.Attribute(attribute)
        dtype, comps = attribute_format(attribute)
        check_int(ctypes.c_uint32, first, "first")
        if count is not None:
            check_int(ctypes.c_uint32, count, "count")
        if out is not None:
            if not isinstance(out, np.ndarray):
                raise TypeError(f"out: expected a numpy array, got {type(out).__name__}")
            want = (comps,) if comps > 1 else ()
            if out.dtype != dtype or out.ndim != 1 + len(want) or out.shape[1:] != want:
                shape = f"(n, {comps})" if want else "(n,)"
                raise ValueError(f"out: {attribute.name} needs dtype {dtype} and shape {shape}, got {out.dtype} {out.shape}")
            if comps > 1 and out.strides[1] != dtype.itemsize:
                raise ValueError("out: the components of each row must be contiguous")
            if not out.flags.writeable:
                raise ValueError("out: array is read-only")
        if count is None:
            count = max(self.particle_count - first, 0) if out is None else len(out)
        if out is None:
            out = np.empty((count, comps) if comps > 1 else (count,), dtype)
        elem = comps * dtype.itemsize
        stride = out.strides[0] if out.ndim and len(out) > 1 else elem
        if stride < elem:
            raise ValueError(f"out: row stride {stride} is smaller than an element ({elem} bytes)")
        size = 0 if len(out) == 0 else (len(out) - 1) * stride + elem
        written = ctypes.c_uint32()
        check(library().sph_world_copy_attribute(self.handle, int(attribute), ctypes.c_void_p(out.ctypes.data), size,
                                                 stride, first, count, ctypes.byref(written)),
              "sph_world_copy_attribute")
        return out[:written.value]

    def positions(self, out=None):
        """(n, 3) float32 positions, m, in the world's current order."""
        return self.copy_attribute(_g.Attribute.POSITION, out)

    def velocities(self, out=None):
        """(n, 3) float32 velocities, m/s."""
        return self.copy_attribute(_g.Attribute.VELOCITY, out)

    def densities(self, out=None):
        """(n,) float32 densities, kg/m^3, from the last density evaluation."""
        return self.copy_attribute(_g.Attribute.DENSITY, out)

    def pressures(self, out=None):
        """(n,) float32 pressures, Pa, from the last density evaluation."""
        return self.copy_attribute(_g.Attribute.PRESSURE, out)

    def ids(self, out=None):
        """(n,) uint32 persistent particle ids, in the same order as the other attributes."""
        return self.copy_attribute(_g.Attribute.ID, out)

    def user_attributes(self, out=None):
        """(n,) uint32 user attributes (Feature.USER_ATTRIBUTE), in the same order."""
        return self.copy_attribute(_g.Attribute.USER, out)

    # -- writing particles
    def set_attribute(self, attribute, values, first=0):
        """Overwrites particles [first, first + len(values)) of POSITION, VELOCITY ((n, 3)
        float32) or USER ((n,) uint32) in the world's current order (sph_world_set_attribute:
        all-or-nothing, every value checked first). Strided numpy rows pass without a copy.
        USER values must be integers in [0, 2^32): others raise TypeError (floats, strings)
        or ValueError (out of range) before anything is written, never wrap or truncate."""
        attribute = _g.Attribute(attribute)
        dtype, comps = attribute_format(attribute)
        check_int(ctypes.c_uint32, first, "first")
        if comps == 3:
            a = _vec3_rows(values, "values")
        else:
            a = np.asarray(values)
            if a.ndim != 1:
                raise ValueError(f"values: expected an array of shape (n,), got {a.shape}")
            if dtype.kind in "ui" and a.dtype != dtype:
                a = _integers(values, a, dtype, f"values ({attribute.name})")
            if a.dtype != dtype or a.strides[0] < dtype.itemsize:
                a = np.ascontiguousarray(a, dtype=dtype)
        elem = comps * dtype.itemsize
        stride = a.strides[0] if len(a) > 1 else elem
        size = 0 if len(a) == 0 else (len(a) - 1) * stride + elem
        check(library().sph_world_set_attribute(self.handle, int(attribute), ctypes.c_void_p(a.ctypes.data), size,
                                                stride, first, len(a)),
              "sph_world_set_attribute")

    def set_positions(self, values, first=0):
        """(n, 3) positions, m, for particles [first, first + n) (set_attribute)."""
        self.set_attribute(_g.Attribute.POSITION, values, first)

    def set_velocities(self, values, first=0):
        """(n, 3) velocities, m/s, for particles [first, first + n) (set_attribute)."""
        self.set_attribute(_g.Attribute.VELOCITY, values, first)

    def set_user_attributes(self, values, first=0):
        """(n,) uint32 user attributes for particles [first, first + n) (set_attribute)."""
        self.set_attribute(_g.Attribute.USER, values, first)

    def remove_particles(self, ids):
        """Removes the particles with these ids (sph_world_remove_particles; all-or-nothing: an
        unknown or repeated id raises, naming the first). The ids join removed_ids(). They must be
        integers in [0, 2^32), as set_user_attributes' values: others raise TypeError (floats,
        strings: 1.7 removed particle 1) or ValueError (out of range) before anything is removed."""
        a = np.asarray(ids)
        flat = a.reshape(-1)
        if flat.dtype != np.uint32:
            flat = _integers(ids if a.ndim == 1 else flat, flat, np.dtype(np.uint32), "ids")
        a = np.ascontiguousarray(flat)
        check(library().sph_world_remove_particles(self.handle, a.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32)),
                                                   len(a)),
              "sph_world_remove_particles")

    # -- statistics
    def stats(self):
        """Statistics of the last step as a Stats struct (sph_world_get_stats): attribute
        access (``s.substeps``), ``s.to_dict()``, and ``stage_times(s)`` for stage_ms by Stage."""
        s = _g.Stats()
        check(library().sph_world_get_stats(self.handle, ctypes.byref(s)), "sph_world_get_stats")
        return s


def stage_times(stats):
    """{Stage: milliseconds} from a Stats struct's stage_ms array."""
    return {stage: stats.stage_ms[int(stage)] for stage in _g.Stage}


__all__.append("stage_times")
_ = SphError  # re-exported by the package
