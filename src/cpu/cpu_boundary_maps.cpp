// SPDX-License-Identifier: MIT
#include "cpu_boundary_maps.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "../physics/boundary_map.h"

namespace sph {

SdfSlopeMaxima sdf_slope_maxima(const SdfAsset& asset, const VoxelBox& voxels, const CpuParallel& parallel) {
  const SdfGridView g = asset.host_view();
  const size_t nx = static_cast<size_t>(g.nx), ny = static_cast<size_t>(g.ny), nz = static_cast<size_t>(g.nz);
  // A cell's lower corner runs over every voxel but the last along each axis that has more than one.
  const size_t cx = nx > 1 ? nx - 1 : 1, cy = ny > 1 ? ny - 1 : 1, cz = nz > 1 ? nz - 1 : 1;
  const size_t di = nx > 1 ? 1 : 0, dj = ny > 1 ? nx : 0, dk = nz > 1 ? nx * ny : 0;
  // The cells holding a voxel of the box: lower corners from a voxel below it to its last.
  const size_t cells[3] = {cx, cy, cz};
  size_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = voxels.lo[a] > 0 ? static_cast<size_t>(voxels.lo[a]) - 1 : 0;
    hi[a] = std::min(cells[a], static_cast<size_t>(std::max(voxels.hi[a], 0)));
    if (hi[a] <= lo[a]) return SdfSlopeMaxima{};
  }
  const size_t row_length = hi[1] - lo[1];
  const size_t rows = row_length * (hi[2] - lo[2]);
  HostVector<SdfSlopeMaxima> per_block((rows + 15) / 16);
  parallel.for_blocks(rows, 16, [&](size_t first, size_t last) {
    SdfSlopeMaxima s;
    for (size_t row = first; row < last; ++row) {
      const size_t j = lo[1] + row % row_length, k = lo[2] + row / row_length;
      for (size_t i = lo[0]; i < hi[0]; ++i) {
        const float* c = g.distance + i + nx * (j + ny * k);
        const float v[8] = {c[0], c[di], c[dj], c[dj + di], c[dk], c[dk + di], c[dk + dj], c[dk + dj + di]};
        // Along each axis the interpolant's slope is a mix of the cell's four edge differences.
        double along[3] = {0.0, 0.0, 0.0};
        for (int e = 0; e < 4; ++e) {
          along[0] = std::fmax(along[0], std::fabs(static_cast<double>(v[2 * e + 1]) - v[2 * e]));
          const int y = (e & 1) + 4 * (e >> 1), z = (e & 1) + 2 * (e >> 1);
          along[1] = std::fmax(along[1], std::fabs(static_cast<double>(v[y + 2]) - v[y]));
          along[2] = std::fmax(along[2], std::fabs(static_cast<double>(v[z + 4]) - v[z]));
        }
        for (float value : v) s.finite = s.finite && std::isfinite(value);
        const double squared = along[0] * along[0] + along[1] * along[1] + along[2] * along[2];
        s.inside = std::fmax(s.inside, squared);
        const bool face = i == 0 || i + 1 >= cx || j == 0 || j + 1 >= cy || k == 0 || k + 1 >= cz;
        if (face) s.boundary = std::fmax(s.boundary, squared);
      }
    }
    per_block[first / 16] = s;
  });
  SdfSlopeMaxima all;
  for (const SdfSlopeMaxima& s : per_block) all.add(s);
  return all;
}

SdfSlope sdf_slope_from(const SdfAsset& asset, const SdfSlopeMaxima& all) {
  if (!all.finite) return SdfSlope{};
  const SdfGridView g = asset.host_view();
  // Outside the grid the clamped axes' part of the slope is the extension's (min_voxel_size per
  // index step along the way out, whatever axes it splits over), the others a face cell's.
  const double extension = static_cast<double>(g.min_voxel_size);
  const double index_slope = std::sqrt(std::fmax(all.inside, all.boundary + extension * extension));
  // |local_to_index|_2 <= sqrt(|.|_1 |.|_inf) of its linear part.
  double rows_max = 0.0, columns_max = 0.0;
  for (int r = 0; r < 3; ++r) {
    double row_sum = 0.0, column_sum = 0.0;
    for (int c = 0; c < 3; ++c) {
      row_sum += std::fabs(static_cast<double>(g.local_to_index.m[4 * r + c]));
      column_sum += std::fabs(static_cast<double>(g.local_to_index.m[4 * c + r]));
    }
    rows_max = std::fmax(rows_max, row_sum), columns_max = std::fmax(columns_max, column_sum);
  }
  const double bound = index_slope * std::sqrt(rows_max * columns_max) * (1.0 + 1e-6);
  if (!(bound > 0.0) || !(bound < 3.0e38)) return SdfSlope{};
  SdfSlope slope;
  slope.bound = std::nextafter(static_cast<float>(bound), INFINITY);
  // A voxel's diagonal is at most the sum of its three edges: the most a value changes across a cell.
  slope.cell_change = static_cast<float>(std::fmin(bound * 3.0 * asset.max_voxel_size(), 3.0e38));
  return slope;
}

