// SPDX-License-Identifier: MIT
// Loads on colliders (SPH_FEATURE_COLLIDER_LOADS) on the CPU: the walls' pressure reactions of a
// force evaluation (or of DFSPH's solves, with its contact clamp's impulses) and the collision
// response with its contact impulses, summed per collider in
// blocks of kLoadBlock particles in storage order, then the blocks in order into the frame's
// double sums, so the loads do not depend on the thread count (the twin of
// cuda/device_collider_loads.cu; the physics is physics/collider_loads.h).
#include <algorithm>

#include "../physics/collider_loads.h"
#include "cpu_backend_impl.h"

namespace sph {

void CpuBackend::begin_loads(const SceneFrame& scene) {
  load_sums_.clear();
  if (config_.features & kFeatureColliderLoads) load_sums_.assign(scene.colliders.size(), ColliderLoadSums{});
}

void CpuBackend::collide_with_loads(const FluidConstants& fluid, const SceneFrame& scene,
                                    const SubstepTime& time, StageTime at, float wall_seconds,
                                    OldPositions old, FrameReport& report, const Float4* clamp) {
  const uint32_t colliders = static_cast<uint32_t>(scene.colliders.size());
  if (colliders == 0) return;
  const auto t = stage_start();
  const bool walls = boundary_ && wall_seconds > 0.0f;
  const bool contacts = old.records != nullptr || old.states != nullptr;
  const uint32_t blocks = (count_ + kLoadBlock - 1) / kLoadBlock;
  load_blocks_.assign(static_cast<size_t>(blocks) * colliders, zero_load_impulse());
  // The load points at the wall pass's time and at the substep's end (the contacts').
  load_points_.resize(2 * static_cast<size_t>(colliders));
  for (uint32_t c = 0; c < colliders; ++c) {
    load_points_[2 * c] = load_point_at(scene.colliders[c].view, at.s);
    load_points_[2 * c + 1] = load_point_at(scene.colliders[c].view, time.s1);
  }
  const float h = config_.kernel_radius;
  const float mass = fluid.particle_mass;
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  Float4* next_pos = next_position_.data();
  Float4* next_vel = next_velocity_.data();
  const Vec3* points = load_points_.data();
  LoadImpulse* partial = load_blocks_.data();
  const uint32_t* origin = origins();  // null unless distributed
  // Blocks go out dynamically like every loop's particles (kParticleChunk); their sums are kept
  // per block and added in block order below, so the split changes no bit.
  constexpr size_t kBlocksPerChunk = kParticleChunk / kLoadBlock;
  parallel().for_blocks(blocks, kBlocksPerChunk, [&](size_t first_block, size_t last_block) {
    for (size_t b = first_block; b < last_block; ++b) {
      LoadImpulse* sums = partial + static_cast<size_t>(b) * colliders;
      const uint32_t end = std::min(count_, (static_cast<uint32_t>(b) + 1) * kLoadBlock);
      for (uint32_t i = static_cast<uint32_t>(b) * kLoadBlock; i < end; ++i) {
        if (origin && origin[i]) continue;  // (a distributed world's halo: its owner's load)
        if (walls) {
          const Vec3 x = xyz(pos[i]);
          const float coefficient_dt = pos[i].w * vel[i].w * vel[i].w * wall_seconds;
          for (uint32_t c = 0; c < colliders; ++c) {
            const BoundaryShare share =
                collider_boundary_share(fluid.methods.boundary, collider_views_[c], x, at.s, at.tau);
            add_load(sums[c], wall_reaction_impulse(share.gradient, mass, coefficient_dt), x, points[2 * c]);
          }
        }
        if (clamp) {  // DFSPH's contact clamp, at the substep's start (where its solves work)
          const Float4 j = clamp[i];
          const uint32_t c = clamp_collider(j, colliders);
          if (c < colliders) add_load(sums[c], clamp_impulse(mass, j), xyz(pos[i]), points[2 * c]);
        }
        if (contacts) {
          Vec3 x = xyz(next_pos[i]);
          Vec3 v = xyz(next_vel[i]);
          const Vec3 from = old.records ? xyz(old.records[i]) : old.states[i].position;
          for (uint32_t c = 0; c < colliders; ++c) {
            const Vec3 before = v;
            collide_particle(scene.colliders[c].view, time, h, from, x, v);
            add_load(sums[c], contact_impulse(mass, before, v), x, points[2 * c + 1]);
          }
          next_pos[i] = make_float4_record(x, next_pos[i].w);
          next_vel[i] = make_float4_record(v, next_vel[i].w);
        }
      }
    }
  });
  for (uint32_t b = 0; b < blocks; ++b)
    for (uint32_t c = 0; c < colliders; ++c) {
      const LoadImpulse& s = partial[static_cast<size_t>(b) * colliders + c];
      ColliderLoadSums& sum = load_sums_[c];
      sum.linear[0] += s.linear.x;
      sum.linear[1] += s.linear.y;
      sum.linear[2] += s.linear.z;
      sum.angular[0] += s.angular.x;
      sum.angular[1] += s.angular.y;
      sum.angular[2] += s.angular.z;
    }
  end_stage(report, kStageCollide, t);
}

}  // namespace sph
