// SPDX-License-Identifier: MIT
// Device and pinned-host allocation failures on the CUDA backend (issue 9, item 6), injected
// at every device allocation point of every call in turn through the hook in
// cuda/device_allocation_faults.h (linked from sph_internal; libsph does not export it).
//
// For each call, n runs 0, 1, 2, ... until the call completes without reaching the n-th device
// allocation. Every injected failure must come back as SPH_ERROR_OUT_OF_DEVICE_MEMORY (or
// OUT_OF_HOST_MEMORY for pinned memory) with a message, leave the world bitwise as it was, and
// the world must then step bitwise like an undisturbed copy (the CUDA backend is
// deterministic: gpu_check_determinism). The growable-world calls (issue 19 item 1) start from
// a world whose capacity its particles fill exactly, so the call must grow it first: every
// allocation of the growth fails in turn and must leave the world, its capacity included, as
// it was.
#include <cstring>
#include <functional>

#include "../../cuda/device_allocation_faults.h"
#include "gpu_check.h"

using namespace gpu_check;
namespace faults = sph::testing;

namespace {

constexpr float kFrameDt = 1.0f / 60.0f;

struct Scene {
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  sph_sdf* tank = nullptr;
  sph_sdf* blob = nullptr;
};

sph_transform at(float x, float y, float z) {
  sph_transform t = sph_transform_identity();
  t.position = sph_vec3{x, y, z};
  return t;
}

enum class Objects { None, BeforeFirstStep, AfterFirstStep };

// The context, the world of `def` and the tank's and the blob's SDFs (no collider yet).
void create_world_and_shapes(Scene* s, const sph_world_def& def) {
  s->context = make_context(SPH_BACKEND_CUDA);
  require_ok(sph_world_create(s->context, &def, &s->world), "sph_world_create");
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents = sph_vec3{0.2f, 0.2f, 0.1f};
  shape.voxel_size = 0.02f;
  require_ok(sph_sdf_create_shape(s->context, &shape, &s->tank), "tank");
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.04f;
  shape.voxel_size = 0.02f;
  require_ok(sph_sdf_create_shape(s->context, &shape, &s->blob), "blob");
}

// The block of water in the tank.
void fill_water(Scene* s) {
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{-0.18f, -0.18f, -0.08f};
  box.max = sph_vec3{-0.02f, 0.02f, 0.08f};
  require_ok(sph_world_fill_box(s->world, &box, nullptr), "fill");
}

// A tank with water and one frame behind it; with a tank collider, a continuous source and a
// sink added before that frame, or after it (so the next step is their first). A growable
// world starts at capacity 16 and grows to exactly its water's count with the fill.
void build_scene(Scene* s, Objects objects, bool growable = false) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = growable ? 16 : 4000;
  def.max_capacity = growable ? 100000 : 0;
  def.particle_spacing = 0.02f;
  create_world_and_shapes(s, def);
  fill_water(s);
  if (objects == Objects::AfterFirstStep) require_ok(sph_world_step(s->world, kFrameDt), "first step");
  if (objects != Objects::None) {
    sph_collider_def collider;
    sph_collider_def_init(&collider);
    collider.sdf = s->tank;
    collider.flags = SPH_COLLIDER_FLAG_INVERTED;
    sph_collider_id cid;
    require_ok(sph_collider_create(s->world, &collider, &cid), "collider");
    sph_source_def source;
    sph_source_def_init(&source);
    source.mode = SPH_SOURCE_CONTINUOUS;
    source.region = s->blob;
    source.transform = at(0.1f, 0.1f, 0.0f);
    source.rate = 600.0f;
    sph_source_id sid;
    require_ok(sph_source_create(s->world, &source, &sid), "source");
    sph_sink_def sink;
    sph_sink_def_init(&sink);
    sink.region = s->blob;
    sink.transform = at(0.15f, -0.17f, 0.0f);
    sph_sink_id kid;
    require_ok(sph_sink_create(s->world, &sink, &kid), "sink");
  }
  if (objects != Objects::AfterFirstStep) require_ok(sph_world_step(s->world, kFrameDt), "first step");
}

