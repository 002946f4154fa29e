// SPDX-License-Identifier: MIT
// Host geometry of one triangle for building SDFs from meshes: the exact distance from a point
// and the signed solid angle it subtends (the generalised winding number's term).
#pragma once

#include <Eigen/Dense>

namespace sph {

struct MeshTriangle {
  Eigen::Vector3d a, b, c;
  // No usable plane (zero area, or collinear within rounding): distances are to its edges.
  bool degenerate = false;
};

// Fills `degenerate` from the corners (a triangle whose area is below 1e-12 of its longest
// edge squared has no reliable normal).
MeshTriangle make_mesh_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

// The exact Euclidean distance from p to the closed triangle (its face, edges and corners).
double point_triangle_distance(const Eigen::Vector3d& p, const MeshTriangle& t);

// The solid angle (steradians) of the triangle seen from p, positive when p lies behind the
// face of the counter-clockwise (a, b, c) normal: Van Oosterom & Strackee (1983),
// tan(Omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|) with a, b, c the
// corners relative to p. Summed over a closed outward mesh it is 4 pi inside and 0 outside.
double triangle_solid_angle(const Eigen::Vector3d& p, const MeshTriangle& t);

}  // namespace sph
