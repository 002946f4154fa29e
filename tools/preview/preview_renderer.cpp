// SPDX-License-Identifier: MIT
#include "preview_renderer.h"

#include <algorithm>
#include <cmath>

#include "frame_caption.h"
#include "geometry.h"
#include "mesh_raster.h"
#include "particle_splat.h"
#include "sdf_factory.h"
#include "shading.h"

namespace sph_tools {

PreviewRenderer::PreviewRenderer(const SceneRuntime& runtime) : settings_(runtime.scene().output) {
  const SceneDesc& scene = runtime.scene();
  particle_radius_ = 0.6f * scene.world.particle_spacing;
  have_bounds_ = scene_bounds(scene, &lo_, &hi_);
  if (settings_.speed_max > 0.0f) {
    speed_max_ = settings_.speed_max;
  } else {
    // The speed of a free fall over the scene's height: what a splash in it reaches.
    const float g = length(scene.params.gravity);
    const float height = have_bounds_ ? hi_.y - lo_.y : 0.5f;
    speed_max_ = std::max(0.5f, std::sqrt(2.0f * std::max(g, 1.0f) * std::max(height, 0.05f)));
  }
}

void PreviewRenderer::setup_camera(const float* positions, uint32_t count) {
  sph_vec3 lo = lo_, hi = hi_;
  bool any = have_bounds_;
  for (uint32_t i = 0; i < count; ++i) {  // particles (from a particle list or fill) extend the box
    const sph_vec3 p = v3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    lo = any ? vmin(lo, p) : p;
    hi = any ? vmax(hi, p) : p;
    any = true;
  }
  if (!any) {
    lo = v3(-0.5f, -0.5f, -0.5f);
    hi = v3(0.5f, 0.5f, 0.5f);
  }
  const CameraDesc& c = settings_.camera;
  camera_ = c.automatic ? Camera::framing(lo, hi, c.fov_degrees, settings_.width, settings_.height)
                        : Camera::look_at(c.position, c.target, c.up, c.fov_degrees, settings_.width,
                                          settings_.height);
  near_depth_ = 1e30f;
  far_depth_ = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const sph_vec3 corner = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    const float depth = dot(corner - camera_.eye, camera_.forward);
    near_depth_ = std::min(near_depth_, depth);
    far_depth_ = std::max(far_depth_, depth);
  }
  near_depth_ = std::max(near_depth_, 0.0f);
  camera_ready_ = true;
}

void PreviewRenderer::render(const SceneRuntime& runtime, const float* positions, const float* velocities,
                             uint32_t count, const SurfaceMesh* mesh, uint32_t frame, double time,
                             Image* image) {
  if (!camera_ready_) setup_camera(positions, count);
  const auto& colliders = runtime.colliders();
  if (!overlay_ready_) {
    for (const SceneRuntime::Collider& c : colliders) {
      sph_vec3 lo, hi;
      if (!shape_local_bounds(c.desc->shape, &lo, &hi)) {
        // A level set from a file: its extent is unknown here; draw it within the scene's box.
        lo = lo_ - v3(0.5f, 0.5f, 0.5f);
        hi = hi_ + v3(0.5f, 0.5f, 0.5f);
      }
      const float voxel =
          c.desc->shape.kind == ShapeDesc::Kind::kAnalytic ? c.desc->shape.analytic.voxel_size : 0.01f;
      overlay_.add(c.sdf, lo, hi, voxel, !c.desc->motion.empty());
    }
    overlay_ready_ = true;
  }
  image->resize(settings_.width, settings_.height);
  for (uint32_t y = 0; y < image->height; ++y) {
    const Rgb bg = background(static_cast<float>(y) / static_cast<float>(image->height));
    for (uint32_t x = 0; x < image->width; ++x) {
      float* c = &image->rgb[3 * (static_cast<size_t>(y) * image->width + x)];
      c[0] = bg.r;
      c[1] = bg.g;
      c[2] = bg.b;
    }
  }
  if (mesh) {
    raster_mesh(*mesh, camera_, near_depth_, far_depth_, image);
  } else {
    SplatStyle style;
    style.radius = particle_radius_;
    style.speed_max = speed_max_;
    style.near_depth = near_depth_;
    style.far_depth = far_depth_;
    splat_particles(positions, velocities, count, camera_, style, image);
  }
  if (!overlay_.empty()) {
    std::vector<sph_transform> poses;
    for (size_t i = 0; i < colliders.size(); ++i) poses.push_back(runtime.collider_pose(i));
    overlay_.trace(camera_, poses);
    overlay_.composite(image);
  }
  FrameCaption caption;
  caption.frame = frame;
  caption.time = time;
  caption.particles = count;
  caption.speed_legend = mesh == nullptr;
  caption.speed_max = speed_max_;
  draw_caption(caption, image);
}

}  // namespace sph_tools
