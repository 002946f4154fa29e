// SPDX-License-Identifier: MIT
// Scene-file errors (issue 7, item 6): every bad field is reported with its path and what was
// expected there; unknown fields (physics options of later issues among them) are rejected;
// scene objects the library refuses are reported at their path too.
#include <cstdio>
#include <cstring>
#include <string>

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

#include "scene_error.h"
#include "scene_parser.h"
#include "scene_runtime.h"

namespace {

using sph_tools::SceneError;

struct Case {
  const char* json;
  const char* message;  // the whole "path: message" must start with this
};

const Case kCases[] = {
    {R"({"world": {"capacity": -5}})", "world.capacity: expected an integer in [1, 1073741824], got -5"},
    {R"({"world": {"capacity": 1.5}})", "world.capacity: expected an integer in [1, 1073741824], got 1.5"},
    {R"({"world": {"capacity": 4294967296}})",
     "world.capacity: expected an integer in [1, 1073741824], got 4294967296"},
    {R"({"world": {"max_capacity": 1073741825}})",
     "world.max_capacity: expected an integer in [1, 1073741824], got 1073741825"},
    {R"({"params": {"max_substeps": 4294967296}})",
     "params.max_substeps: expected an integer in [0, 4294967295], got 4294967296"},
    {R"({"comment": 5})", "comment: expected a string (a comment), got 5"},
    {R"({"world": {"comment": [1, 2]}})", "world.comment: expected a string (a comment), got an array"},
    {R"({"output": {"format": ["csv", "ply", "csv"]}})",
     "output.format[2]: expected a format not listed before it, got the string \"csv\""},
    {R"({"world": {"particle_spacing": "small"}})",
     "world.particle_spacing: expected a positive number, got the string \"small\""},
    {R"({"world": {"particle_spacing": 0.02, "kernel_radius": 0.01}})",
     "world.kernel_radius: expected a radius >= particle_spacing (0.02)"},
    {R"({"world": {"integrator": "verlet"}})", "world.integrator: expected \"symplectic_euler\" or \"rk4\""},
    {R"({"world": {"surface_tension": 0.07}})", "world.surface_tension: unknown field; world takes capacity"},
    {R"({"surface_tension": {"coefficient": 0.07}})",
     "surface_tension: unknown field; a scene takes version"},
    {R"({"version": 2})", "version: expected an integer in [1, 1], got 2"},
    {R"({"params": {"gravity": [0, -9.81]}})", "params.gravity: expected an array of 3 numbers [x, y, z]"},
    {R"({"params": {"gravity": [0, "down", 0]}})", "params.gravity[1]: expected a number"},
    {R"({"params": {"viscosity": "thick"}})",
     "params.viscosity: expected a number, got the string \"thick\""},
    {R"({"params": {"max_substeps": -1}})", "params.max_substeps: expected an integer >= 0, got -1"},
    {R"({"params": {"surface_tension": 0.07}})",
     "params.surface_tension: unknown field; params takes max_substeps, gravity, stiffness, viscosity, "
     "step_factor, "
     "dt_min, dt_max, step_limits, tension_ratio"},
    {R"({"world": {"features": ["surface_tension", "foam"]}})",
     "world.features[1]: expected \"surface_tension\", \"normalized_density\", \"springs\", "
     "\"boundary_density\", \"collider_loads\" or \"density_diffusion\", got the string \"foam\""},
    {R"({"world": {"features": "springs"}})", "world.features: expected a list of feature names (an array)"},
    {R"({"world": {"viscosity_method": "xsph"}})",
     "world.viscosity_method: expected \"mueller\" or \"clavet\""},
    {R"({"world": {"equation_of_state": 7}})",
     "world.equation_of_state: expected \"ideal_gas\" or \"tait\", got 7"},
    {R"({"physics": {"tait": {"speed_of_sound": 20}}})",
     "physics.tait: the world does not use tait (set world.equation_of_state to \"tait\")"},
    {R"({"physics": {"springs": {}}})",
     "physics.springs: the world does not use springs (add \"springs\" to world.features)"},
    {R"({"physics": {"foam": {}}})",
     "physics.foam: unknown field; physics takes surface_tension, clavet, tait, springs, dfsph, "
     "density_diffusion (and "
     "\"comment\")"},
    {R"({"world": {"equation_of_state": "tait"}, "physics": {"tait": {"speed": 20}}})",
     "physics.tait.speed: unknown field; tait takes speed_of_sound (and \"comment\")"},
    {R"({"world": {"features": ["springs"]}, "physics": {"springs": {"stiffness": "hard"}}})",
     "physics.springs.stiffness: expected a number, got the string \"hard\""},
    {R"({"time": {"fps": 0}})", "time.fps: expected a positive number, got 0"},
    {R"({"fluids": {"type": "box"}})", "fluids: expected a list of fluid bodies (an array), got an object"},
    {R"({"fluids": [{"type": "cube"}]})",
     "fluids[0].type: expected \"box\", \"sphere\" or \"particles\", got the string \"cube\""},
    {R"({"fluids": [{"type": "sphere", "center": [0, 0, 0]}]})",
     "fluids[0].radius: missing (expected a positive number)"},
    {R"({"fluids": [{"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]}]})",
     "fluids[0].max: expected a corner above min in every component"},
    {R"({"fluids": [{"type": "particles", "positions": [[0, 0, 0]], "velocities": []}]})",
     "fluids[0].velocities: expected an array of 1 velocities (one per position)"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}}, {"shape": {"type": "sphere", "radius": 1}},
                       {"shape": {"type": "sphere", "radius": -1}}]})",
     "colliders[2].shape.radius: expected a positive number, got -1"},
    {R"({"colliders": [{"shape": {"type": "cup", "radius": 0.1, "half_height": 0.1}}]})",
     "colliders[0].shape.wall_thickness: missing (expected a positive number)"},
    {R"({"colliders": [{"shape": {"type": "box", "half_extents": [1, 0, 1]}}]})",
     "colliders[0].shape.half_extents[1]: expected a positive number, got 0"},
    {R"({"colliders": [{"shape": {"type": "box", "half_extents": [1, 1, 1], "open_top": true}}]})",
     "colliders[0].shape.open_top: expected false (an open top needs a hollow box"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1, "half_height": 2}}]})",
     "colliders[0].shape.half_height: unknown field; a sphere takes type, radius"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}, "restitution": 2}]})",
     "colliders[0].restitution: expected a number in [0, 1], got 2"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1},
                        "transform": {"rotation": {"axis": [0, 1, 0], "degrees": 90, "quaternion": [0, 0, 0, 1]}}}]})",
     "colliders[0].transform.rotation: give either \"quaternion\" or \"axis\""},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1},
                        "transform": {"rotation": {"axis": [0, 0, 0], "degrees": 90}}}]})",
     "colliders[0].transform.rotation.axis: expected a non-zero vector"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1},
                        "motion": {"keyframes": [{"time": 1, "position": [0, 0, 0]}, {"time": 0.5}]}}]})",
     "colliders[0].motion.keyframes[1].time: expected a time greater than the previous keyframe's (1)"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}, "motion": {"keyframes": []}}]})",
     "colliders[0].motion.keyframes: expected keyframes (an array of at least 1)"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}, "motion": {"keyframes": [{"time": 0}],
                        "interpolation": "cubic"}}]})",
     "colliders[0].motion.interpolation: expected \"linear\" or \"smooth\""},
    {R"({"sources": [{"shape": {"type": "sphere", "radius": 0.1}, "start": 2, "stop": 1}]})",
     "sources[0].stop: expected a time after start (2 s), got 1"},
    {R"({"sources": [{"shape": {"type": "sphere", "radius": 0.1}, "mode": "once", "rate": 100}]})",
     "sources[0].rate: expected no rate for a \"once\" source"},
    {R"({"sinks": [{"type": "outside_bounds", "min": [0, 0, 0], "max": [1, 1, -1]}]})",
     "sinks[0].max: expected a corner above min in every component"},
    {R"({"sinks": [{"type": "region"}]})", "sinks[0].shape: missing (expected a shape"},
    {R"({"force_fields": [{"type": "vortex", "strength": 1}]})",
     "force_fields[0].axis: missing (expected an array of 3 numbers [x, y, z])"},
    {R"({"force_fields": [{"type": "grid"}]})",
     "force_fields[0].type: expected \"uniform\", \"radial\" or \"vortex\", got the string \"grid\""},
    {R"({"probes": [{"type": "gauge", "position": [0, 0, 0]}]})",
     "probes[0].length: missing (expected a positive number)"},
    {R"({"probes": [{"type": "point"}]})",
     "probes[0].position: missing (expected an array of 3 numbers [x, y, z])"},
    {R"({"probes": [{"type": "gauge", "position": [0, 0, 0], "length": -1}]})",
     "probes[0].length: expected a positive number, got -1"},
    {R"({"output": {"format": "exr"}})",
     "output.format: expected \"vdb\", \"ply\", \"csv\" or \"vtp\", got the string \"exr\""},
    {R"({"output": {"preview": {"camera": {"position": [1, 1, 1], "target": [1, 1, 1]}}}})",
     "output.preview.camera.target: expected a point other than the position"},
    {R"({"output": {"preview": {"width": 4}}})",
     "output.preview.width: expected an integer in [16, 8192], got 4"},
    {R"({"output": {"surface": {"enabled": true, "iso": 0.5}}})", "output.surface.iso: unknown field"},
    {"{\"world\": {\n  \"capacity\": 10,\n}}", "not valid JSON: parse error at line 3, column 1"},
    {"[1, 2]", "expected a scene (an object), got an array of 2"},
    {R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}},
                       {"shape": {"type": "sphere", "radius": 1, "radius": 2}}]})",
     "colliders[1].shape.radius: given twice in one object"},
    {R"({"time": {"fps": 30}, "time": {"fps": 60}})", "time: given twice in one object"},
};

