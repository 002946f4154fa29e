// SPDX-License-Identifier: MIT
#include "cpu_neighbor_columns.h"

namespace sph {

namespace {

// Sizes a column for n particles plus the padding, which is zero (finite, and masked off). The
// first n elements are written by the passes before anything reads them (a distributed rank's
// spring ghosts' density and normal slots excepted: no pass writes them, and a gather loads them
// only in lanes its mask turns off, whose values select drops).
void size_column(HostVector<float>& column, uint32_t n, bool keep) {
  if (!keep) return column.clear();
  column.reserve(n + kLanePadding);
  column.resize(n);
  column.resize(n + kLanePadding, 0.0f);
}

const float* data_or_null(const HostVector<float>& column) {
  return column.empty() ? nullptr : column.data();
}

}  // namespace

void CpuNeighborColumns::resize(uint32_t n) {
  for (HostVector<float>* c : {&x_, &y_, &z_, &vx_, &vy_, &vz_, &pressure_, &inv_density_})
    size_column(*c, n, true);
  size_column(neighbor_count_, n, counts_);
  for (HostVector<float>* c : {&normal_x_, &normal_y_, &normal_z_, &normal_length_})
    size_column(*c, n, normals_);
}

NeighborColumns CpuNeighborColumns::view() const {
  return NeighborColumns{x_.data(),
                         y_.data(),
                         z_.data(),
                         vx_.data(),
                         vy_.data(),
                         vz_.data(),
                         pressure_.data(),
                         inv_density_.data(),
                         data_or_null(neighbor_count_),
                         data_or_null(normal_x_),
                         data_or_null(normal_y_),
                         data_or_null(normal_z_),
                         data_or_null(normal_length_)};
}

size_t CpuNeighborColumns::bytes() const {
  size_t total = 0;
  for (const HostVector<float>* c : {&x_, &y_, &z_, &vx_, &vy_, &vz_, &pressure_, &inv_density_,
                                     &neighbor_count_, &normal_x_, &normal_y_, &normal_z_, &normal_length_})
    total += c->capacity() * sizeof(float);
  return total;
}

}  // namespace sph
