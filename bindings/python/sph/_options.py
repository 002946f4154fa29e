# SPDX-License-Identifier: MIT
"""Optional physics (docs/physics.md): feature bits, step limits, and the parameters of the
options a world turned on at creation.

Options are chosen when the world is created, through fields of its WorldDef::

    ctx.world(viscosity_method="clavet",                          # ViscosityMethod.CLAVET
              equation_of_state="tait",                           # EquationOfState.TAIT
              features="surface_tension|normalized_density")      # or Feature.X | Feature.Y
    ctx.world(solver="dfsph")                                     # Solver.DFSPH: world.dfsph_params

Their parameters are structs of their own, read and replaced whole (world.tait_params, ...)
or changed field by field (world.set_tait_params(speed_of_sound=40)). Reading or setting the
parameters of an option the world did not turn on raises SphError with
Result.ERROR_FEATURE_DISABLED. The step-size limits are bits of WorldParams.step_limits:
``world.set_params(step_limits="acoustic|force")``.

Every params struct can also be read and set by kind (world.physics_params("tait"),
world.set_physics_params("springs", damping=2)), and the library describes them for tools:
params_info(kind), param_fields(kind) (names, offsets, ranges, defaults, what a zero means) and
methods() (every method, how WorldDef turns it on, where its parameters are).
"""
import collections.abc
import ctypes
import enum

from . import _generated as _g
from ._errors import check
from ._loader import library

__all__ = ["Feature", "StepLimit", "DfsphFlag", "DfsphLinearSolver", "CudaDfsphMasks", "ColliderFlag", "SourceFlag",
           "ShapeFlag", "WorldOptionsMixin", "params_info", "param_fields", "methods", "params_kind"]


def _flags(name, prefix, doc):
    """An IntFlag whose members are the header's #defines named prefix + MEMBER, so bits added
    to the header appear here without code."""
    members = {k[len(prefix):]: v for k, v in vars(_g).items()
               if k.startswith(prefix) and isinstance(v, int) and not isinstance(v, bool)}
    cls = enum.IntFlag(name, members, module=__name__.rsplit(".", 1)[0])
    cls.__doc__ = doc
    return cls


Feature = _flags("Feature", "SPH_FEATURE_", """World feature bits (SPH_FEATURE_*; WorldDef.features), fixed at creation.

    SURFACE_TENSION: the Morris colour field (thesis eq. 20-23) applied as a capillary stress,
    plus a short-range cohesion (Akinci et al. 2013) carrying 15 % of sigma, calibrated so that
    sigma is the physical N/m (Laplace pressures within 6 %, the mode-2 Rayleigh period within
    5 % at 10 particles per radius; needs about 6 or more), parameters in
    World.surface_tension_params (docs/physics.md). NORMALIZED_DENSITY (thesis eq. 31): every
    particle carries a density factor (4 B of state, sorted, rolled back and checkpointed) so
    that particles at a free surface or a collider wall read the bulk's density instead of up
    to half of it; eq. 31 re-normalises the carried densities on every density pass (one more
    gather). SPRINGS: elasticity and plasticity, springs between neighbours made at each
    particle's first substep (Clavet et al. 2005), parameters in World.spring_params. A feature
    that is off allocates nothing and costs no work.""")

StepLimit = _flags("StepLimit", "SPH_STEP_LIMIT_", """Step-size limits beyond eq. 32 (SPH_STEP_LIMIT_*; WorldParams.step_limits).

    ACOUSTIC: dt <= step_factor h / c, c the equation of state's speed of sound. FORCE:
    dt <= step_factor sqrt(h / |a|_max).""")


def _named(name, doc, members, flag=False):
    """An IntEnum (IntFlag with flag=True) of the header's #defines: members maps each member's
    name to the #define's name in sph._generated (or to a plain int, for a value the header
    gives only in prose, such as 0 = the default)."""
    values = {k: (v if isinstance(v, int) else getattr(_g, v)) for k, v in members.items()}
    cls = (enum.IntFlag if flag else enum.IntEnum)(name, values, module=__name__.rsplit(".", 1)[0])
    cls.__doc__ = doc
    return cls


