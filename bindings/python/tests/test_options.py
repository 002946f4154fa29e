# SPDX-License-Identifier: MIT
"""Optional physics: world def options, feature and step-limit flags, the option parameter
structs (round trips, validation, ERROR_FEATURE_DISABLED when the option is off)."""
import ctypes

import numpy as np
import pytest

import sph


def raw(name, *args):
    return sph._errors.check(getattr(sph.library(), name)(*args), name)


def error(fn, *args, **kwargs):
    with pytest.raises(sph.SphError) as e:
        fn(*args, **kwargs)
    assert e.value.message, "the library explained the failure"
    return e.value


def _get(world, attr):
    return getattr(world, attr)


@pytest.fixture
def full(ctx):
    """A world with every option on."""
    with ctx.world(capacity=4096, viscosity_method="clavet", equation_of_state="tait",
                   features="surface_tension|normalized_density") as w:
        yield w


# The three option structs: (world attribute, set_ method, struct, defaults, a changed field, value).
OPTIONS = [
    ("surface_tension_params", "set_surface_tension_params", sph.SurfaceTensionParams,
     {"coefficient": 0.0728, "normal_threshold": 0.0}, "coefficient", 0.5),
    ("clavet_viscosity_params", "set_clavet_viscosity_params", sph.ClavetViscosityParams,
     {"linear": 10.0, "quadratic": 0.0}, "quadratic", 2.0),
    ("tait_params", "set_tait_params", sph.TaitParams, {"speed_of_sound": 10.0}, "speed_of_sound", 40.0),
]
OPTION_IDS = [o[0] for o in OPTIONS]


# ---- flags and enums --------------------------------------------------------------------------
def test_flag_classes_mirror_the_header_defines():
    assert {name: int(m) for name, m in sph.Feature.__members__.items()} == {
        k[len("SPH_FEATURE_"):]: v for k, v in vars(sph.raw).items() if k.startswith("SPH_FEATURE_")}
    assert sph.Feature.SURFACE_TENSION == sph.raw.SPH_FEATURE_SURFACE_TENSION
    assert sph.Feature.NORMALIZED_DENSITY == sph.raw.SPH_FEATURE_NORMALIZED_DENSITY
    assert sph.StepLimit.ACOUSTIC == sph.raw.SPH_STEP_LIMIT_ACOUSTIC
    assert sph.StepLimit.FORCE == sph.raw.SPH_STEP_LIMIT_FORCE
    assert sph.ViscosityMethod.CLAVET == sph.raw.SPH_VISCOSITY_CLAVET
    assert sph.EquationOfState.TAIT == sph.raw.SPH_EOS_TAIT


def test_def_and_params_accept_names_and_read_back_flags():
    d = sph.WorldDef(viscosity_method="Clavet", equation_of_state="tait",
                     features=["surface_tension", sph.Feature.NORMALIZED_DENSITY])
    assert d.viscosity_method is sph.ViscosityMethod.CLAVET
    assert d.equation_of_state is sph.EquationOfState.TAIT
    assert d.features == sph.Feature.SURFACE_TENSION | sph.Feature.NORMALIZED_DENSITY
    assert isinstance(d.features, sph.Feature)
    assert sph.WorldDef(features="normalized_density").features is sph.Feature.NORMALIZED_DENSITY
    assert sph.WorldDef(features=sph.Feature.SURFACE_TENSION).features is sph.Feature.SURFACE_TENSION
    assert sph.WorldDef().features == sph.Feature.NONE == 0
    assert sph.WorldDef(integrator="rk4").integrator is sph.Integrator.RK4  # every enum field takes names
    p = sph.WorldParams(step_limits="acoustic | force")
    assert p.step_limits == sph.StepLimit.ACOUSTIC | sph.StepLimit.FORCE and isinstance(p.step_limits, sph.StepLimit)
    assert sph.WorldParams().step_limits == 0
    assert sph.WorldParams(step_limits=[]).step_limits == 0
    with pytest.raises(ValueError, match="surface_tension"):
        sph.WorldDef(features="surface_tenson")  # the message lists the valid names
    with pytest.raises(ValueError, match="clavet"):
        sph.WorldDef(viscosity_method="clavett")


