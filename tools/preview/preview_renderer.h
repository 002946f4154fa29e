// SPDX-License-Identifier: MIT
// The headless preview: each frame's particles (or the fluid surface) drawn on the CPU with
// the colliders as faint glass, from the scene's camera or one that frames the scene.
#ifndef SPH_TOOLS_PREVIEW_RENDERER_H
#define SPH_TOOLS_PREVIEW_RENDERER_H

#include <memory>
#include <vector>

#include "camera.h"
#include "collider_overlay.h"
#include "image.h"
#include "scene_runtime.h"
#include "surface_mesh.h"

namespace sph_tools {

class PreviewRenderer {
 public:
  // Sets up the camera and the collider overlay for a built scene.
  explicit PreviewRenderer(const SceneRuntime& runtime);

  // Draws one frame. positions/velocities: 3 floats per particle. With a mesh, the surface is
  // drawn instead of the particles. The caption gives the frame's number and time (s), the
  // particle count and, for particles, the speed legend.
  void render(const SceneRuntime& runtime, const float* positions, const float* velocities, uint32_t count,
              const SurfaceMesh* mesh, uint32_t frame, double time, Image* image);

  const Camera& camera() const { return camera_; }

 private:
  void setup_camera(const float* positions, uint32_t count);

  const OutputDesc& settings_;
  float particle_radius_ = 0.01f;
  float speed_max_ = 2.0f;
  bool have_bounds_ = false;
  sph_vec3 lo_{}, hi_{};
  bool camera_ready_ = false;
  Camera camera_;
  float near_depth_ = 0.0f, far_depth_ = 1.0f;
  ColliderOverlay overlay_;
  bool overlay_ready_ = false;
};

// The box that holds a scene's fluid bodies, sources and colliders (planes excluded: they
// are floors, not things to frame). False when the scene gives none.
bool scene_bounds(const SceneDesc& scene, sph_vec3* lo, sph_vec3* hi);

}  // namespace sph_tools

#endif