DfsphFlag = _named("DfsphFlag", """DFSPH option bits (SPH_DFSPH_* flags; DfsphParams.flags).

    SKIP_DIVERGENCE_SOLVE: no divergence solve (cheaper; a noisier pressure). CORRECTED_GRADIENT:
    the Jacobi solves' pressure gradient corrected to first order (Jacobi only).
    NO_DEPTH_STEP_LIMIT: the depth step limit (DfsphParams.depth_step_factor) off.""",
                   {"NONE": 0, "SKIP_DIVERGENCE_SOLVE": "SPH_DFSPH_SKIP_DIVERGENCE_SOLVE",
                    "CORRECTED_GRADIENT": "SPH_DFSPH_CORRECTED_GRADIENT",
                    "NO_DEPTH_STEP_LIMIT": "SPH_DFSPH_NO_DEPTH_STEP_LIMIT"}, flag=True)

DfsphLinearSolver = _named("DfsphLinearSolver", """How DFSPH's density solve iterates (DfsphParams.linear_solver).

    DEFAULT (0) is JACOBI; CONJUGATE_GRADIENTS (Jacobi-preconditioned); CHEBYSHEV (the Jacobi
    steps accelerated by Chebyshev's semi-iteration, not with CORRECTED_GRADIENT).""",
                           {"DEFAULT": 0, "JACOBI": "SPH_DFSPH_JACOBI",
                            "CONJUGATE_GRADIENTS": "SPH_DFSPH_CONJUGATE_GRADIENTS",
                            "CHEBYSHEV": "SPH_DFSPH_CHEBYSHEV"})

CudaDfsphMasks = _named("CudaDfsphMasks", """DFSPH's candidate masks on the CUDA backend (ContextDef.cuda_dfsph_masks; docs/cuda.md).

    ON (0, the default): the density pass records which of each particle's 27-cell candidates
    are neighbours; OFF (SPH_CUDA_DFSPH_MASKS_OFF): the solves walk every candidate;
    NEIGHBOR_LISTS (SPH_CUDA_DFSPH_NEIGHBOR_LISTS): the masks and neighbour lists. A CPU context
    checks and ignores it.""",
                        {"ON": 0, "OFF": "SPH_CUDA_DFSPH_MASKS_OFF",
                         "NEIGHBOR_LISTS": "SPH_CUDA_DFSPH_NEIGHBOR_LISTS"})

ColliderFlag = _flags("ColliderFlag", "SPH_COLLIDER_FLAG_", """Collider bits (SPH_COLLIDER_FLAG_*; ColliderDef.flags).

    INVERTED: solid where the SDF is positive (a container).""")

SourceFlag = _flags("SourceFlag", "SPH_SOURCE_FLAG_", """Source bits (SPH_SOURCE_FLAG_*; SourceDef.flags).

    VELOCITY_FROM_FIELD: emitted particles take their velocity from the region's velocity
    channel instead of SourceDef.velocity.""")

ShapeFlag = _flags("ShapeFlag", "SPH_SHAPE_FLAG_", """Analytic shape bits (SPH_SHAPE_FLAG_*; ShapeDesc.flags).

    OPEN_TOP: a hollow box without its lid (a tank open at +y).""")

# These fields read back as their enums and flags and accept their names (a member, its name in
# any case, "a|b" or a list for flags; a plain int still works).
for _struct, _field, _cls in ((_g.WorldDef, "features", Feature), (_g.WorldParams, "step_limits", StepLimit),
                              (_g.DfsphParams, "flags", DfsphFlag),
                              (_g.DfsphParams, "linear_solver", DfsphLinearSolver),
                              (_g.ContextDef, "cuda_dfsph_masks", CudaDfsphMasks),
                              (_g.ColliderDef, "flags", ColliderFlag), (_g.SourceDef, "flags", SourceFlag),
                              (_g.ShapeDesc, "flags", ShapeFlag)):
    _struct._sph_enums_ = {**_struct._sph_enums_, _field: _cls}
del _struct, _field, _cls