void destroy_scene(Scene* s) {
  sph_world_destroy(s->world);
  sph_sdf_destroy(s->tank);
  sph_sdf_destroy(s->blob);
  sph_context_destroy(s->context);
  *s = Scene{};
}

struct Snapshot {
  uint32_t count = 0;
  uint32_t capacity = 0;
  double time = 0.0;
  std::vector<float> position, velocity, density;
  std::vector<uint32_t> id;
  bool operator==(const Snapshot& o) const {
    return count == o.count && capacity == o.capacity && time == o.time && position == o.position &&
           velocity == o.velocity && density == o.density && id == o.id;
  }
};

Snapshot take(const sph_world* world) {
  Snapshot s;
  require_ok(sph_world_get_particle_count(world, &s.count), "count");
  sph_stats stats;
  sph_stats_init(&stats);
  require_ok(sph_world_get_stats(world, &stats), "stats");
  s.time = stats.simulated_time;
  s.capacity = stats.capacity;
  s.position.resize(3 * size_t{s.count});
  s.velocity.resize(3 * size_t{s.count});
  s.density.resize(s.count);
  s.id.resize(s.count);
  const uint32_t n = s.count;
  require_ok(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, s.position.data(), 12ull * n, 0, 0, n, nullptr),
      "positions");
  require_ok(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, s.velocity.data(), 12ull * n, 0, 0, n, nullptr),
      "velocities");
  require_ok(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, s.density.data(), 4ull * n, 0, 0, n, nullptr),
      "densities");
  require_ok(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, s.id.data(), 4ull * n, 0, 0, n, nullptr),
             "ids");
  return s;
}

struct Call {
  const char* name;
  Objects objects;
  std::function<sph_result(Scene&)> run;
  std::function<void(Scene&)> undo;  // releases what a successful call made (not the world's)
  bool changes_world;
  bool growable = false;  // the scene's world is full and may grow (build_scene)
  // The call may make no device allocation (allocation_free below); any other call that reaches no
  // allocation point was not tested, and fails.
  bool may_allocate_nothing = false;
};

// A call that may do its work without a device allocation (its buffers made earlier).
Call allocation_free(Call call) {
  call.may_allocate_nothing = true;
  return call;
}

void check_call(const Call& call) {
  Scene scene;
  build_scene(&scene, call.objects, call.growable);
  long faults_injected = 0;
  bool ok = true;
  std::string problem;
  for (long n = 0; ok; ++n) {
    const Snapshot before = take(scene.world);
    uint32_t objects_before = 0;
    sph_get_live_object_count(&objects_before);
    faults::arm_device_allocation_fault(n);
    const sph_result r = call.run(scene);
    const bool injected = faults::disarm_device_allocation_fault();
    const std::string message = sph_get_last_error();  // the next sph_ call clears it
    if (!injected) {
      if (r != SPH_OK) {
        ok = false;
        problem = std::string("without a fault: ") + sph_result_string(r) + " (" + message + ")";
      }
      if (r == SPH_OK && call.undo) call.undo(scene);
      break;
    }
    ++faults_injected;
    if (r == SPH_OK) {  // absorbed (a fallback path): start again from a fresh scene
      if (call.undo) call.undo(scene);
      destroy_scene(&scene);
      build_scene(&scene, call.objects, call.growable);
      continue;
    }
    uint32_t objects_after = 0;
    sph_get_live_object_count(&objects_after);
    if (r != SPH_ERROR_OUT_OF_DEVICE_MEMORY && r != SPH_ERROR_OUT_OF_HOST_MEMORY) {
      ok = false;
      problem =
          "allocation " + std::to_string(n) + " failing gave " + sph_result_string(r) + " (" + message + ")";
    } else if (message.find("cudaMalloc") == std::string::npos) {
      ok = false;
      problem = "the message does not name the allocation: " + message;
    } else if (objects_after != objects_before) {
      ok = false;
      problem = "allocation " + std::to_string(n) + " failing leaked a handle";
    } else if (!(take(scene.world) == before)) {
      ok = false;
      problem = "allocation " + std::to_string(n) + " failing changed the world";
    }
  }
  // World creation, a scene's first frame and a growth cannot complete without device allocations
  // (18, 26 and 34 points of the three world creations, 10 of the first scene frame, 14 and 24 of
  // the growths on an H100, session 46): none failed means the hook never saw them.
  if (ok && !call.may_allocate_nothing && faults_injected == 0) {
    ok = false;
    problem = "no device allocation reached the injection hook";
  }
  if (ok && call.changes_world) {
    Scene reference;
    build_scene(&reference, call.objects, call.growable);
    require_ok(call.run(reference), call.name);
    require_ok(sph_world_step(scene.world, kFrameDt), "step after the faults");
    require_ok(sph_world_step(reference.world, kFrameDt), "reference step");
    if (!(take(scene.world) == take(reference.world))) {
      ok = false;
      problem = "after the faults the world steps differently from an undisturbed copy";
    }
    destroy_scene(&reference);
  }
  destroy_scene(&scene);
  report(ok, (std::string("allocation_faults/") + call.name).c_str(),
         "%ld device allocation points failed once each%s%s", faults_injected, ok ? "" : "; ",
         problem.c_str());
}