SdfSlope sdf_slope(const SdfAsset& asset, const CpuParallel& parallel) {
  return sdf_slope_from(asset, sdf_slope_maxima(asset, asset.whole_grid(), parallel));
}

namespace {

// `box` grown by reach[a] voxels along each axis a, within the grid.
VoxelBox grown(const VoxelBox& box, const int64_t reach[3], const SdfAsset& asset) {
  const int32_t n[3] = {asset.nx(), asset.ny(), asset.nz()};
  VoxelBox out;
  for (int a = 0; a < 3; ++a) {
    out.lo[a] = static_cast<int32_t>(std::max<int64_t>(0, box.lo[a] - reach[a]));
    out.hi[a] = static_cast<int32_t>(std::min<int64_t>(n[a], box.hi[a] + reach[a]));
  }
  return out;
}

// Runs body(i, j, k, index) over the voxels of `box`, a (j, k) row of it per item, `rows` a block.
template <class Body>
void for_box(const SdfAsset& asset, const VoxelBox& box, size_t rows, const CpuParallel& parallel,
             Body&& body) {
  if (box.empty()) return;
  const size_t ny = static_cast<size_t>(box.hi[1] - box.lo[1]);
  const size_t nz = static_cast<size_t>(box.hi[2] - box.lo[2]);
  const size_t nx = static_cast<size_t>(asset.nx()), grid_ny = static_cast<size_t>(asset.ny());
  parallel.for_blocks(ny * nz, rows, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const int32_t j = box.lo[1] + static_cast<int32_t>(row % ny),
                    k = box.lo[2] + static_cast<int32_t>(row / ny);
      const size_t start = nx * (static_cast<size_t>(j) + grid_ny * static_cast<size_t>(k));
      for (int32_t i = box.lo[0]; i < box.hi[0]; ++i) body(i, j, k, start + static_cast<size_t>(i));
    }
  });
}

}  // namespace

VoxelBox changed_voxels(const SdfAsset& asset, const HostVector<float>& before, const VoxelBox& within,
                        const CpuParallel& parallel) {
  const VoxelBox box = within.intersected(asset.whole_grid());
  if (box.empty()) return VoxelBox{};
  const HostVector<float>& now = asset.distance();
  const size_t nx = static_cast<size_t>(asset.nx()), ny = static_cast<size_t>(asset.ny());
  const size_t row_length = static_cast<size_t>(box.hi[1] - box.lo[1]);
  const size_t rows = row_length * static_cast<size_t>(box.hi[2] - box.lo[2]);
  const size_t width = static_cast<size_t>(box.hi[0] - box.lo[0]);
  constexpr size_t kRows = 64;
  HostVector<VoxelBox> per_block((rows + kRows - 1) / kRows);
  parallel.for_blocks(rows, kRows, [&](size_t first, size_t last) {
    VoxelBox b;
    for (size_t row = first; row < last; ++row) {
      const int32_t j = box.lo[1] + static_cast<int32_t>(row % row_length);
      const int32_t k = box.lo[2] + static_cast<int32_t>(row / row_length);
      const size_t start = static_cast<size_t>(box.lo[0]) + nx * (static_cast<size_t>(j) + ny * k);
      const float* a = before.data() + start;
      const float* c = now.data() + start;
      if (std::memcmp(a, c, width * sizeof(float)) == 0) continue;
      int32_t lo = 0, hi = static_cast<int32_t>(width);
      while (std::memcmp(a + lo, c + lo, sizeof(float)) == 0) ++lo;
      while (std::memcmp(a + hi - 1, c + hi - 1, sizeof(float)) == 0) --hi;
      VoxelBox changed;
      changed.lo[0] = box.lo[0] + lo, changed.hi[0] = box.lo[0] + hi;
      changed.lo[1] = j, changed.hi[1] = j + 1, changed.lo[2] = k, changed.hi[2] = k + 1;
      b = b.joined(changed);
    }
    per_block[first / kRows] = b;
  });
  VoxelBox all;
  for (const VoxelBox& b : per_block) all = all.joined(b);
  return all;
}

