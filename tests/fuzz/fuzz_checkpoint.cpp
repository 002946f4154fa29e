// SPDX-License-Identifier: MIT
// libFuzzer harness: the input is a checkpoint given to sph_world_load (and to
// sph_world_restore of a live world). The loader validates the whole checkpoint before it
// creates anything (sph_c.h): it must return a world or an error with a message, and on error
// create nothing and leave the restored world exactly as it was. A loaded world must hold only
// finite particles with unique ids within its capacity, step (bounded: <= 4096 particles,
// 4 substeps) and save a checkpoint that loads again.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_check.h"
#include "sph_c.h"

using sph_fuzz::create_cpu_context;
using sph_fuzz::violation;

namespace {

constexpr uint32_t kMaxParticles = 4096;

sph_context* shared_context() {
  static sph_context* context = create_cpu_context();
  return context;
}

// A small world that sph_world_restore is tried on, rebuilt for every input.
sph_world* make_target_world() {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 256;
  sph_world* w = nullptr;
  if (FUZZ_CALL(sph_world_create(shared_context(), &def, &w)) != SPH_OK) violation("no world");
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{0.0f, 0.0f, 0.0f};
  box.max = sph_vec3{0.1f, 0.1f, 0.1f};
  FUZZ_CALL(sph_world_fill_box(w, &box, nullptr));
  return w;
}

std::vector<unsigned char> save(const sph_world* w) {
  uint64_t size = 0;
  if (FUZZ_CALL(sph_world_save(w, nullptr, 0, &size)) != SPH_OK) violation("size query failed");
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  uint64_t written = 0;
  if (FUZZ_CALL(sph_world_save(w, bytes.data(), bytes.size(), &written)) != SPH_OK || written != size)
    violation("save failed");
  return bytes;
}

void check_world(sph_world* w) {
  uint32_t n = 0;
  FUZZ_CALL(sph_world_get_particle_count(w, &n));
  sph_world_def def;
  sph_world_def_init(&def);
  FUZZ_CALL(sph_world_get_def(w, &def));
  if (n > def.capacity) violation("%u particles in a world of capacity %u", n, def.capacity);
  if (n > kMaxParticles || def.capacity > kMaxParticles) return;  // legal, too slow to step here
  std::vector<float> x(3 * static_cast<size_t>(n) + 3);
  std::vector<uint32_t> ids(n + 1);
  FUZZ_CALL(sph_world_copy_attribute(w, SPH_ATTRIBUTE_POSITION, x.data(), x.size() * 4, 0, 0, n, nullptr));
  FUZZ_CALL(sph_world_copy_attribute(w, SPH_ATTRIBUTE_ID, ids.data(), ids.size() * 4, 0, 0, n, nullptr));
  for (size_t i = 0; i < 3 * static_cast<size_t>(n); ++i)
    if (!std::isfinite(x[i])) violation("a loaded world with a non-finite position");
  ids.resize(n);
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) violation("a loaded world with a repeated id");

  // Save, load again: a checkpoint the library wrote must load, and save the same bytes.
  sph_world_params p;
  sph_world_params_init(&p);
  FUZZ_CALL(sph_world_get_params(w, &p));
  p.max_substeps = 4;
  if (FUZZ_CALL(sph_world_set_params(w, &p)) != SPH_OK) return;
  const std::vector<unsigned char> again = save(w);
  sph_world* copy = nullptr;
  if (FUZZ_CALL(sph_world_load(shared_context(), again.data(), again.size(), &copy)) != SPH_OK)
    violation("the library's own checkpoint does not load: %s", sph_get_last_error());
  if (save(copy) != again) violation("a world loaded from the library's own checkpoint saves other bytes");

  // Step the loaded world and its copy: the same answer; a failed step changes no carried
  // field (the checkpoint is the same byte for byte), a successful one leaves the two alike.
  const sph_result r = FUZZ_CALL(sph_world_step(w, 1.0f / 60.0f));
  if (r == SPH_ERROR_INTERNAL)
    violation("stepping a loaded world failed internally: %s", sph_get_last_error());
  if (r < 0 && save(w) != again) violation("a failed step (%d) of a loaded world changed its checkpoint", r);
  const sph_result rc = FUZZ_CALL(sph_world_step(copy, 1.0f / 60.0f));
  if (rc != r) violation("a loaded world's step answered %d, its reloaded copy's %d", r, rc);
  std::vector<float> xa(3 * static_cast<size_t>(def.capacity) + 3), xb(xa.size());
  uint32_t na = 0, nb = 0;
  FUZZ_CALL(
      sph_world_copy_attribute(w, SPH_ATTRIBUTE_POSITION, xa.data(), xa.size() * 4, 0, 0, def.capacity, &na));
  FUZZ_CALL(sph_world_copy_attribute(copy, SPH_ATTRIBUTE_POSITION, xb.data(), xb.size() * 4, 0, 0,
                                     def.capacity, &nb));
  if (na != nb || std::memcmp(xa.data(), xb.data(), 3 * static_cast<size_t>(na) * sizeof(float)) != 0)
    violation("a loaded world and its reloaded copy stepped apart");
  FUZZ_CALL(sph_world_destroy(copy));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sph_context* context = shared_context();
  uint32_t live_before = 0;
  FUZZ_CALL(sph_get_live_object_count(&live_before));

  sph_world* world = reinterpret_cast<sph_world*>(&live_before);  // must stay untouched on error
  const sph_result r = FUZZ_CALL(sph_world_load(context, data, size, &world));
  if (r == SPH_OK) {
    check_world(world);
    FUZZ_CALL(sph_world_destroy(world));
  } else if (world != reinterpret_cast<sph_world*>(&live_before)) {
    violation("sph_world_load wrote *out on failure");
  }

  // Restore into a live world: all-or-nothing.
  sph_world* target = make_target_world();
  const std::vector<unsigned char> before = save(target);
  const sph_result rr = FUZZ_CALL(sph_world_restore(target, data, size));
  if (rr != SPH_OK && save(target) != before) violation("a failed sph_world_restore changed the world");
  if ((rr == SPH_OK) != (r == SPH_OK)) violation("load returned %d but restore %d", r, rr);
  FUZZ_CALL(sph_world_destroy(target));

  uint32_t live_after = 0;
  FUZZ_CALL(sph_get_live_object_count(&live_after));
  if (live_after != live_before) violation("%u objects alive before, %u after", live_before, live_after);
  return 0;
}
