// SPDX-License-Identifier: MIT
// Colliders drawn as faint glass: each collider's SDF is sampled once into a local grid
// (through sph_sdf_sample), and every pixel's ray records where it crosses the zero level set.
// Crossings in front of the fluid are blended over it, brighter where the surface is seen
// edge-on, so the outlines of tanks, cups and paddles show without hiding the fluid.
#ifndef SPH_TOOLS_COLLIDER_OVERLAY_H
#define SPH_TOOLS_COLLIDER_OVERLAY_H

#include <vector>

#include "camera.h"
#include "image.h"
#include "sph_c.h"

namespace sph_tools {

class ColliderOverlay {
 public:
  // Adds a collider: its SDF, the box of its local frame to draw ([lo, hi]) and the cell size
  // of the local grid to sample it on. A collider that never moves is traced once.
  void add(const sph_sdf* sdf, sph_vec3 lo, sph_vec3 hi, float cell, bool moving);
  bool empty() const { return colliders_.empty(); }

  // Traces the colliders at their poses (one per add, in order) for this camera.
  void trace(const Camera& camera, const std::vector<sph_transform>& poses);
  // Blends the traced crossings in front of image.depth over the image.
  void composite(Image* image) const;

 private:
  struct Grid {
    sph_vec3 origin{};
    float cell = 0.0f;
    int n[3] = {0, 0, 0};
    std::vector<float> d;
    float sample(sph_vec3 p) const;
  };
  struct Collider {
    Grid grid;
    bool moving = false;
  };
  struct Crossing {
    uint32_t x;
    float depth, alpha, shade;
  };
  using Rows = std::vector<std::vector<Crossing>>;
  void trace_one(const Collider& c, const sph_transform& pose, const Camera& camera, Rows* rows) const;

  std::vector<Collider> colliders_;
  Rows static_rows_, moving_rows_;
  bool static_traced_ = false;
};

}  // namespace sph_tools

#endif
