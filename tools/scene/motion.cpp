// SPDX-License-Identifier: MIT
#include "motion.h"

#include <cmath>

#include "geometry.h"

namespace sph_tools {

namespace {

sph_vec3 catmull_rom(sph_vec3 p0, sph_vec3 p1, sph_vec3 p2, sph_vec3 p3, double t0, double t1, double t2,
                     double t3, float u) {
  // Non-uniform Catmull-Rom in Hermite form: tangents from the neighbouring keys' times.
  const float d1 = static_cast<float>(t2 - t1);
  const sph_vec3 m1 = (p2 - p0) * (d1 / static_cast<float>(t2 - t0));
  const sph_vec3 m2 = (p3 - p1) * (d1 / static_cast<float>(t3 - t1));
  const float u2 = u * u, u3 = u2 * u;
  return p1 * (2 * u3 - 3 * u2 + 1) + m1 * (u3 - 2 * u2 + u) + p2 * (-2 * u3 + 3 * u2) + m2 * (u3 - u2);
}

}  // namespace

sph_transform Motion::at(double t) const {
  const size_t n = keys.size();
  const double first = keys.front().time, last = keys.back().time;
  if (n == 1) return keys.front().transform;
  if (loop && last > first) {
    t = first + std::fmod(t - first, last - first);
    if (t < first) t += last - first;
  }
  if (t <= first) return keys.front().transform;
  if (t >= last) return keys.back().transform;
  size_t i = 0;
  while (i + 2 < n && keys[i + 1].time <= t) ++i;
  const Keyframe& a = keys[i];
  const Keyframe& b = keys[i + 1];
  const float u = static_cast<float>((t - a.time) / (b.time - a.time));
  sph_transform out;
  if (interpolation == Interpolation::kLinear) {
    out.position = a.transform.position + (b.transform.position - a.transform.position) * u;
    out.rotation = quat_slerp(a.transform.rotation, b.transform.rotation, u);
    return out;
  }
  // Neighbouring keys; at the ends, a looping motion wraps around (its last key repeats its
  // first), a held one mirrors the segment so the tangent there is the segment's own slope.
  auto key = [&](long j, double* time) -> sph_vec3 {
    const double period = last - first;
    if (j < 0) {
      if (loop) {
        *time = keys[n - 2].time - period;
        return keys[n - 2].transform.position;
      }
      *time = 2 * keys[0].time - keys[1].time;
      return keys[0].transform.position * 2.0f - keys[1].transform.position;
    }
    if (j >= static_cast<long>(n)) {
      if (loop) {
        *time = keys[1].time + period;
        return keys[1].transform.position;
      }
      *time = 2 * keys[n - 1].time - keys[n - 2].time;
      return keys[n - 1].transform.position * 2.0f - keys[n - 2].transform.position;
    }
    *time = keys[j].time;
    return keys[j].transform.position;
  };
  double t0, t1, t2, t3;
  const long li = static_cast<long>(i);
  const sph_vec3 p0 = key(li - 1, &t0), p1 = key(li, &t1), p2 = key(li + 1, &t2), p3 = key(li + 2, &t3);
  out.position = catmull_rom(p0, p1, p2, p3, t0, t1, t2, t3, u);
  out.rotation = quat_slerp(a.transform.rotation, b.transform.rotation, u);
  return out;
}

}  // namespace sph_tools