def test_world_def_options_reach_the_library(full, world):
    d = full.definition
    assert d.viscosity_method is sph.ViscosityMethod.CLAVET
    assert d.equation_of_state is sph.EquationOfState.TAIT
    assert d.features == sph.Feature.SURFACE_TENSION | sph.Feature.NORMALIZED_DENSITY
    assert (full.features, full.viscosity_method, full.equation_of_state) == (
        d.features, sph.ViscosityMethod.CLAVET, sph.EquationOfState.TAIT)
    assert world.features == sph.Feature.NONE
    assert world.viscosity_method is sph.ViscosityMethod.MUELLER
    assert world.equation_of_state is sph.EquationOfState.IDEAL_GAS


@pytest.mark.parametrize("fields", [{"viscosity_method": 9}, {"equation_of_state": 9}, {"features": 0x80}])
def test_unknown_options_are_unsupported(ctx, fields):
    assert error(ctx.world, **fields).result == sph.Result.ERROR_UNSUPPORTED


# ---- parameters of the options -----------------------------------------------------------------
@pytest.mark.parametrize("attr, setter, cls, defaults, field, value", OPTIONS, ids=OPTION_IDS)
def test_option_params_feature_disabled(world, attr, setter, cls, defaults, field, value):
    """A world that did not turn the option on refuses its parameters, both ways."""
    e = error(_get, world, attr)
    assert e.result == sph.Result.ERROR_FEATURE_DISABLED and e.function.startswith("sph_world_get_")
    e = error(setattr, world, attr, cls())
    assert e.result == sph.Result.ERROR_FEATURE_DISABLED and e.function.startswith("sph_world_set_")
    e = error(getattr(world, setter), **{field: value})
    assert e.result == sph.Result.ERROR_FEATURE_DISABLED


@pytest.mark.parametrize("attr, setter, cls, defaults, field, value", OPTIONS, ids=OPTION_IDS)
def test_option_params_defaults_and_round_trip(full, attr, setter, cls, defaults, field, value):
    p = getattr(full, attr)
    assert isinstance(p, cls) and p.struct_size == ctypes.sizeof(cls)
    assert p == cls(), "a new world starts at the struct's init defaults"
    assert {k: pytest.approx(v) for k, v in defaults.items()} == {k: getattr(p, k) for k in defaults}
    p = cls(**{field: value})
    setattr(full, attr, p)
    assert getattr(full, attr) == p
    setattr(full, attr, {field: value / 2})  # a dict: its fields over the defaults
    assert getattr(getattr(full, attr), field) == pytest.approx(value / 2)
    q = getattr(full, setter)(**{field: value * 2})
    assert getattr(q, field) == pytest.approx(value * 2) and getattr(full, attr) == q
    with pytest.raises(AttributeError):
        getattr(full, setter)(no_such_field=1)
    with pytest.raises(TypeError):
        setattr(full, attr, sph.WorldParams())


@pytest.mark.parametrize("attr, setter, cls, defaults, field, value", OPTIONS, ids=OPTION_IDS)
def test_option_params_validation_changes_nothing(full, attr, setter, cls, defaults, field, value):
    before = getattr(full, attr)
    for bad in (-1.0, float("nan"), float("inf")):
        assert error(getattr(full, setter), **{field: bad}).result == sph.Result.ERROR_INVALID_ARGUMENT
    if "reserved0" in dict(cls._fields_):
        assert error(getattr(full, setter), reserved0=1).result == sph.Result.ERROR_INVALID_ARGUMENT
    assert getattr(full, attr) == before
    p = cls()
    p.struct_size = 2
    assert error(setattr, full, attr, p).result == sph.Result.ERROR_VERSION_MISMATCH
    fn = "sph_world_get_" + attr
    assert error(raw, fn, full.handle, ctypes.byref(p)).result == sph.Result.ERROR_VERSION_MISMATCH
    assert error(raw, fn, full.handle, None).result == sph.Result.ERROR_INVALID_ARGUMENT
    assert getattr(full, attr) == before


