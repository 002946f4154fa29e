// SPDX-License-Identifier: MIT
// The CPU backend's boundary-density maps (SPH_FEATURE_BOUNDARY_DENSITY; the physics is
// src/physics/boundary_map.h): one map per SDF asset the world's colliders use, computed on host
// threads for the world's kernel radius when a collider first steps with the asset and again
// after every change of it (SdfAsset::version: sph_sdf_update), and dropped when no collider uses
// the asset any more (the twin of cuda/device_boundary_maps.h). From an asset's second change on,
// a map keeps the distances it was computed from and recomputes only the voxels within reach of
// those that changed (a terrain dug in one place, a velocity-only update: none), with the bits a
// whole recomputation gives.
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
  // 16 bytes per voxel of every map held, and 4 more for a changing asset's (computed_from).
  uint64_t bytes() const;
  // Maps computed since the backend was made (tests: a changed asset recomputes, an unchanged
  // one does not), and the voxels whose correction was computed (a partial update counts its box).
  uint64_t builds() const { return builds_; }
  uint64_t voxels_computed() const { return voxels_computed_; }

 private:
  struct Entry {
    uint64_t version = 0;
    float kernel_radius = 0.0f;
    uint64_t last_frame = 0;
    HostVector<Float4> correction;
    // The distances `correction` was computed from, kept once the asset has changed (a static
    // asset's map never needs them); empty otherwise.
    HostVector<float> computed_from;
  };
  using Key = std::pair<uint64_t, float>;
  std::map<Key, Entry, std::less<Key>, HostAllocator<std::pair<const Key, Entry>>>
      entries_;  // by asset uid and level
  uint64_t frame_ = 0;
  uint64_t builds_ = 0;
  uint64_t voxels_computed_ = 0;
};

// A box of voxels, [lo, hi) along each index axis; empty when any hi <= lo.
struct VoxelBox {
  int32_t lo[3] = {0, 0, 0};
  int32_t hi[3] = {0, 0, 0};
  bool empty() const { return !(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2]); }
  uint64_t voxels() const {
    return empty() ? 0 : static_cast<uint64_t>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  }
};

// The smallest box holding every voxel whose distance differs, bit for bit, between `before`
// (the asset's voxel count of values) and the asset's distances now.
VoxelBox changed_voxels(const SdfAsset& asset, const HostVector<float>& before, const CpuParallel& parallel);

// The map of an asset for kernel radius h and SDF level `level` (every voxel; zero outside the band
// |phi - level| < h), on `parallel`'s workers. Exposed for tests, which compare it with a
// brute-force integral.
HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel);
// Brings `map`, computed from other distances of the same asset (same dims, transform, h and level),
// up to date after the distances in `changed` were changed: recomputes the corrections of the
// voxels within reach of `changed` (a voxel's rays reach h, its normal and flat share a voxel more)
// and the slopes of those and their neighbours; the others keep theirs, which do not depend on the
// changed values. The same bits as compute_boundary_map. Returns the box whose corrections it computed.
VoxelBox update_boundary_map(const SdfAsset& asset, float h, float level, const CpuParallel& parallel,
                             const VoxelBox& changed, HostVector<Float4>& map);

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
