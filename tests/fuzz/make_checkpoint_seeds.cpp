// SPDX-License-Identifier: MIT
// Writes the seed corpus of fuzz_checkpoint (tests/fuzz/corpus/checkpoint/): checkpoints of
// small worlds saved by the library, one with every kind of scene object. Run by hand when the
// format changes: fuzz_make_checkpoint_seeds <folder>.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sph_c.h"

namespace {

void check(sph_result r, const char* what) {
  if (r < 0) {
    std::fprintf(stderr, "%s: %s\n", what, sph_get_last_error());
    std::exit(1);
  }
}

void write(const std::string& path, const sph_world* w) {
  uint64_t size = 0;
  check(sph_world_save(w, nullptr, 0, &size), "size");
  std::vector<unsigned char> bytes(size);
  check(sph_world_save(w, bytes.data(), size, &size), "save");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size()) std::exit(1);
  std::fclose(f);
  std::printf("%s: %zu bytes\n", path.c_str(), bytes.size());
}

sph_world* world(sph_context* c, uint32_t capacity, sph_integrator integrator, uint32_t features) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.integrator = integrator;
  def.features = features;
  def.particle_spacing = 0.05f;
  sph_world* w = nullptr;
  check(sph_world_create(c, &def, &w), "world");
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <folder>\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  sph_context_def cdef;
  sph_context_def_init(&cdef);
  cdef.backend = SPH_BACKEND_CPU;
  sph_context* c = nullptr;
  check(sph_context_create(&cdef, &c), "context");

  sph_world* empty = world(c, 16, SPH_INTEGRATOR_SYMPLECTIC_EULER, 0);
  write(dir + "/empty.ckpt", empty);
  sph_world_destroy(empty);

  // A few particles, stepped: particles, clock, statistics.
  sph_world* small = world(c, 64, SPH_INTEGRATOR_RK4, SPH_FEATURE_NORMALIZED_DENSITY);
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{0.0f, 0.0f, 0.0f};
  box.max = sph_vec3{0.15f, 0.15f, 0.15f};
  check(sph_world_fill_box(small, &box, nullptr), "fill");
  check(sph_world_step(small, 0.005f), "step");
  write(dir + "/particles_rk4.ckpt", small);
  sph_world_destroy(small);

  // Every kind of scene object, with small SDF grids.
  sph_world* scene = world(c, 128, SPH_INTEGRATOR_SYMPLECTIC_EULER, SPH_FEATURE_SURFACE_TENSION);
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.1f;
  shape.voxel_size = 0.05f;
  shape.padding_voxels = 1;
  sph_sdf* sdf = nullptr;
  check(sph_sdf_create_shape(c, &shape, &sdf), "sdf");
  sph_collider_def col;
  sph_collider_def_init(&col);
  col.sdf = sdf;
  col.flags = SPH_COLLIDER_FLAG_INVERTED;
  sph_collider_id cid;
  check(sph_collider_create(scene, &col, &cid), "collider");
  sph_source_def src;
  sph_source_def_init(&src);
  src.region = sdf;
  src.mode = SPH_SOURCE_CONTINUOUS;
  src.rate = 100.0f;
  sph_source_id sid;
  check(sph_source_create(scene, &src, &sid), "source");
  sph_sink_def sink;
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min = sph_vec3{-1.0f, -1.0f, -1.0f};
  sink.bounds_max = sph_vec3{1.0f, 1.0f, 1.0f};
  sph_sink_id kid;
  check(sph_sink_create(scene, &sink, &kid), "sink");
  sph_force_field_def ff;
  sph_force_field_def_init(&ff);
  ff.kind = SPH_FORCE_FIELD_VORTEX;
  ff.vector = sph_vec3{0.0f, 1.0f, 0.0f};
  ff.strength = 1.0f;
  ff.region = sdf;
  sph_force_field_id fid;
  check(sph_force_field_create(scene, &ff, &fid), "force field");
  check(sph_world_step(scene, 0.005f), "step");
  sph_transform t = sph_transform_identity();
  t.position.y = 0.01f;
  check(sph_collider_set_target_transform(scene, cid, &t), "target");
  write(dir + "/scene_objects.ckpt", scene);
  sph_world_destroy(scene);
  sph_sdf_destroy(sdf);
  sph_context_destroy(c);
  return 0;
}