def test_tait_speed_of_sound_must_be_positive(full):
    e = error(full.set_tait_params, speed_of_sound=-1.0)
    assert e.result == sph.Result.ERROR_INVALID_ARGUMENT
    assert "params->speed_of_sound: must be > 0, got -1" in e.message
    full.set_tait_params(speed_of_sound=0.0)
    assert full.tait_params.speed_of_sound == 10.0  # 0 takes the default
    full.set_surface_tension_params(coefficient=0.0)  # sigma = 0 and beta = 0 are values
    full.set_clavet_viscosity_params(linear=0.0, quadratic=0.0)
    assert (full.clavet_viscosity_params.linear, full.surface_tension_params.coefficient) == (0.0, 0.0)


# ---- every params struct by kind, and the descriptions tools read -------------------------------
def test_params_are_described_for_tools():
    assert [sph.params_info(k).name for k in sph.ParamsKind] == [
        b"world", b"surface_tension", b"clavet", b"tait", b"springs", b"dfsph", b"density_diffusion"]
    assert sph.params_info("tait").type_name == b"sph_tait_params"
    assert sph.params_info("clavet").params_size == ctypes.sizeof(sph.ClavetViscosityParams)
    names = [f.name for f in sph.param_fields(sph.ParamsKind.WORLD)]
    assert names == [b"max_substeps", b"gravity", b"stiffness", b"viscosity", b"step_factor", b"dt_min", b"dt_max",
                     b"step_limits", b"tension_ratio"]
    speed = sph.param_fields("tait")[0]
    assert (speed.name, speed.unit, speed.offset) == (b"speed_of_sound", b"m/s", sph.TaitParams.speed_of_sound.offset)
    assert speed.lower == 0.0 and speed.lower_bound == sph.ParamBound.EXCLUSIVE
    assert speed.zero == sph.ParamZero.DEFAULT and speed.default_value[0] == 10.0
    gravity = sph.param_fields("world")[1]
    assert gravity.type == sph.ParamType.VEC3 and gravity.zero == sph.ParamZero.VALUE
    assert tuple(gravity.default_value) == pytest.approx((0, -9.81, 0))
    methods = {m.name: m for m in sph.methods()}
    assert list(methods) == [b"ideal_gas", b"tait", b"mueller", b"clavet", b"surface_tension",
                             b"normalized_density", b"springs", b"wcsph", b"dfsph",
                             b"boundary_density", b"collider_loads", b"density_diffusion"]
    assert methods[b"density_diffusion"].params_kind == sph.ParamsKind.DENSITY_DIFFUSION
    assert methods[b"dfsph"].switch_by == sph.MethodSwitch.SOLVER and methods[b"dfsph"].value == sph.Solver.DFSPH
    assert methods[b"dfsph"].params_kind == sph.ParamsKind.DFSPH
    assert methods[b"wcsph"].has_params and methods[b"wcsph"].params_kind == sph.ParamsKind.WORLD  # tension_ratio
    assert methods[b"springs"].switch_by == sph.MethodSwitch.FEATURE
    assert methods[b"springs"].value == sph.Feature.SPRINGS and methods[b"springs"].has_params
    assert methods[b"tait"].params_kind == sph.ParamsKind.TAIT
    assert not methods[b"normalized_density"].has_params
    with pytest.raises(ValueError):
        sph.params_kind("no such params")


def test_params_by_kind_are_the_typed_params(full):
    p = full.set_physics_params("tait", speed_of_sound=33)
    assert isinstance(p, sph.TaitParams) and full.tait_params.speed_of_sound == 33
    full.set_physics_params(sph.ParamsKind.CLAVET_VISCOSITY, {"linear": 4})
    assert full.clavet_viscosity_params.linear == 4 and full.clavet_viscosity_params.quadratic == 0
    assert full.physics_params("world") == full.params
    e = error(full.set_physics_params, "tait", speed_of_sound=-2)
    assert "params->speed_of_sound: must be > 0, got -2" in e.message
    assert error(full.physics_params, "springs").result == sph.Result.ERROR_FEATURE_DISABLED


