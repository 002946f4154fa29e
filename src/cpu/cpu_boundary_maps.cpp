// SPDX-License-Identifier: MIT
#include "cpu_boundary_maps.h"

#include <cmath>

#include "../physics/boundary_map.h"

namespace sph {

SdfSlope sdf_slope(const SdfAsset& asset, const CpuParallel& parallel) {
  const SdfGridView g = asset.host_view();
  const size_t nx = static_cast<size_t>(g.nx), ny = static_cast<size_t>(g.ny), nz = static_cast<size_t>(g.nz);
  // A cell's lower corner runs over every voxel but the last along each axis that has more than one.
  const size_t cx = nx > 1 ? nx - 1 : 1, cy = ny > 1 ? ny - 1 : 1, cz = nz > 1 ? nz - 1 : 1;
  const size_t di = nx > 1 ? 1 : 0, dj = ny > 1 ? nx : 0, dk = nz > 1 ? nx * ny : 0;
  struct Slopes {
    double inside = 0.0;    // the largest squared index-space slope bound of a cell
    double boundary = 0.0;  // the same over the cells on the grid's faces
    bool finite = true;
  };
  const size_t rows = cy * cz;
  HostVector<Slopes> per_block((rows + 15) / 16);
  parallel.for_blocks(rows, 16, [&](size_t first, size_t last) {
    Slopes s;
    for (size_t row = first; row < last; ++row) {
      const size_t j = row % cy, k = row / cy;
      for (size_t i = 0; i < cx; ++i) {
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
  Slopes all;
  for (const Slopes& s : per_block) {
    all.finite = all.finite && s.finite;
    all.inside = std::fmax(all.inside, s.inside), all.boundary = std::fmax(all.boundary, s.boundary);
  }
  if (!all.finite) return SdfSlope{};
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

HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel) {
  HostVector<Float4> map(asset.voxel_count(), Float4{0.0f, 0.0f, 0.0f, 0.0f});
  const SdfGridView g = asset.host_view();
  const Affine3x4 index_to_local = asset.index_to_local();
  const SdfSlope slope = sdf_slope(asset, parallel);
  const size_t planes = static_cast<size_t>(asset.ny()) * static_cast<size_t>(asset.nz());
  const size_t nx = static_cast<size_t>(asset.nx());
  // One (j, k) row of voxels per item, four rows a block: the band's rows cost far more than the
  // rest, so small blocks go out on demand.
  parallel.for_blocks(planes, 4, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const int32_t j = static_cast<int32_t>(row % asset.ny()), k = static_cast<int32_t>(row / asset.ny());
      for (int32_t i = 0; i < asset.nx(); ++i)
        map[static_cast<size_t>(i) + nx * row].x =
            boundary_map_correction(g, index_to_local, i, j, k, h, level, slope);
    }
  });
  // The slopes from the values: all values are in place before any slope is written, and a slope
  // writes only its own voxel's gradient channels.
  parallel.for_blocks(planes, 64, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const int32_t j = static_cast<int32_t>(row % asset.ny()), k = static_cast<int32_t>(row / asset.ny());
      for (int32_t i = 0; i < asset.nx(); ++i) {
        const Vec3 s = boundary_map_slope(g, map.data(), i, j, k, h, level);
        Float4& m = map[static_cast<size_t>(i) + nx * row];
        m.y = s.x, m.z = s.y, m.w = s.z;
      }
    }
  });
  return map;
}

const Float4* CpuBoundaryMaps::bind(const SdfAsset& asset, float h, float level,
                                    const CpuParallel& parallel) {
  Entry& e = entries_[std::make_pair(asset.uid(), level)];
  e.last_frame = frame_;
  if (e.version != asset.version() || e.kernel_radius != h || e.correction.size() != asset.voxel_count()) {
    e.version = 0;  // until the map below is complete
    e.correction = compute_boundary_map(asset, h, level, parallel);
    e.kernel_radius = h;
    e.version = asset.version();
    ++builds_;
  }
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
  for (const auto& kv : entries_) total += kv.second.correction.size() * sizeof(Float4);
  return total;
}

}  // namespace sph
