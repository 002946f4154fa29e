// SPDX-License-Identifier: MIT
// The box a preview frames: what the scene file places, before any particle moves.
#include "geometry.h"
#include "preview_renderer.h"
#include "sdf_factory.h"

namespace sph_tools {

namespace {

void grow(sph_vec3 p, bool* any, sph_vec3* lo, sph_vec3* hi) {
  *lo = *any ? vmin(*lo, p) : p;
  *hi = *any ? vmax(*hi, p) : p;
  *any = true;
}

// The world box of a shape's local box under a transform (its 8 corners).
void grow_shape(const ShapeDesc& shape, const sph_transform& t, bool* any, sph_vec3* lo, sph_vec3* hi) {
  sph_vec3 a, b;
  if (!shape_local_bounds(shape, &a, &b)) return;
  for (int k = 0; k < 8; ++k)
    grow(to_world(t, v3(k & 1 ? b.x : a.x, k & 2 ? b.y : a.y, k & 4 ? b.z : a.z)), any, lo, hi);
}

}  // namespace

bool scene_bounds(const SceneDesc& scene, sph_vec3* lo, sph_vec3* hi) {
  bool any = false;
  for (const FluidDesc& f : scene.fluids) {
    if (f.kind == FluidDesc::Kind::kBox) {
      grow(f.min, &any, lo, hi);
      grow(f.max, &any, lo, hi);
    } else if (f.kind == FluidDesc::Kind::kSphere) {
      grow(f.center - v3(f.radius, f.radius, f.radius), &any, lo, hi);
      grow(f.center + v3(f.radius, f.radius, f.radius), &any, lo, hi);
    } else {
      for (size_t i = 0; i < f.positions.size(); i += 3)
        grow(v3(f.positions[i], f.positions[i + 1], f.positions[i + 2]), &any, lo, hi);
    }
  }
  for (const SourceDesc& s : scene.sources) grow_shape(s.shape, s.transform, &any, lo, hi);
  for (const ColliderDesc& c : scene.colliders) {
    if (c.shape.kind == ShapeDesc::Kind::kAnalytic && c.shape.analytic.shape == SPH_SHAPE_PLANE) continue;
    grow_shape(c.shape, c.transform, &any, lo, hi);
    for (const Keyframe& k : c.motion.keys) grow_shape(c.shape, k.transform, &any, lo, hi);
  }
  return any;
}

}  // namespace sph_tools