def test_each_option_alone_enables_only_its_params(ctx):
    with ctx.world(capacity=16, equation_of_state=sph.EquationOfState.TAIT) as w:
        w.tait_params = sph.TaitParams(speed_of_sound=25)
        assert w.tait_params.speed_of_sound == 25
        assert error(_get, w, "clavet_viscosity_params").result == sph.Result.ERROR_FEATURE_DISABLED
        assert error(_get, w, "surface_tension_params").result == sph.Result.ERROR_FEATURE_DISABLED
    with ctx.world(capacity=16, features=sph.Feature.NORMALIZED_DENSITY) as w:
        assert error(_get, w, "surface_tension_params").result == sph.Result.ERROR_FEATURE_DISABLED
    with ctx.world(capacity=16, features="surface_tension") as w:
        assert w.surface_tension_params.coefficient == pytest.approx(0.0728)


def test_closed_world_option_calls_are_invalid_handle(ctx):
    w = ctx.world(capacity=16, viscosity_method="clavet", equation_of_state="tait", features="surface_tension")
    w.close()
    for attr, _, cls, *_ in OPTIONS:
        assert error(_get, w, attr).result == sph.Result.ERROR_INVALID_HANDLE
        assert error(setattr, w, attr, cls()).result == sph.Result.ERROR_INVALID_HANDLE


# ---- step limits ------------------------------------------------------------------------------------
def test_step_limits_round_trip_and_validation(world):
    p = world.set_params(step_limits=sph.StepLimit.ACOUSTIC)
    assert world.params.step_limits is sph.StepLimit.ACOUSTIC and p == world.params
    world.set_params(step_limits="acoustic|force")
    assert world.params.step_limits == sph.StepLimit.ACOUSTIC | sph.StepLimit.FORCE
    world.set_params(step_limits=0)
    assert world.params.step_limits == 0
    before = world.params
    assert error(world.set_params, step_limits=0x80).result == sph.Result.ERROR_UNSUPPORTED
    assert error(world.set_params, reserved0=1).result == sph.Result.ERROR_INVALID_ARGUMENT
    assert world.params == before


def test_acoustic_limit_with_a_fast_tait_sound_speed_takes_more_substeps(ctx):
    """c = 100 m/s, step factor 0.1. Without the flag the always-on stability ceiling still holds
    dt <= 0.4 h / c = 1.4e-4 s (about 58 substeps in a 1/120 s frame); the acoustic limit makes
    it dt <= 0.1 h / c (about 231)."""
    counts = {}
    for limits in (0, sph.StepLimit.ACOUSTIC):
        with ctx.world(capacity=2000, equation_of_state="tait") as w:
            w.set_tait_params(speed_of_sound=100)
            w.set_params(step_limits=limits, step_factor=0.1)
            w.fill_sphere((0, 0, 0), 0.04)
            assert w.step(1 / 120) == sph.Result.OK
            counts[limits] = w.stats().substeps
    h = 1.8 * 0.02
    assert counts[0] >= (1 / 120) / (0.4 * h / 100) - 1
    assert counts[sph.StepLimit.ACOUSTIC] >= (1 / 120) / (0.1 * h / 100) - 1
    assert counts[sph.StepLimit.ACOUSTIC] > 3 * counts[0]


# ---- every option on: the world still steps ---------------------------------------------------------
def test_a_world_with_every_option_steps(full):
    full.set_params(step_limits="acoustic|force")
    full.set_tait_params(speed_of_sound=30)
    full.set_clavet_viscosity_params(linear=5, quadratic=1)
    full.set_surface_tension_params(coefficient=0.05)
    n = full.fill_sphere((0, 0, 0), 0.05)
    assert full.step(1 / 240) == sph.Result.OK
    s = full.stats()
    assert s.particle_count == n and s.substeps > 0
    assert np.isfinite(full.positions()).all() and np.isfinite(full.densities()).all()


# ---- springs (Feature.SPRINGS) ------------------------------------------------------------------
def test_spring_params_round_trip_validation_and_feature(ctx):
    with ctx.world(capacity=16) as plain:
        assert error(_get, plain, "spring_params").result == sph.Result.ERROR_FEATURE_DISABLED
    with ctx.world(capacity=16, features="springs") as w:
        assert w.features == sph.Feature.SPRINGS
        p = w.spring_params
        assert (p.stiffness, p.link_radius, p.yield_ratio, p.plasticity, p.damping) == pytest.approx(
            (1e4, 0.0, 0.1, 0.0, 0.0))
        w.set_spring_params(plasticity=5.0, stiffness=2e5)
        assert w.spring_params.plasticity == 5.0 and w.spring_params.stiffness == 2e5
        assert error(w.set_spring_params, yield_ratio=1.5).result == sph.Result.ERROR_INVALID_ARGUMENT
        assert w.spring_params.yield_ratio == pytest.approx(0.1)
        w.spring_params = {"damping": 3.0}
        assert w.spring_params.damping == 3.0 and w.spring_params.plasticity == 0.0


