// SPDX-License-Identifier: MIT
// The CPU backend's boundary-density maps (SPH_FEATURE_BOUNDARY_DENSITY; the physics is
// src/physics/boundary_map.h): one map per SDF asset the world's colliders use, computed on host
// threads for the world's kernel radius when a collider first steps with the asset and again
// after every change of it (SdfAsset::version: sph_sdf_update), and dropped when no collider uses
// the asset any more (the twin of cuda/device_boundary_maps.h).
#pragma once

#include <stdint.h>

#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "../core/host_memory.h"
#include "../core/sdf_asset.h"
#include "../physics/float4_types.h"
#include "cpu_parallel.h"

namespace sph {

class CpuBoundaryMaps {
 public:
  // Marks the start of a frame's binding: maps not bound again until end_frame() are dropped.
  void begin_frame() { ++frame_; }
  // The map of an asset for kernel radius h and SDF level `level` (boundary_map.h), computed on
  // `parallel`'s workers when new or stale.
  const Float4* bind(const SdfAsset& asset, float h, float level, const CpuParallel& parallel);
  void end_frame();
  // 16 bytes per voxel of every map held.
  uint64_t bytes() const;
  // Maps computed since the backend was made (tests: a changed asset recomputes, an unchanged
  // one does not).
  uint64_t builds() const { return builds_; }

 private:
  struct Entry {
    uint64_t version = 0;
    float kernel_radius = 0.0f;
    uint64_t last_frame = 0;
    HostVector<Float4> correction;
  };
  using Key = std::pair<uint64_t, float>;
  std::map<Key, Entry, std::less<Key>, HostAllocator<std::pair<const Key, Entry>>>
      entries_;  // by asset uid and level
  uint64_t frame_ = 0;
  uint64_t builds_ = 0;
};

// The map of an asset for kernel radius h and SDF level `level` (every voxel; zero outside the band
// |phi - level| < h), on `parallel`'s workers. Exposed for tests, which compare it with a
// brute-force integral.
HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel);

// A bound on the slope of the asset's sample_distance along any local direction, from its values:
// the trilinear interpolant's slope along an index axis is a mix of the differences of
// neighbouring values along it, so it is at most their largest magnitude D_a (per index step);
// outside the grid the distance to the grid's box adds at most min_voxel_size per index step; and
// index_to_local's inverse stretches a local step by at most the square root of its matrix's
// largest row sum times its largest column sum. The result is rounded up; a grid holding a
// non-finite value gives none (0). compute_boundary_map uses it to skip ray samples that cannot
// reach the solid (boundary_map.h, integrate_rays); exposed for tests.
SdfSlope sdf_slope(const SdfAsset& asset, const CpuParallel& parallel);

}  // namespace sph
