// SPDX-License-Identifier: MIT
// Probes and gauges on the CPU: after a substep's density pass, each sample point gathers the
// SPH interpolant's sums over the sorted particles (one point per loop iteration, its neighbours
// in the grid's fixed walk order), then each probe adds its points in order and its sample to the
// frame's sums (the twin of cuda/device_probes.cu; the physics is physics/probe_sampling.h). The
// result depends on neither the thread count nor the scheduling.
#include "../physics/probe_sampling.h"
#include "cpu_backend_impl.h"

namespace sph {

void CpuBackend::begin_probes(const SceneFrame& scene) {
  probe_sums_.assign(scene.probes.size(), ProbeSums{});
  probe_points_.resize(scene.probe_points);
}

void CpuBackend::sample_probes(const SceneFrame& scene, float dt, FrameReport& report) {
  if (scene.probes.empty()) return;
  const auto t = stage_start();
  ProbeConstants constants;
  constants.kernel = make_kernel_coefficients(config_.kernel_radius);
  constants.particle_mass = config_.particle_mass;
  constants.rest_density = config_.rest_density;
  const GridView view = grid_.view();
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  const ProbeView* probes = scene.probes.data();
  ProbeGather* points = probe_points_.data();
  const int probe_count = static_cast<int>(scene.probes.size());
  // One probe a block: a gauge's points are many, a point probe's one. A distributed rank gathers
  // only the points its slab holds (the others' gathers replace the rest below; its own table is
  // a band of the world's, where a point far outside would only meet particles to reject).
  const CpuRankHalo* rank = rank_.get();
  parallel().for_blocks(scene.probes.size(), 1, [&](size_t k, size_t) {
    const ProbeView& p = probes[k];
    for (uint32_t q = 0; q < p.point_count; ++q) {
      const Vec3 x = probe_point(p, q);
      points[p.first_point + q] = rank && !rank->owns_probe_point(x)
                                      ? zero_probe_gather()
                                      : gather_probe_point(constants, view, pos, vel, x);
    }
  });
  // Every rank reads each point's owner's sums.
  if (rank_) rank_->pick_probe_points(probes, scene.probes.size(), points, probe_points_.size());
  for (int k = 0; k < probe_count; ++k) {
    const ProbeView& p = probes[k];
    ProbeGather g = zero_probe_gather();
    for (uint32_t q = 0; q < p.point_count; ++q) g = g + points[p.first_point + q];
    add_probe_sample(probe_sums_[static_cast<size_t>(k)], p, probe_sample(constants, p, g), dt);
  }
  end_stage(report, kStageDensity, t);
}

}  // namespace sph