sph_probe_id add_probe(sph_world* world, float x) {
  sph_probe_def def;
  sph_probe_def_init(&def);
  def.position = sph_vec3{x, -0.15f, 0.0f};
  sph_probe_id id{};
  require_ok(sph_probe_create(world, &def, &id), "sph_probe_create");
  return id;
}

// A scene stepped once with two probes.
void two_probe_frame(Scene* s, sph_probe_id ids[2]) {
  build_scene(s, Objects::None);
  ids[0] = add_probe(s->world, -0.14f);  // in the water
  ids[1] = add_probe(s->world, -0.06f);
  require_ok(sph_world_step(s->world, kFrameDt), "the two probes' first frame");
}

std::vector<sph_probe_reading> readings(const sph_world* world, const sph_probe_id* ids, int count) {
  std::vector<sph_probe_reading> r(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    sph_probe_reading_init(&r[k]);
    require_ok(sph_probe_get_reading(world, ids[k], &r[k]), "sph_probe_get_reading");
  }
  return r;
}

// The probes' host copy grows when a step has more probes than before. An allocation that failed
// there (OUT_OF_HOST_MEMORY, the world unchanged) left the buffer freed but its size counted, so
// once the new probe was gone every later step copied the readings into a null pointer and
// failed (CudaBackend's device_probes.cu); and a failed growth freed the sums that the cached frame
// graph copies from, which the next step replayed (the loads case below). Each allocation point of
// the step with a third probe fails in turn; then the third probe goes and the world must step,
// its two probes reading what an undisturbed world's read.
void check_probe_growth_failure() {
  Scene reference;
  sph_probe_id ids[2];
  two_probe_frame(&reference, ids);
  require_ok(sph_world_step(reference.world, kFrameDt), "reference frame");
  const std::vector<sph_probe_reading> want = readings(reference.world, ids, 2);
  const Snapshot want_state = take(reference.world);
  destroy_scene(&reference);
  long failed = 0;
  bool ok = true;
  std::string problem;
  for (long n = 0; ok; ++n) {
    Scene s;
    two_probe_frame(&s, ids);
    const sph_probe_id third = add_probe(s.world, -0.1f);
    faults::arm_device_allocation_fault(n);
    const sph_result r = sph_world_step(s.world, kFrameDt);
    const bool injected = faults::disarm_device_allocation_fault();
    if (!injected || r == SPH_OK) {
      destroy_scene(&s);
      if (!injected) break;
      continue;
    }
    ++failed;
    require_ok(sph_probe_destroy(s.world, third), "sph_probe_destroy");
    const sph_result again = sph_world_step(s.world, kFrameDt);
    if (again != SPH_OK) {
      ok = false;
      problem = "allocation " + std::to_string(n) +
                " failing, then the third probe gone: the next step gave " + sph_result_string(again) + " (" +
                sph_get_last_error() + ")";
    } else {
      const std::vector<sph_probe_reading> got = readings(s.world, ids, 2);
      const bool same = std::memcmp(got.data(), want.data(), sizeof(sph_probe_reading) * 2) == 0 &&
                        take(s.world) == want_state;
      if (!same) {
        ok = false;
        problem = "allocation " + std::to_string(n) + " failing: the world or its probes step differently";
      }
    }
    destroy_scene(&s);
  }
  report(ok && failed > 0, "allocation_faults/probe readings after a failed growth of their buffers",
         "%ld allocation points of a step with a new probe failed once each, the probe then destroyed%s%s",
         failed, ok ? "" : ": ", problem.c_str());
}

