// SPDX-License-Identifier: MIT
#include "sdf_asset.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "status.h"

namespace sph {
namespace {

std::atomic<uint64_t> g_next_uid{1};

Eigen::Matrix4d to_matrix(const Affine3x4& a) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = a.m[r * 4 + c];
  return m;
}

Affine3x4 from_matrix(const Eigen::Matrix4d& m) {
  Affine3x4 a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.m[r * 4 + c] = static_cast<float>(m(r, c));
  return a;
}

}  // namespace

SdfAsset::SdfAsset(int32_t nx, int32_t ny, int32_t nz, const Affine3x4& index_to_local)
    : nx_(nx), ny_(ny), nz_(nz), index_to_local_(index_to_local), uid_(g_next_uid.fetch_add(1)) {
  if (nx < 1 || ny < 1 || nz < 1) throw Error(Status::InvalidArgument, "dims: every dimension must be >= 1");
  for (float v : index_to_local.m)
    if (!std::isfinite(v)) throw Error(Status::InvalidArgument, "index_to_local: has a non-finite entry");
  const Eigen::Matrix4d m = to_matrix(index_to_local);
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  const double det = linear.determinant();
  const double scale = linear.cwiseAbs().maxCoeff();
  if (!(std::fabs(det) > 1e-12 * scale * scale * scale) || !std::isfinite(det))
    throw Error(Status::InvalidArgument, "index_to_local: the linear part is singular");
  local_to_index_ = from_matrix(m.inverse());
  // A voxel near float's smallest (a denormal) inverts to infinity, and every sample to NaN.
  for (float v : local_to_index_.m)
    if (!std::isfinite(v))
      throw Error(Status::InvalidArgument, "index_to_local: its inverse (local to index) overflows float");
  // The shortest voxel edge: the smallest column norm of the linear part.
  min_voxel_size_ = static_cast<float>(linear.colwise().norm().minCoeff());
  if (!(min_voxel_size_ > 0.0f) || !std::isfinite(min_voxel_size_))
    throw Error(Status::InvalidArgument, "index_to_local: voxel size is not representable in float");
  distance_.assign(voxel_count(), 0.0f);
}

double SdfAsset::max_voxel_size() const {
  return to_matrix(index_to_local_).topLeftCorner<3, 3>().colwise().norm().maxCoeff();
}

bool SdfAsset::has_moving_surface() const {
  for (const Vec3& v : velocity_)
    if (v.x != 0.0f || v.y != 0.0f || v.z != 0.0f) return true;
  return false;
}

SdfGridView SdfAsset::view_with(const float* distance, const Vec3* velocity, const float* friction) const {
  SdfGridView v;
  v.distance = distance;
  v.velocity = velocity;
  v.friction = friction;
  v.nx = nx_;
  v.ny = ny_;
  v.nz = nz_;
  v.local_to_index = local_to_index_;
  v.min_voxel_size = min_voxel_size_;
  return v;
}

SdfGridView SdfAsset::host_view() const {
  return view_with(distance_.data(), velocity_.empty() ? nullptr : velocity_.data(),
                   friction_.empty() ? nullptr : friction_.data());
}

VoxelBox SdfAsset::whole_grid() const {
  VoxelBox box;
  box.hi[0] = nx_, box.hi[1] = ny_, box.hi[2] = nz_;
  return box;
}

void SdfAsset::record_change(const VoxelBox& distance_box) {
  std::lock_guard<std::mutex> lock(changes_mutex_);
  const uint64_t version = version_.fetch_add(1) + 1;
  changes_[version % kChangesKept] = Change{version, distance_box};
}

bool SdfAsset::distance_changed_since(uint64_t version, VoxelBox* out) const {
  std::lock_guard<std::mutex> lock(changes_mutex_);
  const uint64_t now = version_.load();
  if (version > now || now - version > static_cast<uint64_t>(kChangesKept)) return false;
  VoxelBox box;
  for (uint64_t v = version + 1; v <= now; ++v) {
    const Change& c = changes_[v % kChangesKept];
    if (c.version != v) return false;
    box = box.joined(c.distance_box);
  }
  *out = box;
  return true;
}

}  // namespace sph