# ---- density diffusion (Feature.DENSITY_DIFFUSION, with the normalised density) ----------------------
def test_density_diffusion_params_and_its_requirement(ctx):
    e = error(ctx.world, capacity=16, features="density_diffusion")
    assert e.result == sph.Result.ERROR_UNSUPPORTED and "SPH_FEATURE_NORMALIZED_DENSITY" in e.message
    with ctx.world(capacity=256, features="normalized_density|density_diffusion") as w:
        assert w.density_diffusion_params.delta == pytest.approx(0.1)
        w.set_density_diffusion_params(delta=0.2)
        assert w.physics_params("density_diffusion").delta == pytest.approx(0.2)
        e = error(w.set_density_diffusion_params, delta=2.0)
        assert "params->delta" in e.message and w.density_diffusion_params.delta == pytest.approx(0.2)
        w.density_diffusion_params = {"delta": 0.0}  # 0 = the default
        assert w.density_diffusion_params.delta == pytest.approx(0.1)
        w.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
        w.step(1 / 60)
    with ctx.world(capacity=16, features="normalized_density") as w:
        assert error(lambda: w.density_diffusion_params).result == sph.Result.ERROR_FEATURE_DISABLED


# ---- the solver (WorldDef.solver) -------------------------------------------------------------------
def test_dfsph_world_has_its_params_and_refuses_what_it_does_not_support(ctx):
    with ctx.world(capacity=256, solver="dfsph") as w:
        assert w.definition.solver is sph.Solver.DFSPH
        p = w.dfsph_params
        assert (p.density_error, p.divergence_error, p.max_iterations, p.max_divergence_iterations, p.flags) == (
            pytest.approx(0.001), 1.0, 100, 100, 0)
        assert p.density_error_max == pytest.approx(0.05)
        assert p.divergence_error_per_step == pytest.approx(0.001)
        e = error(w.set_dfsph_params, density_error_max=1.5)
        assert "params->density_error_max" in e.message and w.dfsph_params.density_error_max == pytest.approx(0.05)
        w.set_dfsph_params(density_error=1e-4, flags=sph.raw.SPH_DFSPH_SKIP_DIVERGENCE_SOLVE)
        assert w.dfsph_params.density_error == pytest.approx(1e-4)
        assert w.physics_params("dfsph").flags == sph.raw.SPH_DFSPH_SKIP_DIVERGENCE_SOLVE
        e = error(w.set_dfsph_params, max_iterations=1)
        assert "params->max_iterations" in e.message and w.dfsph_params.max_iterations == 100
        w.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
        w.step(1 / 60)
        s = w.stats()
        assert s.pressure_iterations >= 2 * s.substeps and s.density_error_max <= 1e-4
        # The conjugate gradients' density solve: the same bound (either backend); other values refused.
        assert w.dfsph_params.linear_solver == sph.raw.SPH_DFSPH_JACOBI
        e = error(w.set_dfsph_params, linear_solver=4)
        assert "params->linear_solver" in e.message and w.dfsph_params.linear_solver == sph.raw.SPH_DFSPH_JACOBI
        w.set_dfsph_params(linear_solver=sph.raw.SPH_DFSPH_CONJUGATE_GRADIENTS)
        w.step(1 / 60)
        s = w.stats()
        assert s.pressure_iterations >= 2 * s.substeps and s.density_error_max <= 1e-4
        # The Chebyshev solve: the same bound.
        w.set_dfsph_params(linear_solver=sph.raw.SPH_DFSPH_CHEBYSHEV)
        w.step(1 / 60)
        s = w.stats()
        assert s.pressure_iterations >= 2 * s.substeps and s.density_error_max <= 1e-4
    with ctx.world(capacity=16) as w:
        assert w.definition.solver is sph.Solver.WCSPH
        assert error(_get, w, "dfsph_params").result == sph.Result.ERROR_FEATURE_DISABLED
    for refused in ({"integrator": "rk4"}, {"equation_of_state": "tait"}, {"features": "normalized_density"}):
        e = error(ctx.world, capacity=16, solver="dfsph", **refused)
        assert e.result == sph.Result.ERROR_UNSUPPORTED and "SPH_SOLVER_DFSPH" in e.message


