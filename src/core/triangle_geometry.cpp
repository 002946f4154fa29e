// SPDX-License-Identifier: MIT
#include "triangle_geometry.h"

#include <algorithm>
#include <cmath>

namespace sph {
namespace {

using V3 = Eigen::Vector3d;

double point_segment_distance(const V3& p, const V3& a, const V3& b) {
  const V3 ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

}  // namespace

MeshTriangle make_mesh_triangle(const V3& a, const V3& b, const V3& c) {
  MeshTriangle t{a, b, c, false};
  const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  const double area2 = (b - a).cross(c - a).norm();  // twice the area
  t.degenerate = !(area2 > 1e-12 * longest2);
  return t;
}

// Ericson, Real-Time Collision Detection (2005) 5.1.5: the closest point by the Voronoi region
// of p (corner, edge or face) from the barycentric numerators; exact, no iteration.
double point_triangle_distance(const V3& p, const MeshTriangle& t) {
  const V3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  // The barycentric numerators below (va, vb, vc) are differences of products of about
  // |edge|^2 |ap|^2 whose sum is |ab x ac|^2, about |edge|^4: for a triangle far smaller than its
  // distance from p they cancel to noise (the sum came out 0 and 0 / 0 NaN for a 1e-45 m triangle
  // seen from 0.04 m, leaving voxels of its SDF infinite). Under 1e-7 of the distance (a relative
  // error of at most about 1e-2 in the sum above it), the closest point of the edges is within the
  // longest edge, 1e-7 of the distance, of the exact one.
  const double longest2 = std::max({ab.squaredNorm(), ac.squaredNorm(), (t.c - t.b).squaredNorm()});
  if (t.degenerate || longest2 < 1e-14 * ap.squaredNorm())
    return std::min({point_segment_distance(p, t.a, t.b), point_segment_distance(p, t.b, t.c),
                     point_segment_distance(p, t.c, t.a)});
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.norm();
  const V3 bp = p - t.b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (p - (t.a + (d1 / (d1 - d3)) * ab)).norm();
  const V3 cp = p - t.c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (p - (t.a + (d2 / (d2 - d6)) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return (p - (t.b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (t.c - t.b))).norm();
  const double denominator = 1.0 / (va + vb + vc);
  return (p - (t.a + ab * (vb * denominator) + ac * (vc * denominator))).norm();
}

double triangle_solid_angle(const V3& p, const MeshTriangle& t) {
  if (t.degenerate) return 0.0;
  const V3 a = t.a - p, b = t.b - p, c = t.c - p;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2.0 * std::atan2(numerator, denominator);
}

}  // namespace sph