// The loads' buffers grow the same way when a step has more colliders than before (the collider's
// first frame also uploads its SDF and the scene's views). A captured frame graph copies from the
// loads' and the probes' sums, so it must not be replayed once a failed growth freed them: it
// was, when the buffers came back at the old addresses, and cudaGraphLaunch crashed (session 45,
// the probe case above; same_setup in cuda/frame_loop.cu now compares the buffers' generation).
// Each allocation point of the step with a second collider fails in turn; then that collider
// goes and the world must step, the first collider's loads and the particles as an undisturbed
// world's. (Without the loads' generation in same_setup this case still passed on an H100: the
// scene's collider views moved too, so the graph was rebuilt anyway. Whether they move is the
// allocator's choice; the generation does not depend on it. The probe case crashed without it.)
struct LoadsScene {
  Scene scene;
  sph_collider_id tank{};
};

void loads_frame(LoadsScene* l) {
  Scene* s = &l->scene;
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 4000;
  def.particle_spacing = 0.02f;
  def.features = SPH_FEATURE_COLLIDER_LOADS;
  create_world_and_shapes(s, def);
  sph_collider_def collider;
  sph_collider_def_init(&collider);
  collider.sdf = s->tank;
  collider.flags = SPH_COLLIDER_FLAG_INVERTED;
  require_ok(sph_collider_create(s->world, &collider, &l->tank), "tank collider");
  fill_water(s);
  require_ok(sph_world_step(s->world, kFrameDt), "the loads' first frame");
}

sph_collider_loads tank_loads(const LoadsScene& l) {
  sph_collider_loads out;
  sph_collider_loads_init(&out);
  require_ok(sph_collider_get_loads(l.scene.world, l.tank, &out), "sph_collider_get_loads");
  return out;
}

void check_load_growth_failure() {
  LoadsScene reference;
  loads_frame(&reference);
  require_ok(sph_world_step(reference.scene.world, kFrameDt), "reference frame");
  const sph_collider_loads want = tank_loads(reference);
  const Snapshot want_state = take(reference.scene.world);
  destroy_scene(&reference.scene);
  long failed = 0;
  bool ok = true;
  std::string problem;
  for (long n = 0; ok; ++n) {
    LoadsScene l;
    loads_frame(&l);
    sph_collider_def ball;
    sph_collider_def_init(&ball);
    ball.sdf = l.scene.blob;
    ball.transform = at(-0.1f, -0.12f, 0.0f);  // in the water
    sph_collider_id second{};
    require_ok(sph_collider_create(l.scene.world, &ball, &second), "second collider");
    faults::arm_device_allocation_fault(n);
    const sph_result r = sph_world_step(l.scene.world, kFrameDt);
    const bool injected = faults::disarm_device_allocation_fault();
    if (!injected || r == SPH_OK) {
      destroy_scene(&l.scene);
      if (!injected) break;
      continue;
    }
    ++failed;
    require_ok(sph_collider_destroy(l.scene.world, second), "sph_collider_destroy");
    const sph_result again = sph_world_step(l.scene.world, kFrameDt);
    if (again != SPH_OK) {
      ok = false;
      problem = "allocation " + std::to_string(n) +
                " failing, then the second collider gone: the next step gave " + sph_result_string(again) +
                " (" + sph_get_last_error() + ")";
    } else {
      const sph_collider_loads got = tank_loads(l);
      if (std::memcmp(&got, &want, sizeof got) != 0 || !(take(l.scene.world) == want_state)) {
        ok = false;
        problem = "allocation " + std::to_string(n) + " failing: the world or its loads step differently";
      }
    }
    destroy_scene(&l.scene);
  }
  report(ok && failed > 0, "allocation_faults/collider loads after a failed growth of their buffers",
         "%ld allocation points of a step with a new collider failed once each, the collider then "
         "destroyed%s%s",
         failed, ok ? "" : ": ", problem.c_str());
}

