// SPDX-License-Identifier: MIT
// The generalised winding number of a triangle soup (Jacobson, Kavan & Sorkine-Hornung 2013):
// w(p) = sum of the triangles' solid angles / 4 pi, 1 inside a closed outward mesh, 0 outside,
// and near 1/2 only close to the surface or across a hole, so thresholding it at 1/2 signs
// the inside of meshes with small holes, gaps and overlaps. Far triangle clusters are summed
// as one dipole (Barill et al. 2018, "Fast winding numbers for soups and clouds", order 1),
// so a query costs about log(triangles) plus the triangles near it.
#pragma once

#include <stdint.h>

#include <vector>

#include "host_memory.h"
#include "triangle_geometry.h"

namespace sph {

class WindingNumber {
 public:
  // Keeps a reference to `triangles`, which must outlive this object.
  explicit WindingNumber(const HostVector<MeshTriangle>& triangles);

  double at(const Eigen::Vector3d& p) const;

 private:
  struct Node {
    Eigen::Vector3d centre;       // area-weighted centroid of its triangles
    Eigen::Vector3d area_normal;  // sum of the triangles' area vectors (1/2 (b - a) x (c - a))
    double radius = 0.0;          // the farthest corner from centre
    uint32_t first = 0, count = 0;
    int32_t left = -1, right = -1;  // children; -1 in a leaf
  };
  int32_t build(uint32_t first, uint32_t count);

  const HostVector<MeshTriangle>& triangles_;
  HostVector<uint32_t> order_;
  HostVector<Node> nodes_;
};

}  // namespace sph