void test_each_bad_field_names_its_path(void**) {
  int failures = 0;
  for (const Case& c : kCases) {
    std::string what = "(no error)";
    try {
      sph_tools::parse_scene(c.json, ".");
    } catch (const SceneError& e) {
      what = e.what();
    }
    if (what.compare(0, std::strlen(c.message), c.message) != 0) {
      std::printf("scene %s\n  expected: %s...\n  got:      %s\n", c.json, c.message, what.c_str());
      ++failures;
    }
  }
  assert_int_equal(failures, 0);
}

// A CPU context with one worker, for the scenes' worlds.
sph_context* one_worker_context() {
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 1;
  sph_context* context = nullptr;
  assert_int_equal(sph_context_create(&def, &context), SPH_OK);
  return context;
}

// Builds the world of tests/cli/scenes/`file`, hands it to check, then steps one frame.
template <class Check>
void check_scene_world(const char* file, Check check) {
  sph_context* context = one_worker_context();
  {
    const sph_tools::SceneDesc scene = sph_tools::load_scene_file(std::string(CLI_SCENES_DIR "/") + file);
    sph_tools::SceneRuntime runtime(scene, context);
    check(runtime.world());
    assert_int_equal(runtime.step_frame(), SPH_OK);
  }
  assert_int_equal(sph_context_destroy(context), SPH_OK);
}

