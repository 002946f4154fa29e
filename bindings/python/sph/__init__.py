# SPDX-License-Identifier: MIT
"""sph: Python bindings of the sph SPH fluid library (ctypes + numpy, no compiler needed).

    import sph
    with sph.Context("cpu") as ctx, ctx.world(particle_spacing=0.02) as world:
        world.fill_box((0, 0, 0), (0.2, 0.2, 0.2))
        world.step(1 / 60)
        xyz = world.positions()          # (n, 3) float32, copied straight into numpy

The library is found through SPH_LIBRARY (a full path), next to this package, or the system
loader (libsph.so.0); it is loaded on first use and checked against the ABI version and struct
layouts these bindings were generated for (see sph._loader). Failures raise SphError with
.result (a Result) and .message (the library's sph_get_last_error()).

Structs are the generated ctypes classes with keyword construction and library defaults:
``sph.WorldParams(gravity=(0, 0, 0))``. Optional physics is chosen at world creation
(``ctx.world(equation_of_state="tait", features=sph.Feature.NORMALIZED_DENSITY)``) and tuned
through World.tait_params, .clavet_viscosity_params and .surface_tension_params (or any of them by
kind: World.physics_params("tait"); sph.param_fields(kind) and sph.methods() describe them). The
raw declarations of every C function are in
sph._generated (FUNCTIONS) and are bound on sph.library().
"""
from . import _generated as raw
from ._core import (Context, World, abi_version, attribute_format, build_info, live_object_count, make_version,
                    result_string, stage_times, version)
from ._cuda import CudaArray
from ._errors import SphError, SphLoadError, last_error
from ._generated import (ABI_VERSION, STRUCTS, Attribute, Backend, Integrator, LogLevel, Result, Stage)
from ._loader import helper_library, library, library_path
from ._options import (ColliderFlag, CudaDfsphMasks, DfsphFlag, DfsphLinearSolver, Feature, ShapeFlag, SourceFlag,
                       StepLimit, methods, param_fields, params_info, params_kind)
from ._scene import Collider, ForceField, Probe, Sdf, Sink, Source, as_transform, grid_transform

# Every generated struct under its Python name (ContextDef, WorldDef, WorldParams, Stats, ...).
globals().update({cls.__name__: cls for cls in STRUCTS})
# Every generated IntEnum (Result, Backend, ...), including ones added to the header later.
globals().update({name: obj for name, obj in vars(raw).items()
                  if isinstance(obj, type) and issubclass(obj, raw._enum.IntEnum)})

#: The sph version these bindings were generated from, (major, minor, patch).
BINDINGS_VERSION = raw.VERSION

__all__ = ["Context", "World", "SphError", "SphLoadError", "Result", "Backend", "Integrator", "LogLevel",
           "Attribute", "Stage", "version", "abi_version", "build_info", "result_string", "last_error",
           "live_object_count", "make_version", "attribute_format", "stage_times", "library", "library_path", "helper_library",
           "ABI_VERSION", "BINDINGS_VERSION", "raw", "Sdf", "Collider", "Source", "Sink", "ForceField", "Probe", "CudaArray",
           "as_transform", "grid_transform", "Feature", "StepLimit", "DfsphFlag", "DfsphLinearSolver", "CudaDfsphMasks", "ColliderFlag", "SourceFlag", "ShapeFlag",
           "params_info", "param_fields", "methods", "params_kind", "ViscosityMethod", "EquationOfState", "Solver"] + [cls.__name__ for cls in STRUCTS]