// The fill both fill_box calls make: a block beside the scene's water (into free capacity, or
// growing a full world).
sph_result fill_block(Scene& s) {
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{0.05f, -0.18f, -0.08f};
  box.max = sph_vec3{0.15f, -0.1f, 0.08f};
  return sph_world_fill_box(s.world, &box, nullptr);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  sph_world* made_world = nullptr;
  sph_context* made_context = nullptr;
  const Call calls[] = {
      allocation_free({"sph_context_create", Objects::None,
                       [&](Scene&) {
                         sph_context_def def;
                         sph_context_def_init(&def);
                         def.backend = SPH_BACKEND_CUDA;
                         return sph_context_create(&def, &made_context);
                       },
                       [&](Scene&) { sph_context_destroy(made_context); }, false}),
      {"sph_world_create", Objects::None,
       [&](Scene& s) {
         sph_world_def def;
         sph_world_def_init(&def);
         def.capacity = 100000;
         return sph_world_create(s.context, &def, &made_world);
       },
       [&](Scene&) { sph_world_destroy(made_world); }, false},
      {"sph_world_create (RK4, every option)", Objects::None,
       [&](Scene& s) {
         sph_world_def def;
         sph_world_def_init(&def);
         def.capacity = 20000;
         def.integrator = SPH_INTEGRATOR_RK4;
         def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
         return sph_world_create(s.context, &def, &made_world);
       },
       [&](Scene&) { sph_world_destroy(made_world); }, false},
      // DFSPH's arrays, the conjugate gradients' among them (allocated with any DFSPH world that
      // may choose them: src/core/particle_arrays.cpp), and its solves' block sums.
      {"sph_world_create (DFSPH)", Objects::None,
       [&](Scene& s) {
         sph_world_def def;
         sph_world_def_init(&def);
         def.capacity = 20000;
         def.solver = SPH_SOLVER_DFSPH;
         def.equation_of_state = SPH_EOS_IDEAL_GAS;
         return sph_world_create(s.context, &def, &made_world);
       },
       [&](Scene&) { sph_world_destroy(made_world); }, false},
      allocation_free({"sph_world_fill_box", Objects::None, fill_block, nullptr, true}),
      {"sph_world_step (the first frame of a collider, a source and a sink)", Objects::AfterFirstStep,
       [](Scene& s) { return sph_world_step(s.world, kFrameDt); }, nullptr, true},
      allocation_free({"sph_world_step (scene)", Objects::BeforeFirstStep,
                       [](Scene& s) { return sph_world_step(s.world, kFrameDt); }, nullptr, true}),
      allocation_free({"sph_world_step (plain)", Objects::None,
                       [](Scene& s) { return sph_world_step(s.world, kFrameDt); }, nullptr, true}),
      {"sph_world_fill_box (growing a full world)", Objects::None, fill_block, nullptr, true, true},
      {"sph_world_step (a source growing a full world; a sink reserving for the new capacity)",
       Objects::AfterFirstStep, [](Scene& s) { return sph_world_step(s.world, kFrameDt); }, nullptr, true,
       true},
  };
  for (const Call& call : calls) check_call(call);
  check_probe_growth_failure();
  check_load_growth_failure();
  return finish();
}