// Errors found while building the world carry the path of the object the library refused.
void expect_build_error(const char* json, const char* message) {
  sph_context* context = one_worker_context();
  std::string what = "(no error)";
  try {
    const sph_tools::SceneDesc scene = sph_tools::parse_scene(json, ".");
    sph_tools::SceneRuntime runtime(scene, context);
    while (runtime.frame() < 3) runtime.step_frame();
  } catch (const SceneError& e) {
    what = e.what();
  }
  if (what.compare(0, std::strlen(message), message) != 0)
    std::printf("scene %s\n  expected: %s...\n  got:      %s\n", json, message, what.c_str());
  assert_true(what.compare(0, std::strlen(message), message) == 0);
  assert_int_equal(sph_context_destroy(context), SPH_OK);
}

void test_library_rejections_name_the_object(void**) {
  expect_build_error(
      R"({"world": {"capacity": 100}, "fluids": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}]})",
      "fluids[0]: the fluid body does not fit: the world holds 0 of 100 particles (raise world.capacity)");
  // A growable world grows for a body up to its max_capacity, and names that limit past it.
  expect_build_error(
      R"({"world": {"capacity": 10, "max_capacity": 200}, "fluids": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}]})",
      "fluids[0]: the fluid body does not fit: the world holds 0 of 200 particles (raise "
      "world.max_capacity)");
  expect_build_error(R"({"world": {"capacity": 10, "max_capacity": 5}})",
                     "world: the library rejected the world: sph_world_create: def->max_capacity");
  // A later body that does not fit is reported when its time comes.
  expect_build_error(R"({"world": {"capacity": 1000}, "time": {"fps": 60},
                         "fluids": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1},
                                    {"type": "sphere", "center": [1, 0, 0], "radius": 0.1, "time": 0.02}]})",
                     "fluids[1]: the fluid body does not fit");
  // Parameters: the library's rules and messages, at the field's path in the file.
  expect_build_error(R"({"params": {"viscosity": -1}})", "params.viscosity: must be >= 0, got -1");
  expect_build_error(R"({"params": {"dt_min": 0.001, "dt_max": 0.0001}})",
                     "params.dt_max: 0.0001 is smaller than params.dt_min 0.001");
  expect_build_error(R"({"params": {"step_factor": 11}})", "params.step_factor: must be in (0, 10], got 11");
  expect_build_error(
      R"({"world": {"equation_of_state": "tait"}, "physics": {"tait": {"speed_of_sound": -5}}})",
      "physics.tait.speed_of_sound: must be > 0, got -5");
  expect_build_error(R"({"world": {"features": ["springs"], "particle_spacing": 0.02},
                         "physics": {"springs": {"link_radius": 0.5}}})",
                     "physics.springs.link_radius: 0.5 m is above the kernel radius 0.036");
  expect_build_error(
      R"({"colliders": [{"shape": {"type": "box", "half_extents": [100, 100, 100], "voxel_size": 0.001}}]})",
      "colliders[0].shape: the library rejected the shape: ");