VoxelBox update_boundary_map(const SdfAsset& asset, float h, float level, const CpuParallel& parallel,
                             const VoxelBox& changed, SdfSlope slope, HostVector<Float4>& map) {
  if (changed.empty()) return VoxelBox{};
  const SdfGridView g = asset.host_view();
  const Affine3x4 index_to_local = asset.index_to_local();
  // A voxel's correction reads the SDF along its rays (local distance h), for its normal (half a
  // voxel about it) and its flat share (its own cell): within h + a voxel of it, which along index
  // axis a is at most that times the norm of local_to_index's row a; the trilinear cell of a point
  // takes one voxel more, and one more covers the rounding of the points.
  const double reach_local = static_cast<double>(h) + g.min_voxel_size;
  int64_t reach[3];
  for (int a = 0; a < 3; ++a) {
    double row = 0.0;
    for (int c = 0; c < 3; ++c)
      row += static_cast<double>(g.local_to_index.m[4 * a + c]) * g.local_to_index.m[4 * a + c];
    const double voxels = std::ceil(reach_local * std::sqrt(row) * (1.0 + 1e-5)) + 2.0;
    reach[a] = voxels < 1e9 ? static_cast<int64_t>(voxels) : int64_t{1000000000};
  }
  const VoxelBox values = grown(changed, reach, asset);
  // One (j, k) row of voxels per item, four rows a block: the band's rows cost far more than the
  // rest, so small blocks go out on demand.
  for_box(asset, values, 4, parallel, [&](int32_t i, int32_t j, int32_t k, size_t v) {
    map[v].x = boundary_map_correction(g, index_to_local, i, j, k, h, level, slope);
  });
  // The slopes from the values (central differences: a voxel's own and its neighbours'): all
  // values are in place before any slope is written, and a slope writes only its own voxel's
  // gradient channels.
  const int64_t one[3] = {1, 1, 1};
  for_box(asset, grown(values, one, asset), 64, parallel, [&](int32_t i, int32_t j, int32_t k, size_t v) {
    const Vec3 s = boundary_map_slope(g, map.data(), i, j, k, h, level);
    map[v].y = s.x, map[v].z = s.y, map[v].w = s.z;
  });
  return values;
}

HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel) {
  HostVector<Float4> map(asset.voxel_count(), Float4{0.0f, 0.0f, 0.0f, 0.0f});
  update_boundary_map(asset, h, level, parallel, asset.whole_grid(), sdf_slope(asset, parallel), map);
  return map;
}

const Float4* CpuBoundaryMaps::bind(const SdfAsset& asset, float h, float level,
                                    const CpuParallel& parallel) {
  Entry& e = entries_[std::make_pair(asset.uid(), level)];
  e.last_frame = frame_;
  const uint64_t voxels = asset.voxel_count();
  if (e.version == asset.version() && e.kernel_radius == h && e.correction.size() == voxels)
    return e.correction.data();
  const uint64_t version = asset.version();
  const VoxelBox whole = asset.whole_grid();
  // A map of this h that was complete (version 0 marks one whose computation failed) for other
  // values of the same asset (an asset's dims and transform never change): what changed since.
  VoxelBox changed = whole;
  const bool stale = e.version != 0 && e.kernel_radius == h && e.correction.size() == voxels;
  if (stale && !asset.distance_changed_since(e.version, &changed)) changed = whole;
  if (stale && e.computed_from.size() == voxels)
    changed = changed_voxels(asset, e.computed_from, changed, parallel);
  e.version = 0;  // until the map below is complete
  if (!stale) {
    e.computed_from.clear();
    e.correction.assign(voxels, Float4{0.0f, 0.0f, 0.0f, 0.0f});
  }
  if (changed.voxels() == voxels) {
    e.slope = sdf_slope_maxima(asset, whole, parallel);
    ++builds_;
  } else {
    e.slope.add(sdf_slope_maxima(asset, changed, parallel));
  }
  voxels_computed_ +=
      update_boundary_map(asset, h, level, parallel, changed, sdf_slope_from(asset, e.slope), e.correction)
          .voxels();
  // Keep the distances in step (only the changed box differs), or start keeping them when more
  // than half the grid changed at once (an asset re-sent whole: the next comparison narrows it).
  if (e.computed_from.size() == voxels) {
    const size_t nx = static_cast<size_t>(asset.nx()), ny = static_cast<size_t>(asset.ny());
    for (int32_t k = changed.lo[2]; k < changed.hi[2]; ++k)
      for (int32_t j = changed.lo[1]; j < changed.hi[1]; ++j) {
        const size_t start = static_cast<size_t>(changed.lo[0]) + nx * (static_cast<size_t>(j) + ny * k);
        std::copy(asset.distance().begin() + start,
                  asset.distance().begin() + start + static_cast<size_t>(changed.hi[0] - changed.lo[0]),
                  e.computed_from.begin() + start);
      }
  } else if (stale && changed.voxels() > voxels / 2) {
    e.computed_from = asset.distance();
  }
  e.kernel_radius = h;
  e.version = version;
  return e.correction.data();
}

void CpuBoundaryMaps::end_frame() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.last_frame != frame_)
      it = entries_.erase(it);
    else
      ++it;
  }
}

uint64_t CpuBoundaryMaps::bytes() const {
  uint64_t total = 0;
  for (const auto& kv : entries_)
    total += kv.second.correction.size() * sizeof(Float4) + kv.second.computed_from.size() * sizeof(float);
  return total;
}

}  // namespace sph