def _as_struct(cls, value):
    """value as a cls: a cls passes through, a mapping gives cls(**mapping) (defaults + those)."""
    if isinstance(value, cls):
        return value
    if isinstance(value, collections.abc.Mapping):
        return cls(**value)
    raise TypeError(f"expected {cls.__name__} or a dict of its fields, got {type(value).__name__}")


def _changed(struct, fields):
    for name, value in fields.items():
        setattr(struct, name, value)
    return struct


class WorldOptionsMixin:
    """The parameters of a World's optional physics; mixed into sph.World."""

    # -- what the world turned on (from its WorldDef)
    @property
    def features(self):
        """The world's Feature bits (WorldDef.features, fixed at creation)."""
        return self.definition.features

    @property
    def viscosity_method(self):
        """The world's ViscosityMethod (WorldDef.viscosity_method, fixed at creation)."""
        return self.definition.viscosity_method

    @property
    def equation_of_state(self):
        """The world's EquationOfState (WorldDef.equation_of_state, fixed at creation)."""
        return self.definition.equation_of_state

    # -- surface tension (Feature.SURFACE_TENSION)
    @property
    def surface_tension_params(self):
        """SurfaceTensionParams (coefficient sigma in N/m, normal_threshold in 1/m) of a world
        created with Feature.SURFACE_TENSION (sph_world_get_surface_tension_params). Assign a
        SurfaceTensionParams (or a dict of its fields, the others at their defaults) to
        replace them (sph_world_set_surface_tension_params; validated, unchanged on error).
        Raises SphError(ERROR_FEATURE_DISABLED) when the world does not have the feature."""
        p = _g.SurfaceTensionParams()
        check(library().sph_world_get_surface_tension_params(self.handle, ctypes.byref(p)),
              "sph_world_get_surface_tension_params")
        return p

    @surface_tension_params.setter
    def surface_tension_params(self, params):
        p = _as_struct(_g.SurfaceTensionParams, params)
        check(library().sph_world_set_surface_tension_params(self.handle, ctypes.byref(p)),
              "sph_world_set_surface_tension_params")

    def set_surface_tension_params(self, **fields):
        """Changes some surface-tension parameters, keeping the others:
        ``w.set_surface_tension_params(coefficient=0.5)``. Returns the parameters now set."""
        p = _changed(self.surface_tension_params, fields)
        self.surface_tension_params = p
        return p

    # -- Clavet viscosity (ViscosityMethod.CLAVET)
    @property
    def clavet_viscosity_params(self):
        """ClavetViscosityParams (linear sigma in 1/s, quadratic beta in 1/m) of a world created
        with viscosity_method=ViscosityMethod.CLAVET (sph_world_get_clavet_viscosity_params).
        Assign a ClavetViscosityParams (or a dict of its fields) to replace them
        (sph_world_set_clavet_viscosity_params). Raises SphError(ERROR_FEATURE_DISABLED) on a
        world that uses another viscosity method."""
        p = _g.ClavetViscosityParams()
        check(library().sph_world_get_clavet_viscosity_params(self.handle, ctypes.byref(p)),
              "sph_world_get_clavet_viscosity_params")
        return p

    @clavet_viscosity_params.setter
    def clavet_viscosity_params(self, params):
        p = _as_struct(_g.ClavetViscosityParams, params)
        check(library().sph_world_set_clavet_viscosity_params(self.handle, ctypes.byref(p)),
              "sph_world_set_clavet_viscosity_params")

    def set_clavet_viscosity_params(self, **fields):
        """Changes some Clavet viscosity parameters, keeping the others:
        ``w.set_clavet_viscosity_params(linear=20)``. Returns the parameters now set."""
        p = _changed(self.clavet_viscosity_params, fields)
        self.clavet_viscosity_params = p
        return p

    # -- Tait equation of state (EquationOfState.TAIT)
    @property
    def tait_params(self):
        """TaitParams (speed_of_sound c in m/s) of a world created with
        equation_of_state=EquationOfState.TAIT (sph_world_get_tait_params). Assign a TaitParams
        (or a dict of its fields) to replace them (sph_world_set_tait_params). Raises
        SphError(ERROR_FEATURE_DISABLED) on a world with another equation of state.
        Keep c >= 10 x the fastest flow, and c dt below about 0.4 h (lower dt_max, or
        StepLimit.ACOUSTIC in WorldParams.step_limits)."""
        p = _g.TaitParams()
        check(library().sph_world_get_tait_params(self.handle, ctypes.byref(p)), "sph_world_get_tait_params")
        return p

    @tait_params.setter
    def tait_params(self, params):
        p = _as_struct(_g.TaitParams, params)
        check(library().sph_world_set_tait_params(self.handle, ctypes.byref(p)), "sph_world_set_tait_params")

    def set_tait_params(self, **fields):
        """Changes some Tait parameters, keeping the others: ``w.set_tait_params(speed_of_sound=40)``.
        Returns the parameters now set."""
        p = _changed(self.tait_params, fields)
        self.tait_params = p
        return p

    # -- springs (Feature.SPRINGS)
    @property
    def spring_params(self):
        """SpringParams (stiffness k in 1/s^2, link_radius in m (0 = 1.2 x spacing), yield_ratio
        gamma, plasticity alpha in 1/s (0 = elastic), damping c in 1/s) of a world created with
        Feature.SPRINGS (sph_world_get_spring_params). Assign a SpringParams (or a dict of its
        fields) to replace them (sph_world_set_spring_params; validated, unchanged on error).
        Raises SphError(ERROR_FEATURE_DISABLED) when the world does not have the feature."""
        p = _g.SpringParams()
        check(library().sph_world_get_spring_params(self.handle, ctypes.byref(p)), "sph_world_get_spring_params")
        return p

    @spring_params.setter
    def spring_params(self, params):
        p = _as_struct(_g.SpringParams, params)
        check(library().sph_world_set_spring_params(self.handle, ctypes.byref(p)), "sph_world_set_spring_params")

    def set_spring_params(self, **fields):
        """Changes some spring parameters, keeping the others: ``w.set_spring_params(plasticity=5)``.
        Returns the parameters now set."""
        p = _changed(self.spring_params, fields)
        self.spring_params = p
        return p

    # -- DFSPH (solver=Solver.DFSPH)
    @property
    def dfsph_params(self):
        """DfsphParams of a world created with solver=Solver.DFSPH (sph_world_get_dfsph_params):
        density_error (the bound on the density solve's mean (rho* - rho0)+ / rho0, default
        0.001), divergence_error (1/s, default 1) and divergence_error_per_step (the same bound as a
        share a step, default 0.001: the divergence solve stops at the looser of the two),
        max_iterations, max_divergence_iterations, flags (SPH_DFSPH_*), linear_solver,
        density_error_max and depth_step_factor (every field: include/sph_c.h). Assign a DfsphParams (or a dict of its fields)
        to replace them (sph_world_set_dfsph_params; validated, unchanged on error). Raises
        SphError(ERROR_FEATURE_DISABLED) on a weakly compressible world."""
        p = _g.DfsphParams()
        check(library().sph_world_get_dfsph_params(self.handle, ctypes.byref(p)), "sph_world_get_dfsph_params")
        return p

    @dfsph_params.setter
    def dfsph_params(self, params):
        p = _as_struct(_g.DfsphParams, params)
        check(library().sph_world_set_dfsph_params(self.handle, ctypes.byref(p)), "sph_world_set_dfsph_params")

    def set_dfsph_params(self, **fields):
        """Changes some DFSPH parameters, keeping the others: ``w.set_dfsph_params(density_error=1e-4)``.
        Returns the parameters now set."""
        p = _changed(self.dfsph_params, fields)
        self.dfsph_params = p
        return p

    # -- density diffusion (features normalized_density|density_diffusion)
    @property
    def density_diffusion_params(self):
        """DensityDiffusionParams of a world created with Feature.DENSITY_DIFFUSION
        (sph_world_get_density_diffusion_params): delta, the delta-SPH coefficient (default 0.1,
        in (0, 1]). Assign a DensityDiffusionParams (or a dict of its fields) to replace them
        (sph_world_set_density_diffusion_params; validated, unchanged on error). Raises
        SphError(ERROR_FEATURE_DISABLED) on a world without the feature."""
        p = _g.DensityDiffusionParams()
        check(library().sph_world_get_density_diffusion_params(self.handle, ctypes.byref(p)),
              "sph_world_get_density_diffusion_params")
        return p

    @density_diffusion_params.setter
    def density_diffusion_params(self, params):
        p = _as_struct(_g.DensityDiffusionParams, params)
        check(library().sph_world_set_density_diffusion_params(self.handle, ctypes.byref(p)),
              "sph_world_set_density_diffusion_params")

    def set_density_diffusion_params(self, **fields):
        """Changes some density-diffusion parameters, keeping the others:
        ``w.set_density_diffusion_params(delta=0.2)``. Returns the parameters now set."""
        p = _changed(self.density_diffusion_params, fields)
        self.density_diffusion_params = p
        return p

    # -- any params struct by kind (the generic calls, for tools that read the descriptions)
    def physics_params(self, kind):
        """The params struct of `kind` (a ParamsKind or its name, "world", "tait", ...), read
        from the world (sph_world_get_physics_params): a WorldParams, TaitParams, ... Raises
        SphError(ERROR_FEATURE_DISABLED) for a method the world does not run."""
        kind = params_kind(kind)
        p = _struct_of(kind)()
        check(library().sph_world_get_physics_params(self.handle, kind, ctypes.byref(p)),
              "sph_world_get_physics_params")
        return p

    def set_physics_params(self, kind, params=None, **fields):
        """Replaces the params struct of `kind` (sph_world_set_physics_params) with `params`
        (its struct, or a dict of its fields, the others at their defaults), or changes only
        the given fields: ``w.set_physics_params("tait", speed_of_sound=40)``. Returns the
        parameters now set."""
        kind = params_kind(kind)
        if params is None:
            p = _changed(self.physics_params(kind), fields)
        else:
            p = _changed(_as_struct(_struct_of(kind), params), fields)
        check(library().sph_world_set_physics_params(self.handle, kind, ctypes.byref(p)),
              "sph_world_set_physics_params")
        return p