#ifdef SPH_TOOLS_HAVE_VDB
  expect_build_error(R"({"colliders": [{"shape": {"type": "vdb", "file": "no_such_file.vdb"}}]})",
                     "colliders[0].shape.file: cannot load a level set from ./no_such_file.vdb");
#else
  expect_build_error(R"({"colliders": [{"shape": {"type": "vdb", "file": "no_such_file.vdb"}}]})",
                     "colliders[0].shape.type: \"vdb\" shapes need tools built with OpenVDB");
#endif
}

// The physics section sets the methods' parameters by the C structs' field names; the fields
// the file leaves out keep their defaults (tests/cli/scenes/options.json).
void test_physics_section_sets_the_methods(void**) {
  check_scene_world("options.json", [](sph_world* w) {
    sph_world_def d;
    sph_world_def_init(&d);
    assert_int_equal(sph_world_get_def(w, &d), SPH_OK);
    assert_int_equal(d.features,
                     SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_SPRINGS);
    assert_int_equal(d.viscosity_method, SPH_VISCOSITY_CLAVET);
    assert_int_equal(d.equation_of_state, SPH_EOS_TAIT);
    sph_world_params p;
    sph_world_params_init(&p);
    assert_int_equal(sph_world_get_params(w, &p), SPH_OK);
    assert_true(p.dt_max == 0.001f && p.step_limits == 3u && p.stiffness == 100.0f);  // stiffness: default
    sph_surface_tension_params st;
    sph_surface_tension_params_init(&st);
    assert_int_equal(sph_world_get_surface_tension_params(w, &st), SPH_OK);
    assert_true(st.coefficient == 0.05f && st.normal_threshold == 0.0f);
    sph_clavet_viscosity_params cv;
    sph_clavet_viscosity_params_init(&cv);
    assert_int_equal(sph_world_get_clavet_viscosity_params(w, &cv), SPH_OK);
    assert_true(cv.linear == 12.0f && cv.quadratic == 0.5f);
    sph_tait_params tait;
    sph_tait_params_init(&tait);
    assert_int_equal(sph_world_get_tait_params(w, &tait), SPH_OK);
    assert_true(tait.speed_of_sound == 20.0f);
    sph_spring_params sp;
    sph_spring_params_init(&sp);
    assert_int_equal(sph_world_get_spring_params(w, &sp), SPH_OK);
    assert_true(sp.stiffness == 2000.0f && sp.yield_ratio == 0.2f && sp.plasticity == 1.5f &&
                sp.damping == 3.0f && sp.link_radius == 0.0f);
  });
}

// The solver and DFSPH's parameters (sph_dfsph_params, the divergence bound a step among them) by
// the scene file (tests/cli/scenes/dfsph_options.json); the fields it leaves out keep their defaults.
void test_dfsph_section_sets_the_solver(void**) {
  check_scene_world("dfsph_options.json", [](sph_world* w) {
    sph_world_def d;
    sph_world_def_init(&d);
    assert_int_equal(sph_world_get_def(w, &d), SPH_OK);
    assert_int_equal(d.solver, SPH_SOLVER_DFSPH);
    sph_dfsph_params dp;
    sph_dfsph_params_init(&dp);
    assert_int_equal(sph_world_get_dfsph_params(w, &dp), SPH_OK);
    assert_true(dp.density_error == 0.002f && dp.divergence_error == 0.5f &&
                dp.divergence_error_per_step == 0.0005f && dp.linear_solver == SPH_DFSPH_CHEBYSHEV &&
                dp.depth_step_factor == 0.25f);
    assert_true(dp.max_iterations == 100u && dp.max_divergence_iterations == 100u && dp.flags == 0u &&
                dp.density_error_max == 0.05f);  // the defaults
  });
}

void test_missing_file_is_a_scene_error(void**) {
  std::string what;
  try {
    sph_tools::load_scene_file("/nonexistent/scene.json");
  } catch (const SceneError& e) {
    what = e.what();
  }
  assert_true(what.find("cannot open /nonexistent/scene.json") == 0);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_each_bad_field_names_its_path),
      cmocka_unit_test(test_library_rejections_name_the_object),
      cmocka_unit_test(test_physics_section_sets_the_methods),
      cmocka_unit_test(test_dfsph_section_sets_the_solver),
      cmocka_unit_test(test_missing_file_is_a_scene_error),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
