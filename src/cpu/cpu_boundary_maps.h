// SPDX-License-Identifier: MIT
// The CPU backend's boundary-density maps (SPH_FEATURE_BOUNDARY_DENSITY; the physics is
// src/physics/boundary_map.h): one map per SDF asset the world's colliders use, computed on host
// threads for the world's kernel radius when a collider first steps with the asset and again
// after every change of it (SdfAsset::version: sph_sdf_update), and dropped when no collider uses
// the asset any more (the twin of cuda/device_boundary_maps.h). After a change a map recomputes
// only the voxels within reach of the box the change touched (the asset records each change's box:
// a terrain dug in one place recomputes the dig's reach, a velocity-only update nothing), with the
// bits a whole recomputation gives; a map whose asset is sent whole (a deforming body re-sent
// every frame) keeps the distances it was computed from and narrows that box to the voxels whose
// value changed.
#pragma once

#include <stdint.h>

#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "../core/host_memory.h"
#include "../core/sdf_asset.h"
#include "../core/voxel_box.h"
#include "../physics/float4_types.h"
#include "cpu_parallel.h"

namespace sph {

// What sdf_slope takes from the cells' values (below): the largest squared index-space slope bound
// of a cell, the same over the cells on the grid's faces, and whether every value was finite.
struct SdfSlopeMaxima {
  double inside = 0.0;
  double boundary = 0.0;
  bool finite = true;
  void add(const SdfSlopeMaxima& o) {
    inside = inside > o.inside ? inside : o.inside;
    boundary = boundary > o.boundary ? boundary : o.boundary;
    finite = finite && o.finite;
  }
};

class CpuBoundaryMaps {
 public:
  // Marks the start of a frame's binding: maps not bound again until end_frame() are dropped.
  void begin_frame() { ++frame_; }
  // The map of an asset for kernel radius h and SDF level `level` (boundary_map.h), computed on
  // `parallel`'s workers when new or stale.
  const Float4* bind(const SdfAsset& asset, float h, float level, const CpuParallel& parallel);
  void end_frame();
  // 16 bytes per voxel of every map held, and 4 more for a map that keeps its distances.
  uint64_t bytes() const;
  // Whole maps computed since the backend was made (tests: a changed asset recomputes, an
  // unchanged one does not), and the voxels whose correction was computed (a part counts its box).
  uint64_t builds() const { return builds_; }
  uint64_t voxels_computed() const { return voxels_computed_; }

 private:
  struct Entry {
    uint64_t version = 0;
    float kernel_radius = 0.0f;
    uint64_t last_frame = 0;
    HostVector<Float4> correction;
    // What the slope bound of `correction`'s rays was made from (every cell's, or more).
    SdfSlopeMaxima slope;
    // The distances `correction` was computed from, kept once a change of more than half the grid
    // came (a body re-sent whole every frame: the next comparison finds what moved); else empty.
    HostVector<float> computed_from;
  };
  using Key = std::pair<uint64_t, float>;
  std::map<Key, Entry, std::less<Key>, HostAllocator<std::pair<const Key, Entry>>>
      entries_;  // by asset uid and level
  uint64_t frame_ = 0;
  uint64_t builds_ = 0;
  uint64_t voxels_computed_ = 0;
};

// The smallest box holding every voxel of `within` whose distance differs, bit for bit, between
// `before` (the asset's voxel count of values) and the asset's distances now.
VoxelBox changed_voxels(const SdfAsset& asset, const HostVector<float>& before, const VoxelBox& within,
                        const CpuParallel& parallel);

// The map of an asset for kernel radius h and SDF level `level` (every voxel; zero outside the band
// |phi - level| < h), on `parallel`'s workers. Exposed for tests, which compare it with a
// brute-force integral.
HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel);
// Brings `map`, computed from other distances of the same asset (same dims, transform, h and level),
// up to date after the distances in `changed` were changed: recomputes the corrections of the
// voxels within reach of `changed` (a voxel's rays reach h, its normal and flat share a voxel more)
// and the slopes of those and their neighbours; the others keep theirs, which do not depend on the
// changed values. slope: a bound for the asset's values now (the rays' skip; any valid bound gives
// the same bits). The same bits as compute_boundary_map. Returns the box whose corrections it computed.
VoxelBox update_boundary_map(const SdfAsset& asset, float h, float level, const CpuParallel& parallel,
                             const VoxelBox& changed, SdfSlope slope, HostVector<Float4>& map);

// A bound on the slope of the asset's sample_distance along any local direction, from its values:
// the trilinear interpolant's slope along an index axis is a mix of the differences of
// neighbouring values along it, so it is at most their largest magnitude D_a (per index step);
// outside the grid the distance to the grid's box adds at most min_voxel_size per index step; and
// index_to_local's inverse stretches a local step by at most the square root of its matrix's
// largest row sum times its largest column sum. The result is rounded up; a grid holding a
// non-finite value gives none (0). compute_boundary_map uses it to skip ray samples that cannot
// reach the solid (boundary_map.h, integrate_rays); exposed for tests.
SdfSlope sdf_slope(const SdfAsset& asset, const CpuParallel& parallel);
// sdf_slope in two parts: the cells' maxima over the cells that hold a voxel of `voxels` (maxima
// of any cells combine by SdfSlopeMaxima::add, so after a change in a box a map adds that box's
// cells to what it had: the bound may then exceed the whole grid's, never fall below it), and the
// bound from maxima.
SdfSlopeMaxima sdf_slope_maxima(const SdfAsset& asset, const VoxelBox& voxels, const CpuParallel& parallel);
SdfSlope sdf_slope_from(const SdfAsset& asset, const SdfSlopeMaxima& maxima);

}  // namespace sph