# ---- the descriptions of parameters and methods (static; for tools) ----------------------------
def params_info(kind):
    """The ParamsInfo of a params struct (sph_params_get_info): its scene-file name, C type name,
    size and number of described fields. kind: a ParamsKind or its name ("world", "tait")."""
    info = _g.ParamsInfo()
    check(library().sph_params_get_info(params_kind(kind), ctypes.byref(info)), "sph_params_get_info")
    return info


def param_fields(kind):
    """Every described field of a params struct as a ParamFieldInfo, in the order of the struct
    (sph_params_get_field_info): name, offset, type, range and bound kinds, default, unit and
    what a zero in it means (ParamZero)."""
    kind = params_kind(kind)
    fields = []
    for index in range(params_info(kind).field_count):
        f = _g.ParamFieldInfo()
        check(library().sph_params_get_field_info(kind, index, ctypes.byref(f)), "sph_params_get_field_info")
        fields.append(f)
    return fields


def methods():
    """Every physics method the library has, as PhysicsMethodInfo (sph_get_physics_method_info): its name, the
    WorldDef field that turns it on (MethodSwitch) and value, and the ParamsKind of its
    parameters when it has any."""
    out = []
    index = 0
    while True:
        m = _g.PhysicsMethodInfo()
        check(library().sph_get_physics_method_info(index, ctypes.byref(m)), "sph_get_physics_method_info")
        out.append(m)
        index += 1
        if index >= m.method_count:
            return out


def params_kind(kind):
    """A ParamsKind from itself, its int value or its name (the member's, "SPRINGS", or the
    library's scene-file name, "springs", "clavet")."""
    if isinstance(kind, str):
        for k in _g.ParamsKind:
            if kind.upper() == k.name or kind == params_info(k).name.decode():
                return k
        raise ValueError(f"{kind!r} names no params struct")
    return _g.ParamsKind(kind)


def _struct_of(kind):
    """The generated struct class of a params kind, found by its C type name."""
    name = params_info(kind).type_name.decode()
    return next(cls for cls in _g.STRUCTS if cls._sph_c_name_ == name)