# ---- named DFSPH options, CUDA masks and object flags (the header's #defines as enums) -------------
def test_dfsph_linear_solver_and_flags_take_names_and_read_back_as_enums(ctx):
    assert [(m.name, int(m)) for m in sph.DfsphLinearSolver] == [
        ("DEFAULT", 0), ("JACOBI", sph.raw.SPH_DFSPH_JACOBI),
        ("CONJUGATE_GRADIENTS", sph.raw.SPH_DFSPH_CONJUGATE_GRADIENTS), ("CHEBYSHEV", sph.raw.SPH_DFSPH_CHEBYSHEV)]
    assert sph.DfsphFlag.SKIP_DIVERGENCE_SOLVE == sph.raw.SPH_DFSPH_SKIP_DIVERGENCE_SOLVE
    assert sph.DfsphFlag.CORRECTED_GRADIENT == sph.raw.SPH_DFSPH_CORRECTED_GRADIENT
    assert sph.DfsphFlag.NO_DEPTH_STEP_LIMIT == sph.raw.SPH_DFSPH_NO_DEPTH_STEP_LIMIT
    # A member, its lower-case name, or (compatibility) the int: all read back as the enum.
    for value in ("chebyshev", "CHEBYSHEV", sph.DfsphLinearSolver.CHEBYSHEV, sph.raw.SPH_DFSPH_CHEBYSHEV):
        p = sph.DfsphParams(linear_solver=value)
        assert p.linear_solver is sph.DfsphLinearSolver.CHEBYSHEV
    assert sph.DfsphParams().linear_solver is sph.DfsphLinearSolver.JACOBI  # the library's default
    assert sph.DfsphParams(linear_solver=0).linear_solver is sph.DfsphLinearSolver.DEFAULT
    with pytest.raises(ValueError, match="is not one of default, jacobi"):
        sph.DfsphParams(linear_solver="cheb")
    for value in ("skip_divergence_solve|no_depth_step_limit", ["skip_divergence_solve", sph.DfsphFlag.NO_DEPTH_STEP_LIMIT],
                  sph.DfsphFlag.SKIP_DIVERGENCE_SOLVE | sph.DfsphFlag.NO_DEPTH_STEP_LIMIT, 5):
        p = sph.DfsphParams(flags=value)
        assert p.flags == sph.DfsphFlag.SKIP_DIVERGENCE_SOLVE | sph.DfsphFlag.NO_DEPTH_STEP_LIMIT
        assert isinstance(p.flags, sph.DfsphFlag)
    assert sph.DfsphParams().flags is sph.DfsphFlag.NONE
    with ctx.world(capacity=256, solver="dfsph") as w:
        w.set_dfsph_params(linear_solver="conjugate_gradients", flags="skip_divergence_solve")
        p = w.dfsph_params
        assert p.linear_solver is sph.DfsphLinearSolver.CONJUGATE_GRADIENTS
        assert p.flags is sph.DfsphFlag.SKIP_DIVERGENCE_SOLVE
        w.dfsph_params = {"linear_solver": "chebyshev"}
        assert w.physics_params("dfsph").linear_solver is sph.DfsphLinearSolver.CHEBYSHEV
        # The library still judges the combination: Chebyshev with the corrected gradient is refused.
        e = error(w.set_dfsph_params, flags="corrected_gradient")
        assert e.result == sph.Result.ERROR_INVALID_ARGUMENT
        assert w.dfsph_params.flags is sph.DfsphFlag.NONE
        w.fill_box((0, 0, 0), (0.1, 0.1, 0.1))
        w.step(1 / 60)


