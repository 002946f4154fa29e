// SPDX-License-Identifier: MIT
#include "winding_number.h"

#include <algorithm>
#include <cmath>

namespace sph {
namespace {

using V3 = Eigen::Vector3d;

constexpr uint32_t kLeafTriangles = 8;
// A cluster counts as far when p is beyond kFarRatio times its radius: Barill et al.'s beta = 2,
// which keeps the dipole's error below about 1e-2 of w, far from the 1/2 threshold.
constexpr double kFarRatio = 2.0;
constexpr double kFourPi = 4.0 * 3.14159265358979323846;

V3 centroid(const MeshTriangle& t) { return (t.a + t.b + t.c) / 3.0; }

}  // namespace

WindingNumber::WindingNumber(const HostVector<MeshTriangle>& triangles) : triangles_(triangles) {
  order_.resize(triangles.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  nodes_.reserve(2 * (triangles.size() / kLeafTriangles + 1));
  if (!triangles.empty()) build(0, static_cast<uint32_t>(triangles.size()));
}

int32_t WindingNumber::build(uint32_t first, uint32_t count) {
  const int32_t index = static_cast<int32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.first = first;
  node.count = count;
  node.centre.setZero();
  node.area_normal.setZero();
  double area_sum = 0.0;
  V3 plain_mean = V3::Zero();
  V3 low = V3::Constant(INFINITY), high = V3::Constant(-INFINITY);
  for (uint32_t i = first; i < first + count; ++i) {
    const MeshTriangle& t = triangles_[order_[i]];
    const V3 area_vector = 0.5 * (t.b - t.a).cross(t.c - t.a);
    const double area = area_vector.norm();
    node.area_normal += area_vector;
    node.centre += area * centroid(t);
    area_sum += area;
    plain_mean += centroid(t);
    low = low.cwiseMin(centroid(t));
    high = high.cwiseMax(centroid(t));
  }
  node.centre = area_sum > 0.0 ? V3(node.centre / area_sum) : V3(plain_mean / count);
  for (uint32_t i = first; i < first + count; ++i) {
    const MeshTriangle& t = triangles_[order_[i]];
    node.radius = std::max(
        {node.radius, (t.a - node.centre).norm(), (t.b - node.centre).norm(), (t.c - node.centre).norm()});
  }
  if (count > kLeafTriangles) {
    Eigen::Index axis = 0;
    (high - low).maxCoeff(&axis);
    const uint32_t half = count / 2;
    std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                     [&](uint32_t x, uint32_t y) {
                       return centroid(triangles_[x])[axis] < centroid(triangles_[y])[axis];
                     });
    node.left = build(first, half);
    node.right = build(first + half, count - half);
  }
  nodes_[index] = node;
  return index;
}

double WindingNumber::at(const V3& p) const {
  if (nodes_.empty()) return 0.0;
  double solid_angle = 0.0;
  HostVector<int32_t> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    const V3 to_cluster = node.centre - p;
    const double distance = to_cluster.norm();
    if (distance > kFarRatio * node.radius) {
      // The cluster seen from afar: a dipole of its summed area vector at its centre.
      solid_angle += node.area_normal.dot(to_cluster) / (distance * distance * distance);
    } else if (node.left < 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i)
        solid_angle += triangle_solid_angle(p, triangles_[order_[i]]);
    } else {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
  return solid_angle / kFourPi;
}

}  // namespace sph