def test_cuda_dfsph_masks_take_names(ctx):
    assert [(m.name, int(m)) for m in sph.CudaDfsphMasks] == [
        ("ON", 0), ("OFF", sph.raw.SPH_CUDA_DFSPH_MASKS_OFF), ("NEIGHBOR_LISTS", sph.raw.SPH_CUDA_DFSPH_NEIGHBOR_LISTS)]
    assert sph.ContextDef().cuda_dfsph_masks is sph.CudaDfsphMasks.ON
    for value in ("neighbor_lists", sph.CudaDfsphMasks.NEIGHBOR_LISTS, 2):
        assert sph.ContextDef(cuda_dfsph_masks=value).cuda_dfsph_masks is sph.CudaDfsphMasks.NEIGHBOR_LISTS
    with pytest.raises(ValueError, match="is not one of on, off, neighbor_lists"):
        sph.ContextDef(cuda_dfsph_masks="lists")
    # A CPU context checks and ignores it; a value the library does not know is refused.
    with sph.Context("cpu", cpu_worker_count=1, definition=sph.ContextDef(cuda_dfsph_masks="off")) as c:
        assert c.backend == sph.Backend.CPU
    e = error(sph.Context, "cpu", definition=sph.ContextDef(cuda_dfsph_masks=7))
    assert e.result == sph.Result.ERROR_INVALID_ARGUMENT


def test_object_flags_take_names(ctx):
    assert sph.ColliderFlag.INVERTED == sph.raw.SPH_COLLIDER_FLAG_INVERTED
    assert sph.SourceFlag.VELOCITY_FROM_FIELD == sph.raw.SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD
    assert sph.ShapeFlag.OPEN_TOP == sph.raw.SPH_SHAPE_FLAG_OPEN_TOP
    assert sph.ColliderDef(flags="inverted").flags is sph.ColliderFlag.INVERTED
    assert sph.ColliderDef(flags=1).flags is sph.ColliderFlag.INVERTED
    assert sph.ColliderDef().flags == 0 and isinstance(sph.ColliderDef().flags, sph.ColliderFlag)
    assert sph.SourceDef(flags=["velocity_from_field"]).flags is sph.SourceFlag.VELOCITY_FROM_FIELD
    assert sph.ShapeDesc(flags="open_top").flags is sph.ShapeFlag.OPEN_TOP
    with ctx.world(capacity=4096, particle_spacing=0.02) as w, \
            ctx.shape("box", half_extents=(0.1, 0.1, 0.1), voxel_size=0.02, flags="open_top") as box:
        w.add_collider(box, flags="inverted")
        w.add_collider(box, (1, 0, 0), flags=sph.ColliderFlag.INVERTED, inverted=True)
        # A source whose velocity comes from its region's velocity channel.
        vel = np.zeros((6, 6, 6, 3), np.float32)
        vel[..., 1] = 0.5
        with ctx.sdf(np.full((6, 6, 6), -1.0, np.float32), voxel_size=0.02, origin=(-0.05, -0.05, -0.05),
                     velocity=vel) as region:
            w.set_params(gravity=(0, 0, 0))
            w.add_source(region, (0, 0, 0), flags="velocity_from_field")
            w.step(1 / 240)
        assert len(w) > 0 and w.velocities()[:, 1].mean() > 0.1
    with pytest.raises(ValueError):
        sph.SourceDef(flags="inverted")


def test_every_named_option_constant_has_its_member():
    """A constant of these prefixes added to the header fails here until _options.py names it."""
    named = {"SPH_DFSPH_": (sph.DfsphFlag, sph.DfsphLinearSolver), "SPH_CUDA_DFSPH_": (sph.CudaDfsphMasks,),
             "SPH_COLLIDER_FLAG_": (sph.ColliderFlag,), "SPH_SOURCE_FLAG_": (sph.SourceFlag,),
             "SPH_SHAPE_FLAG_": (sph.ShapeFlag,)}
    found = 0
    for name, value in vars(sph.raw).items():
        prefix = next((p for p in named if name.startswith(p)), None)
        if prefix is None or not isinstance(value, int):
            continue
        tail = name[len(prefix):]
        members = [m for cls in named[prefix] for m in cls.__members__.items() if m[0] in (tail, tail[len("MASKS_"):])]
        assert members and int(members[0][1]) == value, f"{name} has no member in {[c.__name__ for c in named[prefix]]}"
        found += 1
    assert found == 11
